#pragma once
/// \file radiosity/lightmap_atlas.hpp
/// The radiosity elements of a scene as texels of a lightmap atlas (Coombe and Harris 2005,
/// section 39.2: "texels as radiosity elements", after Heckbert 1990).
///
/// Triangles are grouped into charts: a chart is a set of edge-adjacent triangles of one
/// material lying in one plane (a quad's two triangles, a whole wall), else a single
/// triangle. Each chart gets a rectangle of texels on its plane, fitted to the chart's
/// extent along the direction that gives the smallest bounding rectangle, and the texel size
/// is chosen so that the scene has about `atlas_options::elements` elements. A texel is an
/// element where it overlaps the chart's triangles: its area is the exact area of that
/// overlap (the texel square clipped by each triangle), its position the overlap's centroid,
/// so the elements of a chart add up to the chart's area exactly and every element's
/// position lies on the surface. Charts are packed on shelves with `padding` texels around
/// each, and padding texels (and texels of a chart's rectangle that miss its triangles)
/// point to the nearest element of the same chart, so a filtered lightmap lookup never
/// mixes two charts. Where the budget's texels are larger than many charts, charts that fit
/// in one texel share one element in clusters (chart_clusters.hpp; atlas_options::clusters):
/// a cluster is a chart of one texel holding all their triangles.
///
/// Elements are stored struct-of-arrays, chart by chart, and within a chart by square
/// blocks of `block_texels` x `block_texels` texels: a block is a contiguous range of
/// elements, the unit of shooting with substructuring (Cohen et al. 1986; the chapter's
/// section 39.4 shoots from a mip level of the residual texture).

#include <bounce/errors.hpp>
#include <bounce/image.hpp>
#include <bounce/radiosity/cell_overlap.hpp>
#include <bounce/radiosity/chart_clusters.hpp>
#include <bounce/radiosity/chart_growth.hpp>
#include <bounce/radiosity/lightmap_atlas_data.hpp>
#include <bounce/scene_view.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <span>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace bounce::detail {

/// Every triangle of positive area in a chart (chart_growth.hpp), the charts in the atlas
/// with their triangles and normals; returns what the growth counted.
inline grown_charts group_into_charts(const scene_view& scene, const triangle_faces& faces,
                                      const atlas_options& options, lightmap_atlas& atlas) {
    // A cone below the coplanar tolerance is that tolerance: cone 0 gives the planar charts
    // of before (float normals of one plane differ by rounding).
    grown_charts g = grow_charts(scene, faces, std::max(options.cone_degrees, options.coplanar_degrees));
    const double cos_planar = std::cos(options.coplanar_degrees * std::numbers::pi / 180.0);
    for (std::size_t c = 0; c < g.triangles.size(); ++c) {
        lightmap_chart ch;
        ch.material = g.material[c];
        ch.first_triangle = std::uint32_t(atlas.chart_triangles.size());
        ch.triangle_count = std::uint32_t(g.triangles[c].size());
        ch.normal = glm::vec3(g.normal[c]);
        double worst = 1;
        for (const std::uint32_t t : g.triangles[c]) {
            atlas.chart_triangles.push_back(t);
            atlas.chart_of_triangle[t] = std::uint32_t(c);
            worst = std::min(worst, glm::dot(faces.normal[t], g.normal[c]));
        }
        ch.tilt_degrees = float(std::acos(std::clamp(worst, -1.0, 1.0)) * 180.0 / std::numbers::pi);
        ch.planar = worst >= cos_planar;
        atlas.charts.push_back(ch);
    }
    return g;
}

