#pragma once
/// \file radiosity/chart_growth.hpp
/// Charts that follow surfaces (issue 30): a scene's triangles grouped into charts, each a
/// set of edge-adjacent triangles of one material that unfolds onto one plane by plain
/// orthogonal projection, without a flip and without an overlap, the normals of its
/// triangles within a cone about the chart's mean normal. lightmap_atlas.hpp cuts each chart
/// into texels on that plane.
///
/// Growth: seeds are taken in decreasing order of area (so a wall's large triangles start
/// charts and the small ones join them), and a chart grows breadth first over shared edges
/// (edges keyed by welded positions: meshes split vertices for normals and UVs). A neighbour
/// joins when it has the chart's material, its normal lies within the cone's half-angle of
/// both the seed's normal and the chart's current area-weighted mean normal, and its
/// projection onto the seed's plane overlaps none of the chart's triangles (a 2D separating
/// axis test over a uniform grid of the chart's triangles). All normals within the cone of
/// the seed's keeps every triangle's projection the right way round (the cone is below 90
/// degrees). The chart's plane is then its
/// area-weighted mean normal's, checked again: where a triangle's normal leaves the cone about
/// it (the mean drifts as triangles join) or that plane would fold two triangles over each
/// other, the seed's plane, on which the chart grew within the cone and without overlap, is
/// kept. So every triangle's normal lies within the cone of its chart's normal, and its
/// texels stretch at most 1 / cos(cone) across the tilt.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <numeric>
#include <span>
#include <unordered_map>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <bounce/scene_view.hpp>

namespace bounce::detail {

inline glm::dvec3 to_d(const glm::vec3& v) { return glm::dvec3(v); }

/// Unit normals, areas and centroids of a scene's triangles, in double; degenerate triangles
/// have area 0 and normal 0.
struct triangle_faces {
    std::vector<glm::dvec3> normal;
    std::vector<double> area;
    std::vector<glm::dvec3> centroid;
};
inline triangle_faces face_normals_and_areas(const scene_view& scene) {
    const std::size_t nt = scene.triangles.size();
    triangle_faces faces{std::vector<glm::dvec3>(nt), std::vector<double>(nt, 0.0), std::vector<glm::dvec3>(nt)};
    for (std::size_t t = 0; t < nt; ++t) {
        const auto& tri = scene.triangles[t];
        const glm::dvec3 a = to_d(scene.positions[tri.x]), b = to_d(scene.positions[tri.y]), c = to_d(scene.positions[tri.z]);
        const glm::dvec3 cr = glm::cross(b - a, c - a);
        const double len = glm::length(cr);
        faces.area[t] = 0.5 * len;
        faces.normal[t] = len > 0 ? cr / len : glm::dvec3(0);
        faces.centroid[t] = (a + b + c) / 3.0;
    }
    return faces;
}

/// Each position's index of the first position equal to it: meshes often split vertices
/// for normals or UVs, and charts must see through that.
inline std::vector<std::uint32_t> welded_positions(std::span<const glm::vec3> positions) {
    std::unordered_map<std::uint64_t, std::uint32_t> weld;
    std::vector<std::uint32_t> welded(positions.size());
    const auto bits = [](float f) {
        f = f == 0.f ? 0.f : f;  // -0 and +0 are one position
        std::uint32_t u;
        std::memcpy(&u, &f, 4);
        return std::uint64_t(u);
    };
    for (std::size_t i = 0; i < positions.size(); ++i) {
        const glm::vec3 p = positions[i];
        std::uint64_t key = bits(p.x) * 0x9e3779b97f4a7c15ULL ^ (bits(p.y) * 0xc2b2ae3d27d4eb4fULL) ^
                            (bits(p.z) * 0x165667b19e3779f9ULL);
        // Resolve the rare hash collision between different positions by probing.
        for (;;) {
            auto [it, inserted] = weld.try_emplace(key, std::uint32_t(i));
            if (inserted || positions[it->second] == p) {
                welded[i] = it->second;
                break;
            }
            ++key;
        }
    }
    return welded;
}

/// The triangles of positive area on each edge, edges keyed by their welded end points.
class edge_adjacency {
public:
    edge_adjacency(const scene_view& scene, const triangle_faces& faces) : welded_(welded_positions(scene.positions)) {
        triangles_.reserve(3 * scene.triangles.size());
        for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
            if (faces.area[t] <= 0) continue;
            const auto& tri = scene.triangles[t];
            for (int k = 0; k < 3; ++k) triangles_.emplace(key(tri[k], tri[(k + 1) % 3]), std::uint32_t(t));
        }
    }
    /// The triangles on the edge between positions i and j, as a range of (key, triangle).
    auto triangles_on(std::uint32_t i, std::uint32_t j) const { return triangles_.equal_range(key(i, j)); }

private:
    std::uint64_t key(std::uint32_t i, std::uint32_t j) const {
        const std::uint64_t a = welded_[i], b = welded_[j];
        return std::min(a, b) << 32 | std::max(a, b);
    }
    std::vector<std::uint32_t> welded_;
    std::unordered_multimap<std::uint64_t, std::uint32_t> triangles_;
};

