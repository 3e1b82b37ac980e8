// Rotation of SH coefficients (Ivanic and Ruedenberg 1996): band norms are kept, rotating a
// projected light equals projecting the rotated light (all bands, to rounding), rotations
// compose, and a reflection is refused.
#include "sphere_quadrature.hpp"

#include <bounce/errors.hpp>
#include <bounce/sh/lights.hpp>
#include <bounce/sh/rotation.hpp>

#include <catch2/catch.hpp>

#include <cmath>

using namespace bounce;
using namespace bounce::sh_test;

namespace {
constexpr int L = 9;  // order 8

// Rounding of the recurrence: each band's elements are sums of products of the previous
// band's and band 1's, a few ulp per band, growing about linearly with l.
double band_tolerance(int l) { return 1e-14 * (1 + l) * (1 + l); }
}  // namespace

TEST_CASE("rotating a projected light is projecting the rotated light, every band, poles included", "[sh][rotation]") {
    pcg32 rng(21);
    const auto dirs = test_directions(22, 40);
    for (int trial = 0; trial < 20; ++trial) {
        const glm::dmat3 r = random_rotation(rng);
        const sh_rotation<L> rot(r);
        for (const auto& a : dirs) {
            // A directional light and a cone light are zonal about their axis: their
            // projection onto R a is known in closed form.
            const auto before = sh_project_directional_light<L, double>(a, 1.0);
            const auto after = rot.apply(before);
            const auto expected = sh_project_directional_light<L, double>(r * a, 1.0);
            const auto cone = rot.apply(sh_project_cone_light<L, double>(a, 0.3, 2.0));
            const auto cone_expected = sh_project_cone_light<L, double>(r * a, 0.3, 2.0);
            for (int l = 0; l < L; ++l)
                for (int m = -l; m <= l; ++m) {
                    const auto i = sh_index(l, m);
                    INFO("trial " << trial << ", l = " << l << ", m = " << m << ", a = (" << a.x << ", " << a.y << ", " << a.z << ")");
                    CHECK(std::abs(after[i] - expected[i]) < band_tolerance(l));
                    CHECK(std::abs(cone[i] - cone_expected[i]) < 4 * band_tolerance(l));
                }
        }
    }
}

TEST_CASE("rotation keeps each band's norm and composes", "[sh][rotation]") {
    pcg32 rng(23);
    for (int trial = 0; trial < 20; ++trial) {
        const glm::dmat3 r1 = random_rotation(rng), r2 = random_rotation(rng);
        sh_coefficients<L, double> c{};
        for (auto& ci : c) ci = 2 * rng.next_double() - 1;
        const auto once = sh_rotation<L>(r1).apply(c);
        const auto twice = sh_rotation<L>(r2).apply(once);
        const auto composed = sh_rotation<L>(r2 * r1).apply(c);
        for (int l = 0; l < L; ++l) {
            double before = 0, after = 0;
            for (int m = -l; m <= l; ++m) {
                before += c[sh_index(l, m)] * c[sh_index(l, m)];
                after += once[sh_index(l, m)] * once[sh_index(l, m)];
                CHECK(std::abs(twice[sh_index(l, m)] - composed[sh_index(l, m)]) < 4 * band_tolerance(l));
            }
            INFO("band " << l);
            CHECK(std::abs(after - before) < (2 * l + 1) * band_tolerance(l));
        }
    }
    // The identity is exact.
    const sh_rotation<L> id(glm::dmat3(1.0));
    for (int l = 0; l < L; ++l)
        for (int m = -l; m <= l; ++m)
            for (int n = -l; n <= l; ++n) CHECK(std::abs(id.element(l, m, n) - (m == n ? 1.0 : 0.0)) < band_tolerance(l));
}

TEST_CASE("a reflection or a scaled matrix is not a rotation", "[sh][rotation][errors]") {
    glm::dmat3 mirror(1.0);
    mirror[0][0] = -1;
    CHECK_THROWS_AS(sh_rotation<3>(mirror), parameter_error);
    CHECK_THROWS_AS(sh_rotation<3>(glm::dmat3(2.0)), parameter_error);
}
