#pragma once
/// \file neighbour_index.hpp
/// Neighbour clamping (Krivanek et al. 2006) in logarithmic time: R_new <= R_j + |p_new - p_j|
/// over every record j already in the cache, found through an octree whose nodes know the
/// smallest radius below them, instead of the linear loop of
/// bounce::neighbour_clamped_radius. The result is bitwise that loop's: the same float
/// expression is evaluated for every record that could lower the minimum, and a subtree is
/// skipped only when box distance + smallest radius proves none of its records can.
///
/// Why it matters: in detailed scenes a thin strip of bright indirect light (the
/// rim of an arch beside a crack, a contact) is found by one record with a tiny R, while
/// records around it with R near 1 claim the strip's pixels and hide it. Clamping every
/// later record against the small one lets the scan find the strip; the linear loop makes
/// that O(N^2) per frame, which at 100,000 records costs more than the records
/// (docs/irradiance-splatting.md shows such a strip and the cost).

#include <bounce/errors.hpp>
#include <bounce/cache/record.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

namespace bounce::cpu {

/// Record positions and radii in an octree over the box [lo, hi] (the scene's bounds;
/// records outside it are kept in a list that every query scans).
class neighbour_index {
public:
    neighbour_index(const glm::vec3& lo, const glm::vec3& hi) {
        const bool finite = std::isfinite(lo.x) && std::isfinite(lo.y) && std::isfinite(lo.z) && std::isfinite(hi.x) &&
                            std::isfinite(hi.y) && std::isfinite(hi.z);
        require(finite && lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z, "bounds", "must be a finite box with lo <= hi");
        node root;
        root.lo = lo;
        root.hi = hi;
        nodes_.push_back(std::move(root));
    }

    /// Adds a record (its position and final radius). Throws parameter_error when the
    /// position or radius is not finite, or the radius is negative; the index is unchanged.
    void insert(const irradiance_record& r) {
        const glm::vec3 p = r.position;
        require(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), "record.position", "must be finite");
        require(std::isfinite(r.radius) && r.radius >= 0.f, "record.radius", "must be a finite radius >= 0");
        const entry e{p, r.radius, count_++};
        if (!inside(nodes_[0], p)) {
            outside_.push_back(e);
            return;
        }
        std::size_t n = 0;
        for (int depth = 0;; ++depth) {
            nodes_[n].min_radius = std::min(nodes_[n].min_radius, e.radius);
            nodes_[n].max_radius = std::max(nodes_[n].max_radius, e.radius);
            if (nodes_[n].first_child == 0) {
                nodes_[n].entries.push_back(e);
                if (nodes_[n].entries.size() > leaf_size && depth < max_depth) split(n);
                return;
            }
            n = nodes_[n].first_child + octant(nodes_[n], p);
        }
    }

    /// Inserts records[size() ..], so the index mirrors a cache that only grows.
    void sync(const std::vector<irradiance_record>& records) {
        for (std::size_t i = count_; i < records.size(); ++i) insert(records[i]);
    }

    std::size_t size() const noexcept { return count_; }

    /// min(rec.radius, min_j R_j + |p - p_j|) over the records inserted so far: bitwise
    /// bounce::neighbour_clamped_radius(rec, those records).
    float clamped_radius(const irradiance_record& rec) const {
        const glm::vec3 p = rec.position;
        float best = rec.radius;
        for (const entry& e : outside_) best = std::min(best, e.radius + glm::length(p - e.p));
        // |p - p_j| >= box distance, and the float sum R_j + |p - p_j| is at most a few ulps
        // below the exact one: a relative 1e-5 margin keeps the pruning conservative.
        auto may_lower = [&](const node& nd) {
            return (box_distance(nd, p) + double(nd.min_radius)) * (1.0 - 1e-5) < double(best);
        };
        std::vector<std::size_t> stack{0};
        while (!stack.empty()) {
            const node& nd = nodes_[stack.back()];
            stack.pop_back();
            if (!may_lower(nd)) continue;
            if (nd.first_child == 0) {
                for (const entry& e : nd.entries) best = std::min(best, e.radius + glm::length(p - e.p));
                continue;
            }
            // Nearest child last on the stack, so it is searched first and prunes the rest.
            std::array<std::pair<double, std::size_t>, 8> order;
            for (std::size_t c = 0; c < 8; ++c) {
                const std::size_t i = nd.first_child + c;
                order[c] = {box_distance(nodes_[i], p) + double(nodes_[i].min_radius), i};
            }
            std::sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
            for (const auto& [d, i] : order)
                if (std::isfinite(d)) stack.push_back(i);
        }
        return best;
    }

