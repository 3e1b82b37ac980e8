#pragma once
/// \file volume/probe_octree.hpp
/// Irradiance volumes (Greger et al., "The Irradiance Volume", IEEE CG&A 1998; Oat,
/// "Irradiance Volumes for Real-time Rendering", ShaderX5 section 6.1, 2006): SH probes
/// of the incoming radiance at the corners of the cells of an octree over a static scene,
/// looked up to light moving objects.
///
/// - A uniform grid is the octree subdivided everywhere to one depth; an adaptive octree
///   subdivides a cell when one of Oat's heuristics fires, each with its threshold
///   (`irradiance_volume_settings`), between a minimum and a maximum depth, and culls
///   children whose probes do not differ from their parent's interpolation.
/// - Probes sit at cell corners and are shared: a corner is an integer point of the
///   lattice of the finest level, and each lattice point holds at most one probe. A probe
///   inside geometry (flagged by its source) is kept but skipped by every lookup.
/// - Lookups: `find_leaf` descends with the `octree_octant` kernel; `trilinear` weighs the
///   leaf's 8 corners; `weighted` takes Oat's distance-weighted average of the probes
///   around p, each extrapolated with its gradient, with Franke and Nielson's compactly
///   supported weights and a per-probe reach (volume/kernels.hpp), so probes of
///   finer neighbours (T-junctions) enter smoothly instead of popping in.
/// - `flatten` lays nodes and probes out as std430 storage buffers for the GPU.
///
/// Probes come from a caller's `probe_source`: Embree ray casting
/// (embree/probe_baker.hpp), a GL cube-map renderer, or an analytic field in tests.

#include <bounce/errors.hpp>
#include <bounce/volume/kernels.hpp>
#include <bounce/luminance.hpp>
#include <bounce/scene_view.hpp>
#include <bounce/volume/triangle_box_overlap.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <numbers>
#include <tuple>
#include <span>
#include <string>
#include <unordered_map>
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
};

/// Something that fills probes at positions: `source(positions, out)` with spans of equal
/// size (a batch per octree level, so a source can bake them in parallel).
template <class S>
concept probe_source = requires(S& s, std::span<const glm::vec3> positions, std::span<irradiance_probe> out) {
    s(positions, out);
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
    /// trilinear interpolation predicts there. Typical: 0.02-0.1; 0 keeps every child.
    float cull_tolerance = 0.05f;
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
    std::size_t culled = 0;          ///< subdivisions undone by culling
    std::size_t inside_cells = 0;    ///< cells not split because every corner is inside geometry
    std::size_t probes_baked = 0;    ///< probes the source computed, culled ones included
    std::size_t probes_inside = 0;   ///< probes of the final volume flagged inside
};

/// std430 layout of one octree node (80 bytes): `lo.xyz` and `size.xyz` of its box,
/// `first_child` (-1 for a leaf; children are first_child + octant), and the probe index
/// of each of its 8 corners (corner k at lo + size * (k & 1, (k >> 1) & 1, (k >> 2) & 1)).
struct irradiance_volume_gpu_node {
    float lo[4];
    float size[4];
    std::int32_t first_child;
    std::int32_t pad[3];
    std::uint32_t corner[8];
};
static_assert(sizeof(irradiance_volume_gpu_node) == 80, "std430 node layout");

/// std430 layout of one probe (592 bytes): position.xyz and w = reach (0: inside geometry),
/// 9 radiance coefficients and 3 x 9 gradient coefficients as vec4 (w unused).
struct irradiance_volume_gpu_probe {
    float position[4];
    float radiance[irradiance_volume_coefficients][4];
    float gradient[3][irradiance_volume_coefficients][4];
};
static_assert(sizeof(irradiance_volume_gpu_probe) == 16 + 16 * 9 + 16 * 27, "std430 probe layout");

