// Irradiance by the clamped-cosine convolution (Ramamoorthi and Hanrahan 2001): the band
// factors against an independent quadrature, closed-form environments (constant, sky, cone),
// and the known truncation error of order 2 (3 bands, 9 coefficients) under one
// directional light.
#include "sphere_quadrature.hpp"

#include <bounce/sh/irradiance.hpp>
#include <bounce/sh/lights.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace bounce;
using namespace bounce::sh_test;

namespace {
constexpr double pi = std::numbers::pi;
}

TEST_CASE("the band factors are 2 pi int_0^1 x P_l(x) dx, the clamped cosine's zonal coefficients", "[sh][irradiance]") {
    // x P_l(x) has degree l + 1 <= 31: 16 Gauss-Legendre nodes mapped onto [0, 1] integrate
    // it exactly, so only rounding (terms below 1, ~1e-15) separates the two.
    std::vector<double> x, w;
    gauss_legendre(16, x, w);
    for (int l = 0; l < 31; ++l) {
        double integral = 0;
        for (std::size_t k = 0; k < x.size(); ++k) {
            const double t = 0.5 * (x[k] + 1);
            integral += 0.5 * w[k] * t * legendre(l, t);
        }
        INFO("band " << l);
        CHECK(std::abs(clamped_cosine_band_factor(l) - 2 * pi * integral) < 1e-14);
    }
    CHECK(clamped_cosine_band_factor(0) == pi);
    CHECK(std::abs(clamped_cosine_band_factor(2) - pi / 4) < 1e-15);
    CHECK(std::abs(clamped_cosine_band_factor(4) + pi / 24) < 1e-15);
    CHECK(std::abs(clamped_cosine_band_factor(6) - pi / 64) < 1e-15);
    CHECK(clamped_cosine_band_factor(3) == 0);
}

template <int L>
void check_constant_environment() {
    const glm::dvec3 radiance(0.25, 1.0, 7.5);
    const auto c = sh_project_constant<L, glm::dvec3>(radiance);
    for (const auto& n : test_directions(3, 300)) {
        const glm::dvec3 e = sh_irradiance<L, double, glm::dvec3>(c, n);
        const glm::dvec3 e_pi = sh_irradiance_over_pi<L, double, glm::dvec3>(c, n);
        for (int k = 0; k < 3; ++k) {
            INFO("bands " << L << ", normal (" << n.x << ", " << n.y << ", " << n.z << ")");
            // c_00 Y_00 A_0 = L sqrt(4 pi) / sqrt(4 pi) pi: three roundings of values <= 8 pi.
            CHECK(std::abs(e[k] - pi * radiance[k]) < 1e-12 * radiance[k]);
            CHECK(std::abs(e_pi[k] - radiance[k]) < 1e-12 * radiance[k]);
        }
    }
}

TEST_CASE("a constant environment gives E = pi L at every normal and every order, poles included", "[sh][irradiance]") {
    check_constant_environment<1>();
    check_constant_environment<2>();
    check_constant_environment<3>();
    check_constant_environment<5>();
    check_constant_environment<9>();
}

template <int L>
void check_sky() {
    const glm::dvec3 up = glm::normalize(glm::dvec3(0.2, -0.3, 0.9));
    const auto c = sh_project_uniform_sky<L, glm::dvec3>(up, glm::dvec3(2.0));
    for (const auto& n : test_directions(4, 300)) {
        const double exact = pi * 2.0 * (1 + glm::dot(n, up)) / 2;
        const double e = sh_irradiance<L, double, glm::dvec3>(c, n).x;
        INFO("bands " << L);
        // Only bands 0 and 1 of the sky survive the convolution (A_l = 0 for odd l > 1, and
        // a hemisphere has no even bands above 0), so the result is exact to rounding.
        CHECK(std::abs(e - exact) < 1e-12 * pi * 2.0);
    }
}

TEST_CASE("a uniform sky gives pi L (1 + cos theta) / 2 exactly from order 1 on", "[sh][irradiance]") {
    check_sky<2>();
    check_sky<3>();
    check_sky<8>();
}

namespace {
// The SH irradiance of a unit directional light along +z at a normal of cosine c to it:
// E(c) = sum_l A_l (2l + 1) / (4 pi) P_l(c) by the addition theorem.
template <int L>
double directional_irradiance(double c) {
    const auto coeffs = sh_project_directional_light<L, glm::dvec3>({0, 0, 1}, glm::dvec3(1.0));
    const double s = std::sqrt(std::max(0.0, 1 - c * c));
    return sh_irradiance<L, double, glm::dvec3>(coeffs, glm::dvec3(s, 0, c)).x;
}
}  // namespace

