#pragma once
/// \file volume/octree_subdivision.hpp
/// What decides the shape of an irradiance volume's octree (volume/probe_octree.hpp): the
/// probes a source bakes at the cells' corners, Oat's subdivision heuristics with their
/// settings (ShaderX5 section 6.1, 2006), and the culling test that undoes a split whose
/// new probes the parent's trilinear interpolation already predicts.

#include <bounce/errors.hpp>
#include <bounce/luminance.hpp>
#include <bounce/scene_view.hpp>
#include <bounce/volume/hanging_corners.hpp>
#include <bounce/volume/kernels.hpp>
#include <bounce/volume/triangle_box_overlap.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline volume {

/// One probe: SH coefficients of the incoming radiance at `position` (W/(m^2 sr), RGB,
/// bands 0..2), their gradients per unit length, the harmonic mean distance to the
/// surfaces around it, and whether it lies inside geometry.
struct irradiance_probe {
    using coefficients = sh_coefficients<irradiance_volume_bands, glm::vec3>;
    glm::vec3 position{0.f};
    coefficients radiance{};
    /// d radiance / dx, dy, dz (per world unit); zero when the source computes none.
    std::array<coefficients, 3> gradient{};
    /// N / sum_j 1 / d_j over the source's rays (world units; +infinity when all miss).
    float harmonic_mean_distance = std::numeric_limits<float>::infinity();
    /// Inside geometry: flagged by the source, skipped by lookups and heuristics.
    bool inside = false;
    /// Set by the build: half the diagonal of the largest leaf this probe is a corner of
    /// (world units). The weighted lookup lets the probe reach support * reach.
    float reach = 0.f;
    /// Standard error of the probe's irradiance luminance (W/m^2) at the worst of the six
    /// axis normals, e.g. half the difference of two estimates from half the rays each
    /// (embree::probe_baker); 0 when the source has no noise or does not say. Subdivision
    /// treats differences within a few of these as noise (irradiance_volume_settings).
    float noise = 0.f;
};

/// Something that fills probes at positions: `source(positions, out)` with spans of equal
/// size (a batch per octree level, so a source can bake them in parallel).
template <class S>
concept probe_source = requires(S& s, std::span<const glm::vec3> positions, std::span<irradiance_probe> out) {
    s(positions, out);
};

/// How an adaptive irradiance volume finds its shape (irradiance_volume_settings::refinement).
enum class volume_refinement {
    /// Bake the finest uniform grid, then merge 8 leaves into their parent, from the finest
    /// level up, where the parent's trilinear interpolation predicts every baked probe in
    /// its box (prediction_tolerance, noise_sigmas): the decision sees every fine probe.
    merge,
    /// From the root down, try each cell's split and keep it where one of its 19 new probes
    /// is not predicted (prediction_tolerance, noise_sigmas); with prediction_tolerance 0,
    /// Oat's heuristics split and cull_tolerance culls.
    split,
};

/// The unit of irradiance_volume_settings::bias_tolerance.
enum class bias_tolerance_unit {
    scene_light,  ///< L: the mean band-0 irradiance luminance of the finest grid's probes outside geometry
    probe_noise,  ///< sigma: the median of those probes' noise (its standard error, times the calibration's scale)
};

