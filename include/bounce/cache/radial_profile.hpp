#pragma once
/// \file cache/radial_profile.hpp
/// The mean radial profile of rendered hemisphere planes, fitted by least squares, and the
/// band factor kappa of fall-off stretching (plane_weighting::falloff) it implies.

#include <bounce/errors.hpp>
#include <bounce/image.hpp>
#include <bounce/luminance.hpp>
#include <bounce/cache/plane_camera.hpp>
#include <bounce/cache/plane_weights.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include <glm/glm.hpp>

namespace bounce::inline cache {

/// Cosine-weighted mean cosine of the directions the plane misses (its whole band),
/// c = (2/3) int cos^3(theta_e) dphi / int cos^2(theta_e) dphi over the plane's edge, where
/// theta_e(phi) is the elevation of the edge: per azimuth, int_{theta_e}^{pi/2} cos^2 sin =
/// cos^3(theta_e) / 3 and int cos sin = cos^2(theta_e) / 2. Over one eighth of the edge
/// (phi in [0, pi/4], s = sin(phi), b^2 = 1 + a^2):
/// int cos^3 = asin(s / b) - a^2 s / (b^2 sqrt(b^2 - s^2)), int cos^2 = phi - (a / b) atan(a tan(phi) / b).
inline double band_mean_cosine(double aperture_deg) {
    const double a = std::tan(aperture_deg * std::numbers::pi / 360.0), b2 = 1.0 + a * a, b = std::sqrt(b2);
    const double s = std::sqrt(0.5);  // sin(pi / 4)
    const double cube = std::asin(s / b) - a * a * s / (b2 * std::sqrt(b2 - s * s));
    const double square = std::numbers::pi / 4 - (a / b) * std::atan(a / b);
    return (2.0 / 3.0) * cube / square;
}

/// The mean radial profile of a batch of rendered planes, and the band factor kappa of
/// fall-off stretching it implies.
///
/// Irradiance records see, on average, darker surfaces towards their horizon (the floor
/// under a wall, the foot of a column, corners that the lights reach less): border
/// stretching, which extends the border pixels' radiance down to the horizon, overestimates
/// the band. Per concentric square ring m of pixels (Chebyshev distance m from the border)
/// the profile keeps the cosine-weighted luminance summed over the batch, B_m, and the
/// ring's weighted mean cosine c_m. A line B = alpha + beta c fitted (least squares) to the
/// outer half of the rings extrapolates the border ring to the band's mean cosine
/// (band_mean_cosine): kappa = B(c_band) / B(c_0), clamped to [0, 1] (a profile that rises
/// towards the horizon keeps stretching's kappa = 1). Pooling a batch (an atlas of records)
/// keeps the single records' noise out of the fit; docs/hemisphere-sampling.md shows the
/// study that chose the outer half.
class radial_profile {
public:
    /// Throws parameter_error for an invalid camera.
    explicit radial_profile(const plane_camera& camera) : camera_(camera) {
        camera.validate();
        const std::uint32_t N = camera.resolution, rings = (N + 1) / 2;
        luminance_.assign(rings, 0.0);
        weight_.assign(rings, 0.0);
        cosine_.assign(rings, 0.0);
        const double a = camera.half_extent();
        const auto plane = make_plane_weights(camera, plane_weighting::plane);
        for (std::uint32_t j = 0; j < N; ++j)
            for (std::uint32_t i = 0; i < N; ++i) {
                const std::size_t at = std::size_t(j) * N + i;
                const double w = plane.irradiance[at];
                weight_[ring(i, j)] += w;
                cosine_[ring(i, j)] += w * plane_pixel_direction<double, glm::dvec3>(i, j, N, a).z;
            }
        for (std::size_t m = 0; m < rings; ++m) cosine_[m] /= weight_[m];
    }

    /// Adds one plane's radiance (N x N, row 0 at the top). Throws parameter_error on a
    /// size mismatch or a non-finite value.
    void add(image_view<const glm::vec3> radiance) {
        const std::uint32_t N = camera_.resolution;
        require(radiance.width() == N && radiance.height() == N, "radiance", "must be resolution x resolution");
        const auto plane = plane_table();
        for (std::uint32_t j = 0; j < N; ++j)
            for (std::uint32_t i = 0; i < N; ++i) {
                const glm::dvec3 L(radiance(i, j));
                require(std::isfinite(L.x) && std::isfinite(L.y) && std::isfinite(L.z), "radiance", "non-finite value");
                luminance_[ring(i, j)] += plane[std::size_t(j) * N + i] * rec709_luminance<double, glm::dvec3>(L);
            }
        ++planes_;
    }

    /// Adds another profile of the same camera (e.g. one per thread). Throws
    /// parameter_error when the cameras differ.
    void merge(const radial_profile& other) {
        require(other.camera_.resolution == camera_.resolution && other.camera_.aperture_deg == camera_.aperture_deg,
                "other", "profile of another plane camera");
        for (std::size_t m = 0; m < luminance_.size(); ++m) luminance_[m] += other.luminance_[m];
        planes_ += other.planes_;
    }

    std::size_t planes() const noexcept { return planes_; }

    /// kappa in [0, 1]: 1 (stretching) until two rings and one plane with light are known.
    double falloff_factor() const {
        const std::size_t rings = luminance_.size(), fit = std::max<std::size_t>(2, rings / 2);
        if (planes_ == 0 || rings < 2) return 1.0;
        // Least squares over rings 0..fit-1 of B_m = luminance_m / weight_m against c_m.
        double s0 = 0, s1 = 0, s2 = 0, t0 = 0, t1 = 0;
        for (std::size_t m = 0; m < fit; ++m) {
            const double c = cosine_[m], B = luminance_[m] / (weight_[m] * double(planes_));
            s0 += 1;
            s1 += c;
            s2 += c * c;
            t0 += B;
            t1 += B * c;
        }
        const double det = s0 * s2 - s1 * s1;
        if (!(det > 0)) return 1.0;
        const double alpha = (t0 * s2 - t1 * s1) / det, beta = (s0 * t1 - s1 * t0) / det;
        const double border = alpha + beta * cosine_[0];
        if (!(border > 0)) return 1.0;
        const double kappa = (alpha + beta * band_mean_cosine(camera_.aperture_deg)) / border;
        return std::clamp(kappa, 0.0, 1.0);
    }

private:
    std::size_t ring(std::uint32_t i, std::uint32_t j) const {
        const std::uint32_t N = camera_.resolution;
        return std::min(std::min(i, j), std::min(N - 1 - i, N - 1 - j));
    }
    const std::vector<double>& plane_table() {
        if (plane_.empty()) plane_ = make_plane_weights(camera_, plane_weighting::plane).irradiance;
        return plane_;
    }

    plane_camera camera_;
    std::vector<double> luminance_, weight_, cosine_, plane_;
    std::size_t planes_ = 0;
};

}  // namespace bounce::cache
