#pragma once
/// \file splatting.hpp
/// Irradiance splatting on the CPU (Gautron 2008, Algorithms 1 and 5): splat records onto a splat
/// buffer, scan it for cache misses, normalize and compose.
///
/// The splat buffer holds (sum of w * rho_d/pi * E_k(p) in rgb, sum of w) per pixel as
/// float32, the layout of the GL adapter's RGBA32F texture. Records are binned into
/// screen tiles and each tile adds its records in index order, so every pixel sums the same
/// terms in the same order whatever the thread count, and the same order as splatting the
/// records one by one: results are bitwise reproducible. Each record is evaluated on four
/// pixels of a row at once (cpu::lanes), bitwise what the scalar kernel gives each pixel.

#include <bounce/camera.hpp>
#include <bounce/cpu/lanes.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/splat_bounds.hpp>
#include <bounce/cache/weighting.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bounce::cpu {

/// Parameters shared by every splat of a frame (cache/record.hpp).
using bounce::splat_params;

/// Pixel rectangles and the one a sphere covers (splat_bounds.hpp).
using bounce::pixel_rect;
using bounce::sphere_pixel_rect;

namespace detail {
static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "G-buffer rows are read as packed floats");
static_assert(sizeof(glm::vec4) == 4 * sizeof(float), "splat buffer pixels are read as four packed floats");

/// Squared radius beyond which `Weight` gives a record no weight, widened by a relative
/// 1e-5 so that rounding in |p - pk|^2 never culls a point the weight itself would keep.
template <class Weight>
inline float culling_radius2(const irradiance_record& rec, float a) {
    const float zone = Weight::template influence_radius<float>(rec.radius, a);
    return zone * zone * (1.f + 1e-5f);
}

/// What record `rec` adds at a point, one point at a time (the octree's lookups, and the
/// reference the four-lane splat is tested against): splat_contribution (the kernel) behind
/// a squared-distance rejection, which removes most candidates (other surfaces, the
/// corners of a splat box, the far side of an octree node) before the weight's square roots.
template <class Weight>
inline glm::vec4 contribution(const irradiance_record& rec, const glm::vec3& p, const glm::vec3& n,
                              const glm::vec3& albedo, const splat_params& sp, float cull2) {
    const glm::vec3 d = p - rec.position;
    if (!(glm::dot(d, d) <= cull2)) return glm::vec4(0.f);
    const float inv_r = 1.f / rec.radius;
    const auto c = with_kernel_flags(sp, [&](auto gradients, auto front_test) {
        return splat_contribution<Weight, decltype(gradients)::value, decltype(front_test)::value, float, glm::vec3>(
            p, n, albedo, rec.position, rec.normal, inv_r, sp.a, rec.irradiance, rec.rotation[0], rec.rotation[1],
            rec.rotation[2], rec.translation[0], rec.translation[1], rec.translation[2], sp.max_extrapolation,
            sp.front_tolerance);
    });
    return c[3] > 0.f ? glm::vec4(c[0], c[1], c[2], c[3]) : glm::vec4(0.f);
}

