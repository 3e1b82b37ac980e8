#pragma once
/// \file hemisphere.hpp
/// Hemisphere sampling on one plane (seed 000, section 8.4): the plane camera above a
/// record, the exact solid angle and cosine-weighted solid angle of its pixels, and the
/// per-pixel terms of irradiance, rotation and translation gradients and harmonic mean
/// distance, summed on the CPU or (emitted as GLSL) on the GPU.
///
/// The plane is z = 1 in the record's local frame (x, y tangent, z the normal); the camera
/// at the record looks along z with a square field of view of `aperture` (full angle), so
/// the plane spans [-a, a]^2 with a = tan(aperture / 2). Pixel (i, j) of an N x N plane,
/// column i along +x, row j from the top (+y) down, covers
///   x in [a (2 i / N - 1), a (2 (i + 1) / N - 1)],  y in [a (1 - 2 (j + 1) / N), a (1 - 2 j / N)].
///
/// Every weight is the exact integral over the pixel's rectangle, from three closed forms
/// for a rectangle [u0, u1] x [v0, v1] on a plane at unit distance along its normal w
/// (d = sqrt(1 + u^2 + v^2), direction omega = (u, v, 1) / d, d omega = du dv / d^3), each
/// a corner function F with int = F(u1, v1) - F(u0, v1) - F(u1, v0) + F(u0, v0):
///  - solid angle:      F = atan(u v / d)                                     (Eq. H1)
///  - int omega_w dw:   F = (u/cu atan(v/cu) + v/cv atan(u/cv)) / 2            (Eq. H2)
///  - int omega_u dw:   F = -atan(v/cu) / (2 cu)                               (Eq. H3)
///  - int omega_v dw:   F = -atan(u/cv) / (2 cv),   cu = sqrt(1+u^2), cv = sqrt(1+v^2)
/// (each checked by differentiating: d2F/du dv is the integrand). H2 is the cosine-weighted
/// solid angle (the differential-area-to-parallel-rectangle form factor times pi), H3 the
/// in-plane moments the rotation gradient needs. Derivations: docs/hemisphere-sampling.md.
///
/// Directions the plane misses (between its edge and the horizon) are, for border
/// stretching, split among the border pixels by azimuth: the band beyond the edge segment
/// of a border pixel is the set of directions whose azimuth passes through that segment.
/// Seen on the side plane through the edge (x = 1 for the right edge, coordinates
/// u = y / x, v = z / x), that band is the rectangle [s0 / a, s1 / a] x [0, 1 / a], so the
/// same three closed forms give its weights exactly; corner pixels own two such bands.

#include <bounce/concepts.hpp>
#include <bounce/errors.hpp>
#include <bounce/image.hpp>
#include <bounce/irradiance_gradients.hpp>
#include <bounce/sampling.hpp>
#include <bounce/vocabulary.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace bounce {

// ---------------------------------------------------------------------------------------
// Kernels: rectangles on a plane at unit distance

/// Corner function of the solid angle of a rectangle on the plane at unit distance
/// (Eq. H1): atan(u v / sqrt(1 + u^2 + v^2)). Dimensionless (u, v in units of the distance).
template <real T>
T rectangle_solid_angle_corner(T u, T v) {
    return atan(u * v, sqrt(T(1) + u * u + v * v));
}

/// Solid angle (sr) subtended at the origin by the rectangle [u0, u1] x [v0, v1] on the
/// plane at unit distance (corner differences of Eq. H1; exact, unlike the midpoint rule
/// cos^3 du dv). Requires u0 <= u1, v0 <= v1.
template <real T>
T rectangle_solid_angle(T u0, T v0, T u1, T v1) {
    return rectangle_solid_angle_corner<T>(u1, v1) - rectangle_solid_angle_corner<T>(u0, v1) -
           rectangle_solid_angle_corner<T>(u1, v0) + rectangle_solid_angle_corner<T>(u0, v0);
}

