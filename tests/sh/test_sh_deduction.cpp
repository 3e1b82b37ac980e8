// The SH functions that take coefficients deduce the band count (and the scalar) from their
// arguments: each call below spells no template argument, and gives what the spelled call
// gives. Mismatched sizes (a window of the wrong length, a count that is not whole bands)
// do not compile, checked by requires-expressions.
#include "sphere_quadrature.hpp"

#include <bounce/sh/gradients.hpp>
#include <bounce/sh/irradiance.hpp>
#include <bounce/sh/layouts.hpp>
#include <bounce/sh/lights.hpp>
#include <bounce/sh/windowing.hpp>

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <type_traits>

using namespace bounce;
using namespace bounce::sh_test;

namespace {
template <class C, class W>
concept windowable = requires(const C& c, const W& w) { sh_apply_window(c, w); };
template <class C>
concept irradiance_of = requires(const C& c, const glm::dvec3& n) { sh_irradiance(c, n); };
}  // namespace

static_assert(sh_bands_of(1) == 1 && sh_bands_of(9) == 3 && sh_bands_of(1024) == 32);
static_assert(sh_bands_of(0) == 0 && sh_bands_of(8) == 0 && sh_bands_of(10) == 0);
static_assert(windowable<std::array<glm::dvec3, 9>, std::array<double, 3>>);
static_assert(!windowable<std::array<glm::dvec3, 9>, std::array<double, 4>>, "a window for 4 bands on 3 bands' coefficients");
static_assert(irradiance_of<std::array<glm::dvec3, 16>>);
static_assert(!irradiance_of<std::array<glm::dvec3, 10>>, "10 coefficients are not whole bands");

TEST_CASE("SH functions deduce the band count from their coefficients and windows", "[sh][deduction]") {
    const auto radiance = sh_project_cone_light<3, glm::dvec3>(glm::dvec3(0.2, -0.4, 0.9) / std::sqrt(1.01), 0.8,
                                                              glm::dvec3(1.0, 0.5, 0.25));
    const double w = 2.5;
    const auto windowed = sh_apply_window(radiance, hann_window<3>(w));
    static_assert(std::is_same_v<std::remove_const_t<decltype(windowed)>, sh_coefficients<3, glm::dvec3>>);
    CHECK(windowed == sh_apply_window<3, glm::dvec3>(radiance, hann_window<3>(w)));
    CHECK(windowed[4] != radiance[4]);  // band 2 is scaled: the window did something

    const auto convolved = sh_convolve_clamped_cosine(radiance);
    CHECK(convolved == sh_convolve_clamped_cosine<3, glm::dvec3>(radiance));
    for (const auto& n : test_directions(7, 20)) {
        CHECK(sh_irradiance(radiance, n) == sh_irradiance<3, double, glm::dvec3>(radiance, n));
        CHECK(sh_irradiance_over_pi(radiance, n) == sh_irradiance_over_pi<3, double, glm::dvec3>(radiance, n));
        CHECK(sh_evaluate(convolved, n) == sh_evaluate<3, double, glm::dvec3, glm::dvec3>(convolved, n));
        // One channel: C = double, the direction still a vector.
        const auto red = sh_project_cone_light<3, double>(glm::dvec3(0, 0, 1), 0.8, 1.0);
        CHECK(sh_evaluate(red, n) == sh_evaluate<3, double, glm::dvec3, double>(red, n));
    }
    // Single-precision coefficients and directions deduce float.
    const std::array<glm::vec3, 4> f{glm::vec3(1), glm::vec3(0.5f), glm::vec3(0.25f), glm::vec3(0)};
    CHECK(sh_irradiance(f, glm::vec3(0, 0, 1)) == sh_irradiance<2, float, glm::vec3>(f, glm::vec3(0, 0, 1)));
}

TEST_CASE("the window costs, layouts and gradients deduce the band count too", "[sh][deduction]") {
    const auto c = sh_project_directional_light<5, double>(glm::dvec3(0, 0, 1), 1.0);
    const auto h = lanczos_window<5>(4.0);
    const window_cost deduced = sh_window_cost(c, h, 512), spelled = sh_window_cost<5>(c, h, 512);
    CHECK(deduced.energy_kept == spelled.energy_kept);
    CHECK(deduced.min_after == spelled.min_after);
    CHECK(sh_nonnegative_window_width(c, sh_window_family::hann, 5.0, 256, 0.25) ==
          sh_nonnegative_window_width<5>(c, sh_window_family::hann, 5.0, 256, 0.25));

    CHECK(sh_with_condon_shortley_phase(sh_without_condon_shortley_phase(c)) == c);
    CHECK(sh_without_condon_shortley_phase(c) == sh_without_condon_shortley_phase<5, double>(c));
    const auto rgb = sh_project_directional_light<2, glm::dvec3>(glm::dvec3(1, 0, 0), glm::dvec3(1, 2, 3));
    const auto planar = sh_to_channel_major(rgb);
    static_assert(std::tuple_size_v<decltype(planar)> == 12);
    CHECK(sh_from_channel_major(planar) == rgb);

    // A probe field linear in position: the deduced gradient extrapolates it exactly.
    auto probe_at = [](const glm::dvec3& p) {
        sh_coefficients<2, glm::dvec3> k{};
        for (std::size_t i = 0; i < k.size(); ++i) k[i] = glm::dvec3(double(i) + p.x, 2 * p.y, -p.z);
        return k;
    };
    const glm::dvec3 p(0.5, -1, 2), d(0.25, 0.5, -0.75);
    const auto g = sh_translational_gradient(probe_at, p, 0.125);
    static_assert(std::is_same_v<std::remove_const_t<decltype(g)>, sh_gradient<2, glm::dvec3>>);
    const auto moved = sh_extrapolate(probe_at(p), g, d), truth = probe_at(p + d);
    const auto kernel = sh_extrapolate(probe_at(p), g.x, g.y, g.z, d);
    for (std::size_t i = 0; i < truth.size(); ++i) {
        CHECK(glm::length(moved[i] - truth[i]) < 1e-12);
        CHECK(kernel[i] == moved[i]);
    }
}
