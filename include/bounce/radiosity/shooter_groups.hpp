#pragma once
/// \file radiosity/shooter_groups.hpp
/// Grouped shooters (issue 30, "shooting that scales"): the atlas's blocks, each side of each
/// its own leaf, gathered into at most `budget` groups of nearby, similarly oriented leaves
/// across charts, so that the number of shooters, and with it the number of steps to a
/// fraction of the power, is set by the budget and not by the number of charts.
///
/// The leaves (block b on side s, numbered s * blocks + b, as the solvers number shooters)
/// are first put in six bins by the dominant axis of their side's normal (+x, -x, +y ...),
/// then each bin is split recursively at the median of its leaves' centres along the longest
/// side of their bounding box, down to single leaves: a binary tree per bin. The groups are a
/// cut of that forest: starting from the bins, the group whose bounding box has the longest
/// diagonal is replaced by its two halves until there are `budget` groups (or every group is
/// one leaf). A group's subtree is its near-field hierarchy above its blocks: a receiver takes
/// a node of it as one disc when it lies farther than the near field from the node and every
/// member faces it (the node's normal cone), else the node's two halves (cpu::progressive_
/// radiosity's grouped shot). Nodes keep what does not change from shot to shot: their leaves
/// (a contiguous range of `leaves`), their bounding box (of the members' block discs), area,
/// area-weighted normal sum and normal cone.
///
/// The budget derived from the scene (budget 0, group_cut::discs): a grouped shot costs per
/// receiver one visibility ray plus the discs it takes (one per node it does not open), and
/// its steps to a fraction of the power grow with the groups. The split of the widest group
/// goes on while the mean over receivers and groups of the discs a receiver takes from a
/// group's hierarchy exceeds `discs` (a block's shot takes about one); receivers sampled
/// evenly over the elements, every leaf taken as holding power, the near-field and cone tests
/// of the grouped shot. Large groups are opened by every receiver near them (the near field
/// is group_near_field half-diagonals), so the cut stops where the groups are small against
/// the distances between the scene's surfaces: set by the scene's shape and its blocks, not
/// by a fixed count.

#include <bounce/radiosity/lightmap_atlas.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <queue>
#include <span>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline radiosity {

/// One node of the grouping forest.
struct shooter_group_node {
    static constexpr std::uint32_t none = 0xffffffffu;
    glm::vec3 lo{0.f}, hi{0.f};   ///< bounding box of the members' discs (world)
    glm::vec3 normal_sum{0.f};    ///< sum of area times the side's unit normal (m^2)
    double area = 0;              ///< the members' area (m^2)
    float cone_sin = 0;           ///< sine of the half-angle of the members' normals about normal_sum
    std::uint32_t first = 0, count = 0;        ///< leaves [first, first + count) of shooter_groups::leaves
    std::uint32_t left = none, right = none;   ///< the two halves; none for a single leaf
};

/// The groups of a budget (see the file comment).
struct shooter_groups {
    std::vector<std::uint32_t> leaves;           ///< block-sides (side * blocks + block), each node's contiguous
    std::vector<shooter_group_node> nodes;       ///< the forest, children before parents
    std::vector<std::uint32_t> roots;            ///< per group, its node
    std::vector<std::uint32_t> group_of_leaf;    ///< per block-side, its group
    double discs = 0;                            ///< the cut's mean discs per receiver and group (derived budget; else 0)
    std::size_t size() const noexcept { return roots.size(); }
};

/// How a derived budget cuts the forest (build_shooter_groups with budget 0; file comment).
struct group_cut {
    double discs = 2;               ///< the mean discs a receiver takes per group shot, at most
    double near_field = 4;          ///< radiosity_options::near_field (a block's node opens within it times its side)
    double group_near_field = 4;    ///< radiosity_options::group_near_field (half-diagonals)
    std::size_t receivers = 256;    ///< receivers sampled (evenly over the elements)
};

