// Properties of the real spherical-harmonics basis: Sloan's closed forms for bands 0-2,
// orthonormality on the sphere, finite and exact values at the poles, and the addition
// theorem (rotation invariance of each band).
#include "../sh/sphere_quadrature.hpp"

#include <bounce/sampling.hpp>
#include <bounce/sh/basis.hpp>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cmath>
#include <numbers>
#include <vector>

using namespace bounce;

namespace {

constexpr double pi = std::numbers::pi;

// Random unit directions (fixed seed), after the poles, the axes and near-pole directions.
std::vector<glm::dvec3> test_directions() {
    std::vector<glm::dvec3> ds = {{0, 0, 1},  {0, 0, -1},    {1, 0, 0},        {-1, 0, 0},      {0, 1, 0},
                                  {0, -1, 0}, {1e-9, 0, 1}, {0, -1e-12, -1}, {1e-5, 1e-5, 1}, {1, 1, 1}};
    pcg32 rng(17);
    for (int i = 0; i < 500; ++i) {
        const double z = 2 * rng.next_double() - 1, phi = 2 * pi * rng.next_double();
        const double r = std::sqrt(std::max(0.0, 1 - z * z));
        ds.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    for (auto& d : ds) d = glm::normalize(d);
    return ds;
}

using sh_test::gauss_legendre;
using sh_test::legendre;

}  // namespace

TEST_CASE("bands 0-2 of the SH basis match Sloan's closed forms", "[sh]") {
    static const auto dirs = test_directions();
    const auto i = GENERATE(range<std::size_t>(0, 510));
    const glm::dvec3 d = dirs[i];
    const double x = d.x, y = d.y, z = d.z;
    // Sloan 2008, appendix A2, with the Condon-Shortley phase.
    const double c0 = 0.5 * std::sqrt(1 / pi), c1 = std::sqrt(3 / (4 * pi)), c2 = 0.5 * std::sqrt(15 / pi),
                 c20 = 0.25 * std::sqrt(5 / pi), c22 = 0.25 * std::sqrt(15 / pi);
    const double expected[9] = {c0,        -c1 * y,     c1 * z,      -c1 * x,        c2 * x * y,
                                -c2 * y * z, c20 * (3 * z * z - 1), -c2 * x * z, c22 * (x * x - y * y)};

    const auto yd = sh_basis<3, double, glm::dvec3>(d);
    const auto yf = sh_basis<3, float, glm::vec3>(glm::vec3(d));
    for (std::size_t k = 0; k < 9; ++k) {
        INFO("coefficient " << k << " at (" << x << ", " << y << ", " << z << ")");
        // Both sides are a handful of roundings of terms below 1.1: a few ulp of 1.
        CHECK(std::abs(yd[k] - expected[k]) < 1e-14);
        // The float input itself is rounded (2^-24 relative), then as many float roundings.
        CHECK(std::abs(double(yf[k]) - expected[k]) < 2e-6);
    }
    CHECK(sh_index(2, -2) == 4);
    CHECK(sh_index(2, 2) == 8);
}

TEST_CASE("the SH basis is orthonormal on the sphere", "[sh]") {
    // Product Gauss-Legendre (z) x trapezoid (phi) quadrature. Y_i Y_j has degree at most
    // 2 (L - 1) = 14 in z and in the Fourier order of phi, so nz = 16 nodes (exact to
    // degree 31) and nphi = 32 points (exact to order 31) integrate it exactly: what
    // remains is rounding, ~1e-14.
    constexpr int L = 8, nz = 16, nphi = 32;
    std::vector<double> zs, ws;
    gauss_legendre(nz, zs, ws);
    std::vector<double> gram(L * L * L * L, 0.0);
    for (int a = 0; a < nz; ++a)
        for (int b = 0; b < nphi; ++b) {
            const double z = zs[std::size_t(a)], r = std::sqrt(1 - z * z), phi = 2 * pi * (b + 0.5) / nphi;
            const double w = ws[std::size_t(a)] * 2 * pi / nphi;
            const auto y = sh_basis<L, double, glm::dvec3>(glm::dvec3(r * std::cos(phi), r * std::sin(phi), z));
            for (int i = 0; i < L * L; ++i)
                for (int j = 0; j < L * L; ++j) gram[std::size_t(i * L * L + j)] += w * y[std::size_t(i)] * y[std::size_t(j)];
        }
    double worst = 0;
    for (int i = 0; i < L * L; ++i)
        for (int j = 0; j < L * L; ++j)
            worst = std::max(worst, std::abs(gram[std::size_t(i * L * L + j)] - (i == j ? 1.0 : 0.0)));
    CHECK(worst < 1e-12);
}

TEST_CASE("the SH basis is finite and exact at the poles", "[sh]") {
    constexpr int L = 16;
    for (const double sign : {1.0, -1.0}) {
        const auto yd = sh_basis<L, double, glm::dvec3>(glm::dvec3(0, 0, sign));
        const auto yf = sh_basis<L, float, glm::vec3>(glm::vec3(0, 0, float(sign)));
        for (int l = 0; l < L; ++l)
            for (int m = -l; m <= l; ++m) {
                INFO("l = " << l << ", m = " << m << ", pole " << sign);
                const auto k = sh_index(l, m);
                REQUIRE(std::isfinite(yd[k]));
                REQUIRE(std::isfinite(yf[k]));
                // Only the zonal harmonics survive: Y_l0(+-z) = sqrt((2l+1)/(4 pi)) (+-1)^l.
                const double expected = m == 0 ? std::sqrt((2 * l + 1) / (4 * pi)) * std::pow(sign, l) : 0.0;
                CHECK(std::abs(yd[k] - expected) < 1e-13 * (1 + l));
                CHECK(std::abs(double(yf[k]) - expected) < 1e-5 * (1 + l));
            }
    }
}

TEST_CASE("each SH band obeys the addition theorem, so its energy is rotation invariant", "[sh]") {
    // Unsold / addition theorem: sum_m Y_lm(a) Y_lm(b) = (2l + 1) / (4 pi) P_l(a.b);
    // with a = b the band's sum of squares is (2l + 1) / (4 pi) in every direction.
    constexpr int L = 12;
    static const auto dirs = test_directions();
    const auto i = GENERATE(range<std::size_t>(0, 510));
    const glm::dvec3 a = dirs[i], b = dirs[(i * 7 + 3) % dirs.size()];
    const auto ya = sh_basis<L, double, glm::dvec3>(a), yb = sh_basis<L, double, glm::dvec3>(b);
    const auto yf = sh_basis<L, float, glm::vec3>(glm::vec3(a));
    for (int l = 0; l < L; ++l) {
        double same = 0, cross = 0, same_f = 0;
        for (int m = -l; m <= l; ++m) {
            const auto k = sh_index(l, m);
            same += ya[k] * ya[k];
            cross += ya[k] * yb[k];
            same_f += double(yf[k]) * double(yf[k]);
        }
        const double band = (2 * l + 1) / (4 * pi);
        INFO("band " << l);
        // Recurrence error grows about linearly with l (each step a few roundings).
        CHECK(std::abs(same - band) < 1e-13 * band * (1 + l));
        CHECK(std::abs(cross - band * legendre(l, glm::dot(a, b))) < 1e-13 * band * (1 + l));
        // float: relative error of a few float ulp per recurrence step.
        CHECK(std::abs(same_f - band) < 2e-6 * band * (1 + l));
    }
}
