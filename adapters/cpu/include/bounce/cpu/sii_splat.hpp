#pragma once
/// \file sii_splat.hpp
/// Splatting indirect illumination on the CPU (Dachsbacher and Stamminger 2006): every VPL
/// adds its irradiance (indirect/rsm.hpp's pixel_light_irradiance) to the pixels of the screen
/// rectangle that bounds the region where it can give more than a cutoff
/// (pixel_light_bounding_sphere), contributions added up.
///
/// Interleaved, VPL k reaches only the sub-buffer it is dealt to (light_groups), at flux
/// times N M (indirect/interleaved_sampling.hpp), and only that sub-buffer's pixels inside its
/// rectangle: 1/(N M) of the pixels. The (VPL, rectangle) pairs are binned into tiles of the
/// split buffer in a fixed order and each tile adds its pairs in that order, so every pixel
/// sums the same terms in the same order whatever the thread count (bitwise reproducible).

#include <bounce/camera.hpp>
#include <bounce/cpu/imperfect_shadow_maps.hpp>
#include <bounce/cpu/interleave.hpp>
#include <bounce/cpu/rsm_gather.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/indirect/options.hpp>
#include <bounce/indirect/rsm.hpp>
#include <bounce/indirect/rsm_sampling.hpp>
#include <bounce/indirect/visibility.hpp>
#include <bounce/indirect/vpl_sampling.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace bounce::cpu {

/// Parameters of the SII splat.
struct sii_params {
    pixel_light_params light;
    /// Largest irradiance (W/m^2 per channel) the splat bounds may cut off at any pixel,
    /// summed over all VPLs: each VPL is splatted over the sphere outside which it gives
    /// less than cutoff / (number of VPLs). 0 splats every VPL over the whole screen (no
    /// cut). Typical: 1e-3 of the scene's indirect irradiance.
    float cutoff = 0.f;
    int tile = 32;  ///< tile side in pixels of the split buffer (typical: 16-64)
    /// Interleaved VPLs carry N M times their flux (interleaved_weight_scale). false
    /// reproduces the thesis's splat at weight 1 (Hahn 2012, section 5.2) for comparison: the
    /// image then holds 1/(N M) of the energy.
    bool energy_correct = true;

    void validate() const {
        light.validate();
        require(std::isfinite(cutoff) && cutoff >= 0.f, "cutoff", "must be finite and >= 0");
        require(tile > 0, "tile", "must be positive");
    }
};

/// Screen rectangle (full-resolution pixels) of VPL `l` for a frame of `vpl_count` VPLs
/// (indirect/rsm_sampling.hpp's vpl_splat_rect, which the GL backend uses too).
inline bounce::pixel_rect sii_splat_rect(const camera& cam, const glm::mat4& view, const vpl& l,
                                         std::size_t vpl_count, const sii_params& params, std::size_t width,
                                         std::size_t height) {
    return vpl_splat_rect(cam, view, l, vpl_count, params.cutoff, params.light.offset, width, height);
}

namespace detail {
/// Calls add(u, v, E) for each pixel of `rect` inside `tile` (split-buffer pixels) that VPL
/// `l` (flux times `scale`) lights, E its irradiance there, row by row.
template <class Add>
void splat(const gbuffer_view<float>& gb, const vpl& l, float scale, const pixel_light_params& lp,
           const bounce::pixel_rect& rect, const bounce::pixel_rect& tile, Add&& add) {
    const glm::vec3 flux = l.flux * scale;
    const glm::vec3 sender = l.position - l.normal * lp.offset;
    // An interleaved VPL stands for `scale` times its area within its sub-buffer, as for its flux.
    const float min_distance2 = lp.min_distance2_for(l.area * scale);
    for (int v = std::max(rect.y0, tile.y0); v <= std::min(rect.y1, tile.y1); ++v)
        for (int u = std::max(rect.x0, tile.x0); u <= std::min(rect.x1, tile.x1); ++u) {
            const std::size_t uu = std::size_t(u), vv = std::size_t(v);
            if (!gb.covered(uu, vv)) continue;
            // Receivers behind the sender's plane get 0 from the kernel (its cos theta_p
            // clamp): skipping them adds nothing and saves its square root.
            if (!(glm::dot(l.normal, gb.position(uu, vv) - sender) > 0.f)) continue;
            add(uu, vv,
                pixel_light_irradiance<float, glm::vec3>(gb.position(uu, vv), gb.normal(uu, vv), l.position, l.normal,
                                                         flux, lp.offset, min_distance2));
        }
}

/// Scratch of one thread's splat with visibility.
struct visible_splat_scratch {
    std::vector<visibility_segment> segments;
    std::vector<std::array<std::size_t, 2>> pixels;
    std::vector<glm::vec3> terms;
    std::vector<std::uint8_t> blocked;
};

/// splat, adding only where `occlusion` finds the pixel sees the VPL (one batch). With
/// `stats` (not empty), each term's brightness b (its channels' sum) also adds (b, b V, b^2)
/// to the pixel's stats, V 1 where it sees the VPL (visibility_discontinuity's sums).
inline void splat_visible(const gbuffer_view<float>& gb, const vpl& l, float scale, const pixel_light_params& lp,
                          const bounce::pixel_rect& rect, const bounce::pixel_rect& tile,
                          const occlusion_query& occlusion, visible_splat_scratch& s, image_view<glm::vec3> out,
                          image_view<glm::vec3> stats = {}) {
    s.segments.clear();
    s.pixels.clear();
    s.terms.clear();
    splat(gb, l, scale, lp, rect, tile, [&](std::size_t u, std::size_t v, const glm::vec3& e) {
        if (e.x == 0.f && e.y == 0.f && e.z == 0.f) return;
        s.segments.push_back({gb.position(u, v), gb.normal(u, v), l.position, l.normal});
        s.pixels.push_back({u, v});
        s.terms.push_back(e);
    });
    if (s.terms.empty()) return;
    s.blocked.resize(s.terms.size());
    occlusion.occluded(s.segments, s.blocked);
    for (std::size_t k = 0; k < s.terms.size(); ++k)
        if (!s.blocked[k]) out(s.pixels[k][0], s.pixels[k][1]) += s.terms[k];
    if (stats.empty()) return;
    for (std::size_t k = 0; k < s.terms.size(); ++k) {
        const float b = s.terms[k].x + s.terms[k].y + s.terms[k].z;
        stats(s.pixels[k][0], s.pixels[k][1]) += glm::vec3(b, s.blocked[k] ? 0.f : b, b * b);
    }
}
}  // namespace detail

