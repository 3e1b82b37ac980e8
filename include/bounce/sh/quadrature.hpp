#pragma once
/// \file sh/quadrature.hpp
/// Quadrature on [-1, 1] and on the sphere, for integrals of SH products and of functions
/// of one cosine (zonal environments, irradiance profiles). Double precision, CPU only.
///
/// - `gauss_legendre(n, x, w)`: the n-point Gauss-Legendre rule, exact for polynomials of
///   degree <= 2n - 1 on [-1, 1] (nodes by Newton's method on P_n).
/// - `sphere_quadrature(nz, nphi)`: Gauss-Legendre in z times the trapezoid rule in phi.
///   It integrates exactly every polynomial of degree <= 2 nz - 1 in z times a
///   trigonometric polynomial of order < nphi in phi, hence every product of two SH of
///   bands < min(nz, nphi / 2): what remains is rounding.

#include <bounce/errors.hpp>

#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::inline sh {

/// Legendre polynomial P_l(x) by Bonnet's recurrence (l >= 0).
inline double legendre_polynomial(int l, double x) {
    double p0 = 1, p1 = x;
    if (l == 0) return p0;
    for (int k = 2; k <= l; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
    }
    return p1;
}

/// Nodes `x` and weights `w` (sum 2) of the n-point Gauss-Legendre rule on [-1, 1].
/// Throws parameter_error naming "n" unless 1 <= n <= 1000.
inline void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
    require(n >= 1 && n <= 1000, "n", "Gauss-Legendre nodes must number 1 .. 1000");
    x.resize(std::size_t(n));
    w.resize(std::size_t(n));
    if (n == 1) {
        x[0] = 0;
        w[0] = 2;
        return;
    }
    for (int i = 0; i < n; ++i) {
        double t = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5)), dp = 0;
        for (int it = 0; it < 100; ++it) {
            const double p = legendre_polynomial(n, t), q = legendre_polynomial(n - 1, t);
            dp = n * (t * p - q) / (t * t - 1);
            const double step = p / dp;
            t -= step;
            if (std::abs(step) < 1e-16) break;
        }
        const double p = legendre_polynomial(n, t), q = legendre_polynomial(n - 1, t);
        dp = n * (t * p - q) / (t * t - 1);
        x[std::size_t(i)] = t;
        w[std::size_t(i)] = 2 / ((1 - t * t) * dp * dp);
    }
}

/// The integral of f over [lo, hi] by the rule (x, w) of gauss_legendre.
template <class F>
double gauss_legendre_integral(const std::vector<double>& x, const std::vector<double>& w, double lo, double hi, F&& f) {
    double s = 0;
    for (std::size_t k = 0; k < x.size(); ++k) s += w[k] * f(0.5 * (hi - lo) * x[k] + 0.5 * (hi + lo));
    return 0.5 * (hi - lo) * s;
}

/// A direction on the unit sphere and its quadrature weight (sr).
struct sphere_quadrature_point {
    glm::dvec3 d;
    double w;
};

/// nz Gauss-Legendre rings in z times nphi equally spaced azimuths (offset by half a step);
/// the weights sum to 4 pi. Throws parameter_error naming "nz" or "nphi" unless >= 1.
inline std::vector<sphere_quadrature_point> sphere_quadrature(int nz, int nphi) {
    require(nphi >= 1, "nphi", "at least one azimuth");
    std::vector<double> zs, ws;
    gauss_legendre(nz, zs, ws);
    std::vector<sphere_quadrature_point> q;
    q.reserve(std::size_t(nz) * std::size_t(nphi));
    for (int a = 0; a < nz; ++a)
        for (int b = 0; b < nphi; ++b) {
            const double z = zs[std::size_t(a)], r = std::sqrt(1 - z * z), phi = 2 * std::numbers::pi * (b + 0.5) / nphi;
            q.push_back({{r * std::cos(phi), r * std::sin(phi), z}, ws[std::size_t(a)] * 2 * std::numbers::pi / nphi});
        }
    return q;
}

}  // namespace bounce::sh
