#pragma once
/// \file radiosity/subdivision.hpp
/// Adaptive subdivision of radiosity elements (Coombe and Harris 2005, section 39.3; after
/// Heckbert 1990 and Vedel and Puech 1991): every block of the lightmap atlas is the root of a
/// quadtree whose leaves are blocks of the same texel grid (the chapter's 16 x 16 leaf
/// textures: block_texels = 16), and a leaf whose radiosity is not smooth splits into four
/// children with texels half as wide, down to a maximum level.
///
/// The test (radiosity_second_difference): a texel is flagged where the second difference
/// |B(i-1) - 2 B(i) + B(i+1)| of the radiosity along a row or a column of its leaf exceeds
/// `threshold` times the leaf's mean radiosity. Using a second difference, i.e. a change of
/// gradient, rather than the gradient itself is the chapter's point ("using the gradient
/// instead of the value avoids oversubdividing in areas where linear interpolation will
/// adequately represent the function"): a linear ramp flags nothing, a shadow boundary does.
/// A leaf splits when more than `min_texels` of its texels are flagged (the chapter counts
/// them with an occlusion query).
///
/// Splitting is conservative: the children's elements are the exact overlaps of their texels
/// with the chart (as radiosity/lightmap_atlas.hpp computes them), scaled so that they add up to their
/// parent element's area exactly, and they inherit the parent's radiosity and unshot
/// radiosity (both per unit area), so no power is created or lost. Detail appears in what is
/// shot after the split.

#include <bounce/errors.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/scene_view.hpp>
#include <bounce/vocabulary.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce::inline radiosity {

/// When to split a leaf.
struct subdivision_options {
    double threshold = 0.25;  ///< flag a texel where |second difference| > threshold * the leaf's mean radiosity (typical: 0.1-0.5)
    int min_texels = 2;       ///< split a leaf with more flagged texels than this (typical: 1-8)
    int max_level = 2;        ///< deepest level (0 = the base blocks; typical: 2-4)

    void validate() const {
        require(threshold > 0 && std::isfinite(threshold), "subdivision_options.threshold", "must be positive");
        require(min_texels >= 0, "subdivision_options.min_texels", "must be non-negative");
        require(max_level >= 0 && max_level <= 8, "subdivision_options.max_level", "must lie in [0, 8]");
    }
};

/// 1 where the second difference of three neighbouring radiosities (W/m^2, one channel or a
/// channel sum) exceeds `limit` (W/m^2), else 0: the per-texel test of a subdivision pass, as a
/// kernel a GPU pass can run over a leaf texture.
template <real T>
T radiosity_second_difference(T previous, T centre, T next, T limit) {
    return select(abs(previous - T(2) * centre + next) > limit, T(1), T(0));
}

}  // namespace bounce::radiosity