/// The exact overlap of one texel with its chart's triangles, in texels of the chart's grid:
/// its area on the chart's plane, its area on the surface (each triangle's projected area
/// over the cosine of its tilt from the plane), the first moment of the surface area on the
/// plane and the surface-area-weighted sum of the triangles' normals.
struct texel_sum {
    double area = 0;         ///< on the plane
    double world = 0;        ///< on the surface
    glm::dvec2 moment{0};    ///< of the surface area, plane coordinates
    glm::dvec3 normal{0};    ///< surface-area-weighted normals
    double piece_area = 0;   ///< the largest one triangle's overlap (on the plane)
    glm::dvec2 piece{0};     ///< its centroid, which lies on it
    std::uint32_t piece_triangle = 0;  ///< that triangle, its index in the chart
    std::uint32_t on_triangle = 0;     ///< a triangle (index in the chart) the element's point lies on
    bool keep = false;       ///< the texel is an element
};

/// Moves each texel's point (moment / world) that lies on none of `triangles` (a non-convex
/// overlap: a floor's border around a column's base, whose centroid lies under the column) to
/// the centroid of its largest one triangle's overlap, which lies on the chart; records in
/// on_triangle a triangle each point lies on.
inline void place_points_on_chart(std::span<const std::array<glm::dvec2, 3>> triangles, std::uint32_t width,
                                  std::uint32_t height, std::vector<texel_sum>& sums) {
    constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    std::vector<glm::dvec2> point(sums.size());
    for (std::size_t c = 0; c < sums.size(); ++c) point[c] = sums[c].world > 0 ? sums[c].moment / sums[c].world : glm::dvec2(0);
    std::vector<std::uint32_t> on(sums.size(), none);
    for (std::size_t k = 0; k < triangles.size(); ++k)
        for_each_point_on_triangle(triangles[k], width, height, point, [&](std::size_t cell) {
            if (on[cell] == none) on[cell] = std::uint32_t(k);
        });
    for (std::size_t c = 0; c < sums.size(); ++c) {
        if (on[c] != none) sums[c].on_triangle = on[c];
        else if (sums[c].piece_area > 0) {
            sums[c].moment = sums[c].piece * sums[c].world;
            sums[c].on_triangle = sums[c].piece_triangle;
        }
    }
}

/// A texel is an element when its overlap exceeds 1e-6 of a texel (slivers below carry no
/// measurable power and their centroids are ill-conditioned), and a chart with no such texel
/// keeps its largest overlap: every chart has at least one element.
inline bool holds_element(const texel_sum& ts) { return ts.area > 1e-6; }

/// Chart `ch` cut into texels of about h (m): a grid of ceil(extent / h) texels stretched
/// to fit the extent exactly. Sets the chart's size and axes, fills `sums` with each
/// texel's overlap and returns the number of elements; with `place`, each element's point
/// is put on the chart (place_points_on_chart).
inline std::size_t cut_chart(const scene_view& scene, const lightmap_atlas& atlas, const triangle_faces& faces,
                             const chart_extent& ex, double h, bool place, lightmap_chart& ch,
                             std::vector<texel_sum>& sums) {
    ch.width = std::uint32_t(std::clamp(std::ceil(ex.eu / h), 1.0, 65536.0));
    ch.height = std::uint32_t(std::clamp(std::ceil(ex.ev / h), 1.0, 65536.0));
    const double su = ex.eu / ch.width, sv = ex.ev / ch.height;
    ch.origin = glm::vec3(ex.origin);
    ch.axis_u = glm::vec3(ex.u * su);
    ch.axis_v = glm::vec3(ex.v * sv);
    sums.assign(std::size_t(ch.width) * ch.height, texel_sum{});
    const glm::dvec3 n = glm::dvec3(ch.normal);
    std::vector<std::array<glm::dvec2, 3>> triangles_in_texels;
    if (place) triangles_in_texels.reserve(ch.triangle_count);
    for (std::uint32_t k = 0; k < ch.triangle_count; ++k) {
        const std::uint32_t t = atlas.chart_triangles[ch.first_triangle + k];
        std::array<glm::dvec2, 3> q;
        for (int m = 0; m < 3; ++m) {
            const glm::dvec3 d = to_d(scene.positions[scene.triangles[t][m]]) - ex.origin;
            q[std::size_t(m)] = {glm::dot(d, ex.u) / su, glm::dot(d, ex.v) / sv};
        }
        // Surface area per plane area: 1 on a planar chart (exactly, as before charts bent).
        const double w = ch.planar ? 1.0 : 1.0 / std::max(glm::dot(faces.normal[t], n), 1e-6);
        const glm::dvec3 nt = faces.normal[t];
        for_each_cell_overlap(q, ch.width, ch.height, [&](std::size_t cell, double a, glm::dvec2 moment) {
            texel_sum& ts = sums[cell];
            ts.area += a;
            ts.world += a * w;
            ts.moment += moment * w;
            ts.normal += (a * w) * nt;
            if (a > ts.piece_area) ts.piece_area = a, ts.piece = moment / a, ts.piece_triangle = k;
        });
        if (place) triangles_in_texels.push_back(q);
    }
    std::size_t count = 0, largest = 0;
    for (std::size_t c = 0; c < sums.size(); ++c) {
        sums[c].keep = holds_element(sums[c]);
        count += sums[c].keep ? 1 : 0;
        if (sums[c].area > sums[largest].area) largest = c;
    }
    if (count == 0 && sums[largest].area > 0) {
        sums[largest].keep = true;
        count = 1;
    }
    if (place) place_points_on_chart(triangles_in_texels, ch.width, ch.height, sums);
    return count;
}

