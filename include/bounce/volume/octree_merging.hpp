#pragma once
/// \file volume/octree_merging.hpp
/// Bottom-up merging of an irradiance volume's octree (issue 31) and conforming corners at
/// level boundaries, for irradiance_volume::build (volume/probe_octree.hpp).
///
/// - Merging: the build bakes the finest uniform grid and makes a leaf of every cell (the
///   coarsest first) whose trilinear interpolation predicts every baked probe inside its
///   closed box (not only the 19 of one split) within the relative tolerance or within the
///   noise (irradiance_volume_settings::refinement): its children are merged into it.
/// - Conforming corners: a corner of a leaf that lies on a face or an edge of a coarser
///   leaf (a hanging corner, T-junction) takes the value the coarser leaf interpolates
///   there, so trilinear lookups are continuous across level boundaries; the baked value it
///   had becomes a sample for the least-squares refit (refit_probes).
///
/// The functions are templates over the build's lattice (detail::probe_lattice) and node
/// types, so that this header needs only octree_subdivision.hpp.

#include <bounce/volume/octree_subdivision.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace bounce::detail {

/// The standard errors a difference must exceed in a cell that tests `tested` values
/// (6 normals per probe), so that Gaussian noise of the stated standard error keeps the cell
/// split with probability at most what it has in a cell of one level at `sigmas` (19 new
/// probes, 114 values): the union bound n erfc(k_n / sqrt 2) <= 114 erfc(sigmas / sqrt 2).
/// At 4 that bound is 0.72% per cell, at any size.
inline float family_sigmas(float sigmas, std::size_t tested) {
    constexpr double one_level = 6 * 19;
    if (sigmas <= 0 || double(tested) <= one_level) return sigmas;
    const double target = one_level * std::erfc(double(sigmas) / std::sqrt(2.0)) / double(tested);
    double lo = sigmas, hi = 40;  // erfc is decreasing: bisect erfc(k / sqrt 2) = target
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (std::erfc(mid / std::sqrt(2.0)) > target ? lo : hi) = mid;
    }
    return float(hi);
}

/// A cell of the lattice of a build: its origin in cells of the finest level, its depth.
struct lattice_cell {
    std::uint64_t x = 0, y = 0, z = 0;
    int depth = 0;
};

/// The lattice keys of the corners of cell c (corner k at +step (k & 1, (k >> 1) & 1, (k >> 2) & 1)).
template <class Lattice>
std::array<std::uint64_t, 8> lattice_corner_keys(const Lattice& lattice, const lattice_cell& c) {
    return lattice.corner_keys(octree_cell{0, c.x, c.y, c.z, {}}, c.depth);
}