/// Corner function of the first moment int omega d omega of a rectangle on the plane at
/// unit distance (Eqs. H2, H3), as (u component, v component, normal component).
template <real T, vec3_of<T> V>
V rectangle_moment_corner(T u, T v) {
    const T cu = sqrt(T(1) + u * u), cv = sqrt(T(1) + v * v);
    const T au = atan(v, cu), av = atan(u, cv);  // atan(v / cu), atan(u / cv): cu, cv > 0
    return V(-au / (T(2) * cu), -av / (T(2) * cv), (u / cu * au + v / cv * av) / T(2));
}

/// The first moment int omega d omega over the rectangle [u0, u1] x [v0, v1] on the plane at
/// unit distance, in the plane's frame: (int omega_u, int omega_v, int omega_w) in sr. Its
/// normal component is the rectangle's cosine-weighted solid angle int cos(theta) d omega
/// (pi times the form factor from a differential area facing the plane); the in-plane
/// components give the rotation gradient's weights. Requires u0 <= u1, v0 <= v1.
template <real T, vec3_of<T> V>
V rectangle_moment(T u0, T v0, T u1, T v1) {
    return rectangle_moment_corner<T, V>(u1, v1) - rectangle_moment_corner<T, V>(u0, v1) -
           rectangle_moment_corner<T, V>(u1, v0) + rectangle_moment_corner<T, V>(u0, v0);
}

/// Cosine-weighted solid angle (sr) of the rectangle [u0, u1] x [v0, v1] on the plane at
/// unit distance: int cos(theta) d omega, theta measured from the plane's normal (Eq. H2).
template <real T, vec3_of<T> V>
T rectangle_cosine_solid_angle(T u0, T v0, T u1, T v1) {
    return rectangle_moment<T, V>(u0, v0, u1, v1).z;
}

// ---------------------------------------------------------------------------------------
// Kernels: the plane camera's pixels

/// Left, bottom, right, top edges (x0, y0, x1, y1) of pixel (i, j) of an n x n plane of
/// half-extent a = tan(aperture / 2), on the plane z = 1 (see the file comment: column i
/// along +x, row j from the top). i, j, n are passed as reals so that GLSL can call it.
template <real T>
std::array<T, 4> plane_pixel_bounds(T i, T j, T n, T a) {
    const T step = T(2) * a / n;
    return {step * i - a, a - step * (j + T(1)), step * (i + T(1)) - a, a - step * j};
}

/// Unit local direction (z along the record's normal) through the centre of pixel (i, j)
/// of an n x n plane of half-extent a.
template <real T, vec3_of<T> V>
V plane_pixel_direction(T i, T j, T n, T a) {
    const T step = T(2) * a / n;
    return normalize(V(step * (i + T(0.5)) - a, a - step * (j + T(0.5)), T(1)));
}

/// Hit distance a plane pixel stores: |p - eye| from the record's (offset) position `eye` to
/// the surface point `p` (world units), the r of the translation gradient's walls and of
/// the harmonic mean distance. At least 1e-30: a surface through the eye (a record in a
/// corner) can round to distance 0 in float, and distances must stay positive.
template <real T, vec3_of<T> V>
T plane_hit_distance(const V& p, const V& eye) {
    return max(length(p - eye), T(1e-30));
}

