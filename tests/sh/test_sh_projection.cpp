// Projection onto SH: exact cube-map texel solid angles, cube-map and latitude-longitude
// quadrature (constant maps exact, smooth maps converging as h^2), Monte Carlo within its
// own standard error, regularized least squares against the perturbation bound of its
// normal equations, and bad input.
#include "sphere_quadrature.hpp"

#include <bounce/sh/irradiance.hpp>
#include <bounce/sh/lights.hpp>
#include <bounce/sh/projection.hpp>
#include <bounce/sh/windowing.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

using namespace bounce;
using namespace bounce::sh_test;

namespace {

constexpr double pi = std::numbers::pi;
constexpr double eps = std::numeric_limits<double>::epsilon();

// A cube map holding f(direction) at every texel centre.
template <class P, class F>
struct cube_storage {
    std::array<image<P>, 6> faces;
    cube_storage(std::size_t n, F f) {
        for (int k = 0; k < 6; ++k) {
            faces[std::size_t(k)] = image<P>(n, n);
            for (std::size_t y = 0; y < n; ++y)
                for (std::size_t x = 0; x < n; ++x) faces[std::size_t(k)](x, y) = P(f(cube_texel_direction(cube_face(k), n, x, y)));
        }
    }
    cube_map_view<const P> view() const {
        cube_map_view<const P> v;
        for (int k = 0; k < 6; ++k) v.faces[std::size_t(k)] = faces[std::size_t(k)].view();
        return v;
    }
};

template <int L>
sh_coefficients<L, double> random_coefficients(std::uint64_t seed) {
    pcg32 rng(seed);
    sh_coefficients<L, double> c{};
    for (auto& ci : c) ci = 2 * rng.next_double() - 1;
    return c;
}

}  // namespace

TEST_CASE("cube-map texel solid angles are exact: each face sums to 2 pi / 3, the cube to 4 pi", "[sh][projection]") {
    for (const std::size_t n : {1u, 2u, 3u, 64u, 512u}) {
        double face = 0;
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x) face += cube_texel_solid_angle(n, x, y);
        // The corner terms telescope exactly; what remains is rounding: per texel, four
        // atan2 values (<= pi/6, 1 ulp each) and three additions, then one addition into a
        // sum below 4 pi: about 2.3e-15 per texel.
        const double tolerance = 6.0 * double(n * n) * 2.3e-15;
        INFO("size " << n);
        CHECK(std::abs(face - 2 * pi / 3) < tolerance / 6);
        CHECK(std::abs(6 * face - 4 * pi) < tolerance);
    }
    // The texel [-h, 0]^2 (h = 2/n) at a face centre: (1 + u^2 + v^2)^(-3/2) ~ 1 - 3/2 (u^2 + v^2)
    // averages to 1 - h^2 = 1 - 4/n^2 over it; the next term is O(h^4), 1e-11 here.
    const double n = 1024, ratio = cube_texel_solid_angle(1024, 511, 511) / std::pow(2 / n, 2);
    CHECK(std::abs((1 - ratio) - 4 / (n * n)) < 1e-3 * 4 / (n * n));
}

TEST_CASE("cube-map directions follow OpenGL's face table", "[sh][projection]") {
    // Texel (n-1, 0) of +x is at s near 1, t near 0: direction (1, -v, -u) with u ~ 1, v ~ -1.
    const glm::dvec3 d = cube_texel_direction(cube_face::positive_x, 2, 1, 0);
    CHECK(d.x > 0);
    CHECK(d.y > 0);
    CHECK(d.z < 0);
    // Every face centre is its axis.
    const glm::dvec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int k = 0; k < 6; ++k) CHECK(glm::length(glm::normalize(cube_face_direction(cube_face(k), 0, 0)) - axes[k]) == 0);
}

