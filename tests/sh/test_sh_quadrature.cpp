// The library's quadrature (bounce/sh/quadrature.hpp): Gauss-Legendre exact to degree
// 2n - 1 and not beyond, the sphere rule's weights and its exactness on SH products up to
// its bands, bad sizes refused.
#include <bounce/sh/basis.hpp>
#include <bounce/sh/quadrature.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

using namespace bounce;

TEST_CASE("Gauss-Legendre integrates x^k exactly up to k = 2n - 1", "[sh][quadrature]") {
    for (const int n : {1, 2, 5, 16, 64}) {
        std::vector<double> x, w;
        gauss_legendre(n, x, w);
        REQUIRE(x.size() == std::size_t(n));
        for (int k = 0; k <= 2 * n; ++k) {
            const double exact = k % 2 ? 0.0 : 2.0 / (k + 1);
            const double q = gauss_legendre_integral(x, w, -1, 1, [&](double t) { return std::pow(t, k); });
            INFO("n " << n << ", k " << k);
            if (k <= 2 * n - 1) CHECK(std::abs(q - exact) < 1e-13);
            else if (n <= 5) CHECK(std::abs(q - exact) > 1e-6);  // degree 2n: the rule's first error term
                                                                 // (below rounding for large n)
        }
    }
    // On [0, 3]: int x^3 = 81 / 4 with two nodes.
    std::vector<double> x, w;
    gauss_legendre(2, x, w);
    CHECK(gauss_legendre_integral(x, w, 0, 3, [](double t) { return t * t * t; }) == Approx(81.0 / 4).epsilon(1e-14));
    CHECK_THROWS_AS(gauss_legendre(0, x, w), parameter_error);
}

TEST_CASE("the sphere rule sums to 4 pi and integrates SH products within its bands", "[sh][quadrature]") {
    const auto q = sphere_quadrature(6, 12);
    REQUIRE(q.size() == 72);
    double sum = 0;
    for (const auto& p : q) {
        sum += p.w;
        CHECK(std::abs(glm::length(p.d) - 1) < 1e-14);
    }
    CHECK(std::abs(sum - 4 * std::numbers::pi) < 1e-13);
    // Bands 0 .. 5 (36 functions): the Gram matrix is the identity to rounding.
    constexpr int L = 6;
    double worst = 0;
    std::vector<std::array<double, sh_count(L)>> y;
    for (const auto& p : q) y.push_back(sh_basis<L, double, glm::dvec3>(p.d));
    for (std::size_t i = 0; i < sh_count(L); ++i)
        for (std::size_t j = 0; j < sh_count(L); ++j) {
            double g = 0;
            for (std::size_t k = 0; k < q.size(); ++k) g += q[k].w * y[k][i] * y[k][j];
            worst = std::max(worst, std::abs(g - (i == j ? 1.0 : 0.0)));
        }
    CHECK(worst < 1e-13);
    CHECK_THROWS_AS(sphere_quadrature(4, 0), parameter_error);
}
