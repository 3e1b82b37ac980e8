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
/// mixes two charts.
///
/// Elements are stored struct-of-arrays, chart by chart, and within a chart by square
/// blocks of `block_texels` x `block_texels` texels: a block is a contiguous range of
/// elements, the unit of shooting with substructuring (Cohen et al. 1986; the chapter's
/// section 39.4 shoots from a mip level of the residual texture).

#include <bounce/errors.hpp>
#include <bounce/image.hpp>
#include <bounce/radiosity/cell_overlap.hpp>
#include <bounce/radiosity/chart_growth.hpp>
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

namespace bounce::inline radiosity {

/// How to cut a scene into elements.
struct atlas_options {
    std::size_t elements = 10000;  ///< target element count (the program's --elements N); the
                                   ///< result is within a few percent of it (typical: 1e4-1e5)
    int padding = 1;               ///< texels around each chart in the atlas, >= 0 (typical: 1; 2 for mipmaps)
    int block_texels = 4;          ///< side of a shooting block, texels, >= 1 (typical: 4; 1 = no substructuring)
    double cone_degrees = 30;        ///< largest angle between a chart's triangles' normals and the
                                     ///< seed's and the chart's mean normal, in [0, 90) (degrees;
                                     ///< 0 = planar charts only); chart_growth.hpp
    double coplanar_degrees = 0.05;  ///< a chart whose normals all lie within this of its normal is
                                     ///< planar: its elements take the chart's normal and plane

    void validate() const {
        require(elements > 0, "atlas_options.elements", "must be positive");
        require(padding >= 0 && padding <= 64, "atlas_options.padding", "must lie in [0, 64]");
        require(block_texels >= 1 && block_texels <= 256, "atlas_options.block_texels", "must lie in [1, 256]");
        require(cone_degrees >= 0 && cone_degrees < 90, "atlas_options.cone_degrees", "must lie in [0, 90)");
        require(coplanar_degrees >= 0 && coplanar_degrees < 90, "atlas_options.coplanar_degrees",
                "must lie in [0, 90)");
    }
};

/// One chart: a planar set of triangles and its rectangle of texels. Texel (i, j) of the
/// chart covers origin + axis_u [i, i+1] + axis_v [j, j+1] (axis lengths are the texel's
/// sides, m) and sits at atlas texel (atlas_x + i, atlas_y + j).
struct lightmap_chart {
    glm::vec3 origin{0.f}, axis_u{0.f}, axis_v{0.f}, normal{0.f, 0.f, 1.f};
    std::uint32_t width = 0, height = 0;    ///< texels
    std::uint32_t atlas_x = 0, atlas_y = 0; ///< atlas texel of the chart's texel (0, 0)
    std::uint32_t material = 0;
    std::uint32_t first_triangle = 0, triangle_count = 0;  ///< range of lightmap_atlas::chart_triangles
    std::uint32_t first_element = 0, element_count = 0;    ///< range of the elements
    float tilt_degrees = 0;  ///< largest angle between a triangle's normal and `normal`
    bool planar = true;      ///< tilt_degrees within atlas_options::coplanar_degrees
};

/// The elements of a scene and where they lie in the lightmap atlas.
struct lightmap_atlas {
    static constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();

    std::uint32_t width = 0, height = 0;          ///< atlas size, texels
    std::vector<lightmap_chart> charts;
    std::vector<std::uint32_t> chart_triangles;   ///< triangles of each chart (ranges in lightmap_chart)
    std::vector<std::uint32_t> chart_of_triangle; ///< chart of each scene triangle; none for degenerate ones

    // Elements, struct of arrays (index = element id).
    std::vector<glm::vec3> position;  ///< centroid of the texel's overlap with the chart (world, m)
    std::vector<glm::vec3> normal;    ///< unit normal of the chart (front side: counter-clockwise)
    std::vector<float> area;          ///< overlap area, m^2
    std::vector<glm::vec3> albedo;    ///< diffuse reflectance rho per channel
    std::vector<glm::vec3> emission;  ///< emitted radiosity E = pi L_e, W/m^2 per channel
    std::vector<std::uint32_t> chart; ///< chart of each element
    std::vector<glm::uvec2> texel;    ///< atlas texel of each element

    /// Shooting blocks: block k is the elements [block_first[k], block_first[k+1]), all of one
    /// chart. block_first has blocks() + 1 entries.
    std::vector<std::uint32_t> block_first;
    int block_texels = 1;
    /// Each block's rectangle in its chart's texel coordinates (x0, y0, width, height, in
    /// texels of the base grid) and its grid of grid.x x grid.y texels: a base block's grid is
    /// its rectangle's texels; adaptive subdivision (radiosity/subdivision.hpp) splits a block
    /// into four quadrants with the same grid, so level L texels are 2^-L base texels wide.
    std::vector<glm::vec4> block_rect;
    std::vector<glm::uvec2> block_grid;
    std::vector<std::uint8_t> block_level;  ///< 0 for base blocks