/// Whether the interiors of two 2D triangles overlap: no edge of either separates them (the
/// separating axis theorem; for two convex polygons with disjoint interiors one of their
/// edges' lines separates them). Touching along an edge or at a vertex is not an overlap:
/// a vertex on an edge's line counts as outside within `slack` of the edge's length times
/// the triangles' size.
inline bool triangles_overlap(const std::array<glm::dvec2, 3>& a, const std::array<glm::dvec2, 3>& b) {
    const auto cross = [](glm::dvec2 p, glm::dvec2 q) { return p.x * q.y - p.y * q.x; };
    const auto separates = [&](const std::array<glm::dvec2, 3>& s, const std::array<glm::dvec2, 3>& o) {
        const double orient = cross(s[1] - s[0], s[2] - s[0]) > 0 ? 1.0 : -1.0;
        double size = 0;
        for (const auto& p : o) size = std::max(size, glm::length(p - s[0]));
        for (std::size_t k = 0; k < 3; ++k) {
            const glm::dvec2 e = s[(k + 1) % 3] - s[k];
            const double slack = 1e-9 * glm::length(e) * std::max(size, glm::length(e));
            bool all_out = true;
            for (const auto& p : o) all_out = all_out && orient * cross(e, p - s[k]) <= slack;
            if (all_out) return true;
        }
        return false;
    };
    return !separates(a, b) && !separates(b, a);
}

