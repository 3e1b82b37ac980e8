#pragma once
/// \file cache/plane_camera.hpp
/// The camera of single-plane hemisphere sampling (Gautron 2008, section 8.4): an N x N
/// square plane above a record, its frame and turn, the solid angles of the whole plane, the
/// view of one rendered plane, and the ray-cast loop that fills a plane.
///
/// The plane is z = 1 in the record's local frame (x, y tangent, z the normal); the camera
/// at the record looks along z with a square field of view of `aperture` (full angle), so
/// the plane spans [-a, a]^2 with a = tan(aperture / 2). Pixel (i, j) of an N x N plane,
/// column i along +x, row j from the top (+y) down, covers
///   x in [a (2 i / N - 1), a (2 (i + 1) / N - 1)],  y in [a (1 - 2 (j + 1) / N), a (1 - 2 j / N)].
/// The pixels' weights (cache/plane_weights.hpp) are exact integrals over these rectangles
/// (rectangle_solid_angle.hpp).

#include <bounce/errors.hpp>
#include <bounce/image.hpp>
#include <bounce/cache/plane_pixel.hpp>
#include <bounce/sampling.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <glm/glm.hpp>

namespace bounce::inline cache {

/// A number in [0, 1) hashed from the bits of a position (+0 and -0 alike), the fraction of
/// a quarter turn that plane_camera::hashed_turn gives a record's plane (hash_floats): points
/// an ulp apart get unrelated turns and the same point always the same one.
inline double plane_turn_hash(glm::vec3 p) noexcept {
    const auto plus_zero = [](float f) { return f == 0.f ? 0.f : f; };
    return double(hash_floats({plus_zero(p.x), plus_zero(p.y), plus_zero(p.z)}) >> 11) * 0x1p-53;
}

/// The camera of single-plane hemisphere sampling: an N x N square plane above the record.
struct plane_camera {
    std::uint32_t resolution = 64;  ///< N: pixels per side; typical 32-128 (Gautron 2008: 64)
    double aperture_deg = 126.0;    ///< full angle of the square field of view, degrees, in (0, 180); typical 126
    /// Turn of every plane about its normal from the frame of orthonormal_basis(n), degrees
    /// in [0, 90) (the square repeats every 90). Gautron 2008 leaves the turn open; that frame
    /// lays the plane's edges along the walls of an axis-aligned scene.
    double turn_deg = 0.0;
    /// Also turn each record's plane by its own angle, 90 plane_turn_hash(p) degrees: no
    /// edge keeps to the scene's axes, and neighbouring records miss different directions.
    /// docs/hemisphere-sampling.md measures both turns.
    bool hashed_turn = false;

    /// Throws parameter_error unless 1 <= resolution <= 8192, 0 < aperture < 180 and
    /// 0 <= turn < 90.
    void validate() const {
        require(resolution >= 1 && resolution <= 8192, "resolution", "must lie in [1, 8192]");
        require(std::isfinite(aperture_deg) && aperture_deg > 0.0 && aperture_deg < 180.0, "aperture_deg",
                "must lie in (0, 180) degrees");
        require(turn_deg >= 0.0 && turn_deg < 90.0, "turn_deg", "must lie in [0, 90) degrees");
    }
    /// The turn of the plane of a record at p, degrees in [0, 180).
    double turn_at(glm::vec3 p) const { return turn_deg + (hashed_turn ? 90.0 * plane_turn_hash(p) : 0.0); }
    /// The plane's frame {x, y} (z = n) of a record at p with unit normal n: the frame of
    /// orthonormal_basis(n) turned by turn_at(p) about n, exactly that frame at turn 0. The
    /// planes are rendered, and their estimates' gradients expressed, in it.
    std::array<glm::vec3, 2> frame(glm::vec3 p, glm::vec3 n) const {
        const auto tb = orthonormal_basis<float, glm::vec3>(n);
        const double turn = turn_at(p);
        if (turn == 0.0) return tb;
        const double r = turn * std::numbers::pi / 180.0;
        const float c = float(std::cos(r)), s = float(std::sin(r));
        return {c * tb[0] + s * tb[1], c * tb[1] - s * tb[0]};
    }
    /// a = tan(aperture / 2): the plane spans [-a, a]^2 at unit distance.
    double half_extent() const { return std::tan(aperture_deg * std::numbers::pi / 360.0); }
    std::size_t pixel_count() const { return std::size_t(resolution) * resolution; }
    /// Unit local direction through the centre of pixel (i, j) (plane_pixel_direction).
    glm::dvec3 direction(std::uint32_t i, std::uint32_t j) const {
        return plane_pixel_direction<double, glm::dvec3>(i, j, resolution, half_extent());
    }
};

/// Cosine-weighted solid angle (sr) of the whole square plane of half-angle h = aperture/2:
/// 4 sin(h) atan(sin(h)) (Eq. H2 at the corners (+-a, +-a), with a / sqrt(1 + a^2) = sin h).
/// Not pi sin^2(h), which is the cone's. Equals pi only in the limit h -> 90 deg.
inline double plane_cosine_solid_angle(double aperture_deg) {
    const double s = std::sin(aperture_deg * std::numbers::pi / 360.0);
    return 4.0 * s * std::atan(s);
}

/// Solid angle (sr) of the whole square plane: 4 atan(a^2 / sqrt(1 + 2 a^2)) (Eq. H1).
inline double plane_solid_angle(double aperture_deg) {
    const double a = std::tan(aperture_deg * std::numbers::pi / 360.0);
    return 4.0 * std::atan(a * a / std::sqrt(1.0 + 2.0 * a * a));
}

/// What one rendered plane holds: radiance (W/(m^2 sr), RGB) and hit distance (world
/// units, +infinity where nothing was hit) per pixel, row 0 at the top (+y).
struct plane_view {
    image_view<const glm::vec3> radiance;
    image_view<const float> distance;
};

/// Fills a plane by calling `trace(local_direction)` for the centre of every pixel, where
/// `trace` returns the pair (radiance RGB, hit distance or +infinity): the ray-cast
/// sampler's loop, for any ray caster. Throws parameter_error when a view is not N x N.
template <class F>
void sample_plane(const plane_camera& camera, F&& trace, image_view<glm::vec3> radiance, image_view<float> distance) {
    camera.validate();
    const std::size_t N = camera.resolution;
    require(radiance.width() == N && radiance.height() == N && distance.width() == N && distance.height() == N,
            "radiance/distance", "views must be resolution x resolution");
    for (std::uint32_t j = 0; j < N; ++j)
        for (std::uint32_t i = 0; i < N; ++i) {
            const auto [L, r] = trace(camera.direction(i, j));
            radiance(i, j) = L;
            distance(i, j) = r;
        }
}

}  // namespace bounce::cache
