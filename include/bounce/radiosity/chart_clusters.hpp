#pragma once
/// \file radiosity/chart_clusters.hpp
/// Clusters of tiny charts (issue 30): when the texel size h that the element budget gives
/// is larger than many charts (the conference room's bevelled furniture: 48,534 charts of a
/// few millimetres each), every chart keeping a texel of its own overruns the budget. Charts
/// that fit in one texel (both extents on their plane at most h) are grouped instead, and
/// each group of two or more becomes one chart of one texel, one element:
///
/// - near: the charts' area-weighted centroids fall in one cell of a world grid of side h
///   (the texel's size at the budget's density), so a cluster spans at most about 2h;
/// - one material (the element's reflectance and emission are its triangles');
/// - one normal: a chart joins when all its triangles' normals lie within the chart cone
///   (atlas_options::cone_degrees) of the cluster's first (largest) chart's normal; when the
///   cell is done, charts with a triangle outside the cone of the cluster's area-weighted
///   mean normal leave it (and the mean is taken again) until none does, so the element's
///   normal is every triangle's within the cone, as a chart's is.
///
/// The cluster's element has the triangles' total area, their area-weighted mean normal, and
/// the point of its triangles nearest their area-weighted centroid (a point on the surface:
/// rays and item buffers start and end on it). Its chart's frame is the triangles' bounding
/// rectangle on the mean normal's plane, one texel wide and high, so every triangle's
/// lightmap coordinates fall in that one texel. lightmap_atlas.hpp decides when clusters are
/// made (atlas_options::clusters) and cuts the other charts as before.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <tuple>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <bounce/radiosity/chart_growth.hpp>
#include <bounce/scene_view.hpp>

namespace bounce::detail {

/// The tiny charts of an atlas grouped at one texel size.
struct chart_grouping {
    static constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> cluster_of_chart;     ///< none: the chart stays a chart of its own
    std::vector<std::vector<std::uint32_t>> members; ///< the charts of each cluster (two or more)
};

/// Groups the charts of an atlas (each chart's triangles, material and extent on its plane,
/// m) into clusters at a texel size h, as the file comment says.
class chart_clusterer {
public:
    chart_clusterer(const triangle_faces& faces, std::vector<std::span<const std::uint32_t>> triangles,
                    std::vector<std::uint32_t> material, std::vector<double> extent, double cone_degrees)
        : faces_(&faces), triangles_(std::move(triangles)), material_(std::move(material)), extent_(std::move(extent)),
          cos_cone_(std::cos(cone_degrees * std::numbers::pi / 180.0)) {
        const std::size_t n = triangles_.size();
        centroid_.assign(n, glm::dvec3(0));
        area_.assign(n, 0.0);
        normal_.assign(n, glm::dvec3(0));
        sum_.assign(n, glm::dvec3(0));
        for (std::size_t c = 0; c < n; ++c) {
            for (const std::uint32_t t : triangles_[c]) {
                area_[c] += faces.area[t];
                centroid_[c] += faces.area[t] * faces.centroid[t];
                normal_[c] += faces.area[t] * faces.normal[t];
            }
            if (area_[c] > 0) centroid_[c] /= area_[c];
            sum_[c] = normal_[c];
            if (glm::length(normal_[c]) > 0) normal_[c] = glm::normalize(normal_[c]);
        }
    }