/// Every chart cut into texels of about h (m), but for the charts `grouping` clusters (one
/// element per cluster); returns the element count.
inline std::size_t cut_charts(const scene_view& scene, const triangle_faces& faces,
                              const std::vector<chart_extent>& extents, double h, bool place, lightmap_atlas& atlas,
                              std::vector<std::vector<texel_sum>>& sums, const chart_grouping& grouping) {
    std::size_t count = grouping.members.size();
    for (std::size_t c = 0; c < atlas.charts.size(); ++c)
        if (grouping.cluster_of_chart.empty() || grouping.cluster_of_chart[c] == chart_grouping::none)
            count += cut_chart(scene, atlas, faces, extents[c], h, place, atlas.charts[c], sums[c]);
    return count;
}

/// Cuts the charts with the texel density (texels per m^2 of the charts' planes, 1 / h^2)
/// whose element count comes closest to options.elements, and returns h and the number of
/// densities tried. The count grows about linearly in the density, plus the charts' edges,
/// and never falls below one per chart; it jumps where a chart's ceil(extent / h) steps.
/// Density x: x N / count until the count is bracketed, then secant steps inside the
/// bracket (bisection where a step would leave it), until within 0.5% of the count or 32
/// densities, keeping the closest count seen. With a `clusterer`, the tiny charts at each
/// density are grouped (chart_clusters.hpp) and `grouping` is the grouping at the density kept.
inline std::pair<double, int> cut_to_element_count(const scene_view& scene, const triangle_faces& faces,
                                                   const std::vector<chart_extent>& extents, double plane_area,
                                                   const atlas_options& options, lightmap_atlas& atlas,
                                                   std::vector<std::vector<texel_sum>>& sums,
                                                   const chart_clusterer* clusterer, chart_grouping& grouping) {
    const auto count_at = [&](double h, bool place) {
        if (clusterer) grouping = clusterer->group(h);
        return double(cut_charts(scene, faces, extents, h, place, atlas, sums, grouping));
    };
    const double target = double(options.elements);
    double x = target / plane_area, best_x = x, best_miss = std::numeric_limits<double>::infinity();
    double lo = 0, lo_count = 0, hi = std::numeric_limits<double>::infinity(), hi_count = 0;
    int tried = 0;
    for (; tried < 32; ++tried) {
        const double count = count_at(1.0 / std::sqrt(x), false);
        const double miss = std::abs(count - target);
        if (miss < best_miss) best_miss = miss, best_x = x;
        if (miss <= 0.005 * target) break;
        if (count < target) lo = x, lo_count = count;
        else hi = x, hi_count = count;
        double next;
        if (lo > 0 && std::isfinite(hi)) {
            next = lo + (target - lo_count) * (hi - lo) / (hi_count - lo_count);
            if (!(next > lo && next < hi) || hi_count == lo_count) next = std::sqrt(lo * hi);
            if (hi / lo < 1 + 1e-9) break;  // a step in the count no density splits
        } else
            next = x * target / std::max(count, 1.0);
        if (next == x) break;
        x = next;
    }
    count_at(1.0 / std::sqrt(best_x), true);
    return {1.0 / std::sqrt(best_x), tried + 1};
}