/// The contributions of one plane pixel to a record; summed over the plane they give
/// irradiance, gradients and harmonic mean distance (estimate_plane shows the sums).
/// Weights, from a plane_weights table:
///  - `w`: the cosine-weighted solid angle (sr) the pixel's radiance stands for;
///  - `wd`: the same for its hit distance (differs from w only for fall-off stretching,
///    whose band carries attenuated radiance but the border pixel's full distance);
///  - `rot`: int (n x omega) d omega over what the pixel stands for (x, y; sr);
///  - `left`, `up`: translation weights of its walls with the pixels to its left (i - 1)
///    and above (j - 1), tangent-plane vectors (sr-like, per unit of 1 / distance);
///  - `edge`: translation weight of the wall between a border pixel and its own band, for
///    the radiance step (band - border) = -L * edge-scale; 0 inside the plane.
/// Samples: the pixel's radiance L and hit distance r (+infinity for an escaped ray), and
/// those of its left and upper neighbours (any value where the wall weight is 0).
/// Outputs: w L, rot.x L, rot.y L, translation along x and along y, wd / r, wd.
/// A wall moves with the nearer of its two surfaces (Ward and Heckbert 1992; Krivanek et
/// al. 2005), so a radiance step is divided by the smaller distance; escaped rays give 0.
template <real T, vec3_of<T> V, vec2_of<T> V2>
std::tuple<V, V, V, V, V, T, T> plane_pixel_terms(T w, T wd, V2 rot, V2 left, V2 up, V2 edge, V L, V L_left, V L_up,
                                                  T r, T r_left, T r_up) {
    const T far = T(3.0e38);  // beyond any hit distance: an escaped ray (float max ~3.4e38)
    const T near_left = min(r, r_left), near_up = min(r, r_up);
    const T inv_left = select(near_left < far, T(1) / max(near_left, T(1e-30)), T(0));
    const T inv_up = select(near_up < far, T(1) / max(near_up, T(1e-30)), T(0));
    const T inv_r = select(r < far, T(1) / max(r, T(1e-30)), T(0));
    const V d_left = (L - L_left) * inv_left, d_up = (L - L_up) * inv_up, d_self = L * inv_r;
    return {L * w,
            L * rot.x,
            L * rot.y,
            d_left * left.x + d_up * up.x + d_self * edge.x,
            d_left * left.y + d_up * up.y + d_self * edge.y,
            wd * inv_r,
            wd};
}

/// Rec. 709 luminance of linear RGB (the error figures and the fall-off profile use it).
template <real T, vec3_of<T> V>
T rec709_luminance(const V& c) {
    return T(0.2126) * c.x + T(0.7152) * c.y + T(0.0722) * c.z;
}

// ---------------------------------------------------------------------------------------
// The plane camera and its weight tables

/// A number in [0, 1) hashed from the bits of a position (+0 and -0 alike), the fraction of
/// a quarter turn that plane_camera::hashed_turn gives a record's plane (hash_floats): points
/// an ulp apart get unrelated turns and the same point always the same one.
inline double plane_turn_hash(glm::vec3 p) noexcept {
    const auto plus_zero = [](float f) { return f == 0.f ? 0.f : f; };
    return double(hash_floats({plus_zero(p.x), plus_zero(p.y), plus_zero(p.z)}) >> 11) * 0x1p-53;
}

/// The camera of single-plane hemisphere sampling: an N x N square plane above the record.
struct plane_camera {
    std::uint32_t resolution = 64;  ///< N: pixels per side; typical 32-128 (seed: 64)
    double aperture_deg = 126.0;    ///< full angle of the square field of view, degrees, in (0, 180); typical 126
    /// Turn of every plane about its normal from the frame of orthonormal_basis(n), degrees
    /// in [0, 90) (the square repeats every 90). The seed leaves the turn open; that frame
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

/// How the directions the plane misses are accounted for.
enum class plane_weighting {
    plane,     ///< plane only: the pixels' own cosine-weighted solid angles (misses the band)
    coverage,  ///< Larsen and Christensen 2004: plane weights scaled by pi / their sum
    stretch,   ///< border stretching (seed 8.4): each border pixel also carries its azimuth band
    falloff,   ///< fall-off stretching: the band carries kappa times the border radiance (radial_profile)
};

/// Name of a weighting as the study and its JSON spell it.
inline const char* to_string(plane_weighting k) {
    switch (k) {
    case plane_weighting::plane: return "plane";
    case plane_weighting::coverage: return "coverage";
    case plane_weighting::stretch: return "stretch";
    case plane_weighting::falloff: return "falloff";
    }
    return "?";
}

/// Per-pixel weights of one plane camera and one weighting, pixel (i, j) at j * N + i (the
/// inputs of plane_pixel_terms). All in double; the GPU reduction uploads them as float.
struct plane_weights {
    plane_camera camera;
    plane_weighting kind = plane_weighting::stretch;
    double band_factor = 1.0;           ///< radiance factor of the band: 0 plane/coverage, 1 stretch, kappa falloff
    std::vector<double> irradiance;     ///< w: cosine-weighted solid angle the pixel's radiance stands for (sr)
    std::vector<double> distance;       ///< wd: cosine-weighted solid angle its hit distance stands for (sr)
    std::vector<glm::dvec2> rotation;   ///< int (n x omega) d omega, times the band factor over the band (sr)
    std::vector<glm::dvec2> left_wall;  ///< translation weight of the wall with pixel (i - 1, j)
    std::vector<glm::dvec2> up_wall;    ///< translation weight of the wall with pixel (i, j - 1)
    std::vector<glm::dvec2> edge_wall;  ///< translation weight of the step between a border pixel and its band
    /// Factor applied to the irradiance and gradient sums (pi / sum of w for coverage, else 1).
    double scale = 1.0;

