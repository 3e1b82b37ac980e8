#pragma once
// Test helpers of the SH tests: the library's sphere quadrature (bounce/sh/quadrature.hpp:
// Gauss-Legendre in z times the trapezoid rule in phi, exact for products of SH of bands
// < min(nz, nphi / 2)), random test directions and rotations.
#include <bounce/sampling.hpp>
#include <bounce/sh/quadrature.hpp>

#include <glm/glm.hpp>

#include <cmath>
#include <numbers>
#include <vector>

namespace bounce::sh_test {

// The library's quadrature (bounce/sh/quadrature.hpp) under the names the tests use.
using quadrature_point = bounce::sphere_quadrature_point;
using bounce::gauss_legendre;
using bounce::sphere_quadrature;
inline double legendre(int l, double x) { return bounce::legendre_polynomial(l, x); }

// Uniformly distributed random unit directions (fixed seed), after the hard cases: the
// poles, the axes, directions with tiny components.
inline std::vector<glm::dvec3> test_directions(std::uint64_t seed, int count) {
    std::vector<glm::dvec3> ds = {{0, 0, 1},  {0, 0, -1},     {1, 0, 0},        {-1, 0, 0},     {0, 1, 0},
                                  {0, -1, 0}, {1e-9, 0, 1},   {0, -1e-12, -1},  {1e-5, 1e-5, 1}, {1, 1, 1},
                                  {1, 1e-300, 0}, {-1e-20, 1, 1e-20}};
    pcg32 rng(seed);
    for (int i = 0; i < count; ++i) {
        const double z = 2 * rng.next_double() - 1, phi = 2 * std::numbers::pi * rng.next_double();
        const double r = std::sqrt(std::max(0.0, 1 - z * z));
        ds.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    for (auto& d : ds) d = glm::normalize(d);
    return ds;
}

// A uniformly random rotation (fixed seed): a random unit quaternion (Shoemake 1992).
inline glm::dmat3 random_rotation(pcg32& rng) {
    const double u1 = rng.next_double(), u2 = 2 * std::numbers::pi * rng.next_double(),
                 u3 = 2 * std::numbers::pi * rng.next_double();
    const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
    const double x = a * std::sin(u2), y = a * std::cos(u2), z = b * std::sin(u3), w = b * std::cos(u3);
    return glm::dmat3(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),  // column 0
                      2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),  // column 1
                      2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y));  // column 2
}

}  // namespace bounce::sh_test
