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
    double coplanar_degrees = 0.05;  ///< largest angle between the normals of one chart's triangles (degrees)
    double coplanar_distance = 1e-5; ///< largest distance of a chart's vertices from its plane,
                                     ///< relative to the scene's bounding-box diagonal

    void validate() const {
        require(elements > 0, "atlas_options.elements", "must be positive");
        require(padding >= 0 && padding <= 64, "atlas_options.padding", "must lie in [0, 64]");
        require(block_texels >= 1 && block_texels <= 256, "atlas_options.block_texels", "must lie in [1, 256]");
        require(coplanar_degrees >= 0 && coplanar_degrees < 90, "atlas_options.coplanar_degrees",
                "must lie in [0, 90)");
        require(coplanar_distance >= 0 && std::isfinite(coplanar_distance), "atlas_options.coplanar_distance",
                "must be finite and non-negative");
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

inline glm::dvec3 to_d(const glm::vec3& v) { return glm::dvec3(v); }

/// Unit normals and areas of a scene's triangles, in double; degenerate triangles have area
/// 0 and normal 0.
struct triangle_faces {
    std::vector<glm::dvec3> normal;
    std::vector<double> area;
};
inline triangle_faces face_normals_and_areas(const scene_view& scene) {
    const std::size_t nt = scene.triangles.size();
    triangle_faces faces{std::vector<glm::dvec3>(nt), std::vector<double>(nt, 0.0)};
    for (std::size_t t = 0; t < nt; ++t) {
        const auto& tri = scene.triangles[t];
        const glm::dvec3 a = to_d(scene.positions[tri.x]), b = to_d(scene.positions[tri.y]), c = to_d(scene.positions[tri.z]);
        const glm::dvec3 cr = glm::cross(b - a, c - a);
        const double len = glm::length(cr);
        faces.area[t] = 0.5 * len;
        faces.normal[t] = len > 0 ? cr / len : glm::dvec3(0);
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

/// Chart `c` grown from triangle `seed` by flood fill over shared edges: a neighbour joins
/// when it has the seed's material, its normal is within cos_tol of the seed's and its
/// vertices lie within dist_tol of the seed's plane (measuring against the seed, not the
/// neighbour, keeps a gently curved surface from drifting into one chart). Appends the
/// chart's triangles, in index order, to atlas.chart_triangles.
inline lightmap_chart grow_chart(const scene_view& scene, const triangle_faces& faces, const edge_adjacency& edges,
                                 std::uint32_t seed, double cos_tol, double dist_tol, lightmap_atlas& atlas) {
    const std::uint32_t c = std::uint32_t(atlas.charts.size());
    lightmap_chart chart;
    chart.material = scene.material_of[seed];
    chart.first_triangle = std::uint32_t(atlas.chart_triangles.size());
    const glm::dvec3 n0 = faces.normal[seed];
    const glm::dvec3 p0 = to_d(scene.positions[scene.triangles[seed].x]);
    const auto joins = [&](std::uint32_t u) {
        if (scene.material_of[u] != chart.material || glm::dot(faces.normal[u], n0) < cos_tol) return false;
        bool in_plane = true;
        for (int m = 0; m < 3; ++m)
            in_plane = in_plane && std::abs(glm::dot(to_d(scene.positions[scene.triangles[u][m]]) - p0, n0)) <= dist_tol;
        return in_plane;
    };
    atlas.chart_of_triangle[seed] = c;
    std::vector<std::uint32_t> stack(1, seed);
    while (!stack.empty()) {
        const std::uint32_t t = stack.back();
        stack.pop_back();
        atlas.chart_triangles.push_back(t);
        const auto& tri = scene.triangles[t];
        for (int k = 0; k < 3; ++k) {
            const auto range = edges.triangles_on(tri[k], tri[(k + 1) % 3]);
            for (auto it = range.first; it != range.second; ++it) {
                const std::uint32_t u = it->second;
                if (atlas.chart_of_triangle[u] != lightmap_atlas::none || !joins(u)) continue;
                atlas.chart_of_triangle[u] = c;
                stack.push_back(u);
            }
        }
    }
    chart.triangle_count = std::uint32_t(atlas.chart_triangles.size()) - chart.first_triangle;
    // Keep the triangles in index order within a chart (deterministic layout).
    std::sort(atlas.chart_triangles.begin() + chart.first_triangle, atlas.chart_triangles.end());
    glm::dvec3 n_sum(0);
    for (std::uint32_t k = 0; k < chart.triangle_count; ++k) {
        const std::uint32_t t = atlas.chart_triangles[chart.first_triangle + k];
        n_sum += faces.area[t] * faces.normal[t];
    }
    chart.normal = glm::vec3(glm::normalize(n_sum));
    return chart;
}

/// Every triangle of positive area in a chart, charts grown from seeds in triangle order.
inline void group_into_charts(const scene_view& scene, const triangle_faces& faces, const atlas_options& options,
                              double diagonal, lightmap_atlas& atlas) {
    const edge_adjacency edges(scene, faces);
    const double cos_tol = std::cos(options.coplanar_degrees * std::numbers::pi / 180.0);
    const double dist_tol = options.coplanar_distance * std::max(diagonal, 1e-30);
    for (std::size_t seed = 0; seed < scene.triangles.size(); ++seed) {
        if (faces.area[seed] <= 0 || atlas.chart_of_triangle[seed] != lightmap_atlas::none) continue;
        atlas.charts.push_back(grow_chart(scene, faces, edges, std::uint32_t(seed), cos_tol, dist_tol, atlas));
    }
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

/// The exact overlap of one texel with its chart's triangles: area and first moment, in
/// texels of the chart's grid.
struct texel_sum {
    double area = 0;
    glm::dvec2 moment{0};
    double piece_area = 0;   ///< the largest one triangle's overlap
    glm::dvec2 piece{0};     ///< its centroid, which lies on it
};

/// Moves each texel's point (moment / area) that lies on none of `triangles` (a non-convex
/// overlap: a floor's border around a column's base, whose centroid lies under the column) to
/// the centroid of its largest one triangle's overlap, which lies on the chart.
inline void place_points_on_chart(std::span<const std::array<glm::dvec2, 3>> triangles, std::uint32_t width,
                                  std::uint32_t height, std::vector<texel_sum>& sums) {
    std::vector<glm::dvec2> point(sums.size());
    for (std::size_t c = 0; c < sums.size(); ++c) point[c] = sums[c].area > 0 ? sums[c].moment / sums[c].area : glm::dvec2(0);
    std::vector<std::uint8_t> on(sums.size(), 0);
    for (const auto& q : triangles) mark_points_on_triangle(q, width, height, point, on);
    for (std::size_t c = 0; c < sums.size(); ++c)
        if (!on[c] && sums[c].piece_area > 0) sums[c].moment = sums[c].piece * sums[c].area;
}

/// A texel is an element when its overlap exceeds 1e-6 of a texel: slivers below carry no
/// measurable power and their centroids are ill-conditioned.
inline bool holds_element(const texel_sum& ts) { return ts.area > 1e-6; }

/// Chart `ch` cut into texels of about h (m): a grid of ceil(extent / h) texels stretched
/// to fit the extent exactly. Sets the chart's size and axes, fills `sums` with each
/// texel's overlap and returns the number of elements.
inline std::size_t cut_chart(const scene_view& scene, const lightmap_atlas& atlas, const chart_extent& ex, double h,
                             lightmap_chart& ch, std::vector<texel_sum>& sums) {
    ch.width = std::uint32_t(std::clamp(std::ceil(ex.eu / h), 1.0, 65536.0));
    ch.height = std::uint32_t(std::clamp(std::ceil(ex.ev / h), 1.0, 65536.0));
    const double su = ex.eu / ch.width, sv = ex.ev / ch.height;
    ch.origin = glm::vec3(ex.origin);
    ch.axis_u = glm::vec3(ex.u * su);
    ch.axis_v = glm::vec3(ex.v * sv);
    sums.assign(std::size_t(ch.width) * ch.height, texel_sum{});
    std::vector<std::array<glm::dvec2, 3>> triangles_in_texels;
    for (std::uint32_t k = 0; k < ch.triangle_count; ++k) {
        const std::uint32_t t = atlas.chart_triangles[ch.first_triangle + k];
        std::array<glm::dvec2, 3> q;
        for (int m = 0; m < 3; ++m) {
            const glm::dvec3 d = to_d(scene.positions[scene.triangles[t][m]]) - ex.origin;
            q[std::size_t(m)] = {glm::dot(d, ex.u) / su, glm::dot(d, ex.v) / sv};
        }
        for_each_cell_overlap(q, ch.width, ch.height, [&](std::size_t cell, double a, glm::dvec2 moment) {
            sums[cell].area += a;
            sums[cell].moment += moment;
            if (a > sums[cell].piece_area) sums[cell].piece_area = a, sums[cell].piece = moment / a;
        });
        triangles_in_texels.push_back(q);
    }
    place_points_on_chart(triangles_in_texels, ch.width, ch.height, sums);
    std::size_t count = 0;
    for (const auto& ts : sums) count += holds_element(ts) ? 1 : 0;
    return count;
}

/// Every chart cut into texels of about h (m); returns the element count.
inline std::size_t cut_charts(const scene_view& scene, const std::vector<chart_extent>& extents, double h,
                              lightmap_atlas& atlas, std::vector<std::vector<texel_sum>>& sums) {
    std::size_t count = 0;
    for (std::size_t c = 0; c < atlas.charts.size(); ++c)
        count += cut_chart(scene, atlas, extents[c], h, atlas.charts[c], sums[c]);
    return count;
}

/// Cuts the charts with the texel size whose element count comes closest to
/// options.elements. The count grows like 1/h^2 plus the charts' boundaries and jumps where
/// a chart's ceil(extent / h) steps: secant steps on h, keeping the closest count seen.
inline void cut_to_element_count(const scene_view& scene, const std::vector<chart_extent>& extents,
                                 double total_area, const atlas_options& options, lightmap_atlas& atlas,
                                 std::vector<std::vector<texel_sum>>& sums) {
    double h = std::sqrt(total_area / double(options.elements)), best_h = h;
    double best_miss = std::numeric_limits<double>::infinity();
    for (int iteration = 0; iteration < 8; ++iteration) {
        const std::size_t count = cut_charts(scene, extents, h, atlas, sums);
        const double miss = std::abs(double(count) - double(options.elements));
        if (miss < best_miss) {
            best_miss = miss;
            best_h = h;
        }
        if (miss <= 0.01 * double(options.elements)) break;
        h *= std::sqrt(double(count) / double(options.elements));
    }
    cut_charts(scene, extents, best_h, atlas, sums);
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
/// that holds_element, at the centroid of its overlap; a block with elements becomes a
/// shooting block.
inline void add_chart_elements(const scene_view& scene, std::uint32_t c, const chart_extent& ex,
                               const std::vector<texel_sum>& sums, std::uint32_t b, lightmap_atlas& atlas) {
    lightmap_chart& ch = atlas.charts[c];
    const material& mat = scene.materials[ch.material];
    const bool emits = scene.use_emission && (mat.emission.r > 0.f || mat.emission.g > 0.f || mat.emission.b > 0.f);
    const glm::vec3 emitted = emits ? float(std::numbers::pi) * mat.emission : glm::vec3(0.f);
    ch.first_element = std::uint32_t(atlas.size());
    const double su = ex.eu / ch.width, sv = ex.ev / ch.height;
    for (std::uint32_t by = 0; by < ch.height; by += b)
        for (std::uint32_t bx = 0; bx < ch.width; bx += b) {
            const std::uint32_t first = std::uint32_t(atlas.size());
            for (std::uint32_t j = by; j < std::min(by + b, ch.height); ++j)
                for (std::uint32_t i = bx; i < std::min(bx + b, ch.width); ++i) {
                    const texel_sum& ts = sums[std::size_t(j) * ch.width + i];
                    if (!holds_element(ts)) continue;
                    const glm::dvec2 centroid = ts.moment / ts.area;
                    atlas.position.push_back(glm::vec3(ex.origin + ex.u * (centroid.x * su) + ex.v * (centroid.y * sv)));
                    atlas.normal.push_back(ch.normal);
                    atlas.area.push_back(float(ts.area * su * sv));
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
    const auto [lo, hi] = scene.bounds();
    const double diagonal = glm::length(detail::to_d(hi) - detail::to_d(lo));
    detail::group_into_charts(scene, faces, options, diagonal, atlas);
    std::vector<detail::chart_extent> extents(atlas.charts.size());
    for (std::size_t c = 0; c < atlas.charts.size(); ++c)
        extents[c] = detail::smallest_bounding_frame(scene, atlas, atlas.charts[c]);

    double total_area = 0;
    for (std::size_t t = 0; t < nt; ++t) total_area += faces.area[t];
    require(total_area > 0, "scene.triangles", "the scene has no triangle of positive area");
    std::vector<std::vector<detail::texel_sum>> sums(atlas.charts.size());
    detail::cut_to_element_count(scene, extents, total_area, options, atlas, sums);

    const std::uint32_t pad = std::uint32_t(options.padding);
    detail::pack_charts_on_shelves(pad, atlas);
    atlas.element_at = image<std::int32_t>(atlas.width, atlas.height, -1);
    for (std::uint32_t c = 0; c < atlas.charts.size(); ++c) {
        detail::add_chart_elements(scene, c, extents[c], sums[c], std::uint32_t(options.block_texels), atlas);
        detail::fill_chart_padding(atlas.charts[c], pad, atlas);
    }
    atlas.block_first.push_back(std::uint32_t(atlas.size()));
    require(atlas.size() > 0, "scene.triangles", "the scene gives no element");
    return atlas;
}

}  // namespace bounce::radiosity