/// Adds record `rec`'s contributions to the pixels of `r`, four pixels of a row at a time:
/// the kernel runs on lanes::f32x4, which computes what the scalar float kernel computes,
/// bit for bit, so each pixel receives exactly the terms `contribution` gives, in the same
/// order. Lanes past the row's end repeat its last pixel and are masked off.
template <class Weight, bool Gradients, bool FrontTest>
inline void splat_into_lanes(const gbuffer_view<float>& gb, const irradiance_record& rec, const splat_params& sp,
                             const pixel_rect& r, image_view<glm::vec4> out) {
    using namespace lanes;
    const f32x4 cull2(culling_radius2<Weight>(rec, sp.a)), inv_r(1.f / rec.radius), a(sp.a),
        max_extrapolation(sp.max_extrapolation), front_tolerance(sp.front_tolerance);
    const vec3x4 pk = vec3x4::broadcast(rec.position), nk = vec3x4::broadcast(rec.normal),
                 e = vec3x4::broadcast(rec.irradiance);
    const vec3x4 rot_r = vec3x4::broadcast(rec.rotation[0]), rot_g = vec3x4::broadcast(rec.rotation[1]),
                 rot_b = vec3x4::broadcast(rec.rotation[2]), tr_r = vec3x4::broadcast(rec.translation[0]),
                 tr_g = vec3x4::broadcast(rec.translation[1]), tr_b = vec3x4::broadcast(rec.translation[2]);
    for (int y = r.y0; y <= r.y1; ++y) {
        const std::size_t yy = std::size_t(y);
        for (int x = r.x0; x <= r.x1; x += 4) {
            // Four pixels of the row are contiguous in every G-buffer plane: load them
            // packed; the row's last group repeats its last pixel in the spare lanes.
            const bool full = x + 3 <= r.x1;
            std::size_t xs[4];
            mask4 valid{};
            if (full) {
                for (int i = 0; i < 4; ++i) xs[i] = std::size_t(x + i);
                valid = f32x4::load(&gb.depth(xs[0], yy)) < f32x4(std::numeric_limits<float>::infinity());
            } else {
                for (int i = 0; i < 4; ++i) {
                    xs[i] = std::size_t(std::min(x + i, r.x1));
                    valid.bits[i] = x + i <= r.x1 && gb.covered(xs[i], yy) ? -1 : 0;
                }
            }
            if (!valid.any()) continue;
            const auto load = [&](const image_view<glm::vec3>& plane) {
                return full ? vec3x4::load_packed(&plane(xs[0], yy).x)
                            : vec3x4::gather(plane(xs[0], yy), plane(xs[1], yy), plane(xs[2], yy), plane(xs[3], yy));
            };
            const vec3x4 p = load(gb.position);
            const vec3x4 d = p - pk;
            const mask4 inside = valid && dot(d, d) <= cull2;
            if (!inside.any()) continue;
            const vec3x4 n = load(gb.normal);
            const vec3x4 albedo = load(gb.albedo);
            const auto c = splat_contribution<Weight, Gradients, FrontTest, f32x4, vec3x4>(
                p, n, albedo, pk, nk, inv_r, a, e, rot_r, rot_g, rot_b, tr_r, tr_g, tr_b, max_extrapolation,
                front_tolerance);
            const mask4 keep = inside && c[3] > f32x4(0.f);
            if (!keep.any()) continue;
            const auto pixels = transpose(c[0], c[1], c[2], c[3]);  // (r, g, b, w) of each lane
            for (int i = 0; i < 4; ++i)
                if (keep[i]) {
                    glm::vec4& o = out(xs[i], yy);
                    (f32x4::load(&o.x) + pixels[i]).store(&o.x);
                }
        }
    }
}

template <class Weight>
inline void splat_into(const gbuffer_view<float>& gb, const irradiance_record& rec, const splat_params& sp,
                       const pixel_rect& r, image_view<glm::vec4> out) {
    with_kernel_flags(sp, [&](auto gradients, auto front_test) {
        splat_into_lanes<Weight, decltype(gradients)::value, decltype(front_test)::value>(gb, rec, sp, r, out);
    });
}
}  // namespace detail

/// Splats one record (Gautron 2008, Algorithm 1) onto `out`, sequentially. Used by the cache-miss
/// scan, where each new record must be visible to the next pixel at once. Returns the
/// pixel rectangle it touched (empty when the zone is off screen).
template <class Weight>
pixel_rect splat_record(const gbuffer_view<float>& gb, const camera& cam, const irradiance_record& rec,
                        const splat_params& sp, image_view<glm::vec4> out) {
    const pixel_rect r = sphere_pixel_rect(cam, cam.view_matrix(), rec.position,
                                           Weight::template influence_radius<float>(rec.radius, sp.a), gb.width(),
                                           gb.height());
    if (!r.empty()) detail::splat_into<Weight>(gb, rec, sp, r, out);
    return r;
}