/// Whether cell c's trilinear interpolation of its corners predicts every probe of the
/// finest level in its closed box (outside geometry), as parent_predicts_probe says with
/// `tolerance` and noise_sigmas (family_sigmas for the number of values tested) times the
/// noise pooled (root mean square) over those probes. A cell whose probes are all inside
/// geometry merges (nothing to light).
/// The bias-budget test (irradiance_volume_settings::bias_budget > 0): the cell merges
/// when the bias its interpolation adds, estimated as the mean squared miss at the tested
/// probes less the noise variance expected there (noise_scale2 * sigma^2 (1 + sum w^2)),
/// stays below bias_budget times the noise variance merging removes from a point of the
/// finest grid (8/27 sigma^2, the mean of sum w^2 over a cell), with noise_sigmas standard
/// deviations of that estimate (sqrt(2 / probes) of the expected variance) as slack so that
/// noise alone merges, and differences below 0.1% of the light ignored. With
/// bias_tolerance > 0 the bound is (bias_tolerance * scene_level)^2 instead (scene_level:
/// the finest grid's mean light, absolute_floor_level at 1).
template <class Lattice>
bool cell_bias_within_budget(const Lattice& lattice, const std::array<std::uint32_t, 8>& corner, const parent_prediction& parent,
                             const std::vector<std::uint32_t>& tested, float sigma2, float noise_scale2,
                             const irradiance_volume_settings& s, float scene_level = 0) {
    const auto& all = lattice.probes();
    const glm::vec3 lo = all[corner[0]].position, size = all[corner[7]].position - lo;
    double miss2 = 0, expected = 0, expected2 = 0, level = 0;
    std::size_t n = 0;
    for (const std::uint32_t idx : tested) {
        const auto w = trilinear_weights<float, glm::vec3>(all[idx].position, lo, size);
        std::array<double, 6> predicted{};
        double wsum = 0, w2sum = 0;
        for (std::size_t j = 0; j < 8; ++j) {
            const double wj = double(w[j]) * parent.corner_valid[j];
            wsum += wj, w2sum += wj * wj;
            for (std::size_t a = 0; a < 6; ++a) predicted[a] += wj * parent.corner_e[j][a];
        }
        if (wsum <= 0) return false;  // no usable corner predicts this probe
        const auto actual = axis_irradiance(all[idx].radiance);
        for (std::size_t a = 0; a < 6; ++a) {
            const double d = actual[a] - predicted[a] / wsum;
            miss2 += d * d, level += std::abs(predicted[a] / wsum);
        }
        double corner_var = 0;  // each probe's own noise, not the cell's pooled one
        for (std::size_t j = 0; j < 8; ++j) {
            const double wj = double(w[j]) * parent.corner_valid[j] / wsum, sj = all[corner[j]].noise;
            corner_var += wj * wj * sj * sj;
        }
        const double var = double(noise_scale2) * (double(all[idx].noise) * all[idx].noise + corner_var);
        expected += 6 * var, expected2 += 6 * var * var, n += 6;
    }
    if (n == 0) return true;
    // The slack: noise_sigmas standard deviations of sum (m^2 - var) under noise alone,
    // sqrt(2 sum var^2) over the probes (the 6 normals of a probe counted as one).
    const double bias2 = (miss2 - expected) / double(n), slack = s.noise_sigmas * std::sqrt(2 * expected2 * 6) / double(n);
    const double floor2 = std::pow(1e-3 * (level / double(n) + parent.floor_level), 2);
    const double bound = s.bias_tolerance > 0 ? std::pow(double(s.bias_tolerance) * scene_level, 2)
                                              : s.bias_budget * (8.0 / 27.0) * noise_scale2 * sigma2;
    return bias2 <= bound + slack + floor2;
}

/// The scale of the probes' reported noise variance the finest grid supports: the median
/// over probes (outside geometry, with both neighbours on an axis usable) of the squared
/// second difference along the axes (mean over the 3 axes and 6 normals, over 3/2: the
/// variance of p - (p- + p+) / 2 for independent noise) over the median of noise^2,
/// at most 1. The even and odd halves of a Fibonacci set differ more than the whole set
/// errs, so the reported noise overstates it; the second difference bounds it from above
/// (curvature adds to it).
template <class Lattice>
float noise_scale2(const Lattice& lattice, int max_depth) {
    const auto& all = lattice.probes();
    const std::uint64_t res = std::uint64_t(1) << max_depth;
    std::vector<double> rough, reported;
    lattice.for_each_point([&](std::uint32_t idx, const std::array<std::uint64_t, 3>& p) {
        if (all[idx].inside) return;
        const auto e = axis_irradiance(all[idx].radiance);
        double r2 = 0;
        int axes = 0;
        for (std::size_t a = 0; a < 3; ++a) {
            if (p[a] == 0 || p[a] == res) continue;
            auto lo = p, hi = p;
            --lo[a], ++hi[a];
            const auto& pl = all[lattice.index(lattice.key_of(lo[0], lo[1], lo[2]))];
            const auto& ph = all[lattice.index(lattice.key_of(hi[0], hi[1], hi[2]))];
            if (pl.inside || ph.inside) continue;
            const auto el = axis_irradiance(pl.radiance), eh = axis_irradiance(ph.radiance);
            for (std::size_t k = 0; k < 6; ++k) r2 += std::pow(e[k] - 0.5 * (el[k] + eh[k]), 2) / 6;
            ++axes;
        }
        if (axes == 0) return;
        rough.push_back(r2 / axes / 1.5);
        reported.push_back(double(all[idx].noise) * all[idx].noise);
    });
    if (rough.empty()) return 1.f;
    const auto median = [](std::vector<double>& v) {
        std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
        return v[v.size() / 2];
    };
    const double r = median(rough), n = median(reported);
    return n > 0 ? float(std::min(1.0, r / n)) : 1.f;
}

