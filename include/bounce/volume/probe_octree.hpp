#pragma once
/// \file volume/probe_octree.hpp
/// Irradiance volumes (Greger et al., "The Irradiance Volume", IEEE CG&A 1998; Oat,
/// "Irradiance Volumes for Real-time Rendering", ShaderX5 section 6.1, 2006): SH probes
/// of the incoming radiance at the corners of the cells of an octree over a static scene,
/// looked up to light moving objects.
///
/// - A uniform grid is the octree subdivided everywhere to one depth; an adaptive octree
///   is merged from the finest grid where a cell's interpolation predicts its probes
///   (volume/octree_merging.hpp, the default), or split from the root by prediction error
///   or by Oat's heuristics, each with its threshold (`irradiance_volume_settings`),
///   between a minimum and a maximum depth. The probes, the settings and the heuristics
///   are in volume/octree_subdivision.hpp. Corners at level boundaries take the coarser
///   leaf's interpolation (conforming_corners), so trilinear lookups are continuous.
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
#include <bounce/scene_view.hpp>
#include <bounce/volume/kernels.hpp>
#include <bounce/volume/octree_merging.hpp>
#include <bounce/volume/octree_subdivision.hpp>

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

    /// Nodes and probes as std430 buffers. Throws parameter_error naming "volume" when it
    /// computes its hanging corners (the GL lookup reads a probe at every corner).
    irradiance_volume_gpu_layout flatten() const;

    /// The computed hanging corners (settings.hanging_corners = computed; empty otherwise):
    /// a leaf corner c with c & 0x80000000 is hanging_corners()[c & 0x7fffffff], whose terms
    /// (stored probes and weights, hanging_terms()) sum to the coarser leaf's interpolation.
    const std::vector<hanging_corner>& hanging_corners() const noexcept { return hanging_.corners; }
    const std::vector<hanging_term>& hanging_terms() const noexcept { return hanging_.terms; }
    /// Hanging corners stored as probes (conforming corners with hanging_corners = stored).
    std::size_t stored_hanging_corners() const noexcept { return stored_hanging_; }
    /// Throws parameter_error naming "volume" when the volume computes hanging corners:
    /// `what` (a lookup other than trilinear) needs a probe at every corner.
    void require_stored_corners(const char* what) const;

    /// Bakes every stored probe again from `source` at its position and takes its light
    /// (radiance, gradients, harmonic mean distance, noise), keeping the layout: leaves,
    /// inside flags, reaches and the computed hanging corners' weights. With more rays per
    /// probe than the bake that decided the layout it compares layouts at equal total rays.
    /// Throws parameter_error naming "volume" when hanging corners are stored (their values
    /// would no longer be their coarser leaf's interpolation), "probes" when the source
    /// returns a non-finite probe or moves one.
    template <probe_source Source>
    void rebake(Source&& source);

    /// Cap on the weight at a probe, in units of its reach (see weighted_probe_accumulate).
    static constexpr float min_relative_distance = 1e-4f;

private:
    std::vector<node> nodes_;
    std::vector<irradiance_probe> probes_;
    std::vector<std::uint32_t> owner_;
    float reference_reach_ = 1.f;
    detail::hanging_table hanging_;
    std::size_t stored_hanging_ = 0;
};

// ---- implementation ------------------------------------------------------------------------

}  // namespace bounce::volume

namespace bounce::detail {

/// The probes of a build, each at a point of the lattice of the finest level (max_depth
/// cells per axis), at most one per point, found by their lattice key.
class probe_lattice {
public:
    probe_lattice(glm::vec3 lo, glm::vec3 hi, int max_depth)
        : lo_(lo), extent_(hi - lo), res_(std::uint64_t(1) << max_depth) {}