/// Splats every record onto `out` (added to what it holds) in parallel over screen tiles.
/// `out` must be the G-buffer's size. Throws parameter_error on bad parameters or sizes.
template <class Weight>
void splat_records(const gbuffer_view<float>& gb, const camera& cam, std::span<const irradiance_record> records,
                   const splat_params& sp, image_view<glm::vec4> out, int tile = 32) {
    sp.validate();
    require(out.width() == gb.width() && out.height() == gb.height(), "out", "splat buffer and G-buffer sizes differ");
    require(tile > 0, "tile", "must be positive");
    if (gb.width() == 0 || gb.height() == 0 || records.empty()) return;
    const int tw = int((gb.width() + tile - 1) / tile), th = int((gb.height() + tile - 1) / tile);
    const glm::mat4 view = cam.view_matrix();

    std::vector<pixel_rect> rects(records.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, records.size()), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i)
            rects[i] = sphere_pixel_rect(cam, view, records[i].position,
                                         Weight::template influence_radius<float>(records[i].radius, sp.a), gb.width(),
                                         gb.height());
    });
    // Bin in record order: each tile's list is ascending, which fixes the summation order.
    std::vector<std::vector<std::uint32_t>> bins(std::size_t(tw) * th);
    for (std::size_t i = 0; i < records.size(); ++i) {
        const auto& r = rects[i];
        if (r.empty()) continue;
        for (int ty = r.y0 / tile; ty <= r.y1 / tile; ++ty)
            for (int tx = r.x0 / tile; tx <= r.x1 / tile; ++tx) bins[std::size_t(ty) * tw + tx].push_back(std::uint32_t(i));
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bins.size()), [&](const auto& range) {
        for (std::size_t t = range.begin(); t != range.end(); ++t) {
            const int tx = int(t % std::size_t(tw)), ty = int(t / std::size_t(tw));
            const pixel_rect tile_rect{tx * tile, ty * tile, std::min(int(gb.width()), (tx + 1) * tile) - 1,
                                       std::min(int(gb.height()), (ty + 1) * tile) - 1};
            for (std::uint32_t i : bins[t]) {
                const auto& r = rects[i];
                const pixel_rect clipped{std::max(r.x0, tile_rect.x0), std::max(r.y0, tile_rect.y0),
                                         std::min(r.x1, tile_rect.x1), std::min(r.y1, tile_rect.y1)};
                if (!clipped.empty()) detail::splat_into<Weight>(gb, records[i], sp, clipped, out);
            }
        }
    });
}

/// A scan order that visits a coarse grid first: pixels whose x and y are multiples of
/// `coarsest` (a power of two), then of coarsest/2, ..., then every pixel, each level row by
/// row. With a record budget (progressive mode) the first records spread over the whole
/// image, each covering its zone at once, instead of filling the top rows and leaving the
/// rest black. A permutation of 0 .. width*height-1 (indices y * width + x).
inline std::vector<std::uint32_t> coarse_to_fine_order(std::size_t width, std::size_t height, std::size_t coarsest = 32) {
    require(coarsest >= 1 && (coarsest & (coarsest - 1)) == 0, "coarsest", "must be a power of two");
    require(width * height <= std::size_t(UINT32_MAX), "width/height", "more pixels than 32-bit indices hold");
    std::vector<std::uint32_t> order;
    order.reserve(width * height);
    for (std::size_t s = coarsest; s >= 1; s /= 2)
        for (std::size_t y = 0; y < height; y += s)
            for (std::size_t x = 0; x < width; x += s)
                // On this level's grid but not on the coarser one (listed already).
                if (s == coarsest || x % (2 * s) != 0 || y % (2 * s) != 0) order.push_back(std::uint32_t(y * width + x));
    return order;
}