/// The median noise of the probes outside geometry (0 when there is none).
inline float median_noise(const std::vector<irradiance_probe>& probes) {
    std::vector<float> noise;
    for (const auto& p : probes)
        if (!p.inside) noise.push_back(p.noise);
    if (noise.empty()) return 0.f;
    std::nth_element(noise.begin(), noise.begin() + std::ptrdiff_t(noise.size() / 2), noise.end());
    return noise[noise.size() / 2];
}

template <class Lattice>
bool cell_predicts_finest(const Lattice& lattice, const lattice_cell& c, float floor_level, float tolerance,
                          const irradiance_volume_settings& s, float noise_scale2 = 1, float scene_level = 0) {
    const auto& all = lattice.probes();
    const auto keys = lattice_corner_keys(lattice, c);
    parent_prediction parent;
    parent.tolerance = tolerance;
    parent.floor_level = floor_level;
    std::array<std::uint32_t, 8> corner{};
    for (std::size_t k = 0; k < 8; ++k) {
        corner[k] = lattice.index(keys[k]);
        parent.corner_e[k] = axis_irradiance(all[corner[k]].radiance);
        parent.corner_valid[k] = all[corner[k]].inside ? 0.f : 1.f;
    }
    const std::uint64_t st = lattice.step(c.depth);
    std::vector<std::uint32_t> tested;
    double noise2 = 0;
    std::size_t usable = 0;
    for (std::uint64_t k = 0; k <= st; ++k)
        for (std::uint64_t j = 0; j <= st; ++j)
            for (std::uint64_t i = 0; i <= st; ++i) {
                const std::uint32_t idx = lattice.index(lattice.key_of(c.x + i, c.y + j, c.z + k));
                if (all[idx].inside) continue;
                noise2 += double(all[idx].noise) * double(all[idx].noise), ++usable;
                if (std::find(corner.begin(), corner.end(), idx) == corner.end()) tested.push_back(idx);
            }
    if (usable == 0) return true;
    if (s.bias_budget > 0 || s.bias_tolerance > 0)
        return cell_bias_within_budget(lattice, corner, parent, tested, float(noise2 / double(usable)), noise_scale2, s,
                                       scene_level);
    parent.noise = family_sigmas(s.noise_sigmas, 6 * tested.size()) * float(std::sqrt(noise2 / double(usable)));
    const glm::vec3 lo = all[corner[0]].position, size = all[corner[7]].position - lo;
    for (const std::uint32_t idx : tested)
        if (!parent_predicts_probe(all[idx], lo, size, parent)) return false;
    return true;
}