/// The octree's shape and Oat's subdivision heuristics. A heuristic is off when its
/// threshold is 0. A cell at or above min_depth and below max_depth is split when any
/// fires, unless all its corners are inside geometry (nothing there to light).
struct irradiance_volume_settings {
    /// Depth every cell reaches (0: the root may stay a leaf). Uniform grid: min = max.
    int min_depth = 1;
    /// Depth no cell exceeds, 0 .. irradiance_volume::depth_limit (10). A uniform grid of
    /// depth D has (2^D + 1)^3 probes. Typical: 4-6.
    int max_depth = 4;
    /// Harmonic mean distance against cell size: split when a corner probe's harmonic mean
    /// distance is below distance_ratio times the cell's diagonal (lighting changes over
    /// about the distance to the surfaces a probe sees). Typical: 0.5-2; 0 off.
    float distance_ratio = 1.f;
    /// Change between neighbours: split when two corners' irradiance luminance (the band-0
    /// term, pi * c_00 Y_00) differ by more than this fraction of their mean (plus
    /// `absolute_floor`). Typical: 0.1-0.5; 0 off.
    float neighbour_change = 0.25f;
    /// Geometry inside the cell: split when at least this many triangles overlap the cell
    /// (exact triangle-box test). Typical: 1; 0 off.
    std::uint32_t geometry_triangles = 1;
    /// Gradient magnitude: split when |grad E| times the cell's longest edge exceeds this
    /// fraction of E at a corner (E: the band-0 irradiance luminance). Typical: 0.2-0.5;
    /// 0 off (and off for probes without gradients).
    float gradient_ratio = 0.3f;
    /// Culling: children are removed again when every new probe's irradiance at the six
    /// axis normals lies within this fraction (plus `absolute_floor`) of what the parent's
    /// trilinear interpolation predicts there, or within noise_sigmas standard errors.
    /// Typical: 0.02-0.1; 0 keeps every child.
    float cull_tolerance = 0.05f;
    /// Merging from the finest grid (the default) or splitting from the root; merging needs
    /// prediction_tolerance > 0 (with 0, Oat's heuristics split whatever this says).
    volume_refinement refinement = volume_refinement::merge;
    /// Subdivision by prediction error (issue 31), which replaces the four heuristics above
    /// when > 0: every cell with a corner outside geometry is tried, its children's new
    /// corners baked, and the split kept only where some new probe's irradiance at an axis
    /// normal differs from the parent's trilinear prediction by more than this fraction of
    /// the prediction (plus `absolute_floor`) *and* by more than noise_sigmas standard
    /// errors of the difference; otherwise the children are culled. Typical: 0.02-0.1;
    /// 0: Oat's heuristics propose and cull_tolerance culls.
    float prediction_tolerance = 0.05f;
    /// Differences within this many standard errors (from the probes' `noise`, pooled over
    /// the parent's corners and the new probes) are noise: they neither split nor keep a
    /// cell (at 4, noise alone splits about 1% of cells: 19 new probes each, at most
    /// 6e-5 of them beyond 4 standard errors). Typical: 3-5; 0 ignores the noise.
    float noise_sigmas = 4.f;
    /// Least-squares refit (issue 31): the probes baked for a split that culling undid are
    /// samples of the light inside the parent cell, which its corners interpolate within
    /// the noise; with this on, every kept probe becomes the least-squares fit of its own
    /// value and of those samples' trilinear interpolations (sweeps of Gauss-Seidel), which
    /// lowers the corners' noise instead of throwing the samples away. Off: the probes keep
    /// their baked values.
    bool refit_culled = true;
    /// Conforming corners (issue 31): a leaf corner on a face or edge of a coarser leaf (a
    /// T-junction) takes that leaf's interpolation there, so trilinear lookups are
    /// continuous across level boundaries; its baked value joins the refit's samples. Off:
    /// such corners keep their baked values and trilinear lookups jump at the boundary.
    bool conforming_corners = true;
    /// Merging (refinement merge) by a bias budget instead of the per-probe test, when > 0:
    /// a cell merges while the bias its interpolation adds (mean squared miss less the
    /// expected noise) stays below this fraction of the noise variance merging removes
    /// (cell_bias_within_budget). 1: break-even with the refit's noise reduction.
    float bias_budget = 0.f;
    /// Merging by an error target instead (issue 31, fourth session), when > 0: a cell
    /// merges while the bias its interpolation adds (the same estimate, noise taken out,
    /// noise_sigmas standard deviations of slack) stays below (bias_tolerance * L)^2, L the
    /// mean band-0 irradiance luminance of the finest grid's probes outside geometry: one
    /// bound in units of the scene's light for every cell, whatever its noise, so cells
    /// stay fine where the light departs from trilinear and merge where it does not.
    /// Replaces bias_budget's bound. Typical: 0.01-0.1.
    float bias_tolerance = 0.f;
    /// The unit of bias_tolerance (issue 31, fifth session): the scene's light L, or the
    /// median noise sigma of the finest grid's probes (the bound is then (t sigma)^2: an
    /// error target relative to what the probes resolve, derived from the bake).
    bias_tolerance_unit tolerance_unit = bias_tolerance_unit::scene_light;
    /// Where hanging corners live (with conforming_corners): a stored probe each, or none,
    /// computed by the trilinear lookup from the coarser leaf's corners (the same values;
    /// the weighted lookup, the visibility test and flatten() (GL) then refuse the volume).
    hanging_corner_storage hanging_corners = hanging_corner_storage::stored;
    /// With bias_budget or bias_tolerance: scale the probes' reported noise to what the finest grid's second
    /// differences support (noise_scale2).
    bool calibrate_noise = true;
    /// Absolute floor added to the denominators above, as a fraction of the mean
    /// luminance of the root's probes, so that dark regions do not split on noise.
    /// Typical: 0.02.
    float absolute_floor = 0.02f;
    /// Memory the build may use, in bytes (irradiance_volume::estimated_bytes); 0: no limit.
    /// Before baking a level the build counts the probes and nodes the volume will hold
    /// after it and throws parameter_error naming "settings.max_depth", with the figures,
    /// when their estimated_bytes exceed the limit. Programs pass
    /// the memory available (study::available_memory_bytes).
    std::uint64_t memory_limit_bytes = 0;
};