    /// Element at each atlas texel: the texel's own element, the nearest element of the same
    /// chart for padding texels and texels that miss the chart's triangles, -1 elsewhere.
    image<std::int32_t> element_at;

    atlas_statistics statistics;  ///< what build_lightmap_atlas made

    std::size_t size() const noexcept { return area.size(); }
    std::size_t blocks() const noexcept { return block_first.empty() ? 0 : block_first.size() - 1; }

    /// Atlas texel coordinates (continuous: texel (x, y) spans [x, x+1] x [y, y+1]) of the
    /// world point `p` on chart `c`'s plane: the lightmap UV of a vertex, times the atlas size.
    glm::vec2 atlas_coords(std::uint32_t c, const glm::vec3& p) const {
        const lightmap_chart& ch = charts.at(c);
        const glm::vec3 d = p - ch.origin;
        return {float(ch.atlas_x) + glm::dot(d, ch.axis_u) / glm::dot(ch.axis_u, ch.axis_u),
                float(ch.atlas_y) + glm::dot(d, ch.axis_v) / glm::dot(ch.axis_v, ch.axis_v)};
    }

    /// Lightmap coordinates in [0, 1]^2 of every triangle corner of `scene` (the scene the
    /// atlas was built from), three per triangle, (0, 0) for degenerate triangles: what a
    /// renderer's vertex buffer needs to sample a lightmap of width x height texels.
    std::vector<glm::vec2> corner_uvs(const scene_view& scene) const {
        require(scene.triangles.size() == chart_of_triangle.size(), "scene",
                "is not the scene the atlas was built from (triangle counts differ)");
        std::vector<glm::vec2> uv(3 * scene.triangles.size(), glm::vec2(0.f));
        const glm::vec2 size(float(std::max<std::uint32_t>(width, 1)), float(std::max<std::uint32_t>(height, 1)));
        for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
            if (chart_of_triangle[t] == none) continue;
            for (int k = 0; k < 3; ++k)
                uv[3 * t + std::size_t(k)] = atlas_coords(chart_of_triangle[t], scene.positions[scene.triangles[t][k]]) / size;
        }
        return uv;
    }