/// The flattened volume: what a GPU lookup reads from two storage buffers. Node 0 is the
/// root.
struct irradiance_volume_gpu_layout {
    std::vector<irradiance_volume_gpu_node> nodes;
    std::vector<irradiance_volume_gpu_probe> probes;
    int max_depth = 0;  ///< longest root-to-leaf path (bounds the descent loop)
};

/// How `irradiance_volume::weighted` averages probes.
struct weighted_lookup {
    /// Exponent b of w_j ~ (1 / |p - s_j|)^b, in (0, 4]. Typical: 1-2 (higher b makes
    /// Shepard's flat spots at the probes and steep steps between them).
    float b = 2.f;
    /// Extrapolate each probe with its gradient (Oat's I'_i = I_i + grad I_i . d).
    bool gradients = true;
    /// A probe's weight reaches 0 at support * its reach (half the diagonal of the largest
    /// leaf it is a corner of): > 1, so that the corners of the leaf holding p always
    /// reach p. Typical: 1.5.
    float support = 1.5f;
};

/// An octree of SH probes over a box. Build with `build`; immutable afterwards, so
/// lookups from many threads are safe.
class irradiance_volume {
public:
    /// Deepest level a build may reach (lattice coordinates fit 32 bits).
    static constexpr int depth_limit = 10;

    /// Probes of a uniform grid of depth `depth`: (2^depth + 1)^3, the most any build of
    /// that max_depth can hold.
    static constexpr double uniform_probe_count(int depth) {
        const double n = double(std::uint64_t(1) << std::clamp(depth, 0, 62)) + 1;
        return n * n * n;
    }
    /// Bytes a build holding `probes` probes and `nodes` nodes needs at its peak (the probe
    /// store and its lattice index, the final probes, owners and nodes), an estimate good
    /// to a few tens of percent; the triangle lists of the cells under construction come on
    /// top, at most one index per triangle and overlapped cell.
    static constexpr double estimated_bytes(double probes, double nodes) {
        return probes * (2 * double(sizeof(irradiance_probe)) + 64 + 4) + nodes * double(sizeof(node) + 4);
    }
    /// estimated_bytes of the uniform grid of depth `depth`: the bound for any max_depth.
    static constexpr double estimated_bytes(int depth) {
        double nodes = 0;
        for (int d = 0; d <= depth; ++d) nodes += double(std::uint64_t(1) << std::clamp(3 * d, 0, 62));
        return estimated_bytes(uniform_probe_count(depth), nodes);
    }

    struct node {
        glm::vec3 lo{0.f}, size{0.f};
        int depth = 0;
        std::int32_t first_child = -1;  ///< -1: a leaf
        std::array<std::uint32_t, 8> corner{};
        bool leaf() const noexcept { return first_child < 0; }
    };

    /// Builds the octree over the box [lo, hi] of `scene` (whose triangles the geometry
    /// heuristic tests), asking `source` for the probes of each level's new corners.
    /// Throws parameter_error naming "scene" when it has no triangles, "lo"/"hi" for an
    /// empty or non-finite box, "settings.max_depth"/"settings.min_depth" outside
    /// 0 .. depth_limit or min > max, a negative or non-finite threshold by its name, and
    /// "probes" when the source returns a non-finite value or an out-of-place probe,
    /// "settings.max_depth" when a level would exceed settings.memory_limit_bytes, and
    /// "scene" when every probe of the finished volume is inside geometry (the volume would
    /// light nothing: typically a scene whose triangles all face away from the volume,
    /// wound the wrong way, so that every probe's rays hit their backs).
    template <probe_source Source>
    static irradiance_volume build(const scene_view& scene, glm::vec3 lo, glm::vec3 hi,
                                   const irradiance_volume_settings& settings, Source&& source,
                                   irradiance_volume_build_stats* stats = nullptr);

