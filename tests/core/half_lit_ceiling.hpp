#pragma once
// The half-lit ceiling of test_irradiance_gradients.cpp seen by a plane camera, and rigorous
// bounds on the error of point-sampled plane estimates of it (shared by tests/core and
// tests/hemisphere).
#include <bounce/cache/plane_camera.hpp>
#include <bounce/cache/plane_weights.hpp>
#include <bounce/rectangle_solid_angle.hpp>

#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

namespace bounce::ceiling_test {

// The half-lit ceiling of test_irradiance_gradients.cpp: an infinite plane at height h above
// the point, radiance L0 where (world) x cos(rot) + y sin(rot) > -x0, 0 elsewhere.
struct half_lit_ceiling {
    double h, x0, L0, rot;
    std::pair<glm::vec3, float> trace(const glm::dvec3& d) const {
        const double t = h / d.z;
        const double along = t * (d.x * std::cos(rot) + d.y * std::sin(rot));
        return {glm::vec3(float(along > -x0 ? L0 : 0.0)), float(t)};
    }
    double E() const { return std::numbers::pi * L0 / 2 * (1 + x0 / std::hypot(x0, h)); }
    double dE_dx() const { return std::numbers::pi * L0 / 2 * h * h / std::pow(x0 * x0 + h * h, 1.5); }
    double rot_y() const { return std::numbers::pi * L0 / 2 * h / std::hypot(x0, h); }
    glm::dvec3 along() const { return {std::cos(rot), std::sin(rot), 0}; }
    glm::dvec3 across() const { return {-std::sin(rot), std::cos(rot), 0}; }
};

// Bounds on the error of a point-sampled estimate of the half-lit ceiling: a cell (a pixel's
// rectangle, or the band beyond a border pixel's edge segment) whose lit indicator is not
// constant can be wrong by at most L0 times its cosine-weighted solid angle in E, and by
// L0 times its solid angle in |grad_r| (since |n x omega| <= 1). The lit region is a half
// plane in plane coordinates, each cell convex, so a cell is uniform when its corners (for
// a band: the segment's ends and their directions at infinity) agree. A band inherits its
// border pixel's centre sample, so it also counts when that pixel is mixed.
struct error_bound {
    double E = 0, rotation = 0;
};
inline error_bound mixed_cells(const plane_camera& cam, const half_lit_ceiling& hc, bool with_bands) {
    const double a = cam.half_extent(), c = std::cos(hc.rot), s = std::sin(hc.rot), k = -hc.x0 / hc.h;
    const auto side = [&](double x, double y) { return x * c + y * s > k; };
    const auto at_infinity = [&](double x, double y) { return x * c + y * s > 0; };
    const std::uint32_t N = cam.resolution;
    error_bound b;
    for (std::uint32_t j = 0; j < N; ++j)
        for (std::uint32_t i = 0; i < N; ++i) {
            const auto r = plane_pixel_bounds<double>(i, j, N, a);
            const bool s00 = side(r[0], r[1]);
            const bool mixed = s00 != side(r[2], r[1]) || s00 != side(r[0], r[3]) || s00 != side(r[2], r[3]);
            if (mixed) {
                b.E += rectangle_cosine_solid_angle<double, glm::dvec3>(r[0], r[1], r[2], r[3]);
                b.rotation += rectangle_solid_angle<double>(r[0], r[1], r[2], r[3]);
            }
            if (!with_bands) continue;
            // Segments of the plane's edge this pixel owns: (q0, q1) and the band's extent
            // along the edge, s in [s0, s1].
            std::vector<std::pair<glm::dvec2, glm::dvec2>> segments;
            if (i == N - 1) segments.push_back({{a, r[1]}, {a, r[3]}});
            if (i == 0) segments.push_back({{-a, r[1]}, {-a, r[3]}});
            if (j == 0) segments.push_back({{r[0], a}, {r[2], a}});
            if (j == N - 1) segments.push_back({{r[0], -a}, {r[2], -a}});
            for (const auto& [q0, q1] : segments) {
                const bool v = side(q0.x, q0.y);
                const bool band_mixed = v != side(q1.x, q1.y) || v != at_infinity(q0.x, q0.y) ||
                                        v != at_infinity(q1.x, q1.y);
                if (!(band_mixed || mixed)) continue;
                // The band on the side plane: [s0/a, s1/a] x [0, 1/a] (cache/plane_weights.hpp).
                const bool vertical = q0.x == q1.x;
                const double s0 = vertical ? q0.y : q0.x, s1 = vertical ? q1.y : q1.x;
                // Its cosine weight is the moment along the side plane's v = z / x axis.
                b.E += rectangle_moment<double, glm::dvec3>(s0 / a, 0.0, s1 / a, 1.0 / a).y;
                b.rotation += rectangle_solid_angle<double>(s0 / a, 0.0, s1 / a, 1.0 / a);
            }
        }
    return b;
}


}  // namespace bounce::ceiling_test