    /// Lattice cells per cell side at `depth`.
    std::uint64_t step(int depth) const { return res_ >> depth; }
    std::uint64_t key_of(std::uint64_t x, std::uint64_t y, std::uint64_t z) const {
        return x + (res_ + 1) * (y + (res_ + 1) * z);
    }
    /// The lattice keys of cell c's 8 corners (corner k at +step (k & 1, (k >> 1) & 1, (k >> 2) & 1)).
    std::array<std::uint64_t, 8> corner_keys(const octree_cell& c, int depth) const {
        const std::uint64_t st = step(depth);
        std::array<std::uint64_t, 8> keys{};
        for (int k = 0; k < 8; ++k)
            keys[std::size_t(k)] = key_of(c.x + st * std::uint64_t(k & 1), c.y + st * std::uint64_t((k >> 1) & 1),
                                          c.z + st * std::uint64_t((k >> 2) & 1));
        return keys;
    }
    std::uint32_t index(std::uint64_t key) const { return at_key_.at(key); }
    const std::vector<irradiance_probe>& probes() const noexcept { return all_; }
    /// Least-squares refit of the probes to the samples of culled splits (refit_probes).
    void refit(const std::vector<culled_sample>& samples, int sweeps) { refit_probes(all_, samples, sweeps); }
    /// Sets the hanging corners from their coarser leaves (set_hanging_corners).
    void set_hanging(const std::vector<culled_sample>& hanging) { set_hanging_corners(all_, hanging); }
    /// f(index, lattice coordinates) for every baked probe.
    template <class F>
    void for_each_point(F&& f) const {
        for (const auto& [key, idx] : at_key_)
            f(idx, std::array<std::uint64_t, 3>{key % (res_ + 1), key / (res_ + 1) % (res_ + 1), key / ((res_ + 1) * (res_ + 1))});
    }

    /// Bakes every corner of `cells` (cells of `depth`) not yet in the lattice, in one batch
    /// from `source`; `nodes` is the node count the volume will have with them, for
    /// settings.memory_limit_bytes.
    template <class Source>
    void bake_corners(const std::vector<octree_cell>& cells, int depth, std::size_t nodes,
                      const irradiance_volume_settings& s, Source& source, irradiance_volume_build_stats& stats) {
        std::vector<glm::vec3> positions;
        const std::uint64_t st = step(depth);
        std::size_t added = 0;
        for (const auto& c : cells)
            for (int k = 0; k < 8; ++k) {
                const std::uint64_t x = c.x + st * std::uint64_t(k & 1), y = c.y + st * std::uint64_t((k >> 1) & 1),
                                    z = c.z + st * std::uint64_t((k >> 2) & 1);
                if (!at_key_.emplace(key_of(x, y, z), std::uint32_t(all_.size() + added)).second) continue;
                ++added;
                positions.push_back(lo_ + extent_ * (glm::vec3(float(x), float(y), float(z)) / float(res_)));
            }
        if (positions.empty()) return;
        check_memory(all_.size() + positions.size(), nodes, depth, s);
        std::vector<irradiance_probe> baked(positions.size());
        source(std::span<const glm::vec3>(positions), std::span<irradiance_probe>(baked));
        for (std::size_t i = 0; i < baked.size(); ++i) {
            require(finite_probe(baked[i]), "probes",
                    "the probe source returned a non-finite probe (NaN or infinite coefficient or position)");
            require(glm::length(baked[i].position - positions[i]) <= 1e-5f * glm::length(extent_), "probes",
                    "the probe source moved a probe away from its lattice position");
            all_.push_back(baked[i]);
        }
        stats.probes_baked += baked.size();
    }

private:
    static void check_memory(std::size_t probe_count, std::size_t node_count, int depth, const irradiance_volume_settings& s) {
        if (s.memory_limit_bytes == 0) return;
        const double probes = double(probe_count), nodes = double(node_count),
                     need = irradiance_volume::estimated_bytes(probes, nodes);
        if (need > double(s.memory_limit_bytes))
            throw parameter_error("settings.max_depth",
                                  "depth " + std::to_string(depth) + " would hold " + std::to_string(std::uint64_t(probes)) +
                                      " probes, about " + std::to_string(std::uint64_t(need / 1e6)) + " MB, more than the " +
                                      std::to_string(s.memory_limit_bytes / 1000000) + " MB allowed; choose a smaller max_depth");
    }