    const std::vector<node>& nodes() const noexcept { return nodes_; }
    const std::vector<irradiance_probe>& probes() const noexcept { return probes_; }
    glm::vec3 lo() const noexcept { return nodes_.front().lo; }
    glm::vec3 hi() const noexcept { return nodes_.front().lo + nodes_.front().size; }
    std::size_t leaf_count() const noexcept;
    int depth() const noexcept;

    /// Index of the leaf holding `p` (clamped into the volume; a point on a splitting
    /// plane belongs to the upper cell, as `octree_octant` says).
    std::uint32_t find_leaf(glm::vec3 p) const;

    /// Trilinear interpolation of the irradiance (W/m^2, RGB) of the 8 corners of the leaf
    /// holding p at normal n (unit), renormalized over the usable corners; 0 if none is.
    glm::vec3 trilinear(glm::vec3 p, glm::vec3 n) const;

    /// Distance-weighted average (weighted_probe_accumulate) of every usable probe whose
    /// reach (times how.support) covers p, found by descending into the nodes whose box,
    /// grown by support times its half-diagonal, holds p; each probe is added once, from
    /// the leaf that sets its reach. Continuous in p wherever the probes are.
    glm::vec3 weighted(glm::vec3 p, glm::vec3 n, const weighted_lookup& how) const;

    /// The probe indices `weighted` averages at p (those within support * reach), in the
    /// order it adds them.
    void weighted_candidates(glm::vec3 p, float support, std::vector<std::uint32_t>& out) const;

    /// The leaf that sets each probe's reach (the largest of the leaves it is a corner of;
    /// the first in node order among equals).
    const std::vector<std::uint32_t>& probe_owners() const noexcept { return owner_; }
    /// The smallest reach of a usable probe (the `ref` scale of the weights).
    float reference_reach() const noexcept { return reference_reach_; }

    /// Nodes and probes as std430 buffers.
    irradiance_volume_gpu_layout flatten() const;

    /// Cap on the weight at a probe, in units of its reach (see weighted_probe_accumulate).
    static constexpr float min_relative_distance = 1e-4f;

private:
    std::vector<node> nodes_;
    std::vector<irradiance_probe> probes_;
    std::vector<std::uint32_t> owner_;
    float reference_reach_ = 1.f;
};

// ---- implementation ------------------------------------------------------------------------

}  // namespace bounce::volume