/// The point of chart c's surface over `coords` (chart texel coordinates: the plane point
/// origin + axis_u x + axis_v y) and that surface's unit normal: on a planar chart the plane
/// point and the chart's normal; on a curved one the point lifted onto the triangle whose
/// projection holds it (else the nearest, clamped onto it). For subdivision.hpp's leaves.
inline std::pair<glm::vec3, glm::vec3> chart_surface_point(const scene_view& scene, const lightmap_atlas& atlas,
                                                           std::uint32_t c, glm::dvec2 coords) {
    const lightmap_chart& ch = atlas.charts[c];
    const glm::dvec3 origin(ch.origin), au(ch.axis_u), av(ch.axis_v);
    if (ch.planar) return {glm::vec3(origin + au * coords.x + av * coords.y), ch.normal};
    const double uu = glm::dot(au, au), vv = glm::dot(av, av);
    double best = std::numeric_limits<double>::infinity();
    glm::dvec3 point(0), normal(ch.normal);
    for (std::uint32_t k = 0; k < ch.triangle_count; ++k) {
        const std::uint32_t t = atlas.chart_triangles[ch.first_triangle + k];
        std::array<glm::dvec2, 3> q;
        std::array<glm::dvec3, 3> corner;
        for (int m = 0; m < 3; ++m) {
            corner[std::size_t(m)] = to_d(scene.positions[scene.triangles[t][m]]);
            const glm::dvec3 d = corner[std::size_t(m)] - origin;
            q[std::size_t(m)] = {glm::dot(d, au) / uu, glm::dot(d, av) / vv};
        }
        const glm::dvec3 p = lift_to_triangle(q, corner, coords);
        const glm::dvec3 d = p - origin;
        const double miss = glm::length(glm::dvec2(glm::dot(d, au) / uu, glm::dot(d, av) / vv) - coords);
        if (miss < best) {
            best = miss;
            point = p;
            normal = glm::normalize(glm::cross(corner[1] - corner[0], corner[2] - corner[0]));
        }
        if (best == 0) break;
    }
    return {glm::vec3(point), glm::vec3(normal)};
}

/// Shelf packing: charts by decreasing height, each with `pad` texels around it, on rows as
/// wide as a square atlas. Sets each chart's atlas position and the atlas size.
inline void pack_charts_on_shelves(std::uint32_t pad, lightmap_atlas& atlas) {
    std::vector<std::uint32_t> order(atlas.charts.size());
    double padded_area = 0;
    std::uint32_t widest = 1;
    for (std::size_t c = 0; c < order.size(); ++c) {
        order[c] = std::uint32_t(c);
        padded_area += double(atlas.charts[c].width + 2 * pad) * double(atlas.charts[c].height + 2 * pad);
        widest = std::max(widest, atlas.charts[c].width + 2 * pad);
    }
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        return atlas.charts[a].height > atlas.charts[b].height;
    });
    atlas.width = std::max(widest, std::uint32_t(std::ceil(std::sqrt(padded_area))));
    std::uint32_t x = 0, y = 0, shelf = 0;
    for (const std::uint32_t c : order) {
        lightmap_chart& ch = atlas.charts[c];
        const std::uint32_t w = ch.width + 2 * pad, hh = ch.height + 2 * pad;
        if (x + w > atlas.width) {
            x = 0;
            y += shelf;
            shelf = 0;
        }
        ch.atlas_x = x + pad;
        ch.atlas_y = y + pad;
        x += w;
        shelf = std::max(shelf, hh);
    }
    atlas.height = std::max<std::uint32_t>(y + shelf, 1);
}