/// The 2D triangles of one chart, projected onto a plane, in a uniform grid for overlap
/// queries. Triangles covering more than `max_cells` cells go to a list checked against all.
class projected_chart {
public:
    projected_chart(const glm::dvec3& normal, double cell) : cell_(cell > 0 ? cell : 1.0) {
        n_ = glm::normalize(normal);
        const glm::dvec3 helper = std::abs(n_.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
        u_ = glm::normalize(glm::cross(helper, n_));
        v_ = glm::cross(n_, u_);
    }
    std::array<glm::dvec2, 3> project(const scene_view& scene, std::uint32_t t) const {
        std::array<glm::dvec2, 3> q;
        for (int m = 0; m < 3; ++m) {
            const glm::dvec3 p = to_d(scene.positions[scene.triangles[t][m]]);
            q[std::size_t(m)] = {glm::dot(p, u_), glm::dot(p, v_)};
        }
        return q;
    }
    /// Whether q overlaps a triangle already added.
    bool overlaps(const std::array<glm::dvec2, 3>& q) const {
        bool hit = false;
        for (const std::uint32_t k : big_) hit = hit || triangles_overlap(q, tris_[k]);
        if (hit) return true;
        const auto [i0, i1, j0, j1] = cells(q);
        if (std::int64_t(i1 - i0 + 1) * std::int64_t(j1 - j0 + 1) > max_cells) {
            for (std::size_t k = 0; k < tris_.size() && !hit; ++k) hit = triangles_overlap(q, tris_[k]);
            return hit;
        }
        for (std::int64_t j = j0; j <= j1 && !hit; ++j)
            for (std::int64_t i = i0; i <= i1 && !hit; ++i) {
                const auto it = grid_.find(key(i, j));
                if (it == grid_.end()) continue;
                for (const std::uint32_t k : it->second)
                    if (triangles_overlap(q, tris_[k])) {
                        hit = true;
                        break;
                    }
            }
        return hit;
    }
    void add(const std::array<glm::dvec2, 3>& q) {
        const std::uint32_t k = std::uint32_t(tris_.size());
        tris_.push_back(q);
        const auto [i0, i1, j0, j1] = cells(q);
        if (std::int64_t(i1 - i0 + 1) * std::int64_t(j1 - j0 + 1) > max_cells) {
            big_.push_back(k);
            return;
        }
        for (std::int64_t j = j0; j <= j1; ++j)
            for (std::int64_t i = i0; i <= i1; ++i) grid_[key(i, j)].push_back(k);
    }

private:
    static constexpr std::int64_t max_cells = 256;
    std::array<std::int64_t, 4> cells(const std::array<glm::dvec2, 3>& q) const {
        const glm::dvec2 mn = glm::min(q[0], glm::min(q[1], q[2])) / cell_, mx = glm::max(q[0], glm::max(q[1], q[2])) / cell_;
        const auto fl = [](double x) { return std::int64_t(std::floor(std::clamp(x, -1e15, 1e15))); };
        return {fl(mn.x), fl(mx.x), fl(mn.y), fl(mx.y)};
    }
    static std::uint64_t key(std::int64_t i, std::int64_t j) {
        return std::uint64_t(i) * 0x9e3779b97f4a7c15ULL ^ (std::uint64_t(j) + 0x632be59bd9b4e019ULL);
    }
    double cell_;
    glm::dvec3 n_, u_, v_;
    std::vector<std::array<glm::dvec2, 3>> tris_;
    std::vector<std::uint32_t> big_;
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid_;
};

/// The charts of a scene (chart_growth.hpp's file comment).
struct grown_charts {
    static constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::vector<std::uint32_t>> triangles;  ///< each chart's triangles, in index order
    std::vector<glm::dvec3> normal;                     ///< each chart's projection normal (unit)
    std::vector<std::uint32_t> material;
    std::vector<std::uint32_t> chart_of_triangle;       ///< none for degenerate triangles
    std::size_t seed_plane_kept = 0;  ///< charts projected on the seed's plane (the mean's left the cone or folded)
    std::size_t overlaps_refused = 0; ///< neighbours kept out of a chart by the overlap test
};

/// The largest extent of a 2D triangle (its bounding box's longer side).
inline double extent_of(const std::array<glm::dvec2, 3>& q) {
    const glm::dvec2 s = glm::max(q[0], glm::max(q[1], q[2])) - glm::min(q[0], glm::min(q[1], q[2]));
    return std::max(s.x, s.y);
}

/// Whether the triangles `tris` projected along `normal` overlap anywhere (cell size: the
/// largest triangle's extent).
inline bool chart_folds(const scene_view& scene, std::span<const std::uint32_t> tris, const glm::dvec3& normal) {
    projected_chart probe(normal, 1.0);
    double cell = 0;
    for (const std::uint32_t t : tris) cell = std::max(cell, extent_of(probe.project(scene, t)));
    projected_chart grid(normal, cell);
    for (const std::uint32_t t : tris) {
        const auto q = grid.project(scene, t);
        if (grid.overlaps(q)) return true;
        grid.add(q);
    }
    return false;
}

/// Grows the charts of `scene` as the file comment says, with a cone of half-angle
/// `cone_degrees` (in [0, 90)). Triangles of zero area get no chart.
inline grown_charts grow_charts(const scene_view& scene, const triangle_faces& faces, double cone_degrees) {
    const std::size_t nt = scene.triangles.size();
    const double cos_cone = std::cos(cone_degrees * std::numbers::pi / 180.0);
    grown_charts out;
    out.chart_of_triangle.assign(nt, grown_charts::none);
    const edge_adjacency edges(scene, faces);
    std::vector<std::uint32_t> order;
    order.reserve(nt);
    for (std::size_t t = 0; t < nt; ++t)
        if (faces.area[t] > 0) order.push_back(std::uint32_t(t));
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return faces.area[a] > faces.area[b]; });
    // Triangles a chart looked at and refused (reset per chart), so each is tested once.
    std::vector<std::uint32_t> refused_by(nt, grown_charts::none);
    std::vector<std::uint32_t> queue;
    for (const std::uint32_t seed : order) {
        if (out.chart_of_triangle[seed] != grown_charts::none) continue;
        const std::uint32_t c = std::uint32_t(out.triangles.size());
        const std::uint32_t material = scene.material_of[seed];
        const glm::dvec3 n0 = faces.normal[seed];
        glm::dvec3 n_sum = faces.area[seed] * n0;
        projected_chart grid(n0, 0.0);
        grid = projected_chart(n0, extent_of(grid.project(scene, seed)));
        grid.add(grid.project(scene, seed));
        out.chart_of_triangle[seed] = c;
        std::vector<std::uint32_t> mine(1, seed);
        queue.assign(1, seed);
        for (std::size_t head = 0; head < queue.size(); ++head) {
            const auto& tri = scene.triangles[queue[head]];
            for (int k = 0; k < 3; ++k) {
                const auto range = edges.triangles_on(tri[k], tri[(k + 1) % 3]);
                for (auto it = range.first; it != range.second; ++it) {
                    const std::uint32_t u = it->second;
                    if (out.chart_of_triangle[u] != grown_charts::none || refused_by[u] == c) continue;
                    const glm::dvec3 nu = faces.normal[u];
                    bool joins = scene.material_of[u] == material && glm::dot(nu, n0) >= cos_cone &&
                                 glm::dot(nu, glm::normalize(n_sum)) >= cos_cone;
                    if (joins) {
                        const auto q = grid.project(scene, u);
                        if (grid.overlaps(q)) {
                            joins = false;
                            ++out.overlaps_refused;
                        } else
                            grid.add(q);
                    }
                    if (!joins) {
                        refused_by[u] = c;
                        continue;
                    }
                    out.chart_of_triangle[u] = c;
                    n_sum += faces.area[u] * nu;
                    mine.push_back(u);
                    queue.push_back(u);
                }
            }
        }
        std::sort(mine.begin(), mine.end());
        glm::dvec3 n = glm::normalize(n_sum);
        // A chart that is not one plane is checked again on its mean plane: every normal
        // within the cone of it, and no fold. Else the seed's plane, where both hold by
        // construction.
        bool planar = true, in_cone = true;
        for (const std::uint32_t t : mine) {
            planar = planar && glm::dot(faces.normal[t], n0) >= 1.0 - 1e-12;
            in_cone = in_cone && glm::dot(faces.normal[t], n) >= cos_cone;
        }
        if (!planar && (!in_cone || chart_folds(scene, mine, n))) {
            n = n0;
            ++out.seed_plane_kept;
        }
        out.triangles.push_back(std::move(mine));
        out.normal.push_back(n);
        out.material.push_back(material);
    }
    return out;
}