namespace bounce::detail {

inline bool finite_probe(const irradiance_probe& p) {
    const auto ok = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    if (!ok(p.position) || std::isnan(p.harmonic_mean_distance) || p.harmonic_mean_distance < 0) return false;
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

}  // namespace bounce::detail

namespace bounce::inline volume {

template <probe_source Source>
irradiance_volume irradiance_volume::build(const scene_view& scene, glm::vec3 lo, glm::vec3 hi,
                                           const irradiance_volume_settings& s, Source&& source,
                                           irradiance_volume_build_stats* stats_out) {
    require(!scene.triangles.empty(), "scene", "the scene has no triangles: nothing to light, no geometry to test");
    const auto finite3 = [](glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    require(finite3(lo) && finite3(hi), "lo", "volume bounds must be finite");
    require(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z, "hi", "volume bounds must enclose a non-empty box (hi > lo)");
    require(s.max_depth >= 0 && s.max_depth <= depth_limit, "settings.max_depth", "must lie in 0 .. 10");
    require(s.min_depth >= 0 && s.min_depth <= s.max_depth, "settings.min_depth", "must lie in 0 .. max_depth");
    const auto threshold = [](float v, const char* name) {
        require(std::isfinite(v) && v >= 0, name, "threshold must be finite and >= 0 (0: off)");
    };
    threshold(s.distance_ratio, "settings.distance_ratio");
    threshold(s.neighbour_change, "settings.neighbour_change");
    threshold(s.gradient_ratio, "settings.gradient_ratio");
    threshold(s.cull_tolerance, "settings.cull_tolerance");
    threshold(s.absolute_floor, "settings.absolute_floor");

    irradiance_volume_build_stats stats;
    irradiance_volume v;
    const std::uint64_t res = std::uint64_t(1) << s.max_depth;  // lattice cells per axis at max depth
    const glm::vec3 extent = hi - lo;
    // Probe store: lattice key -> index into `all`.
    std::vector<irradiance_probe> all;
    std::unordered_map<std::uint64_t, std::uint32_t> at_key;
    const auto key_of = [&](std::uint64_t x, std::uint64_t y, std::uint64_t z) { return x + (res + 1) * (y + (res + 1) * z); };
    const auto lattice_position = [&](std::uint64_t x, std::uint64_t y, std::uint64_t z) {
        return lo + extent * (glm::vec3(float(x), float(y), float(z)) / float(res));
    };

    // Cells under construction carry their lattice origin and the triangles that overlap them.
    struct cell {
        std::uint32_t node;
        std::uint64_t x, y, z;  // lattice origin (finest-level units)
        std::vector<std::uint32_t> triangles;
    };
    const auto corner_keys = [&](const cell& c, int depth) {
        const std::uint64_t step = res >> depth;
        std::array<std::uint64_t, 8> keys{};
        for (int k = 0; k < 8; ++k)
            keys[std::size_t(k)] = key_of(c.x + step * std::uint64_t(k & 1), c.y + step * std::uint64_t((k >> 1) & 1),
                                          c.z + step * std::uint64_t((k >> 2) & 1));
        return keys;
    };
    // Bakes every corner of `cells` not yet in the store, in one batch.
    const auto bake_corners = [&](const std::vector<cell>& cells, int depth) {
        std::vector<std::uint64_t> new_keys;
        std::vector<glm::vec3> positions;
        const std::uint64_t step = res >> depth;
        for (const auto& c : cells)
            for (int k = 0; k < 8; ++k) {
                const std::uint64_t x = c.x + step * std::uint64_t(k & 1), y = c.y + step * std::uint64_t((k >> 1) & 1),
                                    z = c.z + step * std::uint64_t((k >> 2) & 1);
                const std::uint64_t key = key_of(x, y, z);
                if (at_key.count(key)) continue;
                at_key.emplace(key, std::uint32_t(all.size() + new_keys.size()));
                new_keys.push_back(key);
                positions.push_back(lattice_position(x, y, z));
            }
        if (positions.empty()) return;
        if (s.memory_limit_bytes > 0) {
            const double probes = double(all.size() + positions.size()), nodes = double(v.nodes_.size() + cells.size()),
                         need = estimated_bytes(probes, nodes);
            if (need > double(s.memory_limit_bytes))
                throw parameter_error("settings.max_depth",
                                      "depth " + std::to_string(depth) + " would hold " + std::to_string(std::uint64_t(probes)) +
                                          " probes, about " + std::to_string(std::uint64_t(need / 1e6)) + " MB, more than the " +
                                          std::to_string(s.memory_limit_bytes / 1000000) + " MB allowed; choose a smaller max_depth");
        }
        std::vector<irradiance_probe> baked(positions.size());
        source(std::span<const glm::vec3>(positions), std::span<irradiance_probe>(baked));
        for (std::size_t i = 0; i < baked.size(); ++i) {
            require(detail::finite_probe(baked[i]), "probes",
                    "the probe source returned a non-finite probe (NaN or infinite coefficient or position)");
            require(glm::length(baked[i].position - positions[i]) <= 1e-5f * glm::length(extent), "probes",
                    "the probe source moved a probe away from its lattice position");
            all.push_back(baked[i]);
        }
        stats.probes_baked += baked.size();
    };

    // Root.
    cell root{0, 0, 0, 0, {}};
    root.triangles.reserve(scene.triangles.size());
    {
        const glm::dvec3 c = glm::dvec3(lo + hi) * 0.5, h = glm::dvec3(hi - lo) * 0.5;
        for (std::uint32_t t = 0; t < scene.triangles.size(); ++t) {
            const auto& tri = scene.triangles[t];
            if (triangle_box_overlap(c, h, glm::dvec3(scene.positions[tri.x]), glm::dvec3(scene.positions[tri.y]),
                                     glm::dvec3(scene.positions[tri.z])))
                root.triangles.push_back(t);
        }
    }
    v.nodes_.push_back(node{lo, extent, 0, -1, {}});
    std::vector<cell> level{std::move(root)};
    bake_corners(level, 0);
    float floor_level = 0;
    {
        double sum = 0;
        int n = 0;
        for (const auto& p : all)
            if (!p.inside) sum += detail::probe_level(p.radiance), ++n;
        floor_level = n ? float(sum / n) * s.absolute_floor : 0.f;
    }

    for (int depth = 0; depth <= s.max_depth; ++depth) {
        for (const auto& c : level) {
            const auto keys = corner_keys(c, depth);
            for (int k = 0; k < 8; ++k) v.nodes_[c.node].corner[std::size_t(k)] = at_key.at(keys[std::size_t(k)]);
        }
        if (depth == s.max_depth) break;
        // Decide which cells split.
        std::vector<cell> children;
        std::vector<std::size_t> split_cells;
        for (std::size_t ci = 0; ci < level.size(); ++ci) {
            const cell& c = level[ci];
            const node& nd = v.nodes_[c.node];
            bool split = false;
            bool any_usable = false;
            for (std::uint32_t idx : nd.corner) any_usable = any_usable || !all[idx].inside;
            if (depth < s.min_depth) {
                split = true;
                ++stats.split_min_depth;
            } else if (!any_usable) {
                // Every corner inside geometry: nothing here to light, nothing to refine.
                ++stats.inside_cells;
            } else {
                const float diagonal = glm::length(nd.size), edge = std::max({nd.size.x, nd.size.y, nd.size.z});
                std::array<const irradiance_probe*, 8> corners{};
                for (int k = 0; k < 8; ++k) corners[std::size_t(k)] = &all[nd.corner[std::size_t(k)]];
                if (!split && s.distance_ratio > 0)
                    for (const auto* p : corners)
                        if (!p->inside && p->harmonic_mean_distance < s.distance_ratio * diagonal) {
                            split = true;
                            ++stats.split_distance;
                            break;
                        }
                if (!split && s.neighbour_change > 0)
                    for (int a = 0; a < 8 && !split; ++a)
                        for (int b = a + 1; b < 8; ++b) {
                            const auto* pa = corners[std::size_t(a)];
                            const auto* pb = corners[std::size_t(b)];
                            if (pa->inside || pb->inside) continue;
                            const float ea = detail::probe_level(pa->radiance), eb = detail::probe_level(pb->radiance);
                            if (std::abs(ea - eb) > s.neighbour_change * (0.5f * (ea + eb) + floor_level)) {
                                split = true;
                                ++stats.split_neighbour;
                                break;
                            }
                        }
                if (!split && s.geometry_triangles > 0 && c.triangles.size() >= s.geometry_triangles) {
                    split = true;
                    ++stats.split_geometry;
                }
                if (!split && s.gradient_ratio > 0)
                    for (const auto* p : corners) {
                        if (p->inside) continue;
                        const float e = detail::probe_level(p->radiance);
                        const glm::vec3 g(detail::probe_level(p->gradient[0]), detail::probe_level(p->gradient[1]),
                                          detail::probe_level(p->gradient[2]));
                        if (glm::length(g) * edge > s.gradient_ratio * (e + floor_level)) {
                            split = true;
                            ++stats.split_gradient;
                            break;
                        }
                    }
            }
            if (!split) continue;
            split_cells.push_back(ci);
        }
        // Children of the splitting cells, with their triangles; bake their corners.
        std::vector<std::vector<cell>> families(split_cells.size());
        const std::uint64_t half_step = res >> (depth + 1);
        for (std::size_t si = 0; si < split_cells.size(); ++si) {
            const cell& c = level[split_cells[si]];
            const node& nd = v.nodes_[c.node];
            for (int k = 0; k < 8; ++k) {
                cell ch{0, c.x + half_step * std::uint64_t(k & 1), c.y + half_step * std::uint64_t((k >> 1) & 1),
                        c.z + half_step * std::uint64_t((k >> 2) & 1), {}};
                const glm::vec3 centre = nd.lo + nd.size * 0.5f;
                const glm::vec3 clo = glm::vec3((k & 1) ? centre.x : nd.lo.x, (k & 2) ? centre.y : nd.lo.y,
                                                (k & 4) ? centre.z : nd.lo.z);
                const glm::vec3 csize = nd.size * 0.5f;
                const glm::dvec3 cc = glm::dvec3(clo) + glm::dvec3(csize) * 0.5, ch_half = glm::dvec3(csize) * 0.5;
                for (std::uint32_t t : c.triangles) {
                    const auto& tri = scene.triangles[t];
                    if (triangle_box_overlap(cc, ch_half, glm::dvec3(scene.positions[tri.x]),
                                             glm::dvec3(scene.positions[tri.y]), glm::dvec3(scene.positions[tri.z])))
                        ch.triangles.push_back(t);
                }
                families[si].push_back(std::move(ch));
            }
        }
        {
            std::vector<cell> batch;
            for (const auto& f : families)
                for (const auto& ch : f) batch.push_back(cell{0, ch.x, ch.y, ch.z, {}});
            bake_corners(batch, depth + 1);
        }
        // Culling: undo a split whose new probes the parent already predicts.
        for (std::size_t si = 0; si < split_cells.size(); ++si) {
            const cell& c = level[split_cells[si]];
            const node parent = v.nodes_[c.node];
            bool keep = depth < s.min_depth || s.cull_tolerance <= 0;
            if (!keep) {
                std::array<std::array<float, 6>, 8> corner_e{};
                std::array<float, 8> corner_valid{};
                for (int k = 0; k < 8; ++k) {
                    const auto& p = all[parent.corner[std::size_t(k)]];
                    corner_e[std::size_t(k)] = detail::axis_irradiance(p.radiance);
                    corner_valid[std::size_t(k)] = p.inside ? 0.f : 1.f;
                }
                for (const auto& ch : families[si]) {
                    const auto keys = corner_keys(ch, depth + 1);
                    for (int k = 0; k < 8 && !keep; ++k) {
                        const std::uint32_t idx = at_key.at(keys[std::size_t(k)]);
                        const auto& p = all[idx];
                        if (p.inside) continue;
                        const auto w = trilinear_weights<float, glm::vec3>(p.position, parent.lo, parent.size);
                        std::array<float, 6> predicted{};
                        float wsum = 0;
                        for (int j = 0; j < 8; ++j) {
                            const float wj = w[std::size_t(j)] * corner_valid[std::size_t(j)];
                            wsum += wj;
                            for (int a = 0; a < 6; ++a) predicted[std::size_t(a)] += wj * corner_e[std::size_t(j)][std::size_t(a)];
                        }
                        if (wsum <= 0) {
                            keep = true;
                            break;
                        }
                        const auto actual = detail::axis_irradiance(p.radiance);
                        for (int a = 0; a < 6; ++a) {
                            const float pred = predicted[std::size_t(a)] / wsum;
                            if (std::abs(actual[std::size_t(a)] - pred) >
                                s.cull_tolerance * (std::abs(pred) + floor_level)) {
                                keep = true;
                                break;
                            }
                        }
                    }
                    if (keep) break;
                }
            }
            if (!keep) {
                ++stats.culled;
                continue;
            }
            const std::uint32_t first = std::uint32_t(v.nodes_.size());
            v.nodes_[c.node].first_child = std::int32_t(first);
            for (int k = 0; k < 8; ++k) {
                const glm::vec3 centre = parent.lo + parent.size * 0.5f;
                const glm::vec3 clo = glm::vec3((k & 1) ? centre.x : parent.lo.x, (k & 2) ? centre.y : parent.lo.y,
                                                (k & 4) ? centre.z : parent.lo.z);
                v.nodes_.push_back(node{clo, parent.size * 0.5f, depth + 1, -1, {}});
            }
            for (int k = 0; k < 8; ++k) {
                families[si][std::size_t(k)].node = first + std::uint32_t(k);
                children.push_back(std::move(families[si][std::size_t(k)]));
            }
        }
        level = std::move(children);
        if (level.empty()) break;
    }

    // Keep only the probes some leaf uses, renumbered in order of first use.
    std::vector<std::uint32_t> remap(all.size(), std::numeric_limits<std::uint32_t>::max());
    for (auto& nd : v.nodes_) {
        if (!nd.leaf()) continue;
        for (auto& idx : nd.corner) {
            if (remap[idx] == std::numeric_limits<std::uint32_t>::max()) {
                remap[idx] = std::uint32_t(v.probes_.size());
                v.probes_.push_back(all[idx]);
            }
            idx = remap[idx];
        }
    }
    // Inner nodes keep corner indices only where the probe survived (else the first leaf's).
    for (auto& nd : v.nodes_) {
        if (nd.leaf()) continue;
        for (auto& idx : nd.corner) idx = remap[idx] == std::numeric_limits<std::uint32_t>::max() ? 0u : remap[idx];
    }
    for (const auto& p : v.probes_) stats.probes_inside += p.inside ? 1 : 0;
    if (stats.probes_inside == v.probes_.size())
        throw parameter_error("scene", "every one of the " + std::to_string(v.probes_.size()) +
                                           " probes is inside geometry (its rays hit the backs of triangles), so the volume "
                                           "would light nothing; are the scene's triangles wound the wrong way, facing away "
                                           "from the volume and the lights?");
    // Reach and owner: the largest leaf each probe is a corner of.
    v.owner_.assign(v.probes_.size(), 0);
    for (auto& p : v.probes_) p.reach = 0.f;
    for (std::uint32_t i = 0; i < v.nodes_.size(); ++i) {
        const node& nd = v.nodes_[i];
        if (!nd.leaf()) continue;
        const float half_diagonal = 0.5f * glm::length(nd.size);
        for (std::uint32_t idx : nd.corner)
            if (half_diagonal > v.probes_[idx].reach) v.probes_[idx].reach = half_diagonal, v.owner_[idx] = i;
    }
    v.reference_reach_ = std::numeric_limits<float>::infinity();
    for (const auto& p : v.probes_) v.reference_reach_ = std::min(v.reference_reach_, p.reach);
    if (stats_out) *stats_out = stats;
    return v;
}

inline std::size_t irradiance_volume::leaf_count() const noexcept {
    return std::size_t(std::count_if(nodes_.begin(), nodes_.end(), [](const node& n) { return n.leaf(); }));
}

inline int irradiance_volume::depth() const noexcept {
    int d = 0;
    for (const auto& n : nodes_) d = std::max(d, n.depth);
    return d;
}

inline std::uint32_t irradiance_volume::find_leaf(glm::vec3 p) const {
    const node& root = nodes_.front();
    p = volume_clamp<float, glm::vec3>(p, root.lo, root.size);
    std::uint32_t i = 0;
    while (!nodes_[i].leaf()) {
        const node& n = nodes_[i];
        const float octant = octree_octant<float, glm::vec3>(p, n.lo, n.size);
        i = std::uint32_t(n.first_child) + std::uint32_t(octant);
    }
    return i;
}

inline glm::vec3 irradiance_volume::trilinear(glm::vec3 p, glm::vec3 n) const {
    const node& leaf = nodes_[find_leaf(p)];
    const auto w = trilinear_weights<float, glm::vec3>(p, leaf.lo, leaf.size);
    glm::vec3 sum(0.f);
    float wsum = 0.f;
    for (int k = 0; k < 8; ++k) {
        const irradiance_probe& pr = probes_[leaf.corner[std::size_t(k)]];
        std::tie(sum, wsum) = trilinear_probe_accumulate<irradiance_volume_bands, float, glm::vec3>(
            sum, wsum, n, w[std::size_t(k)], pr.inside ? 0.f : 1.f, pr.radiance);
    }
    return probe_average<float, glm::vec3>(sum, wsum);
}

inline void irradiance_volume::weighted_candidates(glm::vec3 p, float support, std::vector<std::uint32_t>& out) const {
    out.clear();
    std::uint32_t stack[8 * depth_limit + 8];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const std::uint32_t i = stack[--top];
        const node& nd = nodes_[i];
        if (octree_node_reaches<float, glm::vec3>(p, nd.lo, nd.size, support) == 0.f) continue;
        if (!nd.leaf()) {
            for (int k = 7; k >= 0; --k) stack[top++] = std::uint32_t(nd.first_child + k);
            continue;
        }
        for (std::uint32_t idx : nd.corner) {
            const irradiance_probe& pr = probes_[idx];
            if (owner_[idx] == i && !pr.inside && glm::length(p - pr.position) < support * pr.reach) out.push_back(idx);
        }
    }
}

inline glm::vec3 irradiance_volume::weighted(glm::vec3 p, glm::vec3 n, const weighted_lookup& how) const {
    require(how.b > 0 && how.b <= 4, "b", "the distance exponent must lie in (0, 4]");
    require(how.support > 1 && std::isfinite(how.support), "support", "must be finite and > 1");
    thread_local std::vector<std::uint32_t> candidates;
    weighted_candidates(p, how.support, candidates);
    glm::vec3 sum(0.f);
    float wsum = 0.f;
    const float ref = how.support * reference_reach_;
    for (std::uint32_t idx : candidates) {
        const irradiance_probe& pr = probes_[idx];
        std::tie(sum, wsum) = weighted_probe_accumulate<irradiance_volume_bands, float, glm::vec3>(
            sum, wsum, p, n, pr.position, pr.inside ? 0.f : how.support * pr.reach, ref, how.b, min_relative_distance,
            how.gradients ? 1.f : 0.f, pr.radiance, pr.gradient[0], pr.gradient[1], pr.gradient[2]);
    }
    return probe_average<float, glm::vec3>(sum, wsum);
}

inline irradiance_volume_gpu_layout irradiance_volume::flatten() const {
    irradiance_volume_gpu_layout out;
    out.max_depth = depth();
    out.nodes.reserve(nodes_.size());
    for (const auto& n : nodes_) {
        irradiance_volume_gpu_node g{};
        for (int k = 0; k < 3; ++k) g.lo[k] = n.lo[k], g.size[k] = n.size[k];
        g.first_child = n.first_child;
        for (int k = 0; k < 8; ++k) g.corner[k] = n.corner[std::size_t(k)];
        out.nodes.push_back(g);
    }
    out.probes.reserve(probes_.size());
    for (const auto& p : probes_) {
        irradiance_volume_gpu_probe g{};
        for (int k = 0; k < 3; ++k) g.position[k] = p.position[k];
        g.position[3] = p.inside ? 0.f : p.reach;
        for (std::size_t i = 0; i < irradiance_volume_coefficients; ++i)
            for (int k = 0; k < 3; ++k) {
                g.radiance[i][k] = p.radiance[i][k];
                for (int a = 0; a < 3; ++a) g.gradient[a][i][k] = p.gradient[std::size_t(a)][i][k];
            }
        out.probes.push_back(g);
    }
    return out;
}

}  // namespace bounce::volume