TEST_CASE("a constant cube map projects to c_00 = L sqrt(4 pi) and gives E = pi L to 1e-12", "[sh][projection]") {
    const double radiance = 1.75;
    const cube_storage<double, double (*)(glm::dvec3)> cube(64, [](glm::dvec3) { return 1.75; });
    const auto c = sh_project_cube_map<3>(cube.view());
    // The texel directions are symmetric under every axis permutation and sign change, so
    // bands 1 and 2 cancel exactly; rounding leaves 24576 terms of ~1e-3 (~1e-15).
    CHECK(std::abs(c[0] - radiance * std::sqrt(4 * pi)) < 1e-12);
    for (std::size_t i = 1; i < 9; ++i) CHECK(std::abs(c[i]) < 1e-13);
    std::array<glm::dvec3, 9> rgb{};
    for (std::size_t i = 0; i < 9; ++i) rgb[i] = glm::dvec3(c[i]);
    for (const auto& n : test_directions(1, 200)) CHECK(std::abs(sh_irradiance<3, double, glm::dvec3>(rgb, n).x - pi * radiance) < 1e-12);
}

TEST_CASE("cube-map and lat-long projections of a smooth function converge as h^2", "[sh][projection]") {
    constexpr int L = 4;
    const auto truth = random_coefficients<L>(11);
    auto f = [&](glm::dvec3 d) { return sh_evaluate<L, double, glm::dvec3>(truth, d); };
    auto cube_error = [&](std::size_t n) {
        const cube_storage<double, decltype(f)> cube(n, f);
        const auto c = sh_project_cube_map<L>(cube.view());
        double e = 0;
        for (std::size_t i = 0; i < sh_count(L); ++i) e = std::max(e, std::abs(c[i] - truth[i]));
        return e;
    };
    auto latlong_error = [&](std::size_t h) {
        image<double> map(2 * h, h);
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t x = 0; x < 2 * h; ++x) map(x, y) = f(latlong_direction(2 * h, h, x, y));
        const auto c = sh_project_latlong<L>(image_view<const double>(map.view()));
        double e = 0;
        for (std::size_t i = 0; i < sh_count(L); ++i) e = std::max(e, std::abs(c[i] - truth[i]));
        return e;
    };
    // The midpoint rule with exact cell weights has an error expansion in even powers of h:
    // halving h divides the error by 4 (+- the h^4 term, a few percent at these sizes).
    const double c16 = cube_error(16), c32 = cube_error(32), c64 = cube_error(64);
    INFO("cube errors " << c16 << " " << c32 << " " << c64);
    CHECK(c16 / c32 > 3.6);
    CHECK(c16 / c32 < 4.4);
    CHECK(c32 / c64 > 3.8);
    CHECK(c32 / c64 < 4.2);
    // In phi the trapezoid rule is exact for these trigonometric polynomials; in theta
    // the midpoint rule gives the h^2 expansion.
    const double l16 = latlong_error(16), l32 = latlong_error(32), l64 = latlong_error(64);
    INFO("lat-long errors " << l16 << " " << l32 << " " << l64);
    CHECK(l16 / l32 > 3.6);
    CHECK(l16 / l32 < 4.4);
    CHECK(l32 / l64 > 3.8);
    CHECK(l32 / l64 < 4.2);
    // A constant lat-long map is exact: its pixel solid angles telescope to 4 pi.
    image<double> constant(64, 32, 2.0);
    const auto k = sh_project_latlong<L>(image_view<const double>(constant.view()));
    CHECK(std::abs(k[0] - 2.0 * std::sqrt(4 * pi)) < 1e-13);
}

