#pragma once
/// \file rsm_gather.hpp
/// The RSM gather on the CPU (Dachsbacher and Stamminger 2005, section 3.2): every pixel
/// sums the irradiance of the map texels a fixed disc pattern of samples picks around the
/// pixel's own texel (indirect/rsm.hpp's rsm_disc_sample and pixel_light_irradiance); optionally at
/// a lower resolution with the geometry-aware upsampling and full-resolution fallback of
/// DS05 section 3.3.
///
/// Interleaved, the pixels of sub-buffer s use only the samples dealt to s, with their
/// weights multiplied by N M (indirect/interleaved_sampling.hpp): a pixel of a split G-buffer reads
/// one contiguous run of the (reordered) pattern, so an 8 x 8 pattern does 1/64 of the
/// work per pixel. The pattern (rsm_disc_pattern, grouped_pattern) and the parameter
/// structs (pixel_light_params, upsample_params) are the core's (indirect/rsm_sampling.hpp,
/// indirect/options.hpp), shared with the GL backend. Each pixel is computed by one task
/// in a fixed order: results do not depend on the thread count.

#include <bounce/camera.hpp>
#include <bounce/cpu/interleave.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/indirect/clamp_compensation.hpp>
#include <bounce/indirect/options.hpp>
#include <bounce/indirect/rsm.hpp>
#include <bounce/indirect/rsm_sampling.hpp>
#include <bounce/indirect/visibility.hpp>
#include <bounce/indirect/vpl_sampling.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace bounce::cpu {

/// The clamp's compensation of a gather (indirect/clamp_compensation.hpp): `grid` cosine rays
/// per receiver of length sqrt(min_distance2) asked of `query`; each ray's first surface (the
/// gather with visibility by rays) or, with `every_surface` (the gather without visibility),
/// every surface it crosses.
struct gather_compensation {
    const near_field_query* query = nullptr;
    compensation_grid grid{16};
    float min_distance2 = 0.f;
    std::uint64_t seed = 1;
    bool every_surface = false;
    bool active() const noexcept { return query != nullptr && min_distance2 > 0.f; }
};

/// What a gather's compensation added: irradiance summed over pixels and channels, the
/// frame's total likewise, and the rays traced.
struct compensation_totals {
    double added = 0, total = 0;
    std::size_t rays = 0;
    double share() const noexcept { return total > 0 ? added / total : 0.0; }
    compensation_totals& operator+=(const compensation_totals& o) noexcept {
        added += o.added, total += o.total, rays += o.rays;
        return *this;
    }
};