/// Per node of `g`, the mean over `receivers` sampled elements of the discs a receiver takes
/// from the node's hierarchy (the grouped shot's near-field and cone tests; a leaf is one
/// disc, or none when it faces away).
inline std::vector<double> group_mean_discs(const lightmap_atlas& atlas, const shooter_groups& g, const group_cut& cut) {
    std::vector<double> mean(g.nodes.size(), 0.0);
    const std::size_t n = atlas.size(), count = std::min(cut.receivers, n);
    std::vector<double> d(g.nodes.size());
    const double near2 = cut.near_field * cut.near_field, half = 0.5 * cut.group_near_field;
    for (std::size_t k = 0; k < count; ++k) {
        const glm::vec3 p = atlas.position[(k * n + n / 2) / count];
        for (std::size_t j = 0; j < g.nodes.size(); ++j) {  // children before parents
            const shooter_group_node& node = g.nodes[j];
            const glm::vec3 c = 0.5f * (node.lo + node.hi), e = node.hi - node.lo, r = p - c;
            const double d2 = glm::dot(r, r);
            const bool leaf = node.left == shooter_group_node::none;
            if (!leaf && d2 < std::max(near2 * node.area, half * half * double(glm::dot(e, e)))) {
                d[j] = d[node.left] + d[node.right];
                continue;
            }
            const double len = std::sqrt(double(glm::dot(node.normal_sum, node.normal_sum)) * d2);
            d[j] = len > 0 && double(glm::dot(node.normal_sum, r)) / len < -double(node.cone_sin) ? 0.0 : 1.0;
        }
        for (std::size_t j = 0; j < d.size(); ++j) mean[j] += d[j] / double(count);
    }
    return mean;
}