/// The radiosity pi L_e a material emits (0 when the scene's emission is off).
inline glm::vec3 emitted_radiosity(const scene_view& scene, const material& mat) {
    const bool emits = scene.use_emission && (mat.emission.r > 0.f || mat.emission.g > 0.f || mat.emission.b > 0.f);
    return emits ? float(std::numbers::pi) * mat.emission : glm::vec3(0.f);
}

/// The elements of chart c, block by block and row by row within a block: one per texel
/// kept (cut_chart), at its point on the chart (the overlap's centroid, or its largest
/// piece's), lifted from the chart's plane onto the triangle it lies on; a block with
/// elements becomes a shooting block.
inline void add_chart_elements(const scene_view& scene, std::uint32_t c, const chart_extent& ex,
                               const std::vector<texel_sum>& sums, std::uint32_t b, lightmap_atlas& atlas) {
    lightmap_chart& ch = atlas.charts[c];
    const material& mat = scene.materials[ch.material];
    const glm::vec3 emitted = emitted_radiosity(scene, mat);
    ch.first_element = std::uint32_t(atlas.size());
    const double su = ex.eu / ch.width, sv = ex.ev / ch.height;
    const auto point_of = [&](const texel_sum& ts) {
        const glm::dvec2 p = ts.moment / ts.world;
        if (ch.planar) return glm::vec3(ex.origin + ex.u * (p.x * su) + ex.v * (p.y * sv));
        const std::uint32_t t = atlas.chart_triangles[ch.first_triangle + ts.on_triangle];
        std::array<glm::dvec2, 3> q;
        std::array<glm::dvec3, 3> corner;
        for (int m = 0; m < 3; ++m) {
            corner[std::size_t(m)] = to_d(scene.positions[scene.triangles[t][m]]);
            const glm::dvec3 d = corner[std::size_t(m)] - ex.origin;
            q[std::size_t(m)] = {glm::dot(d, ex.u) / su, glm::dot(d, ex.v) / sv};
        }
        return glm::vec3(lift_to_triangle(q, corner, p));
    };
    for (std::uint32_t by = 0; by < ch.height; by += b)
        for (std::uint32_t bx = 0; bx < ch.width; bx += b) {
            const std::uint32_t first = std::uint32_t(atlas.size());
            for (std::uint32_t j = by; j < std::min(by + b, ch.height); ++j)
                for (std::uint32_t i = bx; i < std::min(bx + b, ch.width); ++i) {
                    const texel_sum& ts = sums[std::size_t(j) * ch.width + i];
                    if (!ts.keep) continue;
                    atlas.position.push_back(point_of(ts));
                    atlas.normal.push_back(ch.planar ? ch.normal : glm::vec3(glm::normalize(ts.normal)));
                    atlas.area.push_back(float(ts.world * su * sv));
                    atlas.albedo.push_back(mat.albedo);
                    atlas.emission.push_back(emitted);
                    atlas.chart.push_back(c);
                    atlas.texel.emplace_back(ch.atlas_x + i, ch.atlas_y + j);
                    atlas.element_at(ch.atlas_x + i, ch.atlas_y + j) = std::int32_t(atlas.size() - 1);
                }
            if (atlas.size() > first) {
                atlas.block_first.push_back(first);
                const std::uint32_t bw = std::min(b, ch.width - bx), bh = std::min(b, ch.height - by);
                atlas.block_rect.emplace_back(float(bx), float(by), float(bw), float(bh));
                atlas.block_grid.emplace_back(bw, bh);
                atlas.block_level.push_back(0);
            }
        }
    ch.element_count = std::uint32_t(atlas.size()) - ch.first_element;
}

