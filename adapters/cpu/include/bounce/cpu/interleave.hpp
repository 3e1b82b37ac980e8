#pragma once
/// \file interleave.hpp
/// The interleaved-sampling passes on the CPU (Segovia et al. 2006 steps 2, 4, 5 and 6):
/// split a buffer into the N x M sub-buffers of a pattern, gather it back, build the
/// discontinuity buffer, and blur with the geometry-aware tent that covers the pattern.
/// Every index comes from the kernels of indirect/interleaved_sampling.hpp, evaluated once per
/// column and once per row (the maps are separable), so a pass is a copy through two small
/// index tables. Results do not depend on the thread count: each output pixel is written
/// by one task, from inputs no task writes.

#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/indirect/options.hpp>
#include <bounce/indirect/interleaved_sampling.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <tbb/parallel_for.h>

namespace bounce::cpu {

/// The split and gather maps of one image size and pattern, one entry per column / row:
/// `split_x[x]` is the split-buffer column of image column x, `gather_x[u]` the image
/// column of split column u and `cell_x[u]` its sub-buffer index i (likewise for rows).
struct interleave_maps {
    interleave_pattern pattern;
    std::size_t width = 0, height = 0;
    std::vector<std::uint32_t> split_x, split_y, gather_x, gather_y, cell_x, cell_y;