    /// The clusters at texel size h (m).
    chart_grouping group(double h) const {
        const std::size_t n = triangles_.size();
        chart_grouping out;
        out.cluster_of_chart.assign(n, chart_grouping::none);
        using key = std::tuple<std::int64_t, std::int64_t, std::int64_t, std::uint32_t, double, std::uint32_t>;
        std::vector<key> tiny;
        const auto cell = [&](double x) { return std::int64_t(std::floor(std::clamp(x / h, -1e15, 1e15))); };
        for (std::size_t c = 0; c < n; ++c)
            if (extent_[c] <= h && area_[c] > 0)
                tiny.emplace_back(cell(centroid_[c].x), cell(centroid_[c].y), cell(centroid_[c].z), material_[c], -area_[c],
                                  std::uint32_t(c));
        std::sort(tiny.begin(), tiny.end());
        struct open_cluster {
            glm::dvec3 seed;
            std::vector<std::uint32_t> charts;
        };
        std::vector<open_cluster> open;
        const auto close_run = [&]() {
            for (open_cluster& o : open) {
                for (bool left = true; left && o.charts.size() >= 2;) {
                    glm::dvec3 mean(0);
                    for (const std::uint32_t c : o.charts) mean += sum_[c];
                    mean = glm::normalize(mean);
                    const auto kept = std::partition(o.charts.begin(), o.charts.end(),
                                                     [&](std::uint32_t c) { return within_cone(c, mean); });
                    left = kept != o.charts.end();
                    o.charts.erase(kept, o.charts.end());
                }
                if (o.charts.size() < 2) continue;
                for (const std::uint32_t c : o.charts) out.cluster_of_chart[c] = std::uint32_t(out.members.size());
                out.members.push_back(std::move(o.charts));
            }
            open.clear();
        };
        for (std::size_t k = 0; k < tiny.size(); ++k) {
            const auto& [x, y, z, mat, neg_area, c] = tiny[k];
            if (k > 0 && std::tie(x, y, z, mat) != std::tie(std::get<0>(tiny[k - 1]), std::get<1>(tiny[k - 1]),
                                                              std::get<2>(tiny[k - 1]), std::get<3>(tiny[k - 1])))
                close_run();
            open_cluster* joined = nullptr;
            for (open_cluster& o : open)
                if (within_cone(c, o.seed)) {
                    joined = &o;
                    break;
                }
            if (!joined) joined = &open.emplace_back(open_cluster{normal_[c], {}});
            joined->charts.push_back(c);
        }
        close_run();
        return out;
    }

private:
    bool within_cone(std::uint32_t c, const glm::dvec3& n) const {
        for (const std::uint32_t t : triangles_[c])
            if (glm::dot(faces_->normal[t], n) < cos_cone_) return false;
        return true;
    }
    const triangle_faces* faces_;
    std::vector<std::span<const std::uint32_t>> triangles_;
    std::vector<std::uint32_t> material_;
    std::vector<double> extent_;
    double cos_cone_;
    std::vector<glm::dvec3> centroid_, normal_, sum_;  ///< sum_: area-weighted normal sums
    std::vector<double> area_;
};

/// The point of triangle (a, b, c) nearest p (Ericson, Real-Time Collision Detection, 5.1.5).
inline glm::dvec3 nearest_point_on_triangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                            const glm::dvec3& c) {
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    const double denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

/// A cluster's chart and element: the frame of its one texel (origin and axes, m: the
/// triangles' bounding rectangle on the plane of their mean normal), its tilt, and the
/// element (point, normal, area) the file comment describes.
struct cluster_element {
    glm::dvec3 origin{0}, axis_u{0}, axis_v{0}, normal{0, 0, 1}, position{0};
    double area = 0, tilt_degrees = 0;
};
inline cluster_element cluster_of_triangles(const scene_view& scene, const triangle_faces& faces,
                                            std::span<const std::uint32_t> tris) {
    cluster_element out;
    glm::dvec3 n_sum(0), centroid(0);
    for (const std::uint32_t t : tris) {
        out.area += faces.area[t];
        n_sum += faces.area[t] * faces.normal[t];
        centroid += faces.area[t] * faces.centroid[t];
    }
    out.normal = glm::normalize(n_sum);
    centroid /= out.area;
    const glm::dvec3 n = out.normal, helper = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(helper, n)), v = glm::cross(n, u);
    glm::dvec2 mn(std::numeric_limits<double>::infinity()), mx(-std::numeric_limits<double>::infinity());
    double nearest = std::numeric_limits<double>::infinity(), worst = 1;
    for (const std::uint32_t t : tris) {
        std::array<glm::dvec3, 3> p;
        for (int m = 0; m < 3; ++m) {
            p[std::size_t(m)] = to_d(scene.positions[scene.triangles[t][m]]);
            mn = glm::min(mn, glm::dvec2(glm::dot(p[std::size_t(m)], u), glm::dot(p[std::size_t(m)], v)));
            mx = glm::max(mx, glm::dvec2(glm::dot(p[std::size_t(m)], u), glm::dot(p[std::size_t(m)], v)));
        }
        const glm::dvec3 q = nearest_point_on_triangle(centroid, p[0], p[1], p[2]);
        if (glm::length(q - centroid) < nearest) nearest = glm::length(q - centroid), out.position = q;
        worst = std::min(worst, glm::dot(faces.normal[t], n));
    }
    // A side of zero length (triangles in a line on the plane) gets a thousandth of the other.
    const glm::dvec2 size = glm::max(mx - mn, glm::dvec2(1e-3 * std::max(mx.x - mn.x, mx.y - mn.y)));
    out.origin = n * glm::dot(out.position, n) + u * mn.x + v * mn.y;
    out.axis_u = u * size.x;
    out.axis_v = v * size.y;
    out.tilt_degrees = std::acos(std::clamp(worst, -1.0, 1.0)) * 180.0 / std::numbers::pi;
    return out;
}

}  // namespace bounce::detail