namespace bounce::detail {

/// Exact overlap (area in base texels, centroid in chart texel coordinates) of each texel of
/// the grid `grid` over the rectangle `rect` (chart texel coordinates) with chart `c`'s
/// triangles, in double.
struct grid_overlap {
    double area = 0;       ///< on the chart's plane
    double world = 0;      ///< on the surface (a curved chart's triangles tilt from its plane)
    glm::dvec2 moment{0};  ///< of the surface area
};
inline std::vector<grid_overlap> grid_overlaps(const scene_view& scene, const lightmap_atlas& atlas, std::uint32_t c,
                                               glm::dvec4 rect, glm::uvec2 grid) {
    const lightmap_chart& ch = atlas.charts[c];
    const glm::dvec3 origin(ch.origin), au(ch.axis_u), av(ch.axis_v);
    const double uu = glm::dot(au, au), vv = glm::dot(av, av);
    const glm::dvec2 cell(rect.z / grid.x, rect.w / grid.y);
    std::vector<grid_overlap> out(std::size_t(grid.x) * grid.y);
    for (std::uint32_t k = 0; k < ch.triangle_count; ++k) {
        const std::uint32_t t = atlas.chart_triangles[ch.first_triangle + k];
        std::array<glm::dvec2, 3> q;
        for (int m = 0; m < 3; ++m) {
            const glm::dvec3 d = glm::dvec3(scene.positions[scene.triangles[t][m]]) - origin;
            q[std::size_t(m)] = (glm::dvec2(glm::dot(d, au) / uu, glm::dot(d, av) / vv) - glm::dvec2(rect)) / cell;
        }
        const glm::dvec3 a0(scene.positions[scene.triangles[t].x]), a1(scene.positions[scene.triangles[t].y]),
            a2(scene.positions[scene.triangles[t].z]);
        const double w = ch.planar ? 1.0
                                   : 1.0 / std::max(glm::dot(glm::normalize(glm::cross(a1 - a0, a2 - a0)),
                                                             glm::dvec3(ch.normal)), 1e-6);
        for_each_cell_overlap(q, grid.x, grid.y, [&](std::size_t cell, double a, glm::dvec2 moment) {
            out[cell].area += a;
            out[cell].world += a * w;
            out[cell].moment += moment * w;
        });
    }
    // To base texels: areas scale by the cell's area, centroids map back to chart coordinates.
    for (grid_overlap& o : out) {
        const double scale = cell.x * cell.y;
        o.moment = (o.moment * cell + o.world * glm::dvec2(rect)) * scale;
        o.area *= scale;
        o.world *= scale;
    }
    return out;
}

}  // namespace bounce::detail

namespace bounce::inline radiosity {

/// A refined atlas and, for each of its elements, the element of the old atlas it came from.
struct atlas_refinement {
    lightmap_atlas atlas;
    std::vector<std::uint32_t> parent;
};

}  // namespace bounce::radiosity