/// Adds the irradiance of `vpls` to `out` (the split buffer of `gb`'s image, or the image
/// itself for a 1 x 1 pattern): sub-buffer s receives `groups.group(s)`. `gb` is the split
/// G-buffer; `cam` the camera of the full image (maps.width x maps.height). With
/// `occlusion`, a VPL lights only the pixels that see it (indirect/visibility.hpp; the
/// pixels of one VPL and tile asked in one batch); with `ism` instead (built for `vpls`),
/// each term is multiplied by imperfect_shadow_maps::visible. `visibility_stats` (with
/// `occlusion`; empty: not kept) receives each pixel's sums of its terms' brightness before
/// visibility, after it, and squared (visibility_discontinuity's inputs; the caller zeroes it).
inline void splat_vpls(const gbuffer_view<float>& gb, const interleave_maps& maps, const camera& cam,
                       std::span<const vpl> vpls, const light_groups& groups, const sii_params& params,
                       image_view<glm::vec3> out, const occlusion_query* occlusion = nullptr,
                       const imperfect_shadow_maps* ism = nullptr, image_view<glm::vec3> visibility_stats = {}) {
    params.validate();
    detail::require_size(gb.width(), gb.height(), maps, "gb");
    detail::require_size(out.width(), out.height(), maps, "out");
    if (!visibility_stats.empty()) detail::require_size(visibility_stats.width(), visibility_stats.height(), maps,
                                                        "visibility_stats");
    const interleave_pattern& p = maps.pattern;
    require(groups.begin.size() == std::size_t(p.cells()) + 1 && groups.order.size() == vpls.size(), "groups",
            "must deal every VPL to the pattern's sub-buffers");
    if (vpls.empty()) return;
    const glm::mat4 view = cam.view_matrix();
    const float scale = params.energy_correct ? interleaved_weight_scale<float>(float(p.n), float(p.m)) : 1.f;

    // Rectangles in the split buffer, one per VPL, in the order of `groups.order`.
    std::vector<bounce::pixel_rect> rects(vpls.size());
    tbb::parallel_for(std::size_t(0), std::size_t(p.cells()), [&](std::size_t s) {
        const int i = int(s) % p.n, j = int(s) / p.n;
        const auto sub = maps.sub_buffer(i, j);
        for (std::uint32_t k = groups.begin[s]; k < groups.begin[s + 1]; ++k)
            rects[k] = split_buffer_rect(
                sii_splat_rect(cam, view, vpls[groups.order[k]], vpls.size(), params, maps.width, maps.height), p, i,
                j, sub);
    });

    const int tile = params.tile;
    const int tw = int((gb.width() + std::size_t(tile) - 1) / std::size_t(tile));
    const int th = int((gb.height() + std::size_t(tile) - 1) / std::size_t(tile));
    std::vector<std::vector<std::uint32_t>> bins(std::size_t(tw) * std::size_t(th));
    for (std::size_t k = 0; k < rects.size(); ++k) {
        const auto& r = rects[k];
        if (r.empty()) continue;
        for (int ty = r.y0 / tile; ty <= r.y1 / tile; ++ty)
            for (int tx = r.x0 / tile; tx <= r.x1 / tile; ++tx)
                bins[std::size_t(ty) * std::size_t(tw) + std::size_t(tx)].push_back(std::uint32_t(k));
    }
    tbb::enumerable_thread_specific<detail::visible_splat_scratch> scratches;
    tbb::parallel_for(std::size_t(0), bins.size(), [&](std::size_t t) {
        const int tx = int(t % std::size_t(tw)), ty = int(t / std::size_t(tw));
        const int x_lo = tx * tile, y_lo = ty * tile;
        const bounce::pixel_rect tile_rect{x_lo, y_lo, std::min(int(gb.width()), x_lo + tile) - 1,
                                           std::min(int(gb.height()), y_lo + tile) - 1};
        for (const std::uint32_t k : bins[t]) {
            const vpl& l = vpls[groups.order[k]];
            if (occlusion)
                detail::splat_visible(gb, l, scale, params.light, rects[k], tile_rect, *occlusion, scratches.local(),
                                      out, visibility_stats);
            else if (ism)
                detail::splat(gb, l, scale, params.light, rects[k], tile_rect,
                              [&](std::size_t u, std::size_t v, const glm::vec3& e) {
                                  out(u, v) += e * ism->visible(groups.order[k], gb.position(u, v), gb.normal(u, v), l);
                              });
            else
                detail::splat(gb, l, scale, params.light, rects[k], tile_rect,
                              [&](std::size_t u, std::size_t v, const glm::vec3& e) { out(u, v) += e; });
        }
    });
}