    interleave_maps() = default;
    interleave_maps(const interleave_pattern& p, std::size_t w, std::size_t h) : pattern(p), width(w), height(h) {
        p.validate();
        require(w > 0 && h > 0, "width/height", "must be positive");
        require(w < (std::size_t(1) << 24) && h < (std::size_t(1) << 24), "width/height", "must be below 2^24");
        const auto axis = [](std::size_t size, int n, std::vector<std::uint32_t>& split,
                             std::vector<std::uint32_t>& gather, std::vector<std::uint32_t>& cell) {
            split.resize(size);
            gather.resize(size);
            cell.resize(size);
            for (std::size_t x = 0; x < size; ++x) {
                split[x] = std::uint32_t(interleave_split_coordinate<double>(double(x), double(size), double(n)));
                const auto g = interleave_gather_coordinate<double>(double(x), double(size), double(n));
                gather[x] = std::uint32_t(g[0]);
                cell[x] = std::uint32_t(g[1]);
            }
        };
        axis(w, p.n, split_x, gather_x, cell_x);
        axis(h, p.m, split_y, gather_y, cell_y);
    }
    /// Sub-buffer index s = j n + i of split-buffer pixel (u, v).
    int cell(std::size_t u, std::size_t v) const noexcept { return int(cell_y[v]) * pattern.n + int(cell_x[u]); }
    sub_buffer_rect sub_buffer(int i, int j) const { return sub_buffer_of(pattern, i, j, width, height); }
};

namespace detail {
inline void require_size(std::size_t w, std::size_t h, const interleave_maps& maps, const char* name) {
    require(w == maps.width && h == maps.height, name, "size differs from the interleave maps'");
}
}  // namespace detail

/// Copies `image` into `split` so that sub-buffer (i, j) holds pixels (i + a n, j + b m)
/// (Segovia et al. 2006 step 2). One pass row by row: a source row lands in one row of the
/// split buffer, so the CPU has none of the texture-cache trouble that made the paper use
/// two passes on the GPU.
template <class T>
void split_image(image_view<const T> image, image_view<T> split, const interleave_maps& maps) {
    detail::require_size(image.width(), image.height(), maps, "image");
    detail::require_size(split.width(), split.height(), maps, "split");
    tbb::parallel_for(std::size_t(0), maps.height, [&](std::size_t y) {
        const std::size_t v = maps.split_y[y];
        for (std::size_t x = 0; x < maps.width; ++x) split(maps.split_x[x], v) = image(x, y);
    });
}

/// The inverse of split_image (step 4): `image`(x, y) = `split`(split_x[x], split_y[y]).
template <class T>
void gather_image(image_view<const T> split, image_view<T> image, const interleave_maps& maps) {
    detail::require_size(image.width(), image.height(), maps, "image");
    detail::require_size(split.width(), split.height(), maps, "split");
    tbb::parallel_for(std::size_t(0), maps.height, [&](std::size_t y) {
        const std::size_t v = maps.split_y[y];
        for (std::size_t x = 0; x < maps.width; ++x) image(x, y) = split(maps.split_x[x], v);
    });
}

/// split_image on every plane of a G-buffer.
inline void split_gbuffer(const gbuffer_view<float>& gb, const gbuffer_view<float>& split,
                          const interleave_maps& maps) {
    split_image<glm::vec3>(gb.position, split.position, maps);
    split_image<glm::vec3>(gb.normal, split.normal, maps);
    split_image<glm::vec3>(gb.albedo, split.albedo, maps);
    split_image<float>(gb.depth, split.depth, maps);
}

/// The discontinuity buffer (step 5): `edges`(x, y).x is 1 where pixel (x, y) and its right
/// neighbour are on different surfaces (geometry_discontinuity), .y likewise with the pixel
/// below; 0 otherwise. The image border and any pixel that sees no geometry count as edges.
inline void discontinuity_buffer(const gbuffer_view<float>& gb, const discontinuity_params& params,
                                 image_view<glm::vec2> edges) {
    params.validate();
    require(edges.width() == gb.width() && edges.height() == gb.height(), "edges", "size differs from the G-buffer");
    const std::size_t w = gb.width(), h = gb.height();
    const auto edge = [&](std::size_t xa, std::size_t ya, std::size_t xb, std::size_t yb) {
        if (!gb.covered(xa, ya) || !gb.covered(xb, yb)) return 1.f;
        return geometry_discontinuity<float, glm::vec3>(gb.depth(xa, ya), gb.normal(xa, ya), gb.depth(xb, yb),
                                                        gb.normal(xb, yb), params.relative_depth, params.cos_normal);
    };
    tbb::parallel_for(std::size_t(0), h, [&](std::size_t y) {
        for (std::size_t x = 0; x < w; ++x)
            edges(x, y) = glm::vec2(x + 1 < w ? edge(x, y, x + 1, y) : 1.f, y + 1 < h ? edge(x, y, x, y + 1) : 1.f);
    });
}

/// Adds the visibility edges (visibility_discontinuity) to `edges`: .x becomes 1 where
/// pixel (x, y) and its right neighbour see different shares of their senders by more than
/// `sigmas` standard errors, .y likewise with the pixel below. `stats` holds each pixel's
/// (sum, visible sum, sum of squares) of its terms' brightness (cpu::splat_vpls's
/// visibility_stats, gathered back to image order).
inline void add_visibility_edges(image_view<const glm::vec3> stats, float sigmas, image_view<glm::vec2> edges) {
    require(std::isfinite(sigmas) && sigmas >= 0.f, "sigmas", "must be finite and >= 0");
    require(edges.width() == stats.width() && edges.height() == stats.height(), "edges",
            "size differs from the stats");
    const std::size_t w = stats.width(), h = stats.height();
    const auto edge = [&](std::size_t xa, std::size_t ya, std::size_t xb, std::size_t yb) {
        const glm::vec3 a = stats(xa, ya), b = stats(xb, yb);
        return visibility_discontinuity<float>(a.x, a.y, a.z, b.x, b.y, b.z, sigmas);
    };
    tbb::parallel_for(std::size_t(0), h, [&](std::size_t y) {
        for (std::size_t x = 0; x < w; ++x) {
            glm::vec2& e = edges(x, y);
            if (x + 1 < w) e.x = std::max(e.x, edge(x, y, x + 1, y));
            if (y + 1 < h) e.y = std::max(e.y, edge(x, y, x, y + 1));
        }
    });
}

namespace detail {
/// One pass of the tent along x (`Vertical` false) or y, with a compile-time radius R >= n - 1.
template <int R, bool Vertical>
void tent_pass(image_view<const glm::vec3> in, image_view<const glm::vec2> edges, image_view<const float> depth, int n,
               image_view<glm::vec3> out) {
    const std::size_t w = in.width(), h = in.height();
    const std::ptrdiff_t size = std::ptrdiff_t(Vertical ? h : w);
    tbb::parallel_for(std::size_t(0), h, [&](std::size_t y) {
        std::array<glm::vec3, 2 * R + 1> values;
        std::array<float, 2 * R> cuts;
        const auto at = [&](std::size_t x, std::ptrdiff_t t) {
            return Vertical ? std::pair{x, std::size_t(t)} : std::pair{std::size_t(t), y};
        };
        for (std::size_t x = 0; x < w; ++x) {
            if (!(depth(x, y) < std::numeric_limits<float>::infinity())) {
                out(x, y) = in(x, y);
                continue;
            }
            const std::ptrdiff_t along = std::ptrdiff_t(Vertical ? y : x);
            if (along >= R && along + R < size) {
                // Every tap inside the image: no clamping.
                for (int k = 0; k <= 2 * R; ++k) {
                    const auto [tx, ty] = at(x, along - R + k);
                    values[std::size_t(k)] = in(tx, ty);
                    if (k < 2 * R) cuts[std::size_t(k)] = Vertical ? edges(tx, ty).y : edges(tx, ty).x;
                }
            } else {
                for (int k = 0; k <= 2 * R; ++k) {
                    const std::ptrdiff_t t = along - R + k;
                    const bool inside = t >= 0 && t < size;
                    const auto [tx, ty] = at(x, inside ? t : along);
                    values[std::size_t(k)] = in(tx, ty);
                    // Edge between taps k and k + 1: the edge flag of tap k towards +axis;
                    // the image border counts as an edge.
                    if (k < 2 * R)
                        cuts[std::size_t(k)] =
                            inside && t + 1 < size ? (Vertical ? edges(tx, ty).y : edges(tx, ty).x) : 1.f;
                }
            }
            out(x, y) = geometry_aware_tent<R, float, glm::vec3>(values, cuts, float(n));
        }
    });
}

template <int R>
void tent_blur(image_view<const glm::vec3> in, image_view<const glm::vec2> edges, image_view<const float> depth,
               const interleave_pattern& p, image_view<glm::vec3> scratch, image_view<glm::vec3> out) {
    tent_pass<R, false>(in, edges, depth, p.n, scratch);
    tent_pass<R, true>(scratch, edges, depth, p.m, out);
}
}  // namespace detail

/// How many of the pattern's sub-buffers geometry_aware_blur reaches at each pixel with these
/// `edges` (the count its weights are shared among; N M inside a surface, fewer where edges
/// cut the tent short on every side), written to `reached`; pixels that see no geometry
/// (infinite depth, copied by the blur) get N M. `edges` as discontinuity_buffer makes them
/// (a pixel that sees no geometry is cut off on every side). At most 64 sub-buffers a row.
inline void reached_sub_buffers(image_view<const glm::vec2> edges, image_view<const float> depth,
                                const interleave_pattern& p, image_view<float> reached) {
    p.validate();
    require(edges.width() == depth.width() && edges.height() == depth.height() &&
                reached.width() == depth.width() && reached.height() == depth.height(),
            "edges/reached", "size differs from the depth");
    const std::ptrdiff_t w = std::ptrdiff_t(depth.width()), h = std::ptrdiff_t(depth.height());
    // Tap k steps along an axis is reached when no edge lies between it and the centre and k < n.
    const auto span = [](std::ptrdiff_t at, std::ptrdiff_t size, int n, auto&& cut) {
        std::ptrdiff_t lo = 0, hi = 0;
        while (lo + 1 < n && at - lo - 1 >= 0 && !(cut(at - lo - 1) > 0.f)) ++lo;
        while (hi + 1 < n && at + hi + 1 < size && !(cut(at + hi) > 0.f)) ++hi;
        return std::pair{lo, hi};
    };
    // Residues mod n the horizontal pass reaches at each pixel, as a bit mask.
    std::vector<std::uint64_t> row_mask(std::size_t(w * h));
    tbb::parallel_for(std::ptrdiff_t(0), h, [&](std::ptrdiff_t y) {
        for (std::ptrdiff_t x = 0; x < w; ++x) {
            const auto [lo, hi] = span(x, w, p.n, [&](std::ptrdiff_t t) { return edges(std::size_t(t), std::size_t(y)).x; });
            std::uint64_t m = 0;
            for (std::ptrdiff_t t = x - lo; t <= x + hi; ++t) m |= std::uint64_t(1) << std::size_t(t % p.n);
            row_mask[std::size_t(y * w + x)] = m;
        }
    });
    tbb::parallel_for(std::ptrdiff_t(0), h, [&](std::ptrdiff_t y) {
        std::vector<std::uint64_t> by_row(std::size_t(p.m));
        for (std::ptrdiff_t x = 0; x < w; ++x) {
            if (!(depth(std::size_t(x), std::size_t(y)) < std::numeric_limits<float>::infinity())) {
                reached(std::size_t(x), std::size_t(y)) = float(p.cells());
                continue;
            }
            const auto [lo, hi] = span(y, h, p.m, [&](std::ptrdiff_t t) { return edges(std::size_t(x), std::size_t(t)).y; });
            std::fill(by_row.begin(), by_row.end(), 0);
            for (std::ptrdiff_t t = y - lo; t <= y + hi; ++t) by_row[std::size_t(t % p.m)] |= row_mask[std::size_t(t * w + x)];
            int count = 0;
            for (const std::uint64_t m : by_row) count += std::popcount(m);
            reached(std::size_t(x), std::size_t(y)) = float(count);
        }
    });
}

/// The separable geometry-aware blur (step 6): a tent of radius n - 1 along x, then of
/// radius m - 1 along y (interleave_tent_weight), each stopping at the first discontinuity
/// on either side. Inside one surface every sub-buffer of the pattern gets weight 1/(n m),
/// so the result averages the N M sub-buffers' estimates; where an edge cuts the tent short,
/// every sub-buffer still reached gets the same weight (geometry_aware_tent). Pixels that see no geometry are
/// copied. `scratch` holds the horizontal pass; all views are the image's size.
inline void geometry_aware_blur(image_view<const glm::vec3> in, image_view<const glm::vec2> edges,
                                image_view<const float> depth, const interleave_pattern& p,
                                image_view<glm::vec3> scratch, image_view<glm::vec3> out) {
    p.validate();
    require(edges.width() == in.width() && edges.height() == in.height() && depth.width() == in.width() &&
                depth.height() == in.height(),
            "edges/depth", "size differs from the image");
    require(out.width() == in.width() && out.height() == in.height() && scratch.width() == in.width() &&
                scratch.height() == in.height(),
            "out/scratch", "size differs from the image");
    const int reach = std::max(p.n, p.m) - 1;
    if (reach <= 1)
        detail::tent_blur<1>(in, edges, depth, p, scratch, out);
    else if (reach <= 3)
        detail::tent_blur<3>(in, edges, depth, p, scratch, out);
    else if (reach <= 7)
        detail::tent_blur<7>(in, edges, depth, p, scratch, out);
    else if (reach <= 15)
        detail::tent_blur<15>(in, edges, depth, p, scratch, out);
    else if (reach <= 31)
        detail::tent_blur<31>(in, edges, depth, p, scratch, out);
    else
        detail::tent_blur<63>(in, edges, depth, p, scratch, out);
}

}  // namespace bounce::cpu