TEST_CASE("Monte Carlo projection lies within five of its own standard errors of the truth", "[sh][projection]") {
    constexpr int L = 3;
    const auto truth = random_coefficients<L>(12);
    constexpr std::size_t n = 100000;
    std::vector<glm::dvec3> dirs;
    std::vector<double> values;
    pcg32 rng(99);
    for (std::size_t j = 0; j < n; ++j) {
        const double z = 2 * rng.next_double() - 1, phi = 2 * pi * rng.next_double(), r = std::sqrt(1 - z * z);
        dirs.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
        values.push_back(sh_evaluate<L, double, glm::dvec3>(truth, dirs.back()) + 0.5);
    }
    auto expected = truth;
    expected[0] += 0.5 * std::sqrt(4 * pi);
    const auto c = sh_project_monte_carlo<L, double>(dirs, values, 1 / (4 * pi));
    for (std::size_t i = 0; i < sh_count(L); ++i) {
        // Standard error of the mean of f Y_i / p from the sample itself (the CLT: a 5 sigma
        // excursion has probability 6e-7 per coefficient).
        double mean = 0, sq = 0;
        for (std::size_t j = 0; j < n; ++j) {
            const double t = values[j] * sh_basis<L, double, glm::dvec3>(dirs[j])[i] * 4 * pi;
            mean += t / n;
            sq += t * t / n;
        }
        const double sigma = std::sqrt((sq - mean * mean) / n);
        INFO("coefficient " << i << ": " << c[i] << " vs " << expected[i] << ", sigma " << sigma);
        CHECK(std::abs(c[i] - expected[i]) < 5 * sigma);
    }
}

TEST_CASE("least squares recovers a band-limited function, and its regularization damps band l by 1 + lambda (l(l+1))^2",
          "[sh][projection]") {
    constexpr int L = 4;
    constexpr std::size_t n = sh_count(L);
    const auto truth = random_coefficients<L>(13);
    for (const std::size_t count : {400u, 4000u}) {
        std::vector<glm::dvec3> dirs;
        std::vector<double> values;
        for (std::size_t j = 0; j < count; ++j) {
            dirs.push_back(spherical_fibonacci_direction(j, count));
            values.push_back(sh_evaluate<L, double, glm::dvec3>(truth, dirs.back()));
        }
        // E = G - I, G = (4 pi / N) sum_j Y(w_j) Y(w_j)^T: how far the set is from exact.
        double e_frobenius = 0;
        for (std::size_t a = 0; a < n; ++a)
            for (std::size_t b = 0; b < n; ++b) {
                double g = 0;
                for (const auto& d : dirs) {
                    const auto y = sh_basis<L, double, glm::dvec3>(d);
                    g += 4 * pi / double(count) * y[a] * y[b];
                }
                e_frobenius += std::pow(g - (a == b ? 1.0 : 0.0), 2);
            }
        e_frobenius = std::sqrt(e_frobenius);
        REQUIRE(e_frobenius < 0.5);
        INFO(count << " samples, |G - I|_F = " << e_frobenius);

        // lambda = 0 solves G c = b with b = G truth up to rounding: the sums over N samples
        // perturb G and b by at most N eps relative (Higham's bound for recursive summation),
        // Cholesky adds n eps, and cond(G) <= (1 + |E|) / (1 - |E|) <= 3 carries both.
        const auto exact = sh_fit_least_squares<L, double>(dirs, values, 0.0);
        double truth_l1 = 0;
        for (const double t : truth) truth_l1 += std::abs(t);
        for (std::size_t i = 0; i < n; ++i) CHECK(std::abs(exact[i] - truth[i]) < 3 * 2 * double(count + n) * eps * truth_l1);

        // lambda > 0 solves (G + lambda D) c = G truth with M = I + lambda D:
        // c - M^-1 truth = (M + E)^-1 E (I - M^-1) truth, so its norm is at most
        // |E| |truth| / (1 - |E|).
        const double lambda = 1e-3;
        const auto fit = sh_fit_least_squares<L, double>(dirs, values, lambda);
        double truth_norm = 0, diff = 0;
        for (std::size_t i = 0; i < n; ++i) {
            const double eig = double(sh_band(i)) * (sh_band(i) + 1);
            diff += std::pow(fit[i] - truth[i] / (1 + lambda * eig * eig), 2);
            truth_norm += truth[i] * truth[i];
        }
        CHECK(std::sqrt(diff) <= e_frobenius * std::sqrt(truth_norm) / (1 - e_frobenius) + 1e-13);
        // The damping is visible: band 3 loses 1 - 1/1.144 = 13%, far above the bound.
        CHECK(std::abs(fit[15] / truth[15] - 1 / (1 + lambda * 144)) < 0.02);
    }
}