/// A chart's frame on its plane (origin, unit in-plane axes u and v) and its extent along
/// them (m).
struct chart_extent {
    glm::dvec3 origin, u, v;
    double eu = 0, ev = 0;
};

/// The frame of a chart (its triangles `tris`, its unit normal n) whose axis u runs along one of its triangles' edges and whose
/// bounding rectangle is the smallest (a rectangle's own sides for walls and quads). At most
/// 64 edges are tried, which covers every chart of a few dozen triangles.
inline chart_extent smallest_bounding_frame(const scene_view& scene, std::span<const std::uint32_t> tris,
                                            const glm::dvec3& n) {
    chart_extent out{};
    const auto corner = [&](std::uint32_t t, int k) { return to_d(scene.positions[scene.triangles[t][k]]); };
    double best = std::numeric_limits<double>::infinity();
    int tried = 0;
    for (const std::uint32_t t : tris) {
        for (int k = 0; k < 3 && tried < 64; ++k, ++tried) {
            const glm::dvec3 e = corner(t, (k + 1) % 3) - corner(t, k);
            glm::dvec3 u = e - n * glm::dot(e, n);
            if (glm::length(u) <= 0) continue;
            u = glm::normalize(u);
            const glm::dvec3 v = glm::cross(n, u);
            glm::dvec2 mn(std::numeric_limits<double>::infinity()), mx(-std::numeric_limits<double>::infinity());
            for (const std::uint32_t s : tris)
                for (int m = 0; m < 3; ++m) {
                    const glm::dvec3 p = corner(s, m);
                    const glm::dvec2 q(glm::dot(p, u), glm::dot(p, v));
                    mn = glm::min(mn, q);
                    mx = glm::max(mx, q);
                }
            const glm::dvec2 size = mx - mn;
            if (size.x * size.y < best) {
                best = size.x * size.y;
                // Origin on the chart's plane: the rectangle's corner, moved onto the plane.
                const glm::dvec3 on_plane = n * glm::dot(to_d(scene.positions[scene.triangles[tris[0]].x]), n);
                out = {on_plane + u * mn.x + v * mn.y, u, v, size.x, size.y};
            }
        }
    }
    return out;
}

}  // namespace bounce::detail

namespace bounce::inline radiosity {

/// What build_lightmap_atlas made (charts, texels, packing, stretch), for reports.
struct atlas_statistics {
    std::size_t triangles = 0, charts = 0, curved_charts = 0, one_element_charts = 0;
    std::size_t elements = 0;
    std::size_t chart_texels = 0;  ///< texels of the charts' rectangles (without padding)
    std::size_t atlas_texels = 0;  ///< width x height
    double packing_efficiency = 0; ///< elements / atlas_texels
    std::uint32_t median_elements_per_chart = 0;
    double stretch_mean = 1;       ///< surface area over its area on the charts' planes
    double stretch_max = 1;        ///< the largest 1 / cos(tilt) of a triangle: a texel's side across the tilt
    double cone_max_degrees = 0;   ///< the largest tilt of a triangle from its chart's normal
    std::size_t seed_plane_kept = 0, overlaps_refused = 0;  ///< chart_growth.hpp
    double texel_size = 0;         ///< h (m on the charts' planes): density 1 / h^2 texels per m^2
    int densities_tried = 0;       ///< cut_to_element_count's iterations
    std::size_t clusters = 0;          ///< charts that are clusters of tiny charts (chart_clusters.hpp), in `charts`
    std::size_t clustered_charts = 0;  ///< the tiny charts they hold
};

}  // namespace bounce::radiosity