/// Completes the pixels of a blurred interleaved SII frame that its blur isolates: where
/// `reached` (reached_sub_buffers) is below `min_reached`, the pixel of `out` (image order,
/// irradiance) becomes the sum of every one of `vpls` at the pixel itself, each at its own
/// weight (1 / (N M) of the interleaved one; its area likewise for the clamp), with an
/// occlusion ray per term that is not 0 when `occlusion` is given: the plain frame's estimate
/// there. Unbiased as the blurred value is (the union of the sub-buffers' VPLs is the plain
/// frame's sample), with the variance of all the VPLs instead of the few reached sub-buffers'
/// share at N M times the weight (docs section 15, fifth session). The splat's cutoff is not
/// applied (every VPL counts in full). `gb` is the image's G-buffer. Returns the pixels completed.
inline std::size_t complete_isolated_pixels(const gbuffer_view<float>& gb, image_view<const float> reached,
                                            float min_reached, std::span<const vpl> vpls,
                                            const pixel_light_params& lp, image_view<glm::vec3> out,
                                            const occlusion_query* occlusion = nullptr) {
    lp.validate();
    require(reached.width() == gb.width() && reached.height() == gb.height() && out.width() == gb.width() &&
                out.height() == gb.height(),
            "reached/out", "size differs from the G-buffer");
    std::vector<std::array<std::size_t, 2>> pixels;
    for (std::size_t y = 0; y < gb.height(); ++y)
        for (std::size_t x = 0; x < gb.width(); ++x)
            if (gb.covered(x, y) && reached(x, y) < min_reached) pixels.push_back({x, y});
    tbb::enumerable_thread_specific<detail::visible_splat_scratch> scratches;
    tbb::parallel_for(std::size_t(0), pixels.size(), [&](std::size_t i) {
        const auto [u, v] = pixels[i];
        detail::visible_splat_scratch& s = scratches.local();
        s.segments.clear();
        s.terms.clear();
        const glm::vec3 x = gb.position(u, v), n = gb.normal(u, v);
        for (const vpl& l : vpls) {
            if (!(glm::dot(l.normal, x - (l.position - l.normal * lp.offset)) > 0.f)) continue;
            const glm::vec3 e = pixel_light_irradiance<float, glm::vec3>(x, n, l.position, l.normal, l.flux,
                                                                         lp.offset, lp.min_distance2_for(l.area));
            if (e.x == 0.f && e.y == 0.f && e.z == 0.f) continue;
            s.segments.push_back({x, n, l.position, l.normal});
            s.terms.push_back(e);
        }
        s.blocked.assign(s.terms.size(), 0);
        if (occlusion && !s.terms.empty()) occlusion->occluded(s.segments, s.blocked);
        glm::vec3 sum(0.f);
        for (std::size_t k = 0; k < s.terms.size(); ++k)
            if (!s.blocked[k]) sum += s.terms[k];
        out(u, v) = sum;
    });
    return pixels.size();
}

/// The plain splat (no interleaving): every VPL, in index order, over the G-buffer `gb`
/// (the image itself), added to `out`.
inline void splat_vpls(const gbuffer_view<float>& gb, const camera& cam, std::span<const vpl> vpls,
                       const sii_params& params, image_view<glm::vec3> out,
                       const occlusion_query* occlusion = nullptr) {
    const interleave_maps maps({1, 1}, gb.width(), gb.height());
    splat_vpls(gb, maps, cam, vpls, assign_lights(vpls.size(), 1, light_assignment::interleaved), params, out,
               occlusion);
}

}  // namespace bounce::cpu