/// The one element of cluster chart c (chart_clusters.hpp), its texel and its 1 x 1 block.
inline void add_cluster_element(const scene_view& scene, const triangle_faces& faces, std::uint32_t c,
                                lightmap_atlas& atlas) {
    lightmap_chart& ch = atlas.charts[c];
    const cluster_element ce =
        cluster_of_triangles(scene, faces, std::span(atlas.chart_triangles).subspan(ch.first_triangle, ch.triangle_count));
    ch.first_element = std::uint32_t(atlas.size());
    ch.element_count = 1;
    atlas.block_first.push_back(ch.first_element);
    atlas.block_rect.emplace_back(0.f, 0.f, 1.f, 1.f);
    atlas.block_grid.emplace_back(1u, 1u);
    atlas.block_level.push_back(0);
    atlas.position.push_back(glm::vec3(ce.position));
    atlas.normal.push_back(glm::vec3(ce.normal));
    atlas.area.push_back(float(ce.area));
    atlas.albedo.push_back(scene.materials[ch.material].albedo);
    atlas.emission.push_back(emitted_radiosity(scene, scene.materials[ch.material]));
    atlas.chart.push_back(c);
    atlas.texel.emplace_back(ch.atlas_x, ch.atlas_y);
    atlas.element_at(ch.atlas_x, ch.atlas_y) = std::int32_t(ch.first_element);
}

/// Replaces the charts `grouping` clusters by one chart per cluster, after the others: one
/// texel on the frame cluster_of_triangles gives; extents and sums follow the charts.
inline void merge_clusters(const scene_view& scene, const triangle_faces& faces, const chart_grouping& grouping,
                           std::vector<chart_extent>& extents, std::vector<std::vector<texel_sum>>& sums,
                           lightmap_atlas& atlas) {
    std::vector<lightmap_chart> charts;
    std::vector<std::uint32_t> tris;
    std::vector<chart_extent> ex;
    std::vector<std::vector<texel_sum>> su;
    const auto take = [&](lightmap_chart ch, std::span<const std::uint32_t> t) {
        ch.first_triangle = std::uint32_t(tris.size());
        ch.triangle_count = std::uint32_t(t.size());
        for (const std::uint32_t u : t) tris.push_back(u), atlas.chart_of_triangle[u] = std::uint32_t(charts.size());
        charts.push_back(ch);
    };
    const auto triangles_of = [&](std::uint32_t c) {
        return std::span(atlas.chart_triangles).subspan(atlas.charts[c].first_triangle, atlas.charts[c].triangle_count);
    };
    for (std::uint32_t c = 0; c < atlas.charts.size(); ++c)
        if (grouping.cluster_of_chart[c] == chart_grouping::none) {
            take(atlas.charts[c], triangles_of(c));
            ex.push_back(extents[c]);
            su.push_back(std::move(sums[c]));
        }
    for (const std::vector<std::uint32_t>& members : grouping.members) {
        std::vector<std::uint32_t> mine;
        for (const std::uint32_t c : members) mine.insert(mine.end(), triangles_of(c).begin(), triangles_of(c).end());
        std::sort(mine.begin(), mine.end());
        const cluster_element ce = cluster_of_triangles(scene, faces, mine);
        lightmap_chart ch;
        ch.origin = glm::vec3(ce.origin), ch.axis_u = glm::vec3(ce.axis_u), ch.axis_v = glm::vec3(ce.axis_v);
        ch.normal = glm::vec3(ce.normal);
        ch.width = ch.height = 1;
        ch.material = atlas.charts[members[0]].material;
        ch.tilt_degrees = float(ce.tilt_degrees);
        ch.planar = false;
        ch.clustered_charts = std::uint32_t(members.size());
        take(ch, mine);
        ex.emplace_back();
        su.emplace_back();
    }
    atlas.charts = std::move(charts);
    atlas.chart_triangles = std::move(tris);
    extents = std::move(ex);
    sums = std::move(su);
}