/// Counts of a build: which heuristic split how many cells, how many were culled.
struct irradiance_volume_build_stats {
    std::size_t split_min_depth = 0, split_distance = 0, split_neighbour = 0, split_geometry = 0, split_gradient = 0;
    std::size_t split_prediction = 0;  ///< cells tried by prediction error (culled ones included)
    std::size_t culled = 0;          ///< subdivisions undone by culling
    std::size_t merged = 0;          ///< cells merged from their children (refinement merge)
    std::size_t hanging_corners = 0; ///< leaf corners set from a coarser leaf (conforming_corners)
    float noise_scale = 1;           ///< scale applied to the probes' noise (calibrate_noise)
    float scene_light = 0;           ///< L of bias_tolerance_unit (merging by bias_tolerance)
    float median_noise = 0;          ///< sigma of bias_tolerance_unit, noise_scale applied (merging by bias_tolerance)
    std::size_t inside_cells = 0;    ///< cells not split because every corner is inside geometry
    std::size_t probes_baked = 0;    ///< probes the source computed, culled ones included
    std::size_t probes_inside = 0;   ///< probes of the final volume flagged inside
};

}  // namespace bounce::volume

namespace bounce::detail {

inline bool finite_probe(const irradiance_probe& p) {
    const auto ok = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    if (!ok(p.position) || std::isnan(p.harmonic_mean_distance) || p.harmonic_mean_distance < 0) return false;
    if (!std::isfinite(p.noise) || p.noise < 0) return false;
    for (const auto& c : p.radiance)
        if (!ok(c)) return false;
    for (const auto& g : p.gradient)
        for (const auto& c : g)
            if (!ok(c)) return false;
    return true;
}

/// Band-0 irradiance luminance of a probe: pi * c_00 * Y_00 (the irradiance averaged over
/// all normals), the scalar the split heuristics compare.
inline float probe_level(const irradiance_probe::coefficients& c) {
    constexpr float y00 = 0.28209479177387814f;
    return std::numbers::pi_v<float> * y00 * rec709_luminance<float, glm::vec3>(c[0]);
}

/// Irradiance of a probe's coefficients at the six axis normals (luminance).
inline std::array<float, 6> axis_irradiance(const irradiance_probe::coefficients& c) {
    static const glm::vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    std::array<float, 6> e{};
    for (int k = 0; k < 6; ++k) e[std::size_t(k)] = rec709_luminance<float, glm::vec3>(sh_irradiance<irradiance_volume_bands, float, glm::vec3>(c, axes[k]));
    return e;
}

/// The mean band-0 irradiance luminance of the probes outside geometry, times `fraction`:
/// the absolute floor of the heuristics' denominators (irradiance_volume_settings).
inline float absolute_floor_level(const std::vector<irradiance_probe>& probes, float fraction) {
    double sum = 0;
    int n = 0;
    for (const auto& p : probes)
        if (!p.inside) sum += probe_level(p.radiance), ++n;
    return n ? float(sum / n) * fraction : 0.f;
}

/// A cell of the octree under construction: its node, its lattice origin (in cells of the
/// finest level) and the scene's triangles that overlap it.
struct octree_cell {
    std::uint32_t node;
    std::uint64_t x, y, z;
    std::vector<std::uint32_t> triangles;
};

/// Whether triangle t of `scene` overlaps the box of centre c and half-size h (exactly).
inline bool triangle_overlaps_box(const scene_view& scene, std::uint32_t t, glm::dvec3 c, glm::dvec3 h) {
    const auto& tri = scene.triangles[t];
    return triangle_box_overlap(c, h, glm::dvec3(scene.positions[tri.x]), glm::dvec3(scene.positions[tri.y]),
                                glm::dvec3(scene.positions[tri.z]));
}

/// The low corner of octant k (bit 0: x, 1: y, 2: z upper) of the box [lo, lo + size].
inline glm::vec3 octant_lo(glm::vec3 lo, glm::vec3 size, int k) {
    const glm::vec3 centre = lo + size * 0.5f;
    return glm::vec3((k & 1) ? centre.x : lo.x, (k & 2) ? centre.y : lo.y, (k & 4) ? centre.z : lo.z);
}

/// The 8 children of cell c (box [lo, lo + size]; `half_step` lattice cells per child
/// side), each with the triangles of c that overlap it; their nodes are not yet set.
inline std::vector<octree_cell> child_cells(const scene_view& scene, const octree_cell& c, glm::vec3 lo,
                                            glm::vec3 size, std::uint64_t half_step) {
    std::vector<octree_cell> children;
    for (int k = 0; k < 8; ++k) {
        octree_cell ch{0, c.x + half_step * std::uint64_t(k & 1), c.y + half_step * std::uint64_t((k >> 1) & 1),
                       c.z + half_step * std::uint64_t((k >> 2) & 1), {}};
        const glm::vec3 csize = size * 0.5f;
        const glm::dvec3 cc = glm::dvec3(octant_lo(lo, size, k)) + glm::dvec3(csize) * 0.5, half = glm::dvec3(csize) * 0.5;
        for (std::uint32_t t : c.triangles)
            if (triangle_overlaps_box(scene, t, cc, half)) ch.triangles.push_back(t);
        children.push_back(std::move(ch));
    }
    return children;
}

using corner_probes = std::array<const irradiance_probe*, 8>;

/// Oat's distance heuristic: a usable corner's harmonic mean distance below distance_ratio
/// times the cell's diagonal.
inline bool corner_sees_near_surfaces(const corner_probes& corners, float diagonal, const irradiance_volume_settings& s) {
    for (const auto* p : corners)
        if (!p->inside && p->harmonic_mean_distance < s.distance_ratio * diagonal) return true;
    return false;
}

/// Change between neighbours: two usable corners whose irradiance luminance differ by more
/// than neighbour_change times their mean plus the floor.
inline bool corners_differ(const corner_probes& corners, float floor_level, const irradiance_volume_settings& s) {
    for (int a = 0; a < 8; ++a)
        for (int b = a + 1; b < 8; ++b) {
            const auto* pa = corners[std::size_t(a)];
            const auto* pb = corners[std::size_t(b)];
            if (pa->inside || pb->inside) continue;
            const float ea = probe_level(pa->radiance), eb = probe_level(pb->radiance);
            if (std::abs(ea - eb) > s.neighbour_change * (0.5f * (ea + eb) + floor_level)) return true;
        }
    return false;
}

/// Gradient magnitude: a usable corner where |grad E| times the cell's longest edge exceeds
/// gradient_ratio times E plus the floor.
inline bool corner_gradient_steep(const corner_probes& corners, float edge, float floor_level,
                                  const irradiance_volume_settings& s) {
    for (const auto* p : corners) {
        if (p->inside) continue;
        const float e = probe_level(p->radiance);
        const glm::vec3 g(probe_level(p->gradient[0]), probe_level(p->gradient[1]), probe_level(p->gradient[2]));
        if (glm::length(g) * edge > s.gradient_ratio * (e + floor_level)) return true;
    }
    return false;
}

/// Whether cell c (at `depth`, box size `size`, its corners' probe indices `corner` into
/// `probes`) splits: below min_depth always; never when every corner is inside geometry
/// (nothing there to light or refine); else when a heuristic fires, in the order of
/// irradiance_volume_settings. Counts the reason in `stats`.
inline bool cell_splits(const octree_cell& c, const std::array<std::uint32_t, 8>& corner, glm::vec3 size,
                        const std::vector<irradiance_probe>& probes, int depth, float floor_level,
                        const irradiance_volume_settings& s, irradiance_volume_build_stats& stats) {
    const auto fires = [](std::size_t& count) {
        ++count;
        return true;
    };
    if (depth < s.min_depth) return fires(stats.split_min_depth);
    corner_probes corners{};
    bool any_usable = false;
    for (int k = 0; k < 8; ++k) {
        corners[std::size_t(k)] = &probes[corner[std::size_t(k)]];
        any_usable = any_usable || !corners[std::size_t(k)]->inside;
    }
    if (!any_usable) {
        ++stats.inside_cells;
        return false;
    }
    if (s.prediction_tolerance > 0) return fires(stats.split_prediction);
    const float diagonal = glm::length(size), edge = std::max({size.x, size.y, size.z});
    if (s.distance_ratio > 0 && corner_sees_near_surfaces(corners, diagonal, s)) return fires(stats.split_distance);
    if (s.neighbour_change > 0 && corners_differ(corners, floor_level, s)) return fires(stats.split_neighbour);
    if (s.geometry_triangles > 0 && c.triangles.size() >= s.geometry_triangles) return fires(stats.split_geometry);
    if (s.gradient_ratio > 0 && corner_gradient_steep(corners, edge, floor_level, s)) return fires(stats.split_gradient);
    return false;
}

/// What a cell's culling test compares: its corners' axis irradiance, which corners are
/// outside geometry, the relative tolerance, the floor, and the probes' pooled standard
/// error times noise_sigmas.
struct parent_prediction {
    std::array<std::array<float, 6>, 8> corner_e{};
    std::array<float, 8> corner_valid{};
    float tolerance = 0, floor_level = 0, noise = 0;
};

/// Whether probe p (outside geometry) lies, at the six axis normals, within the tolerance
/// (times the prediction, plus the floor) of the trilinear interpolation of the parent box
/// [lo, lo + size]'s corners, or within the noise of that difference (the probe's and
/// the interpolated corners', sqrt(1 + sum of the squared normalized weights) times the
/// pooled standard error).
inline bool parent_predicts_probe(const irradiance_probe& p, glm::vec3 lo, glm::vec3 size, const parent_prediction& parent) {
    const auto w = trilinear_weights<float, glm::vec3>(p.position, lo, size);
    std::array<float, 6> predicted{};
    float wsum = 0, w2sum = 0;
    for (int j = 0; j < 8; ++j) {
        const float wj = w[std::size_t(j)] * parent.corner_valid[std::size_t(j)];
        wsum += wj;
        w2sum += wj * wj;
        for (int a = 0; a < 6; ++a) predicted[std::size_t(a)] += wj * parent.corner_e[std::size_t(j)][std::size_t(a)];
    }
    if (wsum <= 0) return false;
    const float noise = parent.noise * std::sqrt(1 + w2sum / (wsum * wsum));
    const auto actual = axis_irradiance(p.radiance);
    for (int a = 0; a < 6; ++a) {
        const float pred = predicted[std::size_t(a)] / wsum, diff = std::abs(actual[std::size_t(a)] - pred);
        if (diff > parent.tolerance * (std::abs(pred) + parent.floor_level) && diff > noise) return false;
    }
    return true;
}

/// A probe baked for a split that culling undid: its value (`probe`, an index into the
/// build's probes) and where it lies in the parent cell (the parent's corner probes and
/// their trilinear weights there, renormalized over the corners outside geometry).
struct culled_sample {
    std::uint32_t probe = 0;
    std::array<std::uint32_t, 8> corner{};
    std::array<float, 8> weight{};
};

/// The least-squares fit of the radiance coefficients of every probe (outside geometry)
/// that a culled sample's corners name: minimizes sum over those probes of |c_p - v_p|^2
/// plus sum over samples of |sum_k w_k c_k - v_s|^2 (v: the baked values), by `sweeps`
/// Gauss-Seidel sweeps from the baked values. Gradients and noise are left as they are.
inline void refit_probes(std::vector<irradiance_probe>& probes, const std::vector<culled_sample>& samples, int sweeps) {
    using coefficients = irradiance_probe::coefficients;
    std::vector<coefficients> baked(probes.size());
    for (std::size_t i = 0; i < probes.size(); ++i) baked[i] = probes[i].radiance;
    std::vector<std::vector<std::uint32_t>> touching(probes.size());  // samples naming a probe
    for (std::uint32_t si = 0; si < samples.size(); ++si)
        for (int k = 0; k < 8; ++k)
            if (samples[si].weight[std::size_t(k)] > 0) touching[samples[si].corner[std::size_t(k)]].push_back(si);
    // The residual sum_k w_k c_k - v_s of every sample, kept current as corners change.
    std::vector<coefficients> residual(samples.size());
    for (std::size_t si = 0; si < samples.size(); ++si) {
        const culled_sample& cs = samples[si];
        for (std::size_t i = 0; i < residual[si].size(); ++i) {
            glm::vec3 r = -baked[cs.probe][i];
            for (std::size_t k = 0; k < 8; ++k) r += cs.weight[k] * probes[cs.corner[k]].radiance[i];
            residual[si][i] = r;
        }
    }
    for (int sweep = 0; sweep < sweeps; ++sweep)
        for (std::size_t p = 0; p < probes.size(); ++p) {
            if (touching[p].empty() || probes[p].inside) continue;
            float diagonal = 1;
            coefficients g{};
            for (std::size_t i = 0; i < g.size(); ++i) g[i] = probes[p].radiance[i] - baked[p][i];
            std::vector<float> wp(touching[p].size());
            for (std::size_t t = 0; t < touching[p].size(); ++t) {
                const culled_sample& cs = samples[touching[p][t]];
                for (std::size_t k = 0; k < 8; ++k)
                    if (cs.corner[k] == p) wp[t] += cs.weight[k];
                diagonal += wp[t] * wp[t];
                for (std::size_t i = 0; i < g.size(); ++i) g[i] += wp[t] * residual[touching[p][t]][i];
            }
            for (std::size_t i = 0; i < g.size(); ++i) {
                const glm::vec3 step = g[i] / diagonal;
                probes[p].radiance[i] -= step;
                for (std::size_t t = 0; t < touching[p].size(); ++t) residual[touching[p][t]][i] -= wp[t] * step;
            }
        }
}

}  // namespace bounce::detail