/// Groups the block-sides of `atlas` (blocks given by `first`, the shooter ranges of
/// shooter_ranges; `sides` 1 or 2) into at most `budget` groups, and at least one per
/// non-empty normal bin (up to six), whatever the budget; budget 0: as many as `cut` derives
/// from the scene (the file comment).
inline shooter_groups build_shooter_groups(const lightmap_atlas& atlas, std::span<const std::uint32_t> first,
                                           std::size_t sides, std::size_t budget, const group_cut& cut = {}) {
    shooter_groups g;
    const std::size_t blocks = first.size() - 1, leaves = blocks * sides;
    struct leaf_geometry {
        glm::vec3 centre, normal, lo, hi;
        double area;
    };
    std::vector<leaf_geometry> geo(leaves);
    for (std::size_t b = 0; b < blocks; ++b) {
        glm::dvec3 moment(0);
        double area = 0;
        for (std::uint32_t i = first[b]; i < first[b + 1]; ++i) {
            moment += glm::dvec3(atlas.position[i]) * double(atlas.area[i]);
            area += double(atlas.area[i]);
        }
        const glm::vec3 c = area > 0 ? glm::vec3(moment / area) : atlas.position[first[b]];
        const float r = float(std::sqrt(area));  // a block's half-diagonal at most about its side
        for (std::size_t s = 0; s < sides; ++s) {
            const glm::vec3 n = s == 0 ? atlas.normal[first[b]] : -atlas.normal[first[b]];
            geo[s * blocks + b] = {c, n, c - r, c + r, area};
        }
    }
    // Bins by the dominant axis of the normal.
    std::vector<std::uint32_t> bin_of(leaves);
    for (std::size_t k = 0; k < leaves; ++k) {
        const glm::vec3 n = geo[k].normal, a = glm::abs(n);
        const int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
        bin_of[k] = std::uint32_t(2 * axis + (n[axis] < 0.f ? 1 : 0));
    }
    g.leaves.resize(leaves);
    std::iota(g.leaves.begin(), g.leaves.end(), std::uint32_t(0));
    std::stable_sort(g.leaves.begin(), g.leaves.end(), [&](std::uint32_t a, std::uint32_t b) { return bin_of[a] < bin_of[b]; });
    g.nodes.reserve(2 * leaves + 6);
    // Builds the subtree over leaves [lo, hi) and returns its node.
    const auto build = [&](auto&& self, std::uint32_t lo, std::uint32_t hi) -> std::uint32_t {
        shooter_group_node node;
        node.first = lo;
        node.count = hi - lo;
        if (hi - lo > 1) {
            glm::vec3 cmin(INFINITY), cmax(-INFINITY);
            for (std::uint32_t j = lo; j < hi; ++j) cmin = glm::min(cmin, geo[g.leaves[j]].centre), cmax = glm::max(cmax, geo[g.leaves[j]].centre);
            const glm::vec3 e = cmax - cmin;
            const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
            const std::uint32_t mid = lo + (hi - lo) / 2;
            std::nth_element(g.leaves.begin() + lo, g.leaves.begin() + mid, g.leaves.begin() + hi, [&](std::uint32_t a, std::uint32_t b) {
                return geo[a].centre[axis] < geo[b].centre[axis] || (geo[a].centre[axis] == geo[b].centre[axis] && a < b);
            });
            node.left = self(self, lo, mid);
            node.right = self(self, mid, hi);
        }
        node.lo = glm::vec3(INFINITY);
        node.hi = glm::vec3(-INFINITY);
        glm::dvec3 nsum(0);
        for (std::uint32_t j = lo; j < hi; ++j) {
            const leaf_geometry& l = geo[g.leaves[j]];
            node.lo = glm::min(node.lo, l.lo);
            node.hi = glm::max(node.hi, l.hi);
            nsum += glm::dvec3(l.normal) * l.area;
            node.area += l.area;
        }
        node.normal_sum = glm::vec3(nsum);
        const double len = glm::length(nsum);
        double min_cos = 1;
        for (std::uint32_t j = lo; j < hi && len > 0; ++j) min_cos = std::min(min_cos, glm::dot(glm::dvec3(geo[g.leaves[j]].normal), nsum) / len);
        node.cone_sin = len > 0 && min_cos > 0 ? float(std::sqrt(std::max(0.0, 1 - min_cos * min_cos))) + 1e-4f : 1.f;
        g.nodes.push_back(node);
        return std::uint32_t(g.nodes.size() - 1);
    };
    using entry = std::pair<float, std::uint32_t>;  // (bounding-box diagonal squared, node)
    std::priority_queue<entry> open;
    std::vector<std::uint32_t> done, bins;
    for (std::uint32_t lo = 0; lo < leaves;) {
        std::uint32_t hi = lo;
        while (hi < leaves && bin_of[g.leaves[hi]] == bin_of[g.leaves[lo]]) ++hi;
        const std::uint32_t root = build(build, lo, hi);
        const glm::vec3 d = g.nodes[root].hi - g.nodes[root].lo;
        open.push({glm::dot(d, d), root});
        bins.push_back(root);
        lo = hi;
    }
    // Split the widest group while the budget allows (a split adds one group), or, derived,
    // while the groups' mean discs per receiver exceed cut.discs.
    const bool derived = budget == 0;
    const std::vector<double> discs = derived ? group_mean_discs(atlas, g, cut) : std::vector<double>{};
    double sum = 0;
    if (derived)
        for (const std::uint32_t b : bins) sum += discs[b];
    const auto more = [&] {
        const std::size_t groups = open.size() + done.size();
        return derived ? sum > cut.discs * double(groups) : groups < budget;
    };
    while (!open.empty() && more()) {
        const std::uint32_t k = open.top().second;
        open.pop();
        const shooter_group_node& n = g.nodes[k];
        if (n.left == shooter_group_node::none) {
            done.push_back(k);
            continue;
        }
        if (derived) sum += discs[n.left] + discs[n.right] - discs[k];
        for (const std::uint32_t c : {n.left, n.right}) {
            const glm::vec3 d = g.nodes[c].hi - g.nodes[c].lo;
            open.push({glm::dot(d, d), c});
        }
    }
    while (!open.empty()) done.push_back(open.top().second), open.pop();
    std::sort(done.begin(), done.end(), [&](std::uint32_t a, std::uint32_t b) { return g.nodes[a].first < g.nodes[b].first; });
    g.roots = std::move(done);
    if (derived) g.discs = sum / double(std::max<std::size_t>(g.roots.size(), 1));
    g.group_of_leaf.assign(leaves, 0);
    for (std::size_t k = 0; k < g.roots.size(); ++k) {
        const shooter_group_node& n = g.nodes[g.roots[k]];
        for (std::uint32_t j = n.first; j < n.first + n.count; ++j) g.group_of_leaf[g.leaves[j]] = std::uint32_t(k);
    }
    return g;
}

/// A counter-based random number in [0, 1) from (a, b, c): splitmix64 of their mix, the
/// same for any thread count (grouped shots sample visibility with it).
inline float hash_uniform(std::uint64_t a, std::uint64_t b, std::uint64_t c) {
    std::uint64_t z = a * 0x9E3779B97F4A7C15ull ^ (b + 0x632BE59BD9B4E019ull) * 0xBF58476D1CE4E5B9ull ^ (c + 1) * 0x94D049BB133111EBull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return float(z >> 40) * (1.0f / 16777216.0f);
}

}  // namespace bounce::radiosity