namespace detail {
/// The centre of a receiver's disc in `map` (rsm_disc_centre).
inline glm::vec2 disc_centre(const rsm_view& map, const glm::vec3& p) {
    const glm::vec4 clip = map.light_view_projection * glm::vec4(p, 1.f);
    return rsm_disc_centre<float, glm::vec2>(clip.x, clip.y, clip.w);
}

/// Calls term(e, xp, np) for each sample of `pattern` (already grouped, weights times
/// `scale`) that gives the receiver x (unit normal n) light from one of `maps`: e its
/// irradiance, xp and np its texel's position and normal. Maps in order, samples in order.
template <class Term>
void for_each_gather_term(const glm::vec3& x, const glm::vec3& n, std::span<const rsm_view> maps,
                          std::span<const glm::vec3> pattern, float scale, const pixel_light_params& lp, Term&& term) {
    for (const rsm_view& map : maps) {
        const glm::vec2 centre = disc_centre(map, x);
        const float w = float(map.width()), h = float(map.height());
        for (const glm::vec3& s : pattern) {
            const float tu = (centre.x + s.x) * w, tv = (centre.y + s.y) * h;
            if (!(tu >= 0.f && tu < w && tv >= 0.f && tv < h)) continue;
            const std::size_t tx = std::size_t(tu), ty = std::size_t(tv);
            const glm::vec3 flux = map.flux(tx, ty);
            if (flux.x == 0.f && flux.y == 0.f && flux.z == 0.f) continue;
            term(pixel_light_irradiance<float, glm::vec3>(x, n, map.position(tx, ty), map.normal(tx, ty),
                                                          flux * (s.z * scale), lp.offset, lp.min_distance2),
                 map.position(tx, ty), map.normal(tx, ty));
        }
    }
}

/// Scratch of one thread's gather with visibility.
struct visible_gather_scratch {
    std::vector<visibility_segment> segments;
    std::vector<glm::vec3> terms;
    std::vector<std::uint8_t> blocked;
    std::vector<near_field_ray> rays;
    std::vector<glm::vec3> radiance;
    std::vector<float> distance2;
    std::vector<near_field_crossing> crossings;
    compensation_totals totals;  // what this thread's compensation added
};

/// The clamp's compensation at receiver x (unit normal n): the light of the surfaces its
/// rays meet (the first, or every one with comp.every_surface) within the clamp's distance,
/// weighted by the clamp's complement.
inline glm::vec3 compensation_at(const glm::vec3& x, const glm::vec3& n, const gather_compensation& comp,
                                 visible_gather_scratch& sc) {
    sc.rays.clear();
    clamp_compensation_rays(x, n, comp.min_distance2, comp.grid, comp.seed, sc.rays);
    glm::vec3 e(0.f);
    const float count = float(sc.rays.size());
    const auto add = [&](const glm::vec3& radiance, float d2) {
        if (d2 < comp.min_distance2)
            e += clamp_compensation_term<float, glm::vec3>(radiance, d2, comp.min_distance2, count);
    };
    if (comp.every_surface) {
        comp.query->crossings(sc.rays, sc.crossings);
        for (const near_field_crossing& c : sc.crossings) add(c.radiance, c.distance2);
    } else {
        sc.radiance.resize(sc.rays.size());
        sc.distance2.resize(sc.rays.size());
        comp.query->radiance(sc.rays, sc.radiance, sc.distance2);
        for (std::size_t k = 0; k < sc.rays.size(); ++k) add(sc.radiance[k], sc.distance2[k]);
    }
    sc.totals.rays += sc.rays.size();
    sc.totals.added += double(e.x + e.y + e.z);
    return e;
}

/// Irradiance the samples `pattern` (already grouped, weights times `scale`) gather at one
/// receiver from every map; with `occlusion`, only from the texels it sees (one segment a
/// sample that gives light, asked in one batch), plus the clamp's compensation when `comp`
/// is active (with or without `occlusion`).
inline glm::vec3 gather_at(const glm::vec3& x, const glm::vec3& n, std::span<const rsm_view> maps,
                           std::span<const glm::vec3> pattern, float scale, const pixel_light_params& lp,
                           const occlusion_query* occlusion = nullptr, visible_gather_scratch* scratch = nullptr,
                           const gather_compensation& comp = {}) {
    glm::vec3 e(0.f);
    if (!occlusion) {
        for_each_gather_term(x, n, maps, pattern, scale, lp, [&](const glm::vec3& t, auto&, auto&) { e += t; });
        if (!comp.active()) return e;  // the plain gather needs no scratch
    }
    visible_gather_scratch own;  // for a caller without scratch of its own
    visible_gather_scratch& sc = scratch ? *scratch : own;
    if (!occlusion) {
        e += compensation_at(x, n, comp, sc);
        sc.totals.total += double(e.x + e.y + e.z);
        return e;
    }
    sc.segments.clear();
    sc.terms.clear();
    const auto collect = [&](const glm::vec3& t, const glm::vec3& xp, const glm::vec3& np) {
        if (t.x == 0.f && t.y == 0.f && t.z == 0.f) return;
        sc.segments.push_back({x, n, xp, np});
        sc.terms.push_back(t);
    };
    for_each_gather_term(x, n, maps, pattern, scale, lp, collect);
    sc.blocked.resize(sc.terms.size());
    occlusion->occluded(sc.segments, sc.blocked);
    for (std::size_t k = 0; k < sc.terms.size(); ++k)
        if (!sc.blocked[k]) e += sc.terms[k];
    if (comp.active()) e += compensation_at(x, n, comp, sc);
    sc.totals.total += double(e.x + e.y + e.z);
    return e;
}

/// One group holding all `count` samples in order (the plain gather's).
inline light_groups one_group(std::size_t count) {
    light_groups all;
    all.begin = {0, std::uint32_t(count)};
    all.order.resize(count);
    for (std::size_t k = 0; k < count; ++k) all.order[k] = std::uint32_t(k);
    return all;
}

/// The totals of every thread's scratch.
inline compensation_totals sum_totals(tbb::enumerable_thread_specific<visible_gather_scratch>& scratches) {
    compensation_totals t;
    for (const auto& sc : scratches) t += sc.totals;
    return t;
}
}  // namespace detail

