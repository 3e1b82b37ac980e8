#pragma once
// Quadrature on the sphere for the SH tests: Gauss-Legendre in z times the trapezoid rule
// in phi. With nz nodes and nphi points it integrates exactly every polynomial of degree
// <= 2 nz - 1 in z times a trigonometric polynomial of order < nphi in phi, hence every
// product of two SH of bands < min(nz, nphi / 2): what remains is rounding.
#include <bounce/sampling.hpp>

#include <glm/glm.hpp>

#include <cmath>
#include <numbers>
#include <vector>

namespace bounce::sh_test {

struct quadrature_point {
    glm::dvec3 d;
    double w;  // sr
};

// Legendre polynomial P_l(x) by Bonnet's recurrence, independent of the kernels.
inline double legendre(int l, double x) {
    double p0 = 1, p1 = x;
    if (l == 0) return p0;
    for (int k = 2; k <= l; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
    }
    return p1;
}

// Gauss-Legendre nodes and weights on [-1, 1] by Newton's method on P_n.
inline void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
    x.resize(std::size_t(n));
    w.resize(std::size_t(n));
    for (int i = 0; i < n; ++i) {
        double t = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5)), dp = 0;
        for (int it = 0; it < 100; ++it) {
            const double p = legendre(n, t), q = legendre(n - 1, t);
            dp = n * (t * p - q) / (t * t - 1);
            const double step = p / dp;
            t -= step;
            if (std::abs(step) < 1e-16) break;
        }
        const double p = legendre(n, t), q = legendre(n - 1, t);
        dp = n * (t * p - q) / (t * t - 1);
        x[std::size_t(i)] = t;
        w[std::size_t(i)] = 2 / ((1 - t * t) * dp * dp);
    }
}

inline std::vector<quadrature_point> sphere_quadrature(int nz, int nphi) {
    std::vector<double> zs, ws;
    gauss_legendre(nz, zs, ws);
    std::vector<quadrature_point> q;
    for (int a = 0; a < nz; ++a)
        for (int b = 0; b < nphi; ++b) {
            const double z = zs[std::size_t(a)], r = std::sqrt(1 - z * z), phi = 2 * std::numbers::pi * (b + 0.5) / nphi;
            q.push_back({{r * std::cos(phi), r * std::sin(phi), z}, ws[std::size_t(a)] * 2 * std::numbers::pi / nphi});
        }
    return q;
}

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