/// Which cells of each depth are whole (`whole[d][x + n (y + n z)]`, n = 2^d cells per
/// axis): every cell of max_depth; a cell of min_depth .. max_depth - 1 that
/// cell_predicts_finest, whatever its children say (a child kept by a noisy probe does not
/// keep every ancestor split: the parent's test pools more probes). Counts them in
/// stats.merged.
template <class Lattice>
std::vector<std::vector<bool>> merge_from_finest(const Lattice& lattice, float floor_level, const irradiance_volume_settings& s,
                                                 irradiance_volume_build_stats& stats) {
    std::vector<std::vector<bool>> whole(std::size_t(s.max_depth) + 1);
    const auto cells = [](int d) { return std::uint64_t(1) << d; };
    whole[std::size_t(s.max_depth)].assign(cells(s.max_depth) * cells(s.max_depth) * cells(s.max_depth), true);
    const float scale2 = (s.bias_budget > 0 || s.bias_tolerance > 0) && s.calibrate_noise ? noise_scale2(lattice, s.max_depth) : 1.f;
    stats.noise_scale = std::sqrt(scale2);
    float scene_level = 0;
    if (s.bias_tolerance > 0) {
        stats.scene_light = absolute_floor_level(lattice.probes(), 1.f);
        stats.median_noise = median_noise(lattice.probes()) * stats.noise_scale;
        scene_level = s.tolerance_unit == bias_tolerance_unit::probe_noise ? stats.median_noise : stats.scene_light;
    }
    for (int d = s.max_depth - 1; d >= s.min_depth; --d) {
        const std::uint64_t n = cells(d), st = lattice.step(d);
        whole[std::size_t(d)].assign(n * n * n, false);
        for (std::uint64_t z = 0; z < n; ++z)
            for (std::uint64_t y = 0; y < n; ++y)
                for (std::uint64_t x = 0; x < n; ++x) {
                    if (!cell_predicts_finest(lattice, {x * st, y * st, z * st, d}, floor_level, s.prediction_tolerance, s,
                                              scale2, scene_level))
                        continue;
                    whole[std::size_t(d)][x + n * (y + n * z)] = true;
                    ++stats.merged;
                }
    }
    return whole;
}

/// The octree of merged cells: from the root (nodes[0], already in `nodes`), level by
/// level, a node is a leaf at max_depth or where it is whole at min_depth or deeper, else
/// it gets 8 children (octant k at octant_lo). Sets every node's corners (lattice indices).
template <class Lattice, class Node>
void merged_nodes(const Lattice& lattice, const std::vector<std::vector<bool>>& whole, const irradiance_volume_settings& s,
                  std::vector<Node>& nodes) {
    std::vector<std::pair<std::uint32_t, lattice_cell>> level{{0u, lattice_cell{}}};
    while (!level.empty()) {
        std::vector<std::pair<std::uint32_t, lattice_cell>> next;
        for (const auto& [i, c] : level) {
            const auto keys = lattice_corner_keys(lattice, c);
            for (std::size_t k = 0; k < 8; ++k) nodes[i].corner[k] = lattice.index(keys[k]);
            const std::uint64_t n = std::uint64_t(1) << c.depth, st = lattice.step(c.depth);
            if (c.depth == s.max_depth ||
                (c.depth >= s.min_depth && whole[std::size_t(c.depth)][c.x / st + n * (c.y / st + n * (c.z / st))]))
                continue;
            const Node parent = nodes[i];
            nodes[i].first_child = std::int32_t(nodes.size());
            const std::uint64_t half = lattice.step(c.depth + 1);
            for (int k = 0; k < 8; ++k) {
                next.push_back({std::uint32_t(nodes.size()),
                                lattice_cell{c.x + half * std::uint64_t(k & 1), c.y + half * std::uint64_t((k >> 1) & 1),
                                             c.z + half * std::uint64_t((k >> 2) & 1), c.depth + 1}});
                nodes.push_back(Node{octant_lo(parent.lo, parent.size, k), parent.size * 0.5f, parent.depth + 1, -1, {}});
            }
        }
        level = std::move(next);
    }
}