/// The gather over a (split) G-buffer `gb` from `maps` (one per light, six for a point
/// light's cube; all the size `pattern` was made for): pixel (u, v) of sub-buffer s = maps.cell(u, v)
/// uses `pattern[groups.begin[s] .. groups.begin[s + 1])` (grouped_pattern) with weights
/// times interleaved_weight_scale(n, m) (weight 1 with `energy_correct` false, the thesis's
/// choice, for comparison). `out` (irradiance, W/m^2) is written everywhere; 0 where the
/// G-buffer sees nothing. With a 1 x 1 pattern this is the plain DS05 gather. With
/// `occlusion`, a pixel sums only the samples whose texel it sees (indirect/visibility.hpp);
/// with an active `comp` it gets back the light the clamp removes (clamp_compensation.hpp).
/// Returns what the compensation added (zeros without it).
inline compensation_totals rsm_gather(const gbuffer_view<float>& gb, const interleave_maps& imaps,
                                      std::span<const rsm_view> maps, std::span<const glm::vec3> pattern,
                                      const light_groups& groups, const pixel_light_params& lp,
                                      image_view<glm::vec3> out, bool energy_correct = true,
                                      const occlusion_query* occlusion = nullptr, const gather_compensation& comp = {}) {
    lp.validate();
    for (const auto& m : maps) {
        m.validate();
        // The pattern's weights hold one texel count (rsm_disc_pattern).
        require(m.width() == maps[0].width() && m.height() == maps[0].height(), "maps",
                "must all have the size the pattern was made for");
    }
    detail::require_size(gb.width(), gb.height(), imaps, "gb");
    detail::require_size(out.width(), out.height(), imaps, "out");
    require(groups.begin.size() == std::size_t(imaps.pattern.cells()) + 1 && pattern.size() == groups.order.size(),
            "pattern", "must be grouped for the pattern's sub-buffers");
    const float scale =
        energy_correct ? interleaved_weight_scale<float>(float(imaps.pattern.n), float(imaps.pattern.m)) : 1.f;
    tbb::enumerable_thread_specific<detail::visible_gather_scratch> scratches;
    tbb::parallel_for(std::size_t(0), gb.height(), [&](std::size_t v) {
        auto& scratch = scratches.local();
        for (std::size_t u = 0; u < gb.width(); ++u) {
            if (!gb.covered(u, v)) {
                out(u, v) = glm::vec3(0.f);
                continue;
            }
            const int s = imaps.cell(u, v);
            const auto group = pattern.subspan(groups.begin[std::size_t(s)],
                                               groups.begin[std::size_t(s) + 1] - groups.begin[std::size_t(s)]);
            out(u, v) = detail::gather_at(gb.position(u, v), gb.normal(u, v), maps, group, scale, lp, occlusion,
                                          &scratch, comp);
        }
    });
    return detail::sum_totals(scratches);
}

/// The plain gather (no interleaving, DS05): every pixel of `gb` sums the whole `pattern`.
inline void rsm_gather(const gbuffer_view<float>& gb, std::span<const rsm_view> maps,
                       std::span<const glm::vec3> pattern, const pixel_light_params& lp, image_view<glm::vec3> out) {
    rsm_gather(gb, interleave_maps({1, 1}, gb.width(), gb.height()), maps, pattern, detail::one_group(pattern.size()),
               lp, out);
}

/// The plain gather with visibility by `occlusion` and the clamp's compensation `comp`:
/// every pixel of `gb` sums the whole `pattern`. Returns what the compensation added.
inline compensation_totals rsm_gather(const gbuffer_view<float>& gb, std::span<const rsm_view> maps,
                                      std::span<const glm::vec3> pattern, const pixel_light_params& lp,
                                      image_view<glm::vec3> out, const occlusion_query& occlusion,
                                      const gather_compensation& comp) {
    return rsm_gather(gb, interleave_maps({1, 1}, gb.width(), gb.height()), maps, pattern,
                      detail::one_group(pattern.size()), lp, out, true, &occlusion, comp);
}