/// cut_to_element_count without clusters, then with them (merged into the atlas) where
/// options.clusters asks: always, or when the count misses the asked one by more than 10%.
inline std::pair<double, int> cut_within_budget(const scene_view& scene, const triangle_faces& faces,
                                                std::vector<chart_extent>& extents, double plane_area,
                                                const atlas_options& options, lightmap_atlas& atlas,
                                                std::vector<std::vector<texel_sum>>& sums) {
    chart_grouping grouping;
    std::pair<double, int> plain{0.0, 0};
    if (options.clusters != tiny_chart_clusters::always) {
        plain = cut_to_element_count(scene, faces, extents, plane_area, options, atlas, sums, nullptr, grouping);
        double count = 0;
        for (const auto& s : sums)
            for (const texel_sum& ts : s) count += ts.keep ? 1 : 0;
        const double asked = double(options.elements);
        if (options.clusters == tiny_chart_clusters::never || std::abs(count - asked) <= 0.1 * asked) return plain;
    }
    std::vector<std::span<const std::uint32_t>> tris;
    std::vector<std::uint32_t> material;
    std::vector<double> extent;
    for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
        const lightmap_chart& ch = atlas.charts[c];
        tris.push_back(std::span(atlas.chart_triangles).subspan(ch.first_triangle, ch.triangle_count));
        material.push_back(ch.material);
        extent.push_back(std::max(extents[c].eu, extents[c].ev));
    }
    const chart_clusterer clusterer(faces, std::move(tris), std::move(material), std::move(extent),
                                    std::max(options.cone_degrees, options.coplanar_degrees));
    const auto clustered = cut_to_element_count(scene, faces, extents, plane_area, options, atlas, sums, &clusterer, grouping);
    merge_clusters(scene, faces, grouping, extents, sums, atlas);
    return {clustered.first, plain.second + clustered.second};
}

/// Points the empty texels of chart `ch`'s padded rectangle (`pad` texels around it) at the
/// nearest element of the chart: 4-neighbour dilation of element_at, repeated until the
/// rectangle is full.
inline void fill_chart_padding(const lightmap_chart& ch, std::uint32_t pad, lightmap_atlas& atlas) {
    if (ch.element_count == 0) return;
    const std::uint32_t x0 = ch.atlas_x - pad, y0 = ch.atlas_y - pad;
    const std::uint32_t x1 = ch.atlas_x + ch.width + pad, y1 = ch.atlas_y + ch.height + pad;
    const std::uint32_t w = x1 - x0;
    std::vector<std::int32_t> before(std::size_t(w) * (y1 - y0));
    const auto at = [&](std::uint32_t xx, std::uint32_t yy) { return before[std::size_t(yy - y0) * w + (xx - x0)]; };
    for (bool changed = true; changed;) {
        changed = false;
        for (std::uint32_t yy = y0; yy < y1; ++yy)
            for (std::uint32_t xx = x0; xx < x1; ++xx) before[std::size_t(yy - y0) * w + (xx - x0)] = atlas.element_at(xx, yy);
        for (std::uint32_t yy = y0; yy < y1; ++yy)
            for (std::uint32_t xx = x0; xx < x1; ++xx) {
                if (at(xx, yy) >= 0) continue;
                std::int32_t found = -1;
                if (xx > x0 && at(xx - 1, yy) >= 0) found = at(xx - 1, yy);
                else if (xx + 1 < x1 && at(xx + 1, yy) >= 0) found = at(xx + 1, yy);
                else if (yy > y0 && at(xx, yy - 1) >= 0) found = at(xx, yy - 1);
                else if (yy + 1 < y1 && at(xx, yy + 1) >= 0) found = at(xx, yy + 1);
                if (found >= 0) {
                    atlas.element_at(xx, yy) = found;
                    changed = true;
                }
            }
    }
}

}  // namespace bounce::detail

