// Layout converters: the no-phase layout evaluates with the positive constants three.js's
// SphericalHarmonics3 uses, channel-major round trips.
#include "sphere_quadrature.hpp"

#include <bounce/sh/layouts.hpp>

#include <catch2/catch.hpp>

using namespace bounce;
using namespace bounce::sh_test;

TEST_CASE("no-phase coefficients evaluate with the positive constants of the no-phase basis", "[sh][layouts]") {
    pcg32 rng(31);
    sh_coefficients<3, double> c{};
    for (auto& ci : c) ci = 2 * rng.next_double() - 1;
    const auto np = sh_without_condon_shortley_phase<3, double>(c);
    for (const auto& d : test_directions(32, 100)) {
        const double x = d.x, y = d.y, z = d.z;
        // The no-phase basis, as three.js's SphericalHarmonics3.getAt writes it (its
        // rounded constants, hence the 1e-6 relative tolerance).
        const double basis[9] = {0.282095,           0.488603 * y,     0.488603 * z,
                                 0.488603 * x,       1.092548 * x * y, 1.092548 * y * z,
                                 0.315392 * (3 * z * z - 1), 1.092548 * x * z, 0.546274 * (x * x - y * y)};
        double theirs = 0;
        for (int i = 0; i < 9; ++i) theirs += np[std::size_t(i)] * basis[i];
        const double ours = sh_evaluate<3, double, glm::dvec3>(c, d);
        CHECK(std::abs(theirs - ours) < 1e-5);
    }
    CHECK(sh_with_condon_shortley_phase<3, double>(np) == c);
}

TEST_CASE("channel-major layout round-trips", "[sh][layouts]") {
    sh_coefficients<2, glm::vec3> c{};
    for (std::size_t i = 0; i < 4; ++i) c[i] = glm::vec3(float(i), float(10 + i), float(20 + i));
    const auto planar = sh_to_channel_major<2>(c);
    CHECK(planar[0] == 0.f);
    CHECK(planar[4] == 10.f);
    CHECK(planar[11] == 23.f);
    CHECK(sh_from_channel_major<2, float>(planar) == c);
}