/// Picks the G-buffer pixel at the centre of each factor x factor block
/// (pixel (f x + f/2, f y + f/2), clamped) into `low`, whose size is ceil(size / f).
inline void downsample_gbuffer(const gbuffer_view<float>& gb, int factor, const gbuffer_view<float>& low) {
    require(factor >= 1, "factor", "must be positive");
    const std::size_t f = std::size_t(factor);
    require(low.width() == (gb.width() + f - 1) / f && low.height() == (gb.height() + f - 1) / f, "low",
            "must be ceil(size / factor)");
    tbb::parallel_for(std::size_t(0), low.height(), [&](std::size_t y) {
        const std::size_t sy = std::min(gb.height() - 1, y * f + f / 2);
        for (std::size_t x = 0; x < low.width(); ++x) {
            const std::size_t sx = std::min(gb.width() - 1, x * f + f / 2);
            low.position(x, y) = gb.position(sx, sy);
            low.normal(x, y) = gb.normal(sx, sy);
            low.albedo(x, y) = gb.albedo(sx, sy);
            low.depth(x, y) = gb.depth(sx, sy);
        }
    });
}

/// Geometry-aware upsampling of `low_irradiance` (computed on the downsampled G-buffer
/// `low`) to `out`: a pixel interpolates the four low-resolution samples around it with the
/// weights of geometry_aware_upsample_weights when at least three are suitable (DS05); the
/// others are gathered at full resolution with the whole `pattern` (not interleaved; with
/// `occlusion`, from the texels they see). Returns the number of pixels gathered at full
/// resolution.
inline std::size_t upsample_or_gather(const gbuffer_view<float>& gb, const camera& cam, const gbuffer_view<float>& low,
                                      image_view<const glm::vec3> low_irradiance, int factor, const upsample_params& up,
                                      std::span<const rsm_view> maps, std::span<const glm::vec3> pattern,
                                      const pixel_light_params& lp, image_view<glm::vec3> out,
                                      const occlusion_query* occlusion = nullptr, const gather_compensation& comp = {},
                                      compensation_totals* totals = nullptr) {
    require(out.width() == gb.width() && out.height() == gb.height(), "out", "size differs from the G-buffer");
    const float f = float(factor);
    std::vector<std::size_t> fallbacks(gb.height(), 0);
    tbb::enumerable_thread_specific<detail::visible_gather_scratch> scratches;
    tbb::parallel_for(std::size_t(0), gb.height(), [&](std::size_t y) {
        auto& scratch = scratches.local();
        for (std::size_t x = 0; x < gb.width(); ++x) {
            if (!gb.covered(x, y)) {
                out(x, y) = glm::vec3(0.f);
                continue;
            }
            // Low-resolution sample c sits at full-resolution pixel f c + f/2.
            const float lx = (float(x) - float(factor / 2)) / f, ly = (float(y) - float(factor / 2)) / f;
            const float fx0 = std::floor(lx), fy0 = std::floor(ly);
            std::array<glm::vec3, 4> ps, ns, es;
            for (int k = 0; k < 4; ++k) {
                const auto cx = std::size_t(std::clamp(fx0 + float(k & 1), 0.f, float(low.width() - 1)));
                const auto cy = std::size_t(std::clamp(fy0 + float(k >> 1), 0.f, float(low.height() - 1)));
                ps[std::size_t(k)] = low.covered(cx, cy) ? low.position(cx, cy) : glm::vec3(1e30f);
                ns[std::size_t(k)] = low.covered(cx, cy) ? low.normal(cx, cy) : glm::vec3(0.f);
                es[std::size_t(k)] = low_irradiance(cx, cy);
            }
            const float tolerance = up.plane_footprints * f * cam.pixel_footprint(gb.depth(x, y), gb.height());
            const auto w = geometry_aware_upsample_weights<float, glm::vec3>(
                gb.position(x, y), gb.normal(x, y), ps, ns, std::clamp(lx - fx0, 0.f, 1.f),
                std::clamp(ly - fy0, 0.f, 1.f), tolerance, up.cos_normal);
            if (w[4] >= 3.f && w[0] + w[1] + w[2] + w[3] > 0.f) {
                out(x, y) = es[0] * w[0] + es[1] * w[1] + es[2] * w[2] + es[3] * w[3];
            } else {
                out(x, y) = detail::gather_at(gb.position(x, y), gb.normal(x, y), maps, pattern, 1.f, lp, occlusion,
                                              &scratch, comp);
                ++fallbacks[y];
            }
        }
    });
    if (totals) *totals = detail::sum_totals(scratches);
    std::size_t total = 0;
    for (auto c : fallbacks) total += c;
    return total;
}

}  // namespace bounce::cpu