/// The cache-miss scan (Gautron 2008, Algorithm 5, step 4): visits covered pixels in `order` (row
/// by row when empty; any permutation of pixel indices y * width + x otherwise), and where
/// the accumulated weight is below `min_weight` asks `create(x, y)` for a record
/// (std::optional<irradiance_record>; nullopt skips the pixel), appends it to `records` and
/// splats it at once so later pixels see it. Stops after `max_new` records (progressive
/// mode). Returns the number of records created.
/// Gautron 2008 tests the weight sum against a itself (Eq. 8.8); pass `min_weight = a` for that.
template <class Weight, class Create>
std::size_t scan_cache_misses(const gbuffer_view<float>& gb, const camera& cam, const splat_params& sp,
                              float min_weight, Create&& create, std::vector<irradiance_record>& records,
                              image_view<glm::vec4> splat, std::span<const std::uint32_t> order = {},
                              std::size_t max_new = std::size_t(-1)) {
    sp.validate();
    require(std::isfinite(min_weight) && min_weight > 0.f, "min_weight", "must be a positive number");
    require(splat.width() == gb.width() && splat.height() == gb.height(), "splat", "splat buffer and G-buffer sizes differ");
    const std::size_t w = gb.width(), n = w * gb.height();
    require(order.empty() || order.size() == n, "order", "must list every pixel once");
    std::size_t created = 0;
    for (std::size_t i = 0; i < n && created < max_new; ++i) {
        const std::size_t idx = order.empty() ? i : order[i];
        require(idx < n, "order", "pixel index out of range");
        const std::size_t x = idx % w, y = idx / w;
        if (!gb.covered(x, y) || splat(x, y).w >= min_weight) continue;
        std::optional<irradiance_record> rec = create(x, y);
        if (!rec) continue;
        records.push_back(*rec);
        splat_record<Weight>(gb, cam, records.back(), sp, splat);
        ++created;
    }
    return created;
}

namespace detail {
/// f(x, y) for every pixel of a width x height image, rows in parallel.
template <class F>
void for_each_pixel(std::size_t width, std::size_t height, F&& f) {
    tbb::parallel_for(std::size_t(0), height, [&](std::size_t y) {
        for (std::size_t x = 0; x < width; ++x) f(x, y);
    });
}
}  // namespace detail

/// Normalization (Gautron 2008, Algorithm 5, last loop): indirect radiance = sum / weight, 0 where
/// no record reached the pixel.
inline void normalize_splats(image_view<const glm::vec4> splat, image_view<glm::vec3> indirect) {
    require(splat.width() == indirect.width() && splat.height() == indirect.height(), "indirect",
            "size differs from the splat buffer");
    detail::for_each_pixel(splat.width(), splat.height(), [&](std::size_t x, std::size_t y) {
        const glm::vec4 s = splat(x, y);
        indirect(x, y) = normalized_splat<float, glm::vec3>(glm::vec3(s), s.w);
    });
}

/// Normalization with hole filling (progressive display; see hole_filled_splat): `wide`
/// holds the same records splatted with a wider a.
inline void normalize_splats(image_view<const glm::vec4> splat, image_view<const glm::vec4> wide, float lambda,
                             image_view<glm::vec3> indirect) {
    require(splat.width() == indirect.width() && splat.height() == indirect.height() && wide.width() == splat.width() &&
                wide.height() == splat.height(),
            "indirect", "size differs from the splat buffer");
    require(std::isfinite(lambda) && lambda > 0.f, "lambda", "must be a positive number");
    detail::for_each_pixel(splat.width(), splat.height(), [&](std::size_t x, std::size_t y) {
        const glm::vec4 s = splat(x, y), w = wide(x, y);
        indirect(x, y) = hole_filled_splat<float, glm::vec3>(glm::vec3(s), s.w, glm::vec3(w), w.w, lambda);
    });
}

/// Final image = direct + indirect radiance.
inline void compose(image_view<const glm::vec3> direct, image_view<const glm::vec3> indirect, image_view<glm::vec3> out) {
    require(direct.width() == out.width() && indirect.width() == out.width() && direct.height() == out.height() &&
                indirect.height() == out.height(),
            "out", "direct, indirect and output sizes differ");
    detail::for_each_pixel(out.width(), out.height(),
                           [&](std::size_t x, std::size_t y) { out(x, y) = direct(x, y) + indirect(x, y); });
}

}  // namespace bounce::cpu