    /// Sum of the irradiance weights times scale: the cosine-weighted solid angle the table
    /// integrates (pi for coverage and stretch).
    double total() const {
        double s = 0;
        for (double w : irradiance) s += w;
        return s * scale;
    }
};

namespace detail {

/// Which side of the plane a border segment lies on.
enum class plane_edge { right, left, top, bottom };

/// First moment (local frame) of the band of directions between the plane's edge and the
/// horizon whose azimuths pass through the edge segment s in [s0, s1] (y on the right and
/// left edges, x on the top and bottom ones) of the plane of half-extent a. On the side
/// plane of that edge (e.g. x = 1, u = y / x, v = z / x) the band is the rectangle
/// [s0 / a, s1 / a] x [0, 1 / a]; the moment's components map back to local axes.
inline glm::dvec3 band_moment(plane_edge e, double s0, double s1, double a) {
    const glm::dvec3 m = rectangle_moment<double, glm::dvec3>(s0 / a, 0.0, s1 / a, 1.0 / a);
    switch (e) {
    case plane_edge::right: return {m.z, m.x, m.y};
    case plane_edge::left: return {-m.z, m.x, m.y};
    case plane_edge::top: return {m.x, m.z, m.y};
    case plane_edge::bottom: return {m.x, -m.z, m.y};
    }
    return {};
}

/// Translation weight (tangent plane) of the straight wall x = xw, y in [y0, y1] of the plane
/// z = 1, for the cell on its +x side: the tangential part of int cos(theta) nu dl, nu the
/// unit normal of the wall's great circle, (1, 0, -xw) / d: (1 / d^2) [y / sqrt(d^2 + y^2)]
/// with d^2 = 1 + xw^2 (docs/hemisphere-sampling.md, "Translation").
inline double line_wall(double xw, double y0, double y1) {
    const double d2 = 1.0 + xw * xw;
    return (y1 / std::sqrt(d2 + y1 * y1) - y0 / std::sqrt(d2 + y0 * y0)) / d2;
}

/// Translation weight of the radial wall beyond the plane's edge point (ex, ey) (between
/// two border pixels' bands): a vertical great half-circle at the point's azimuth from its
/// elevation to the horizon, int cos(theta) dtheta = 1 - sin(theta_e), along the horizontal
/// unit normal of the wall that points towards `into` (a point of the owning pixel).
inline glm::dvec2 band_wall(glm::dvec2 edge_point, glm::dvec2 into) {
    const double rho = glm::length(edge_point);
    const glm::dvec2 normal = glm::dvec2(-edge_point.y, edge_point.x) / rho;
    const double sign = glm::dot(normal, into - edge_point) >= 0 ? 1.0 : -1.0;
    return normal * (sign * (1.0 - rho / std::sqrt(1.0 + rho * rho)));
}

}  // namespace detail

/// The weight table of `camera` for weighting `kind`, from the closed forms (exact to
/// rounding in double). `kappa` is the band's radiance factor of fall-off stretching
/// (radial_profile::falloff_factor; typical 0.8-0.95) and is ignored by the other kinds.
/// Every irradiance weight is >= 0; stretch and coverage integrate pi, plane integrates
/// plane_cosine_solid_angle(aperture), falloff the plane plus kappa times the band.
/// Throws parameter_error for an invalid camera or a kappa outside [0, 1].
inline plane_weights make_plane_weights(const plane_camera& camera, plane_weighting kind, double kappa = 1.0) {
    camera.validate();
    const bool bands = kind == plane_weighting::stretch || kind == plane_weighting::falloff;
    if (kind == plane_weighting::falloff)
        require(std::isfinite(kappa) && kappa >= 0.0 && kappa <= 1.0, "kappa", "must lie in [0, 1]");
    const double k = kind == plane_weighting::falloff ? kappa : bands ? 1.0 : 0.0;
    const std::uint32_t N = camera.resolution;
    const double a = camera.half_extent(), n = N;
    const std::size_t count = camera.pixel_count();
    plane_weights t;
    t.camera = camera;
    t.kind = kind;
    t.band_factor = k;
    t.irradiance.assign(count, 0.0);
    t.distance.assign(count, 0.0);
    t.rotation.assign(count, glm::dvec2(0));
    t.left_wall.assign(count, glm::dvec2(0));
    t.up_wall.assign(count, glm::dvec2(0));
    t.edge_wall.assign(count, glm::dvec2(0));
    // n x m for a moment m: the rotation weight (int (n x omega) d omega, n = +z).
    const auto cross_z = [](const glm::dvec3& m) { return glm::dvec2(-m.y, m.x); };
    using detail::plane_edge;

    for (std::uint32_t j = 0; j < N; ++j)
        for (std::uint32_t i = 0; i < N; ++i) {
            const auto b = plane_pixel_bounds<double>(i, j, n, a);  // x0, y0, x1, y1
            const std::size_t at = std::size_t(j) * N + i;
            const glm::dvec3 m = rectangle_moment<double, glm::dvec3>(b[0], b[1], b[2], b[3]);
            glm::dvec3 band(0);
            glm::dvec2 outward(0);  // line-wall weights of the pixel's edge segments, towards its bands
            if (bands) {
                if (i == N - 1) {
                    band += detail::band_moment(plane_edge::right, b[1], b[3], a);
                    outward.x += detail::line_wall(a, b[1], b[3]);
                }
                if (i == 0) {
                    band += detail::band_moment(plane_edge::left, b[1], b[3], a);
                    outward.x -= detail::line_wall(-a, b[1], b[3]);
                }
                if (j == 0) {
                    band += detail::band_moment(plane_edge::top, b[0], b[2], a);
                    outward.y += detail::line_wall(a, b[0], b[2]);
                }
                if (j == N - 1) {
                    band += detail::band_moment(plane_edge::bottom, b[0], b[2], a);
                    outward.y -= detail::line_wall(-a, b[0], b[2]);
                }
            }
            // Rounding can leave a cancelling corner sum a hair below 0 for a pixel of
            // vanishing weight; the weight is a measure, so clamp at 0.
            t.irradiance[at] = std::max(0.0, m.z + k * band.z);
            t.distance[at] = std::max(0.0, m.z + band.z);
            t.rotation[at] = cross_z(m + k * band);
            // The band's radiance k L differs from the pixel's by (k - 1) L across the
            // plane's edge: a wall towards the band (0 for stretching).
            t.edge_wall[at] = (k - 1.0) * outward;
            const glm::dvec2 centre((b[0] + b[2]) / 2, (b[1] + b[3]) / 2);
            if (i > 0) {
                // Wall x = x0 between (i - 1, j) and (i, j); this pixel lies on its +x side.
                t.left_wall[at] = glm::dvec2(detail::line_wall(b[0], b[1], b[3]), 0.0);
                if (bands && j == 0) t.left_wall[at] += k * detail::band_wall({b[0], a}, centre);
                if (bands && j == N - 1) t.left_wall[at] += k * detail::band_wall({b[0], -a}, centre);
            }
            if (j > 0) {
                // Wall y = y1 between (i, j - 1) above and (i, j); this pixel lies on its -y side.
                t.up_wall[at] = glm::dvec2(0.0, -detail::line_wall(b[3], b[0], b[2]));
                if (bands && i == 0) t.up_wall[at] += k * detail::band_wall({-a, b[3]}, centre);
                if (bands && i == N - 1) t.up_wall[at] += k * detail::band_wall({a, b[3]}, centre);
            }
        }
    if (kind == plane_weighting::coverage) {
        double sum = 0;
        for (double w : t.irradiance) sum += w;
        t.scale = std::numbers::pi / sum;
    }
    return t;
}

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

/// What one rendered plane holds: radiance (W/(m^2 sr), RGB) and hit distance (world
/// units, +infinity where nothing was hit) per pixel, row 0 at the top (+y).
struct plane_view {
    image_view<const glm::vec3> radiance;
    image_view<const float> distance;
};

/// Irradiance, rotation and translation gradients (local frame, tangent components) and
/// harmonic mean distance sum wd / sum(wd / r) from one rendered plane and a weight table:
/// the sums of plane_pixel_terms in double, irradiance and gradients times weights.scale.
/// Throws parameter_error when the views are not N x N or the table is not the camera's,
/// and on a non-finite radiance or a non-positive (or NaN) distance.
inline hemisphere_estimate estimate_plane(const plane_weights& weights, plane_view plane) {
    const std::size_t N = weights.camera.resolution;
    require(plane.radiance.width() == N && plane.radiance.height() == N && plane.distance.width() == N &&
                plane.distance.height() == N,
            "plane", "radiance and distance must be resolution x resolution");
    require(weights.irradiance.size() == N * N && weights.distance.size() == N * N && weights.rotation.size() == N * N &&
                weights.left_wall.size() == N * N && weights.up_wall.size() == N * N &&
                weights.edge_wall.size() == N * N,
            "weights", "table size does not match its camera");
    hemisphere_estimate e;
    glm::dvec3 rx(0), ry(0), tx(0), ty(0);
    double inv_distance = 0, weight = 0;
    for (std::size_t j = 0; j < N; ++j)
        for (std::size_t i = 0; i < N; ++i) {
            const glm::dvec3 L(plane.radiance(i, j));
            const double r = plane.distance(i, j);
            require(std::isfinite(L.x) && std::isfinite(L.y) && std::isfinite(L.z), "plane.radiance",
                    "non-finite radiance");
            require(r > 0.0 && !std::isnan(r), "plane.distance", "hit distance must be positive");
            const std::size_t at = j * N + i, li = i > 0 ? i - 1 : i, uj = j > 0 ? j - 1 : j;
            const auto [te, trx, tr_y, ttx, tty, tinv, tw] = plane_pixel_terms<double, glm::dvec3, glm::dvec2>(
                weights.irradiance[at], weights.distance[at], weights.rotation[at], weights.left_wall[at],
                weights.up_wall[at], weights.edge_wall[at], L, glm::dvec3(plane.radiance(li, j)),
                glm::dvec3(plane.radiance(i, uj)), r, double(plane.distance(li, j)), double(plane.distance(i, uj)));
            e.irradiance += te;
            rx += trx;
            ry += tr_y;
            tx += ttx;
            ty += tty;
            inv_distance += tinv;
            weight += tw;
        }
    const double s = weights.scale;
    e.irradiance *= s;
    for (int c = 0; c < 3; ++c) {
        e.rotation[c] = glm::dvec3(rx[c], ry[c], 0) * s;
        e.translation[c] = glm::dvec3(tx[c], ty[c], 0) * s;
    }
    if (inv_distance > 0) e.harmonic_mean_distance = weight / inv_distance;
    return e;
}

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

}  // namespace bounce