namespace bounce::detail {

/// Appends element e of `atlas` to r as it is, its own parent.
inline void keep_element(const lightmap_atlas& atlas, std::uint32_t e, atlas_refinement& r) {
    lightmap_atlas& out = r.atlas;
    out.position.push_back(atlas.position[e]);
    out.normal.push_back(atlas.normal[e]);
    out.area.push_back(atlas.area[e]);
    out.albedo.push_back(atlas.albedo[e]);
    out.emission.push_back(atlas.emission[e]);
    out.chart.push_back(atlas.chart[e]);
    out.texel.push_back(atlas.texel[e]);
    r.parent.push_back(e);
}

/// Appends a block of level `level` to out's block lists, starting at out's next element.
inline void open_block(lightmap_atlas& out, glm::vec4 rect, glm::uvec2 grid, std::uint8_t level) {
    out.block_first.push_back(std::uint32_t(out.size()));
    out.block_rect.push_back(rect);
    out.block_grid.push_back(grid);
    out.block_level.push_back(level);
}

/// For each cell of block k's grid, the element whose centroid lies in it (-1: none).
inline std::vector<std::int64_t> cell_owners(const lightmap_atlas& atlas, std::size_t k) {
    const std::uint32_t e0 = atlas.block_first[k], e1 = atlas.block_first[k + 1];
    const glm::vec4 rect = atlas.block_rect[k];
    const glm::uvec2 grid = atlas.block_grid[k];
    const lightmap_chart& ch = atlas.charts[atlas.chart[e0]];
    const glm::dvec3 origin(ch.origin), au(ch.axis_u), av(ch.axis_v);
    const glm::dvec2 cell(double(rect.z) / grid.x, double(rect.w) / grid.y);
    std::vector<std::int64_t> owner(std::size_t(grid.x) * grid.y, -1);
    for (std::uint32_t e = e0; e < e1; ++e) {
        const glm::dvec3 d = glm::dvec3(atlas.position[e]) - origin;
        const glm::dvec2 chart_coords(glm::dot(d, au) / glm::dot(au, au), glm::dot(d, av) / glm::dot(av, av));
        const glm::dvec2 g = (chart_coords - glm::dvec2(rect.x, rect.y)) / cell;
        const glm::uvec2 c(std::clamp(int(std::floor(g.x)), 0, int(grid.x) - 1),
                           std::clamp(int(std::floor(g.y)), 0, int(grid.y) - 1));
        owner[std::size_t(c.y) * grid.x + c.x] = e;
    }
    return owner;
}

/// Appends to r the elements of quadrant (qx, qy) of block k as a block of the next level:
/// the exact overlaps of its grid's texels with the chart, each with the parent element
/// whose cell it lies in (`owner`, from cell_owners).
inline void add_quadrant(const scene_view& scene, const lightmap_atlas& atlas, std::size_t k, int qx, int qy,
                         const std::vector<std::int64_t>& owner, atlas_refinement& r) {
    lightmap_atlas& out = r.atlas;
    const std::uint32_t e0 = atlas.block_first[k];
    const glm::vec4 rect = atlas.block_rect[k];
    const glm::uvec2 grid = atlas.block_grid[k];
    const std::uint32_t c = atlas.chart[e0];
    const lightmap_chart& ch = atlas.charts[c];
    const glm::dvec3 au(ch.axis_u), av(ch.axis_v);
    const double texel_area = glm::length(glm::cross(au, av));  // m^2 per base texel (on the chart's plane)
    const glm::dvec4 child(rect.x + qx * rect.z / 2.0, rect.y + qy * rect.w / 2.0, rect.z / 2.0, rect.w / 2.0);
    const auto overlaps = grid_overlaps(scene, atlas, c, child, grid);
    const std::uint32_t first = std::uint32_t(out.size());
    const double cell_area = child.z / grid.x * child.w / grid.y;
    for (std::size_t idx = 0; idx < overlaps.size(); ++idx) {
        const auto& o = overlaps[idx];
        if (!(o.area > 1e-6 * cell_area)) continue;
        const glm::dvec2 centroid = o.moment / o.world;
        // The parent cell, exactly: child cell (i, j) of quadrant (qx, qy) spans half a
        // parent cell starting at ((qx gx + i) / 2, (qy gy + j) / 2) parent cells.
        const std::size_t i = idx % grid.x, j = idx / grid.x;
        const std::size_t pi = (std::size_t(qx) * grid.x + i) / 2, pj = (std::size_t(qy) * grid.y + j) / 2;
        const std::int64_t p = owner[pj * grid.x + pi];
        // A child whose parent cell held only a dropped sliver takes the block's
        // first element as parent (its radiosity is the nearest estimate there is).
        const std::uint32_t parent = p >= 0 ? std::uint32_t(p) : e0;
        const auto [point, normal] = chart_surface_point(scene, atlas, c, centroid);
        out.position.push_back(point);
        out.normal.push_back(ch.planar ? atlas.normal[e0] : normal);
        out.area.push_back(float(o.world * texel_area));
        out.albedo.push_back(atlas.albedo[e0]);
        out.emission.push_back(atlas.emission[e0]);
        out.chart.push_back(c);
        out.texel.push_back(atlas.texel[parent]);  // a child lies in its parent's base texel
        r.parent.push_back(parent);
    }
    if (out.size() > first) {
        out.block_first.push_back(first);
        out.block_rect.emplace_back(child);
        out.block_grid.push_back(grid);
        out.block_level.push_back(std::uint8_t(atlas.block_level[k] + 1));
    }
}

/// Rescales the areas of the children of block k (r's elements from first_new on) so that
/// the children of one parent add up to its area exactly. A parent none of whose children
/// was kept (possible only for a sliver at a cell's edge, by rounding) stays as it is, in
/// the last child block, so no power is lost.
inline void conserve_parent_areas(const lightmap_atlas& atlas, std::size_t k, std::size_t first_new,
                                  atlas_refinement& r) {
    lightmap_atlas& out = r.atlas;
    const std::uint32_t e0 = atlas.block_first[k], e1 = atlas.block_first[k + 1];
    std::vector<double> child_area(e1 - e0, 0.0);
    for (std::size_t i = first_new; i < out.size(); ++i) child_area[r.parent[i] - e0] += out.area[i];
    for (std::uint32_t e = e0; e < e1; ++e)
        if (child_area[e - e0] == 0) {
            if (out.size() == first_new)
                open_block(out, atlas.block_rect[k], atlas.block_grid[k], std::uint8_t(atlas.block_level[k] + 1));
            keep_element(atlas, e, r);
            child_area[e - e0] = atlas.area[e];
        }
    for (std::size_t i = first_new; i < out.size(); ++i) {
        const double sum = child_area[r.parent[i] - e0];
        if (sum > 0) out.area[i] = float(double(out.area[i]) * double(atlas.area[r.parent[i]]) / sum);
    }
}

/// Block k of `atlas` split into its four quadrants, appended to r.
inline void split_block(const scene_view& scene, const lightmap_atlas& atlas, std::size_t k, atlas_refinement& r) {
    const std::vector<std::int64_t> owner = cell_owners(atlas, k);
    const std::size_t first_new = r.atlas.size();
    for (int qy = 0; qy < 2; ++qy)
        for (int qx = 0; qx < 2; ++qx) add_quadrant(scene, atlas, k, qx, qy, owner, r);
    conserve_parent_areas(atlas, k, first_new, r);
}

/// r's chart ranges and texel map: each atlas texel points to the first child of its old
/// element (or, if it has none, to its chart's first element).
inline void map_texels_to_children(const lightmap_atlas& atlas, atlas_refinement& r) {
    lightmap_atlas& out = r.atlas;
    std::vector<std::int64_t> first_child(atlas.size(), -1);
    for (std::size_t i = out.size(); i-- > 0;) first_child[r.parent[i]] = std::int64_t(i);
    for (std::size_t c = 0; c < out.charts.size(); ++c) out.charts[c].element_count = 0;
    for (std::size_t i = out.size(); i-- > 0;) {
        lightmap_chart& ch = out.charts[out.chart[i]];
        ch.first_element = std::uint32_t(i);
        ++ch.element_count;
    }
    out.element_at = atlas.element_at;
    for (std::uint32_t y = 0; y < out.height; ++y)
        for (std::uint32_t x = 0; x < out.width; ++x) {
            const std::int32_t e = atlas.element_at(x, y);
            if (e < 0) continue;
            const std::int64_t child = first_child[std::size_t(e)];
            out.element_at(x, y) = std::int32_t(child >= 0 ? child : std::int64_t(out.charts[atlas.chart[std::size_t(e)]].first_element));
        }
}

}  // namespace bounce::detail