    glm::vec3 lo_, extent_;
    std::uint64_t res_;
    std::vector<irradiance_probe> all_;
    std::unordered_map<std::uint64_t, std::uint32_t> at_key_;
};

/// Whether the parent box [lo, lo + size] with corner probes `corner` predicts every probe
/// of its children `family` (cells of `child_depth`, their corners baked) outside
/// geometry, as parent_predicts_probe says, with `tolerance` and noise_sigmas times the
/// standard error pooled (root mean square of `noise`) over the corners and new probes
/// outside geometry: then culling undoes the split, and the new probes outside geometry are
/// appended to `samples` (when given) for the refit.
inline bool parent_predicts_children(const probe_lattice& lattice, const std::array<std::uint32_t, 8>& corner,
                                     glm::vec3 lo, glm::vec3 size, const std::vector<octree_cell>& family,
                                     int child_depth, float floor_level, float tolerance, const irradiance_volume_settings& s,
                                     std::vector<culled_sample>* samples) {
    const std::vector<irradiance_probe>& all = lattice.probes();
    parent_prediction parent;
    parent.tolerance = tolerance;
    parent.floor_level = floor_level;
    double noise2 = 0;
    std::size_t counted = 0;
    const auto pool = [&](const irradiance_probe& p) {
        if (!p.inside) noise2 += double(p.noise) * double(p.noise), ++counted;
    };
    for (int k = 0; k < 8; ++k) {
        const auto& p = all[corner[std::size_t(k)]];
        parent.corner_e[std::size_t(k)] = axis_irradiance(p.radiance);
        parent.corner_valid[std::size_t(k)] = p.inside ? 0.f : 1.f;
        pool(p);
    }
    std::vector<std::uint32_t> fresh;
    for (const auto& ch : family)
        for (const std::uint64_t key : lattice.corner_keys(ch, child_depth)) {
            const std::uint32_t i = lattice.index(key);
            if (std::find(corner.begin(), corner.end(), i) != corner.end() ||
                std::find(fresh.begin(), fresh.end(), i) != fresh.end())
                continue;
            fresh.push_back(i);
            pool(all[i]);
        }
    parent.noise = counted ? s.noise_sigmas * float(std::sqrt(noise2 / double(counted))) : 0.f;
    for (const std::uint32_t i : fresh) {
        const auto& p = all[i];
        if (!p.inside && !parent_predicts_probe(p, lo, size, parent)) return false;
    }
    if (samples)  // the new probes outside geometry, where the parent's corners predict them
        for (const std::uint32_t i : fresh) {
            if (all[i].inside) continue;
            culled_sample cs{i, corner, trilinear_weights<float, glm::vec3>(all[i].position, lo, size)};
            float wsum = 0;
            for (std::size_t k = 0; k < 8; ++k) wsum += cs.weight[k] *= parent.corner_valid[k];
            for (float& w : cs.weight) w /= wsum;
            samples->push_back(cs);
        }
    return true;
}

/// Throws parameter_error for the arguments irradiance_volume::build refuses.
inline void validate_volume_build(const scene_view& scene, glm::vec3 lo, glm::vec3 hi, const irradiance_volume_settings& s) {
    require(!scene.triangles.empty(), "scene", "the scene has no triangles: nothing to light, no geometry to test");
    const auto finite3 = [](glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    require(finite3(lo) && finite3(hi), "lo", "volume bounds must be finite");
    require(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z, "hi", "volume bounds must enclose a non-empty box (hi > lo)");
    require(s.max_depth >= 0 && s.max_depth <= irradiance_volume::depth_limit, "settings.max_depth", "must lie in 0 .. 10");
    require(s.min_depth >= 0 && s.min_depth <= s.max_depth, "settings.min_depth", "must lie in 0 .. max_depth");
    const auto threshold = [](float v, const char* name) {
        require(std::isfinite(v) && v >= 0, name, "threshold must be finite and >= 0 (0: off)");
    };
    threshold(s.distance_ratio, "settings.distance_ratio");
    threshold(s.neighbour_change, "settings.neighbour_change");
    threshold(s.gradient_ratio, "settings.gradient_ratio");
    threshold(s.cull_tolerance, "settings.cull_tolerance");
    threshold(s.prediction_tolerance, "settings.prediction_tolerance");
    threshold(s.noise_sigmas, "settings.noise_sigmas");
    threshold(s.absolute_floor, "settings.absolute_floor");
    threshold(s.bias_budget, "settings.bias_budget");
    threshold(s.bias_tolerance, "settings.bias_tolerance");
    require(s.hanging_corners == hanging_corner_storage::stored || s.conforming_corners, "settings.hanging_corners",
            "computed hanging corners are the coarser leaf's interpolation: they need conforming_corners on");
}

/// The root cell over [lo, hi] with the scene's triangles that overlap it.
inline octree_cell root_cell(const scene_view& scene, glm::vec3 lo, glm::vec3 hi) {
    octree_cell root{0, 0, 0, 0, {}};
    root.triangles.reserve(scene.triangles.size());
    const glm::dvec3 c = glm::dvec3(lo + hi) * 0.5, h = glm::dvec3(hi - lo) * 0.5;
    for (std::uint32_t t = 0; t < scene.triangles.size(); ++t)
        if (triangle_overlaps_box(scene, t, c, h)) root.triangles.push_back(t);
    return root;
}

/// The 8 nodes of a split node's children (octant k at octant_lo(lo, size, k)), appended
/// to `nodes`; returns the first one's index.
inline std::uint32_t add_child_nodes(std::vector<irradiance_volume::node>& nodes, std::uint32_t parent) {
    const irradiance_volume::node p = nodes[parent];
    const std::uint32_t first = std::uint32_t(nodes.size());
    nodes[parent].first_child = std::int32_t(first);
    for (int k = 0; k < 8; ++k) nodes.push_back({octant_lo(p.lo, p.size, k), p.size * 0.5f, p.depth + 1, -1, {}});
    return first;
}

/// The next level of the octree: the cells of `level` (at `depth`, their corners set) that
/// a heuristic splits and culling keeps, as nodes and cells with their corners baked.
template <class Source>
std::vector<octree_cell> grow_level(const scene_view& scene, const std::vector<octree_cell>& level, int depth,
                                    float floor_level, const irradiance_volume_settings& s, Source& source,
                                    probe_lattice& lattice, std::vector<irradiance_volume::node>& nodes,
                                    irradiance_volume_build_stats& stats, std::vector<culled_sample>& samples) {
    std::vector<std::size_t> split_cells;
    for (std::size_t ci = 0; ci < level.size(); ++ci)
        if (cell_splits(level[ci], nodes[level[ci].node].corner, nodes[level[ci].node].size, lattice.probes(), depth,
                        floor_level, s, stats))
            split_cells.push_back(ci);
    // Children of the splitting cells, with their triangles; bake their corners.
    std::vector<std::vector<octree_cell>> families(split_cells.size());
    std::vector<octree_cell> batch;
    for (std::size_t si = 0; si < split_cells.size(); ++si) {
        const octree_cell& c = level[split_cells[si]];
        families[si] = child_cells(scene, c, nodes[c.node].lo, nodes[c.node].size, lattice.step(depth + 1));
        for (const auto& ch : families[si]) batch.push_back(octree_cell{0, ch.x, ch.y, ch.z, {}});
    }
    lattice.bake_corners(batch, depth + 1, nodes.size() + batch.size(), s, source, stats);
    // Culling: undo a split whose new probes the parent already predicts (within the
    // prediction tolerance when it drives the splits, else the cull tolerance).
    const float tolerance = s.prediction_tolerance > 0 ? s.prediction_tolerance : s.cull_tolerance;
    std::vector<octree_cell> children;
    for (std::size_t si = 0; si < split_cells.size(); ++si) {
        const irradiance_volume::node& parent = nodes[level[split_cells[si]].node];
        const bool keep = depth < s.min_depth || tolerance <= 0 ||
                          !parent_predicts_children(lattice, parent.corner, parent.lo, parent.size, families[si],
                                                    depth + 1, floor_level, tolerance, s,
                                                    s.refit_culled ? &samples : nullptr);
        if (!keep) {
            ++stats.culled;
            continue;
        }
        const std::uint32_t first = add_child_nodes(nodes, level[split_cells[si]].node);
        for (int k = 0; k < 8; ++k) {
            families[si][std::size_t(k)].node = first + std::uint32_t(k);
            children.push_back(std::move(families[si][std::size_t(k)]));
        }
    }
    return children;
}

/// Sets each probe's reach (half the diagonal of the largest leaf it is a corner of) and
/// owner (that leaf; the first in node order among equals); returns the smallest reach.
inline float set_reach_and_owners(const std::vector<irradiance_volume::node>& nodes,
                                  std::vector<irradiance_probe>& probes, std::vector<std::uint32_t>& owner) {
    owner.assign(probes.size(), 0);
    for (auto& p : probes) p.reach = 0.f;
    for (std::uint32_t i = 0; i < nodes.size(); ++i) {
        const irradiance_volume::node& nd = nodes[i];
        if (!nd.leaf()) continue;
        const float half_diagonal = 0.5f * glm::length(nd.size);
        for (std::uint32_t idx : nd.corner)
            if ((idx & hanging_flag) == 0 && half_diagonal > probes[idx].reach) probes[idx].reach = half_diagonal, owner[idx] = i;
    }
    float smallest = std::numeric_limits<float>::infinity();
    for (const auto& p : probes) smallest = std::min(smallest, p.reach);
    return smallest;
}

}  // namespace bounce::detail

namespace bounce::inline volume {

template <probe_source Source>
irradiance_volume irradiance_volume::build(const scene_view& scene, glm::vec3 lo, glm::vec3 hi,
                                           const irradiance_volume_settings& s, Source&& source,
                                           irradiance_volume_build_stats* stats_out) {
    detail::validate_volume_build(scene, lo, hi, s);
    irradiance_volume_build_stats stats;
    irradiance_volume v;
    detail::probe_lattice lattice(lo, hi, s.max_depth);
    v.nodes_.push_back(node{lo, hi - lo, 0, -1, {}});
    std::vector<detail::octree_cell> level{detail::root_cell(scene, lo, hi)};
    std::vector<detail::culled_sample> samples;
    lattice.bake_corners(level, 0, v.nodes_.size() + level.size(), s, source, stats);
    const float floor_level = detail::absolute_floor_level(lattice.probes(), s.absolute_floor);
    const bool merge = s.refinement == volume_refinement::merge && s.prediction_tolerance > 0 && s.min_depth < s.max_depth;
    if (merge) {  // the finest grid, then merged from the finest level up
        std::vector<detail::octree_cell> finest;
        const std::uint64_t n = std::uint64_t(1) << s.max_depth;
        for (std::uint64_t z = 0; z < n; ++z)
            for (std::uint64_t y = 0; y < n; ++y)
                for (std::uint64_t x = 0; x < n; ++x) finest.push_back({0, x, y, z, {}});
        lattice.bake_corners(finest, s.max_depth, std::size_t((8 * n * n * n - 1) / 7), s, source, stats);
        detail::merged_nodes(lattice, detail::merge_from_finest(lattice, floor_level, s, stats), s, v.nodes_);
    }
    for (int depth = 0; depth <= s.max_depth && !merge; ++depth) {
        for (const auto& c : level) {
            const auto keys = lattice.corner_keys(c, depth);
            for (int k = 0; k < 8; ++k) v.nodes_[c.node].corner[std::size_t(k)] = lattice.index(keys[std::size_t(k)]);
        }
        if (depth == s.max_depth) break;
        level = detail::grow_level(scene, level, depth, floor_level, s, source, lattice, v.nodes_, stats, samples);
        if (level.empty()) break;
    }
    detail::lattice_constraints constraints;
    if (merge || s.conforming_corners) {
        constraints = detail::conforming_constraints(lattice, v.nodes_, s.max_depth);
        samples = std::move(constraints.samples);  // the culled splits' probes are among them
    }
    if (s.refit_culled && !samples.empty()) lattice.refit(samples, 16);
    stats.hanging_corners = s.conforming_corners ? constraints.hanging.size() : 0;
    if (s.conforming_corners && s.hanging_corners == hanging_corner_storage::computed) {
        const auto expanded = detail::expand_hanging(constraints.hanging);
        v.probes_ = detail::used_probes(lattice.probes(), v.nodes_, &expanded, &v.hanging_);
    } else {
        if (s.conforming_corners) lattice.set_hanging(constraints.hanging);
        v.stored_hanging_ = stats.hanging_corners;
        v.probes_ = detail::used_probes(lattice.probes(), v.nodes_);
    }
    for (const auto& p : v.probes_) stats.probes_inside += p.inside ? 1 : 0;
    if (stats.probes_inside == v.probes_.size())
        throw parameter_error("scene", "every one of the " + std::to_string(v.probes_.size()) +
                                           " probes is inside geometry (its rays hit the backs of triangles), so the volume "
                                           "would light nothing; are the scene's triangles wound the wrong way, facing away "
                                           "from the volume and the lights?");
    v.reference_reach_ = detail::set_reach_and_owners(v.nodes_, v.probes_, v.owner_);
    if (stats_out) *stats_out = stats;
    return v;
}

template <probe_source Source>
void irradiance_volume::rebake(Source&& source) {
    if (stored_hanging_ > 0)
        throw parameter_error("volume", "its " + std::to_string(stored_hanging_) +
                                            " stored hanging corners would no longer interpolate their coarser leaf; build it "
                                            "with settings.hanging_corners = computed");
    std::vector<glm::vec3> positions;
    for (const auto& p : probes_) positions.push_back(p.position);
    std::vector<irradiance_probe> baked(positions.size());
    source(std::span<const glm::vec3>(positions), std::span<irradiance_probe>(baked));
    const float scale = glm::length(hi() - lo());
    for (std::size_t i = 0; i < baked.size(); ++i) {
        require(detail::finite_probe(baked[i]), "probes", "the probe source returned a non-finite probe");
        require(glm::length(baked[i].position - positions[i]) <= 1e-5f * scale, "probes",
                "the probe source moved a probe away from its position");
        irradiance_probe& p = probes_[i];
        p.radiance = baked[i].radiance, p.gradient = baked[i].gradient;
        p.harmonic_mean_distance = baked[i].harmonic_mean_distance, p.noise = baked[i].noise;
    }
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
    for (std::size_t k = 0; k < 8; ++k) {
        const std::uint32_t idx = leaf.corner[k];
        if ((idx & detail::hanging_flag) == 0) {
            const irradiance_probe& pr = probes_[idx];
            std::tie(sum, wsum) = trilinear_probe_accumulate<irradiance_volume_bands, float, glm::vec3>(
                sum, wsum, n, w[k], pr.inside ? 0.f : 1.f, pr.radiance);
            continue;
        }
        const hanging_corner& h = hanging_.corners[idx & ~detail::hanging_flag];
        irradiance_probe::coefficients c{};
        for (std::uint32_t t = h.first; t < h.first + h.count; ++t)
            c = probe_combination_add<irradiance_volume_bands, float, glm::vec3>(c, hanging_.terms[t].weight,
                                                                                 probes_[hanging_.terms[t].probe].radiance);
        std::tie(sum, wsum) = trilinear_probe_accumulate<irradiance_volume_bands, float, glm::vec3>(sum, wsum, n, w[k], h.valid, c);
    }
    return probe_average<float, glm::vec3>(sum, wsum);
}

inline void irradiance_volume::require_stored_corners(const char* what) const {
    if (!hanging_.corners.empty())
        throw parameter_error("volume", std::string(what) + " needs a probe at every corner, and this volume computes its " +
                                            std::to_string(hanging_.corners.size()) +
                                            " hanging corners in the trilinear lookup; build it with "
                                            "settings.hanging_corners = stored");
}

inline void irradiance_volume::weighted_candidates(glm::vec3 p, float support, std::vector<std::uint32_t>& out) const {
    require_stored_corners("the weighted lookup");
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
    require_stored_corners("flatten (the GL lookup)");
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