namespace bounce::inline radiosity {

/// Cuts `scene` into charts and elements as the file comment says. Throws parameter_error
/// (via scene.validate() and options.validate()) on a bad scene or options.
inline lightmap_atlas build_lightmap_atlas(const scene_view& scene, const atlas_options& options = {}) {
    scene.validate();
    options.validate();
    const std::size_t nt = scene.triangles.size();
    lightmap_atlas atlas;
    atlas.block_texels = options.block_texels;
    atlas.chart_of_triangle.assign(nt, lightmap_atlas::none);

    const detail::triangle_faces faces = detail::face_normals_and_areas(scene);
    double total_area = 0;
    for (std::size_t t = 0; t < nt; ++t) total_area += faces.area[t];
    require(total_area > 0, "scene.triangles", "the scene has no triangle of positive area");
    const detail::grown_charts grown = detail::group_into_charts(scene, faces, options, atlas);
    std::vector<detail::chart_extent> extents(atlas.charts.size());
    for (std::size_t c = 0; c < atlas.charts.size(); ++c)
        extents[c] = detail::smallest_bounding_frame(
            scene, std::span(atlas.chart_triangles).subspan(atlas.charts[c].first_triangle, atlas.charts[c].triangle_count),
            glm::dvec3(atlas.charts[c].normal));

    // Area on the charts' planes, and the surface's stretch over it.
    atlas_statistics& st = atlas.statistics;
    double plane_area = 0;
    st.stretch_max = 1;
    for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
        const lightmap_chart& ch = atlas.charts[c];
        for (std::uint32_t k = 0; k < ch.triangle_count; ++k) {
            const std::uint32_t t = atlas.chart_triangles[ch.first_triangle + k];
            const double cosine = ch.planar ? 1.0 : std::max(glm::dot(faces.normal[t], glm::dvec3(ch.normal)), 1e-6);
            plane_area += faces.area[t] * cosine;
            st.stretch_max = std::max(st.stretch_max, 1.0 / cosine);
        }
        st.cone_max_degrees = std::max(st.cone_max_degrees, double(ch.tilt_degrees));
    }
    st.stretch_mean = total_area / plane_area;
    std::vector<std::vector<detail::texel_sum>> sums(atlas.charts.size());
    std::tie(st.texel_size, st.densities_tried) =
        detail::cut_within_budget(scene, faces, extents, plane_area, options, atlas, sums);

    const std::uint32_t pad = std::uint32_t(options.padding);
    detail::pack_charts_on_shelves(pad, atlas);
    atlas.element_at = image<std::int32_t>(atlas.width, atlas.height, -1);
    for (std::uint32_t c = 0; c < atlas.charts.size(); ++c) {
        if (atlas.charts[c].cluster()) detail::add_cluster_element(scene, faces, c, atlas);
        else detail::add_chart_elements(scene, c, extents[c], sums[c], std::uint32_t(options.block_texels), atlas);
        detail::fill_chart_padding(atlas.charts[c], pad, atlas);
    }
    atlas.block_first.push_back(std::uint32_t(atlas.size()));
    require(atlas.size() > 0, "scene.triangles", "the scene gives no element");

    st.charts = atlas.charts.size();
    st.elements = atlas.size();
    st.triangles = nt;
    st.atlas_texels = std::size_t(atlas.width) * atlas.height;
    st.packing_efficiency = double(st.elements) / double(std::max<std::size_t>(st.atlas_texels, 1));
    std::vector<std::uint32_t> per_chart(atlas.charts.size());
    for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
        per_chart[c] = atlas.charts[c].element_count;
        st.chart_texels += std::size_t(atlas.charts[c].width) * atlas.charts[c].height;
        st.one_element_charts += per_chart[c] == 1 ? 1 : 0;
        st.curved_charts += atlas.charts[c].planar || atlas.charts[c].cluster() ? 0 : 1;
        st.clusters += atlas.charts[c].cluster() ? 1 : 0;
        st.clustered_charts += atlas.charts[c].clustered_charts;
        st.cone_max_degrees = std::max(st.cone_max_degrees, double(atlas.charts[c].tilt_degrees));
    }
    std::nth_element(per_chart.begin(), per_chart.begin() + std::ptrdiff_t(per_chart.size() / 2), per_chart.end());
    st.median_elements_per_chart = per_chart.empty() ? 0 : per_chart[per_chart.size() / 2];
    st.seed_plane_kept = grown.seed_plane_kept;
    st.overlaps_refused = grown.overlaps_refused;
    return atlas;
}

}  // namespace bounce::radiosity