/// The leaves of an octree as lattice cells (node index, cell), found by descending from
/// the root.
template <class Lattice, class Node>
std::vector<std::pair<std::uint32_t, lattice_cell>> leaf_cells(const Lattice& lattice, const std::vector<Node>& nodes) {
    std::vector<std::pair<std::uint32_t, lattice_cell>> leaves, stack{{0u, lattice_cell{}}};
    while (!stack.empty()) {
        const auto [i, c] = stack.back();
        stack.pop_back();
        if (nodes[i].leaf()) {
            leaves.push_back({i, c});
            continue;
        }
        const std::uint64_t half = lattice.step(c.depth + 1);
        for (int k = 0; k < 8; ++k)
            stack.push_back({std::uint32_t(nodes[i].first_child + k),
                             lattice_cell{c.x + half * std::uint64_t(k & 1), c.y + half * std::uint64_t((k >> 1) & 1),
                                          c.z + half * std::uint64_t((k >> 2) & 1), c.depth + 1}});
    }
    return leaves;
}

/// Finds, for a point of the lattice, the coarsest leaf whose closed box holds it: at each
/// depth from the root down, the (up to 8) cells whose closed box holds the point.
class coarsest_leaf_finder {
public:
    template <class Lattice>
    coarsest_leaf_finder(const Lattice& lattice, std::vector<std::pair<std::uint32_t, lattice_cell>> leaves, int max_depth)
        : leaves_(std::move(leaves)), max_depth_(max_depth) {
        for (std::uint32_t l = 0; l < leaves_.size(); ++l) {
            const lattice_cell& c = leaves_[l].second;
            const std::uint64_t st = lattice.step(c.depth);
            at_.emplace(key(c.depth, c.x / st, c.y / st, c.z / st), l);
        }
    }
    const std::vector<std::pair<std::uint32_t, lattice_cell>>& leaves() const noexcept { return leaves_; }
    /// Index into leaves() of the coarsest leaf holding lattice point p (every point has one).
    std::uint32_t find(const std::array<std::uint64_t, 3>& p) const {
        for (int d = 0; d <= max_depth_; ++d) {
            const std::uint64_t st = std::uint64_t(1) << (max_depth_ - d), n = std::uint64_t(1) << d;
            std::array<std::array<std::uint64_t, 2>, 3> cand{};
            std::array<int, 3> count{};
            for (std::size_t a = 0; a < 3; ++a) {
                const std::uint64_t c = p[a] / st;
                if (c < n) cand[a][std::size_t(count[a]++)] = c;
                if (p[a] % st == 0 && c > 0) cand[a][std::size_t(count[a]++)] = c - 1;  // on a boundary: the cell below too
            }
            for (int i = 0; i < count[0]; ++i)
                for (int j = 0; j < count[1]; ++j)
                    for (int k = 0; k < count[2]; ++k) {
                        const auto it = at_.find(key(d, cand[0][std::size_t(i)], cand[1][std::size_t(j)], cand[2][std::size_t(k)]));
                        if (it != at_.end()) return it->second;
                    }
        }
        return 0;  // not reached: the leaves tile the volume
    }

private:
    static std::uint64_t key(int d, std::uint64_t x, std::uint64_t y, std::uint64_t z) {
        const std::uint64_t n = std::uint64_t(1) << d;
        return (std::uint64_t(d) << 58) | (x + n * (y + n * z));
    }
    std::vector<std::pair<std::uint32_t, lattice_cell>> leaves_;
    std::unordered_map<std::uint64_t, std::uint32_t> at_;
    int max_depth_;
};

/// Lattice point p in leaf cell c (corners `corner`, probes `all`): its trilinear weights
/// there, renormalized over the corners outside geometry (all 0 when none with a weight
/// is), as a culled_sample of probe `probe`.
template <class Lattice>
culled_sample lattice_sample(const Lattice& lattice, const std::vector<irradiance_probe>& all, const lattice_cell& c,
                             const std::array<std::uint32_t, 8>& corner, const std::array<std::uint64_t, 3>& p,
                             std::uint32_t probe) {
    const float st = float(lattice.step(c.depth));
    const glm::vec3 t(float(p[0] - c.x) / st, float(p[1] - c.y) / st, float(p[2] - c.z) / st);
    culled_sample cs{probe, corner, trilinear_weights<float, glm::vec3>(t, glm::vec3(0.f), glm::vec3(1.f))};
    float wsum = 0;
    for (std::size_t k = 0; k < 8; ++k) wsum += cs.weight[k] *= all[corner[k]].inside ? 0.f : 1.f;
    for (float& w : cs.weight) w = wsum > 0 ? w / wsum : 0.f;
    return cs;
}

