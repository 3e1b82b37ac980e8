#pragma once
/// \file radiosity/lightmap_atlas_data.hpp
/// The lightmap atlas's data: its options, charts and elements (radiosity/lightmap_atlas.hpp
/// builds it and describes it; include that one).

#include <bounce/errors.hpp>
#include <bounce/image.hpp>
#include <bounce/radiosity/chart_growth.hpp>
#include <bounce/scene_view.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce::inline radiosity {

/// When charts smaller than a texel share one element (chart_clusters.hpp): never; only when
/// the budget is missed by more than 10% without them (a chart per element at least: the
/// conference room's 48,534 charts for 10,000 asked); or whenever a chart fits in a texel.
enum class tiny_chart_clusters { never, when_needed, always };

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
    tiny_chart_clusters clusters = tiny_chart_clusters::when_needed;  ///< chart_clusters.hpp

    void validate() const {
        require(elements > 0, "atlas_options.elements", "must be positive");
        require(padding >= 0 && padding <= 64, "atlas_options.padding", "must lie in [0, 64]");
        require(block_texels >= 1 && block_texels <= 256, "atlas_options.block_texels", "must lie in [1, 256]");
        require(cone_degrees >= 0 && cone_degrees < 90, "atlas_options.cone_degrees", "must lie in [0, 90)");
        require(coplanar_degrees >= 0 && coplanar_degrees < 90, "atlas_options.coplanar_degrees",
                "must lie in [0, 90)");
        require(clusters == tiny_chart_clusters::never || clusters == tiny_chart_clusters::when_needed ||
                    clusters == tiny_chart_clusters::always,
                "atlas_options.clusters", "must be never, when_needed or always");
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
    std::uint32_t clustered_charts = 0;  ///< > 0: a cluster of that many tiny charts, one texel (chart_clusters.hpp)
    bool cluster() const noexcept { return clustered_charts > 0; }
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