    /// to_texels at 2^level times the atlas resolution, for atlases refined by adaptive
    /// subdivision (radiosity/subdivision.hpp): an element of level l fills the 2^(level - l)
    /// square of fine texels its cell covers (elements deeper than `level` are averaged,
    /// area-weighted); fine texels no element covers (a chart's slanted edge, padding) take
    /// their base texel's to_texels value. level = 0 is to_texels.
    /// With `interpolate_base`, the fine texels of elements that were never split (level 0)
    /// take the bilinear interpolation of the base texels at their centres instead of their
    /// element's constant value, so that a bilinear lookup of the fine map shows unsplit
    /// regions as a bilinear lookup of the base map would (the chapter's reconstruction of
    /// the coarse level), rather than as blocks of 2^level texels.
    template <class T>
    image<T> to_fine_texels(std::span<const T> values, int level, const T& background = T{},
                            bool interpolate_base = false) const {
        require(level >= 0 && level <= 8, "level", "must lie in [0, 8]");
        const image<T> base = to_texels(values, background);
        if (level == 0) return base;
        const std::size_t f = std::size_t(1) << level;
        const std::size_t w = base.width() * f, h = base.height() * f;
        std::vector<T> sum(w * h, T{});
        std::vector<float> weight(w * h, 0.f);
        std::vector<std::int64_t> single(w * h, -1);  // the one element of a fine texel, or -2 for several
        std::vector<std::uint8_t> unsplit(size(), 0);  // elements of level 0
        for (std::size_t k = 0; k < blocks(); ++k) {
            const int l = block_level.empty() ? 0 : int(block_level[k]);
            for (std::uint32_t e = block_first[k]; e < block_first[k + 1]; ++e) unsplit[e] = l == 0 ? 1 : 0;
            const double cells = std::ldexp(1.0, l);  // cells per base texel
            for (std::uint32_t e = block_first[k]; e < block_first[k + 1]; ++e) {
                const lightmap_chart& ch = charts[chart[e]];
                const glm::vec3 d = position[e] - ch.origin;
                const glm::dvec2 c(glm::dot(d, ch.axis_u) / glm::dot(ch.axis_u, ch.axis_u),
                                   glm::dot(d, ch.axis_v) / glm::dot(ch.axis_v, ch.axis_v));
                // The element's cell, clamped into its base texel (its centroid lies inside).
                const glm::dvec2 in_texel = glm::clamp(c * cells - glm::dvec2(texel[e] - glm::uvec2(ch.atlas_x, ch.atlas_y)) * cells,
                                                       glm::dvec2(0.0), glm::dvec2(cells - 1e-9));
                const glm::uvec2 cell(glm::floor(in_texel));
                // Fine texels per cell: f / 2^l (>= 1), or one fine texel shared by 2^(l - level)^2 cells.
                const std::size_t span = l <= level ? f >> l : 1;
                const std::size_t x0 = texel[e].x * f + (l <= level ? cell.x * span : cell.x >> (l - level));
                const std::size_t y0 = texel[e].y * f + (l <= level ? cell.y * span : cell.y >> (l - level));
                for (std::size_t y = y0; y < y0 + span; ++y)
                    for (std::size_t x = x0; x < x0 + span; ++x) {
                        sum[y * w + x] += values[e] * area[e];
                        weight[y * w + x] += area[e];
                        single[y * w + x] = single[y * w + x] == -1 ? std::int64_t(e) : -2;
                    }
            }
        }
        image<T> out(w, h, background);
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t x = 0; x < w; ++x) {
                const std::size_t bx = x / f, by = y / f;
                const std::int32_t e = bx < width && by < height ? element_at(bx, by) : -1;
                if (e < 0) continue;
                // Only a texel's own fine texels come from its elements; padding copies its source texel.
                const bool own = texel[std::size_t(e)].x == bx && texel[std::size_t(e)].y == by;
                const std::int64_t one = single[y * w + x];
                if (interpolate_base && own && one >= 0 && unsplit[std::size_t(one)]) {
                    // Base texel coordinates of the fine texel's centre; base texel i's centre is i + 1/2.
                    const double u = (double(x) + 0.5) / double(f) - 0.5, v = (double(y) + 0.5) / double(f) - 0.5;
                    const double fu = std::floor(u), fv = std::floor(v);
                    const float tu = float(u - fu), tv = float(v - fv);
                    const auto at = [&](double i, double j) {
                        return base(std::size_t(std::clamp(i, 0.0, double(base.width() - 1))),
                                    std::size_t(std::clamp(j, 0.0, double(base.height() - 1))));
                    };
                    out(x, y) = (1.f - tv) * ((1.f - tu) * at(fu, fv) + tu * at(fu + 1, fv)) +
                                tv * ((1.f - tu) * at(fu, fv + 1) + tu * at(fu + 1, fv + 1));
                    continue;
                }
                out(x, y) = !own || one == -1 ? base(bx, by) : one >= 0 ? values[std::size_t(one)] : sum[y * w + x] / weight[y * w + x];
            }
        return out;
    }

    /// A per-element quantity (per unit area, like a radiosity) laid out as the atlas: texel
    /// (x, y) holds the area-weighted mean of `values` over the elements in the base texel of
    /// element_at(x, y) (that element's own value unless its block was subdivided),
    /// `background` where no chart is. `values` has one entry per element; T is a float or a
    /// GLM vector of floats.
    template <class T>
    image<T> to_texels(std::span<const T> values, const T& background = T{}) const {
        require(values.size() == size(), "values", "needs one value per element");
        const std::size_t w = std::max<std::uint32_t>(width, 1), h = std::max<std::uint32_t>(height, 1);
        std::vector<T> sum(w * h, T{});
        std::vector<float> weight(w * h, 0.f);
        for (std::size_t e = 0; e < size(); ++e) {
            const std::size_t i = std::size_t(texel[e].y) * w + texel[e].x;
            sum[i] += values[e] * area[e];
            weight[i] += area[e];
        }
        image<T> out(w, h, background);
        for (std::uint32_t y = 0; y < height; ++y)
            for (std::uint32_t x = 0; x < width; ++x)
                if (const std::int32_t e = element_at(x, y); e >= 0) {
                    const std::size_t i = std::size_t(texel[std::size_t(e)].y) * w + texel[std::size_t(e)].x;
                    // One element: its value exactly (no division round trip).
                    out(x, y) = weight[i] == area[std::size_t(e)] ? values[std::size_t(e)] : sum[i] / weight[i];
                }
        return out;
    }
};

}  // namespace bounce::radiosity

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