TEST_CASE("order 2 (9 coefficients) misses a directional light's irradiance by 3/32 of the peak at most, 3.07% on average",
          "[sh][irradiance]") {
    // By hand: E_2(c) = 3/32 + c/2 + 15 c^2 / 32 against max(0, c). The difference peaks at
    // grazing (c = 0) with 3/32 = 0.09375, is 1/16 at c = +-1 and -0.0396 at c = -8/15 (a
    // negative lobe); it is even in c, and its mean absolute value over the sphere,
    // int_0^1 |3/32 - c/2 + 15 c^2 / 32| dc, is 0.0306737 (roots (8 -+ sqrt 19) / 15).
    const double r1 = (8 - std::sqrt(19.0)) / 15, r2 = (8 + std::sqrt(19.0)) / 15;
    const auto g = [](double c) { return 3 * c / 32 - c * c / 4 + 5 * c * c * c / 32; };
    const double mean_closed_form = 2 * g(r1) - 2 * g(r2) + g(1);
    CHECK(std::abs(mean_closed_form - 0.0306737) < 1e-7);

    // Midpoint rule in c = cos theta (uniform in c is uniform in area) with n cells: on the
    // smooth pieces the error is h^2 / 24 max|f''| <= 1e-11 for h = 2e-5, and each of the
    // five kinks (0 and the four roots) adds at most h^2 max|f'| = 6e-10.
    constexpr int n = 100000;
    double worst = 0, mean = 0;
    for (int k = 0; k < n; ++k) {
        const double c = -1 + 2 * (k + 0.5) / n;
        const double err = std::abs(directional_irradiance<3>(c) - std::max(0.0, c));
        worst = std::max(worst, err);
        mean += err / n;
    }
    CHECK(std::abs(mean - mean_closed_form) < 1e-8);
    // The nearest cell centre to c = 0 is h/2 = 1e-5 away, where the error has slope 1/2.
    CHECK(worst <= 3.0 / 32 + 1e-12);
    CHECK(worst > 3.0 / 32 - 1e-5);
    CHECK(std::abs(directional_irradiance<3>(1) - 17.0 / 16) < 1e-14);
    CHECK(std::abs(directional_irradiance<3>(-8.0 / 15) - (3.0 / 32 - 4.0 / 15 + 2.0 / 15)) < 1e-14);
}

TEST_CASE("a cone light facing the normal gives pi L sin^2 alpha as the bands grow", "[sh][irradiance]") {
    // E(axis) = sum_l A_l 2 pi L I_l (2l + 1) / (4 pi), I_l = int_t^1 P_l
    // = (P_(l-1)(t) - P_(l+1)(t)) / (2l + 1). Bernstein's inequality
    // |P_n(cos a)| < sqrt(2 / (pi n sin a)) bounds the terms beyond band 31; the tolerance
    // is their sum to l = 10^5 (the rest is below 1e-9).
    const double cos_alpha = std::cos(0.4), radiance = 3.0, sin_alpha = std::sin(0.4);
    const auto c = sh_project_cone_light<32, glm::dvec3>({0, 0, 1}, cos_alpha, glm::dvec3(radiance));
    const double e = sh_irradiance<32, double, glm::dvec3>(c, {0, 0, 1}).x;
    double tail = 0;
    for (int l = 32; l < 100000; ++l) {
        const double p_bound = std::sqrt(2 / (pi * (l - 1) * sin_alpha)) + std::sqrt(2 / (pi * (l + 1) * sin_alpha));
        tail += std::abs(clamped_cosine_band_factor(l)) * radiance * 0.5 * p_bound;
    }
    const double exact = pi * radiance * (1 - cos_alpha * cos_alpha);
    INFO("E = " << e << ", exact " << exact << ", tail bound " << tail);
    CHECK(std::abs(e - exact) <= tail + 1e-12);
    CHECK(tail < 5e-3 * exact);  // the bound says something (0.34%)
}

TEST_CASE("sh_irradiance is sh_evaluate of the convolved coefficients, and irradiance / pi its pi-th", "[sh][irradiance]") {
    const auto c = sh_project_cone_light<6, glm::dvec3>(glm::dvec3(1, 2, -0.5), 0.8, glm::dvec3(1, 0.5, 0.25));
    const auto e = sh_convolve_clamped_cosine<6, glm::dvec3>(c);
    for (const auto& n : test_directions(8, 200)) {
        const glm::dvec3 a = sh_irradiance<6, double, glm::dvec3>(c, n), b = sh_evaluate<6, double, glm::dvec3>(e, n);
        const glm::dvec3 p = sh_irradiance_over_pi<6, double, glm::dvec3>(c, n);
        for (int k = 0; k < 3; ++k) {
            // 36 terms of size <= 1 each side, summed in different orders: ~36 ulp of 1.
            CHECK(std::abs(a[k] - b[k]) < 1e-14);
            CHECK(std::abs(p[k] - a[k] / pi) < 1e-14);
        }
    }
}