    /// Calls f(j) for every record j inserted so far (j: its insertion order, the index into
    /// the vector sync mirrors) with |p - p_j| < scale * R_j: the records whose zones of
    /// radius scale * R_j contain p (the neighbours that interpolation at p may ask).
    template <class F>
    void for_each_covering(const glm::vec3& p, float scale, F&& f) const {
        const double s = scale;
        auto covers = [&](const entry& e) { return double(glm::length(p - e.p)) < s * double(e.radius); };
        for (const entry& e : outside_)
            if (covers(e)) f(e.index);
        std::vector<std::size_t> stack{0};
        while (!stack.empty()) {
            const node& nd = nodes_[stack.back()];
            stack.pop_back();
            if (!(box_distance(nd, p) < s * double(nd.max_radius))) continue;
            if (nd.first_child == 0) {
                for (const entry& e : nd.entries)
                    if (covers(e)) f(e.index);
                continue;
            }
            for (std::size_t c = 0; c < 8; ++c) stack.push_back(nd.first_child + c);
        }
    }

private:
    struct entry {
        glm::vec3 p;
        float radius;
        std::size_t index;  // insertion order
    };
    struct node {
        glm::vec3 lo, hi;
        float min_radius = std::numeric_limits<float>::infinity();  // +inf: no record below
        float max_radius = 0.f;                                     // 0: no record below
        std::size_t first_child = 0;                                // 0: a leaf (the root is never a child)
        std::vector<entry> entries;
    };
    static constexpr std::size_t leaf_size = 16;
    static constexpr int max_depth = 24;

    static bool inside(const node& n, const glm::vec3& p) {
        return p.x >= n.lo.x && p.y >= n.lo.y && p.z >= n.lo.z && p.x <= n.hi.x && p.y <= n.hi.y && p.z <= n.hi.z;
    }
    static std::size_t octant(const node& n, const glm::vec3& p) {
        const glm::vec3 c = 0.5f * (n.lo + n.hi);
        return std::size_t(p.x > c.x) | (std::size_t(p.y > c.y) << 1) | (std::size_t(p.z > c.z) << 2);
    }
    static double box_distance(const node& n, const glm::vec3& p) {
        double s = 0;
        for (int k = 0; k < 3; ++k) {
            const double v = std::max({double(n.lo[k]) - double(p[k]), 0.0, double(p[k]) - double(n.hi[k])});
            s += v * v;
        }
        return std::sqrt(s);
    }
    void split(std::size_t n) {
        const std::size_t first = nodes_.size();
        const glm::vec3 lo = nodes_[n].lo, hi = nodes_[n].hi, c = 0.5f * (lo + hi);
        for (std::size_t k = 0; k < 8; ++k) {
            node child;
            child.lo = {k & 1 ? c.x : lo.x, k & 2 ? c.y : lo.y, k & 4 ? c.z : lo.z};
            child.hi = {k & 1 ? hi.x : c.x, k & 2 ? hi.y : c.y, k & 4 ? hi.z : c.z};
            nodes_.push_back(child);  // may reallocate: index nodes_ afresh below
        }
        std::vector<entry> entries = std::move(nodes_[n].entries);
        nodes_[n].entries.clear();
        nodes_[n].first_child = first;
        for (const entry& e : entries) {
            node& child = nodes_[first + octant(nodes_[n], e.p)];
            child.entries.push_back(e);
            child.min_radius = std::min(child.min_radius, e.radius);
            child.max_radius = std::max(child.max_radius, e.radius);
        }
    }

    std::vector<node> nodes_;
    std::vector<entry> outside_;
    std::size_t count_ = 0;
};

}  // namespace bounce::cpu
