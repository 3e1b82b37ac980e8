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
#include <bounce/cpu/interleave.hpp>
#include <bounce/cpu/rsm_gather.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/indirect/options.hpp>
#include <bounce/indirect/rsm.hpp>
#include <bounce/indirect/rsm_sampling.hpp>
#include <bounce/indirect/vpl_sampling.hpp>

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>
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

/// Adds the irradiance of `vpls` to `out` (the split buffer of `gb`'s image, or the image
/// itself for a 1 x 1 pattern): sub-buffer s receives `groups.group(s)`. `gb` is the split
/// G-buffer; `cam` the camera of the full image (maps.width x maps.height).
inline void splat_vpls(const gbuffer_view<float>& gb, const interleave_maps& maps, const camera& cam,
                       std::span<const vpl> vpls, const light_groups& groups, const sii_params& params,
                       image_view<glm::vec3> out) {
    params.validate();
    detail::require_size(gb.width(), gb.height(), maps, "gb");
    detail::require_size(out.width(), out.height(), maps, "out");
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
    tbb::parallel_for(std::size_t(0), bins.size(), [&](std::size_t t) {
        const int tx = int(t % std::size_t(tw)), ty = int(t / std::size_t(tw));
        const int x_lo = tx * tile, y_lo = ty * tile;
        const int x_hi = std::min(int(gb.width()), x_lo + tile) - 1, y_hi = std::min(int(gb.height()), y_lo + tile) - 1;
        for (const std::uint32_t k : bins[t]) {
            const auto& r = rects[k];
            const vpl& l = vpls[groups.order[k]];
            const glm::vec3 flux = l.flux * scale;
            const glm::vec3 sender = l.position - l.normal * params.light.offset;
            for (int v = std::max(r.y0, y_lo); v <= std::min(r.y1, y_hi); ++v)
                for (int u = std::max(r.x0, x_lo); u <= std::min(r.x1, x_hi); ++u) {
                    const std::size_t uu = std::size_t(u), vv = std::size_t(v);
                    if (!gb.covered(uu, vv)) continue;
                    // Receivers behind the sender's plane get 0 from the kernel (its cos
                    // theta_p clamp): skipping them adds nothing and saves its square root.
                    if (!(glm::dot(l.normal, gb.position(uu, vv) - sender) > 0.f)) continue;
                    out(uu, vv) += pixel_light_irradiance<float, glm::vec3>(
                        gb.position(uu, vv), gb.normal(uu, vv), l.position, l.normal, flux, params.light.offset,
                        params.light.min_distance2);
                }
        }
    });
}

/// The plain splat (no interleaving): every VPL, in index order, over the G-buffer `gb`
/// (the image itself), added to `out`.
inline void splat_vpls(const gbuffer_view<float>& gb, const camera& cam, std::span<const vpl> vpls,
                       const sii_params& params, image_view<glm::vec3> out) {
    const interleave_maps maps({1, 1}, gb.width(), gb.height());
    splat_vpls(gb, maps, cam, vpls, assign_lights(vpls.size(), 1, light_assignment::interleaved), params, out);
}

}  // namespace bounce::cpu
