#pragma once
/// \file indirect/rsm_sampling.hpp
/// The choices an indirect renderer of the RSM / SII family makes on the host, whatever
/// its backend: the disc pattern of the RSM gather, the VPLs of a frame (shared between the
/// maps by flux, on a grid or by flux warping) and the pixel rectangles the VPLs are
/// splatted over, in the image (sphere_pixel_rect of splat_bounds.hpp) and in an
/// interleaved split buffer. cpu::indirect_renderer and gl::indirect_renderer both call
/// these, so their frames use the same samples, lights and pixels
/// (docs/rsm-sii-interleaved.md, docs/rsm-sii-gl.md).

#include <bounce/camera.hpp>
#include <bounce/errors.hpp>
#include <bounce/indirect/options.hpp>
#include <bounce/indirect/interleaved_sampling.hpp>
#include <bounce/indirect/rsm.hpp>
#include <bounce/sampling.hpp>
#include <bounce/splat_bounds.hpp>
#include <bounce/indirect/vpl_sampling.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace bounce::inline indirect {

// ---- the RSM gather's disc ----------------------------------------------------------------

/// `count` disc samples (du, dv, w) for a map of `texel_count` texels: rsm_disc_sample on
/// the points of the Halton sequence (stratified over the disc), listed in a shuffled order
/// so that dealing them interleaved gives each sub-buffer a random subset rather than one
/// radius band (the base-2 coordinate of every 64th Halton point lies in one 1/64 interval).
/// `r_max` in map units (0, 2]: 1.5 reaches every texel from any centre inside the map.
inline std::vector<glm::vec3> rsm_disc_pattern(std::size_t count, float r_max, std::size_t texel_count,
                                               std::uint64_t seed = 1,
                                               disc_weighting weighting = disc_weighting::unbiased) {
    require(count > 0, "count", "must be positive");
    require(std::isfinite(r_max) && r_max > 0.f && r_max <= 2.f, "r_max", "must lie in (0, 2]");
    require(texel_count > 0, "texel_count", "must be positive");
    pcg32 rng(seed);
    const glm::dvec2 shift(rng.next_double(), rng.next_double());
    std::vector<glm::vec3> out(count);
    for (std::size_t k = 0; k < count; ++k) {
        const glm::dvec2 xi = halton2(k, shift);
        out[k] =
            weighting == disc_weighting::unbiased
                ? rsm_disc_sample<double, glm::dvec3>(xi.x, xi.y, double(r_max), double(texel_count), double(count))
                : rsm_disc_sample_xi1_squared<double, glm::dvec3>(xi.x, xi.y, double(r_max), double(texel_count),
                                                                  double(count));
    }
    for (std::size_t k = count; k > 1; --k) std::swap(out[k - 1], out[rng.next_u32() % k]);
    return out;
}

/// The pattern in the order the sub-buffers read it: group s's samples contiguous, from
/// `groups.begin[s]`.
inline std::vector<glm::vec3> grouped_pattern(std::span<const glm::vec3> pattern, const light_groups& groups) {
    std::vector<glm::vec3> out(groups.order.size());
    for (std::size_t k = 0; k < out.size(); ++k) out[k] = pattern[groups.order[k]];
    return out;
}

// ---- the VPLs of a frame ----------------------------------------------------------------

/// About `count` VPLs from `maps`, shared between the maps in proportion to their flux (so
/// each VPL carries about the same flux whichever map it comes from; a map gets at least
/// one unless its flux is 0), taken by `selection`: vpls_by_flux_warping with seed
/// `seed + i` for map i, or vpls_on_grid on a grid of the map's aspect. Listed map by map.
inline std::vector<vpl> select_vpls(std::span<const rsm_view> maps, std::size_t count, vpl_selection selection,
                                    std::uint64_t seed) {
    std::vector<vpl> out;
    std::vector<double> totals;
    double sum = 0;
    for (const auto& m : maps) {
        totals.push_back(flux_warping(m).total());
        sum += totals.back();
    }
    for (std::size_t i = 0; i < maps.size(); ++i) {
        if (!(totals[i] > 0)) continue;
        const auto share = std::max<std::size_t>(1, std::size_t(std::llround(double(count) * totals[i] / sum)));
        std::vector<vpl> more;
        if (selection == vpl_selection::flux_warping) {
            more = vpls_by_flux_warping(maps[i], share, seed + i);
        } else {
            const double aspect = double(maps[i].width()) / double(maps[i].height());
            const auto gx = std::max<std::size_t>(1, std::size_t(std::llround(std::sqrt(double(share) * aspect))));
            const auto gy = std::max<std::size_t>(1, (share + gx - 1) / gx);
            more = vpls_on_grid(maps[i], gx, gy);
        }
        out.insert(out.end(), more.begin(), more.end());
    }
    return out;
}

/// The VPLs of one frame as `options` select them (count, selection, seed).
inline std::vector<vpl> select_vpls(std::span<const rsm_view> maps, const indirect_options& options) {
    return select_vpls(maps, options.count, options.selection, options.seed);
}

// ---- pixel rectangles -------------------------------------------------------------------

// pixel_rect and sphere_pixel_rect, the rectangle of a sphere, are splat_bounds.hpp's.

/// The image rectangle SII splats VPL `l` over in a frame of `vpl_count` VPLs: the pixels of
/// the sphere outside which the VPL gives less than cutoff / vpl_count
/// (pixel_light_bounding_sphere, sender moved by `offset`); the whole image for cutoff 0.
inline pixel_rect vpl_splat_rect(const camera& cam, const glm::mat4& view, const vpl& l, std::size_t vpl_count,
                                 float cutoff, float offset, std::size_t width, std::size_t height) {
    if (cutoff == 0.f) return {0, 0, int(width) - 1, int(height) - 1};
    const float flux_max = std::max(std::max(l.flux.x, l.flux.y), l.flux.z);
    const auto [centre, radius] =
        pixel_light_bounding_sphere<float, glm::vec3>(l.position, l.normal, flux_max, cutoff / float(vpl_count), offset);
    return sphere_pixel_rect(cam, view, centre, radius, width, height);
}

/// The pixels of image rectangle `r` that belong to sub-buffer (i, j) of `p` (image column x
/// with x = i + a n, row y = j + b m), as a rectangle of the split buffer, `sub` being that
/// sub-buffer's rectangle (sub_buffer_of): columns origin + [ceil((x0 - i) / n),
/// floor((x1 - i) / n)], rows likewise. Empty when no such pixel exists.
inline pixel_rect split_buffer_rect(const pixel_rect& r, const interleave_pattern& p, int i, int j,
                                    const sub_buffer_rect& sub) {
    pixel_rect q;
    if (r.empty() || sub.width == 0 || sub.height == 0) return q;
    const auto local = [](int lo, int hi, int cell, int n, std::size_t extent, std::size_t origin, int& a, int& b) {
        a = lo <= cell ? 0 : (lo - cell + n - 1) / n;
        b = hi < cell ? -1 : std::min((hi - cell) / n, int(extent) - 1);
        a += int(origin);
        b += int(origin);
    };
    local(r.x0, r.x1, i, p.n, sub.width, sub.x0, q.x0, q.x1);
    local(r.y0, r.y1, j, p.m, sub.height, sub.y0, q.y0, q.y1);
    return q;
}

}  // namespace bounce::indirect
