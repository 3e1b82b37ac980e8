#pragma once
/// \file cache/verification.hpp
/// Error the records cannot see (issue 28, third session): a check of the cache's image
/// against a cheap Monte Carlo estimate at every pixel, pooled over small tiles.
///
/// Ward's miss test asks whether a pixel's weight sum reaches a; it cannot see a feature that
/// no record sampled (a strip narrower than the records' spacing under a light's edge, a rim,
/// a lip): the records around it have the surface's normal and cover it with their own,
/// wrong, irradiance (docs/irradiance-splatting.md, "Why Sponza needs it", "Rays per record
/// and the gradients"). A probe does see it: a few cosine-distributed rays at the pixel's own
/// point are an unbiased estimate of its irradiance, with a variance from the same rays. One
/// probe is too noisy to judge one pixel (8 rays: a standard error near the value itself), so
/// the residuals (probe minus cache) of a `tile` x `tile` block of pixels are pooled: the tile
/// disagrees when the mean residual exceeds `k` of its standard errors and `tolerance` times
/// the frame's mean (the scale the image's relative error is measured on: a gross error such
/// as a missed feature, not the records' own noise, which is a few percent of it, nor a
/// relative error in a dark corner that weighs nothing in the image).
/// Where a tile disagrees, the cache measures a record at its pixel whose residual points
/// furthest the tile's way (the scan's own record maker); with neighbour clamping the older
/// records then shrink to it and the scan fills what they uncover (the mechanism that finds
/// Sponza's rims once one record sampled them).
///
/// Everything here is luminance (Rec. 709) of the quantity the cache's splat buffer holds
/// (rho / pi E, or E with an albedo of pi): the probe's E and variance are scaled by the
/// pixel's albedo / pi.

#include <bounce/errors.hpp>
#include <bounce/luminance.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>

#include <glm/glm.hpp>

namespace bounce::inline cache {

/// A cheap Monte Carlo estimate of the irradiance at one point.
struct probe_estimate {
    glm::vec3 irradiance{0.f};  ///< E (W/m^2, RGB)
    /// Variance of the luminance of `irradiance` as an estimate (the mean's, not one ray's);
    /// not finite or negative: unknown (the pixel is left out of the test).
    float variance = 0.f;
    /// Rays the estimate took (the variance floor's n below; 0: no floor).
    std::uint32_t rays = 0;
};

/// The verification pass after the scan (off by default: rounds = 0).
struct verification_options {
    std::uint32_t rounds = 0;  ///< verify-and-seed passes after the scan, each followed by a scan; 0: off
    std::uint32_t tile = 4;    ///< pixels per side of the blocks whose residuals are pooled
    float k = 3.f;             ///< a tile disagrees beyond k standard errors of its mean residual ...
    float tolerance = 0.25f;   ///< ... and beyond this times the frame's mean luminance (the cache's)

    bool enabled() const noexcept { return rounds > 0; }
    /// Throws parameter_error naming the first bad field.
    void validate() const {
        require(tile >= 1 && tile <= 256, "verify_tile", "must be 1 to 256 pixels");
        require(std::isfinite(k) && k > 0.f, "verify_k", "must be a positive number of standard errors");
        require(std::isfinite(tolerance) && tolerance >= 0.f, "verify_tolerance", "must be a non-negative fraction");
    }
};

/// One pixel's residual: the probe minus the cache, in the splat buffer's quantity.
struct pixel_residual {
    double residual = 0;  ///< Y(probe) - Y(cache)
    double variance = 0;  ///< the probe's variance, scaled as the residual
    double cache = 0;     ///< Y(cache)
    bool valid = false;
};

inline double verification_luminance(const glm::vec3& c) { return double(rec709_luminance<float>(c)); }

/// The residual at a pixel whose splat buffer holds `sum` (rgb: sum of w rho/pi E, w: weights)
/// and whose albedo is `albedo`; invalid where the pixel has no weight, the probe's variance
/// is unknown, or anything is not finite. The probe's variance is floored at
/// (Y(cache) / 2)^2 / rays, a relative spread of one half per ray: a few rays that all saw
/// the same radiance (a dark corner whose rays missed the one bright patch) estimate a
/// variance of 0, and would make any difference significant.
inline pixel_residual residual_at(const glm::vec4& sum, const glm::vec3& albedo, const probe_estimate& probe) {
    pixel_residual r;
    if (!(sum.w > 0.f) || !std::isfinite(probe.variance) || probe.variance < 0.f) return r;
    const glm::vec3 scale = albedo / std::numbers::pi_v<float>;
    const double y_probe_e = verification_luminance(probe.irradiance);
    const double y_probe = verification_luminance(scale * probe.irradiance);
    const double y_cache = verification_luminance(glm::vec3(sum) / sum.w);
    // The variance is E's luminance's: scaled by the albedo's effect on that luminance (exact
    // for grey albedo; the ratio of luminances otherwise).
    const double s = y_probe_e > 0 ? y_probe / y_probe_e : verification_luminance(scale);
    r.residual = y_probe - y_cache;
    r.variance = double(probe.variance) * s * s;
    if (probe.rays > 0) r.variance = std::max(r.variance, 0.25 * y_cache * y_cache / double(probe.rays));
    r.cache = y_cache;
    r.valid = std::isfinite(r.residual) && std::isfinite(r.variance) && std::isfinite(r.cache);
    return r;
}

/// Pooled residuals of one tile.
struct tile_residuals {
    double residual = 0, variance = 0, cache = 0;
    std::size_t pixels = 0;

    void add(const pixel_residual& r) {
        if (!r.valid) return;
        residual += r.residual;
        variance += r.variance;
        cache += r.cache;
        ++pixels;
    }
    /// Whether the tile's mean residual exceeds k standard errors and tolerance times
    /// `scale`, the frame's mean luminance (the mean is sum / n, its variance sum var / n^2).
    bool disagrees(const verification_options& o, double scale) const {
        if (pixels == 0) return false;
        const double d = std::abs(residual) / double(pixels);
        return d > double(o.k) * std::sqrt(variance) / double(pixels) && d > double(o.tolerance) * scale;
    }
};

}  // namespace bounce::inline cache
