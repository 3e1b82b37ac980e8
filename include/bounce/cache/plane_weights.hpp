#pragma once
/// \file cache/plane_weights.hpp
/// The per-pixel weight tables of the hemisphere plane camera (cache/plane_camera.hpp), for the
/// ways of accounting for the directions the plane misses: plane only, coverage scaling
/// (Larsen and Christensen 2004), border stretching (Gautron 2008, section 8.4) and
/// fall-off stretching (cache/radial_profile.hpp gives its band factor).
///
/// Every weight is the exact integral over the pixel's rectangle, from the closed forms of
/// rectangle_solid_angle.hpp (Eqs. H1-H3). Directions the plane misses (between its edge and
/// the horizon) are, for border stretching, split among the border pixels by azimuth: the
/// band beyond the edge segment of a border pixel is the set of directions whose azimuth
/// passes through that segment. Seen on the side plane through the edge (x = 1 for the right
/// edge, coordinates u = y / x, v = z / x), that band is the rectangle
/// [s0 / a, s1 / a] x [0, 1 / a], so the same closed forms give its weights exactly; corner
/// pixels own two such bands.

#include <bounce/errors.hpp>
#include <bounce/cache/plane_camera.hpp>
#include <bounce/cache/plane_pixel.hpp>
#include <bounce/rectangle_solid_angle.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include <glm/glm.hpp>

namespace bounce::inline cache {

/// How the directions the plane misses are accounted for.
enum class plane_weighting {
    plane,     ///< plane only: the pixels' own cosine-weighted solid angles (misses the band)
    coverage,  ///< Larsen and Christensen 2004: plane weights scaled by pi / their sum
    stretch,   ///< border stretching (Gautron 2008, section 8.4): each border pixel also carries its azimuth band
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

}  // namespace bounce::cache

namespace bounce::detail {

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

}  // namespace bounce::detail

namespace bounce::inline cache {

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

}  // namespace bounce::cache
