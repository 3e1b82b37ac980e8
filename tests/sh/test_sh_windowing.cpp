// Windowing (Sloan 2008): the windows' shapes, the energy they report against a quadrature
// of the windowed function, and irradiance of a directional light that rings below zero
// unwindowed and not after the widest non-negative window.
#include "sphere_quadrature.hpp"

#include <bounce/sh/irradiance.hpp>
#include <bounce/sh/lights.hpp>
#include <bounce/sh/windowing.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace bounce;
using namespace bounce::sh_test;

TEST_CASE("Hann and Lanczos windows start at 1, fall monotonically and vanish from the width on", "[sh][windowing]") {
    const auto hann = hann_window<8>(6.0), lanczos = lanczos_window<8>(6.0);
    CHECK(hann[0] == 1);
    CHECK(lanczos[0] == 1);
    CHECK(std::abs(hann[3] - 0.5) < 1e-15);                       // cos(pi/2) = 0
    CHECK(std::abs(lanczos[3] - 2 / std::numbers::pi) < 1e-15);   // sin(pi/2) / (pi/2)
    for (int l = 1; l < 8; ++l) {
        CHECK(hann[std::size_t(l)] <= hann[std::size_t(l - 1)]);
        CHECK(lanczos[std::size_t(l)] <= lanczos[std::size_t(l - 1)]);
        CHECK(hann[std::size_t(l)] >= 0);
    }
    CHECK(hann[6] == 0);
    CHECK(lanczos[7] == 0);
    CHECK_THROWS_AS(hann_window<3>(0.0), parameter_error);
}

TEST_CASE("the energy a window reports is the quadrature of the windowed function squared (Parseval)", "[sh][windowing]") {
    constexpr int L = 7;
    const auto c = sh_project_cone_light<L, double>(glm::dvec3(0.3, -0.2, 0.9), std::cos(0.5), 1.0);
    const auto h = hann_window<L>(L);
    const auto cost = sh_window_cost<L>(c, h);
    // f and f_w have bands < 7: their squares are integrated exactly by 8 x 16 points.
    const auto q = sphere_quadrature(8, 16);
    const auto cw = sh_apply_window<L, double>(c, h);
    double e = 0, ew = 0;
    for (const auto& p : q) {
        e += p.w * std::pow(sh_evaluate<L, double, glm::dvec3>(c, p.d), 2);
        ew += p.w * std::pow(sh_evaluate<L, double, glm::dvec3>(cw, p.d), 2);
    }
    CHECK(std::abs(cost.energy_kept - ew / e) < 1e-13);
    CHECK(cost.energy_kept < 1);
    CHECK(cost.peak_kept < 1);
    CHECK(cost.min_after > cost.min_before);  // the cone's truncation rings; the window damps it
}

namespace {
// A bound on |f''| along any great circle for a function of bands < L: Bernstein's
// inequality for spherical polynomials of degree l gives l^2 max|f_l|, and
// max|f_l| <= sqrt((2l + 1) / (4 pi)) |c_l| (Cauchy-Schwarz with the addition theorem).
template <int L>
double second_derivative_bound(const sh_coefficients<L, double>& c) {
    double b = 0;
    for (int l = 1; l < L; ++l) {
        double norm = 0;
        for (int m = -l; m <= l; ++m) norm += c[sh_index(l, m)] * c[sh_index(l, m)];
        b += double(l) * l * std::sqrt((2 * l + 1) / (4 * std::numbers::pi) * norm);
    }
    return b;
}

template <int L>
void check_nonnegative_irradiance(sh_window_family family) {
    // A unit directional light along +z: its irradiance is zonal, so a fine profile in
    // c = cos theta sees every value it takes.
    const auto radiance = sh_project_directional_light<L, double>({0, 0, 1}, 1.0);
    const auto e = sh_convolve_clamped_cosine<L, double>(radiance);
    auto profile_min = [](const sh_coefficients<L, double>& f) {
        double lo = INFINITY;
        for (int k = 0; k <= 20000; ++k) {
            const double c = -1 + k / 10000.0, s = std::sqrt(std::max(0.0, 1 - c * c));
            lo = std::min(lo, sh_evaluate<L, double, glm::dvec3>(f, glm::dvec3(s, 0, c)));
        }
        return lo;
    };
    INFO("bands " << L << ", family " << int(family));
    CHECK(profile_min(e) < -0.01);  // order >= 2 rings below zero without a window
    constexpr std::size_t probes = 4096;
    const double w = sh_nonnegative_window_width<L>(e, family, L, probes);
    const auto ew = sh_apply_window<L, double>(e, sh_window<L>(family, w));
    // The probes' minimum is >= 0; a minimum between them is lower by at most
    // 1/2 max|f''| r^2, r the covering radius of the spherical Fibonacci set, below
    // 2 sqrt(4 pi / N).
    const double tolerance = 0.5 * second_derivative_bound<L>(ew) * 4 * (4 * std::numbers::pi / probes);
    INFO("width " << w << ", tolerance " << tolerance);
    CHECK(profile_min(ew) >= -tolerance);
    CHECK(w >= 1);
}
}  // namespace

TEST_CASE("the widest non-negative window leaves no negative irradiance under a directional light", "[sh][windowing]") {
    for (const auto family : {sh_window_family::hann, sh_window_family::lanczos}) {
        check_nonnegative_irradiance<3>(family);
        check_nonnegative_irradiance<5>(family);
        check_nonnegative_irradiance<9>(family);
    }
    sh_coefficients<3, double> negative_mean{};
    negative_mean[0] = -1;
    CHECK_THROWS_AS(sh_nonnegative_window_width<3>(negative_mean, sh_window_family::hann, 3.0), parameter_error);
}