namespace bounce::inline radiosity {

/// Splits the blocks `split` (indices into atlas's blocks, any order, each at most once) of
/// `atlas` (built from `scene`) into four children each, keeps the others, and returns the
/// new atlas with each element's parent. Charts, triangles and the atlas layout are unchanged;
/// a child element's `texel` is the base texel it lies in. Throws parameter_error on a block
/// index out of range or a scene the atlas was not built from.
inline atlas_refinement refine_lightmap_atlas(const scene_view& scene, const lightmap_atlas& atlas,
                                              std::span<const std::uint32_t> split) {
    require(atlas.chart_of_triangle.size() == scene.triangles.size(), "atlas",
            "was not built from this scene (triangle counts differ)");
    std::vector<char> splits(atlas.blocks(), 0);
    for (const std::uint32_t k : split) {
        require(k < atlas.blocks(), "split", "block index out of range");
        if (atlas.charts[atlas.chart[atlas.block_first[k]]].cluster())
            throw parameter_error("split", "block " + std::to_string(k) +
                                               " is a cluster of tiny charts (atlas_options::clusters): one texel, not split");
        splits[k] = 1;
    }
    atlas_refinement r;
    lightmap_atlas& out = r.atlas;
    out.width = atlas.width;
    out.height = atlas.height;
    out.charts = atlas.charts;
    out.chart_triangles = atlas.chart_triangles;
    out.chart_of_triangle = atlas.chart_of_triangle;
    out.block_texels = atlas.block_texels;
    for (std::size_t k = 0; k < atlas.blocks(); ++k) {
        if (splits[k]) {
            detail::split_block(scene, atlas, k, r);
            continue;
        }
        detail::open_block(out, atlas.block_rect[k], atlas.block_grid[k], atlas.block_level[k]);
        for (std::uint32_t e = atlas.block_first[k]; e < atlas.block_first[k + 1]; ++e) detail::keep_element(atlas, e, r);
    }
    out.block_first.push_back(std::uint32_t(out.size()));
    detail::map_texels_to_children(atlas, r);
    return r;
}

/// The leaves (blocks) of `atlas` to split given the radiosity `radiosity` (one per element,
/// W/m^2 per channel), by the test in the file comment. Leaves at max_level are never split.
template <class Vec3>
std::vector<std::uint32_t> blocks_to_subdivide(const lightmap_atlas& atlas, std::span<const Vec3> radiosity,
                                               const subdivision_options& options) {
    options.validate();
    require(radiosity.size() == atlas.size(), "radiosity", "needs one value per element");
    std::vector<std::uint32_t> out;
    std::vector<std::int64_t> cell;
    for (std::size_t k = 0; k < atlas.blocks(); ++k) {
        const std::uint32_t e0 = atlas.block_first[k], e1 = atlas.block_first[k + 1];
        if (atlas.block_level[k] >= options.max_level || atlas.charts[atlas.chart[e0]].cluster()) continue;
        const glm::vec4 rect = atlas.block_rect[k];
        const glm::uvec2 grid = atlas.block_grid[k];
        const lightmap_chart& ch = atlas.charts[atlas.chart[e0]];
        const glm::vec3 au = ch.axis_u, av = ch.axis_v;
        cell.assign(std::size_t(grid.x) * grid.y, -1);
        double mean = 0, area = 0;
        for (std::uint32_t e = e0; e < e1; ++e) {
            const glm::vec3 d = atlas.position[e] - ch.origin;
            const glm::vec2 g((glm::dot(d, au) / glm::dot(au, au) - rect.x) / (rect.z / float(grid.x)),
                              (glm::dot(d, av) / glm::dot(av, av) - rect.y) / (rect.w / float(grid.y)));
            const int i = std::clamp(int(std::floor(g.x)), 0, int(grid.x) - 1);
            const int j = std::clamp(int(std::floor(g.y)), 0, int(grid.y) - 1);
            cell[std::size_t(j) * grid.x + std::size_t(i)] = e;
            const double b = double(radiosity[e].x) + double(radiosity[e].y) + double(radiosity[e].z);
            mean += b * double(atlas.area[e]);
            area += double(atlas.area[e]);
        }
        mean /= area;
        const float limit = float(options.threshold * mean);
        const auto value = [&](int i, int j) {
            const std::int64_t e = cell[std::size_t(j) * grid.x + std::size_t(i)];
            return e < 0 ? -1.f : float(radiosity[std::size_t(e)].x + radiosity[std::size_t(e)].y + radiosity[std::size_t(e)].z);
        };
        int flagged = 0;
        for (int j = 0; j < int(grid.y); ++j)
            for (int i = 0; i < int(grid.x); ++i) {
                const float b = value(i, j);
                if (b < 0) continue;
                float flag = 0;
                if (i > 0 && i + 1 < int(grid.x) && value(i - 1, j) >= 0 && value(i + 1, j) >= 0)
                    flag = max(flag, radiosity_second_difference<float>(value(i - 1, j), b, value(i + 1, j), limit));
                if (j > 0 && j + 1 < int(grid.y) && value(i, j - 1) >= 0 && value(i, j + 1) >= 0)
                    flag = max(flag, radiosity_second_difference<float>(value(i, j - 1), b, value(i, j + 1), limit));
                flagged += flag > 0 ? 1 : 0;
            }
        if (flagged > options.min_texels) out.push_back(std::uint32_t(k));
    }
    return out;
}

}  // namespace bounce::radiosity