TEST_CASE("projections and fits reject bad input, naming the parameter", "[sh][projection][errors]") {
    const std::vector<glm::dvec3> dirs = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
    const std::vector<double> values = {1, 2, 3}, two = {1, 2}, pdfs = {1, 0, 1};
    auto names = [](auto&& call, const char* parameter) {
        try {
            call();
        } catch (const parameter_error& e) {
            return e.parameter() == parameter;
        }
        return false;
    };
    CHECK(names([&] { sh_fit_least_squares<3, double>(dirs, values, 0.0); }, "directions"));  // 3 samples, 9 unknowns
    CHECK(names([&] { sh_fit_least_squares<1, double>(dirs, values, -1.0); }, "lambda"));
    CHECK(names([&] { sh_fit_least_squares<1, double>(dirs, two, 0.0); }, "values"));
    CHECK(names([&] { sh_project_monte_carlo<2, double>(dirs, values, std::span<const double>(pdfs)); }, "pdfs"));
    const std::vector<glm::dvec3> not_unit = {{0, 0, 2}};
    const std::vector<double> one = {1};
    CHECK(names([&] { sh_project_monte_carlo<2, double>(not_unit, one, 1.0); }, "directions"));
    CHECK(names([&] { sh_project_cone_light<2, double>({0, 0, 0}, 0.5, 1.0); }, "axis"));
    CHECK(names([&] { sh_project_cone_light<2, double>({0, 0, 1}, 1.5, 1.0); }, "cos_half_angle"));
    CHECK(names([&] { sh_project_disc_light<2, double>({0, 0, 1}, 0.0, 1.0, 1.0); }, "distance"));
    image<double> a(4, 4), b(4, 3);
    cube_map_view<const double> bad;
    for (auto& f : bad.faces) f = a.view();
    bad.faces[3] = b.view();
    CHECK(names([&] { sh_project_cube_map<2>(bad); }, "cube"));
}

TEST_CASE("Parseval: the integral of f^2 is the sum of its squared coefficients", "[sh][projection]") {
    // f = sum_i c_i Y_i with bands < 6: f^2 has bands < 11, integrated exactly by 12 x 24
    // product-quadrature points; what remains is rounding of ~300 terms of size ~10.
    constexpr int L = 6;
    const auto c = random_coefficients<L>(14);
    double integral = 0, sum = 0;
    for (const auto& p : sphere_quadrature(12, 24)) integral += p.w * std::pow(sh_evaluate<L, double, glm::dvec3>(c, p.d), 2);
    for (const double ci : c) sum += ci * ci;
    CHECK(std::abs(integral - sum) < 1e-12 * sum);
    // And for a projected light: a cone's energy 2 pi (1 - cos alpha) L^2 is approached from
    // below as bands are added (Bessel's inequality), never exceeded.
    const auto cone = sh_project_cone_light<16, double>({0, 0, 1}, std::cos(0.6), 1.0);
    double kept = 0, previous = 0;
    for (int l = 0; l < 16; ++l) {
        for (int m = -l; m <= l; ++m) kept += cone[sh_index(l, m)] * cone[sh_index(l, m)];
        CHECK(kept >= previous);
        previous = kept;
    }
    CHECK(kept < 2 * pi * (1 - std::cos(0.6)));
    CHECK(kept > 0.9 * 2 * pi * (1 - std::cos(0.6)));
}