/// A chart's frame on its plane (origin, unit in-plane axes u and v) and its extent along
/// them (m).
struct chart_extent {
    glm::dvec3 origin, u, v;
    double eu = 0, ev = 0;
};

/// The frame of chart `ch` whose axis u runs along one of its triangles' edges and whose
/// bounding rectangle is the smallest (a rectangle's own sides for walls and quads). At most
/// 64 edges are tried, which covers every chart of a few dozen triangles.
inline chart_extent smallest_bounding_frame(const scene_view& scene, const lightmap_atlas& atlas,
                                            const lightmap_chart& ch) {
    chart_extent out{};
    const glm::dvec3 n = glm::dvec3(ch.normal);
    const auto tris = std::span(atlas.chart_triangles).subspan(ch.first_triangle, ch.triangle_count);
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

/// Every chart cut into texels of about h (m); returns the element count.
inline std::size_t cut_charts(const scene_view& scene, const triangle_faces& faces,
                              const std::vector<chart_extent>& extents, double h, bool place, lightmap_atlas& atlas,
                              std::vector<std::vector<texel_sum>>& sums) {
    std::size_t count = 0;
    for (std::size_t c = 0; c < atlas.charts.size(); ++c)
        count += cut_chart(scene, atlas, faces, extents[c], h, place, atlas.charts[c], sums[c]);
    return count;
}

/// Cuts the charts with the texel density (texels per m^2 of the charts' planes, 1 / h^2)
/// whose element count comes closest to options.elements, and returns h and the number of
/// densities tried. The count grows about linearly in the density, plus the charts' edges,
/// and never falls below one per chart; it jumps where a chart's ceil(extent / h) steps.
/// Density x: x N / count until the count is bracketed, then secant steps inside the
/// bracket (bisection where a step would leave it), until within 0.5% of the count or 32
/// densities, keeping the closest count seen.
inline std::pair<double, int> cut_to_element_count(const scene_view& scene, const triangle_faces& faces,
                                                   const std::vector<chart_extent>& extents, double plane_area,
                                                   const atlas_options& options, lightmap_atlas& atlas,
                                                   std::vector<std::vector<texel_sum>>& sums) {
    const double target = double(options.elements);
    double x = target / plane_area, best_x = x, best_miss = std::numeric_limits<double>::infinity();
    double lo = 0, lo_count = 0, hi = std::numeric_limits<double>::infinity(), hi_count = 0;
    int tried = 0;
    for (; tried < 32; ++tried) {
        const double count = double(cut_charts(scene, faces, extents, 1.0 / std::sqrt(x), false, atlas, sums));
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
    cut_charts(scene, faces, extents, 1.0 / std::sqrt(best_x), true, atlas, sums);
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

/// The elements of chart c, block by block and row by row within a block: one per texel
/// kept (cut_chart), at its point on the chart (the overlap's centroid, or its largest
/// piece's), lifted from the chart's plane onto the triangle it lies on; a block with
/// elements becomes a shooting block.
inline void add_chart_elements(const scene_view& scene, std::uint32_t c, const chart_extent& ex,
                               const std::vector<texel_sum>& sums, std::uint32_t b, lightmap_atlas& atlas) {
    lightmap_chart& ch = atlas.charts[c];
    const material& mat = scene.materials[ch.material];
    const bool emits = scene.use_emission && (mat.emission.r > 0.f || mat.emission.g > 0.f || mat.emission.b > 0.f);
    const glm::vec3 emitted = emits ? float(std::numbers::pi) * mat.emission : glm::vec3(0.f);
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
        extents[c] = detail::smallest_bounding_frame(scene, atlas, atlas.charts[c]);

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
        detail::cut_to_element_count(scene, faces, extents, plane_area, options, atlas, sums);

    const std::uint32_t pad = std::uint32_t(options.padding);
    detail::pack_charts_on_shelves(pad, atlas);
    atlas.element_at = image<std::int32_t>(atlas.width, atlas.height, -1);
    for (std::uint32_t c = 0; c < atlas.charts.size(); ++c) {
        detail::add_chart_elements(scene, c, extents[c], sums[c], std::uint32_t(options.block_texels), atlas);
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
        st.curved_charts += atlas.charts[c].planar ? 0 : 1;
    }
    std::nth_element(per_chart.begin(), per_chart.begin() + std::ptrdiff_t(per_chart.size() / 2), per_chart.end());
    st.median_elements_per_chart = per_chart.empty() ? 0 : per_chart[per_chart.size() / 2];
    st.seed_plane_kept = grown.seed_plane_kept;
    st.overlaps_refused = grown.overlaps_refused;
    return atlas;
}

}  // namespace bounce::radiosity