/// What conforming corners needs of an octree: the baked probes outside geometry that are
/// not a corner of the coarsest leaf holding them, as samples of that leaf (the refit's
/// data), and the hanging corners (corners of some leaf that are not a corner of the
/// coarsest leaf holding them) with their weights in that leaf, coarsest leaf first, so
/// that a hanging corner's own corners are final before it is set.
struct lattice_constraints {
    std::vector<culled_sample> samples, hanging;
};

template <class Lattice, class Node>
lattice_constraints conforming_constraints(const Lattice& lattice, const std::vector<Node>& nodes, int max_depth) {
    const coarsest_leaf_finder finder(lattice, leaf_cells(lattice, nodes), max_depth);
    const auto& all = lattice.probes();
    lattice_constraints out;
    std::vector<std::pair<int, culled_sample>> hanging;
    std::vector<bool> seen(all.size(), false);
    const auto classify = [&](std::uint32_t idx, const std::array<std::uint64_t, 3>& p, bool corner_of_leaf) {
        const auto& [node, c] = finder.leaves()[finder.find(p)];
        const std::uint64_t st = lattice.step(c.depth);
        if ((p[0] - c.x) % st == 0 && (p[1] - c.y) % st == 0 && (p[2] - c.z) % st == 0) return;  // a free corner
        const culled_sample cs = lattice_sample(lattice, all, c, nodes[node].corner, p, idx);
        if (corner_of_leaf) hanging.push_back({c.depth, cs});
        else if (!all[idx].inside && std::any_of(cs.weight.begin(), cs.weight.end(), [](float w) { return w > 0; }))
            out.samples.push_back(cs);
    };
    for (const auto& [node, c] : finder.leaves()) {
        const std::uint64_t st = lattice.step(c.depth);
        for (std::size_t k = 0; k < 8; ++k) {
            const std::uint32_t idx = nodes[node].corner[k];
            if (seen[idx]) continue;
            seen[idx] = true;
            classify(idx, {c.x + st * (k & 1), c.y + st * ((k >> 1) & 1), c.z + st * (k >> 2)}, true);
        }
    }
    lattice.for_each_point([&](std::uint32_t idx, const std::array<std::uint64_t, 3>& p) {
        if (!seen[idx]) classify(idx, p, false);
    });
    std::stable_sort(hanging.begin(), hanging.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [d, cs] : hanging) {
        if (!all[cs.probe].inside) out.samples.push_back(cs);  // its baked value is a sample too
        out.hanging.push_back(cs);
    }
    return out;
}

/// Sets each hanging corner (in order) to the interpolation of its coarsest leaf's corners:
/// radiance, gradients and noise; inside geometry when no usable corner has a weight there.
inline void set_hanging_corners(std::vector<irradiance_probe>& probes, const std::vector<culled_sample>& hanging) {
    for (const culled_sample& h : hanging) {
        irradiance_probe& p = probes[h.probe];
        float wsum = 0;
        for (float w : h.weight) wsum += w;
        p.inside = wsum <= 0;
        p.radiance = {};
        p.gradient = {};
        p.noise = 0;
        for (std::size_t k = 0; k < 8; ++k) {
            const float w = h.weight[k];
            if (w <= 0) continue;
            const irradiance_probe& q = probes[h.corner[k]];
            for (std::size_t i = 0; i < p.radiance.size(); ++i) {
                p.radiance[i] += w * q.radiance[i];
                for (std::size_t a = 0; a < 3; ++a) p.gradient[a][i] += w * q.gradient[a][i];
            }
            p.noise += w * q.noise;
        }
    }
}

}  // namespace bounce::detail
