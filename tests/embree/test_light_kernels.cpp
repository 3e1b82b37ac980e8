// Properties of the direct-light kernels of bounce/direct_light.hpp: each against its closed form
// in double, on random and adversarial inputs, in float and double instantiations.
#include <bounce/direct_light.hpp>
#include <bounce/sampling.hpp>

#include "hand_built_scenes.hpp"

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cmath>
#include <numbers>

using namespace bounce;

namespace {

glm::dvec3 random_unit(pcg32& rng) {
    const double z = 2 * rng.next_double() - 1, r = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = 2 * std::numbers::pi * rng.next_double();
    return {r * std::cos(phi), r * std::sin(phi), z};
}
glm::dvec3 random_point(pcg32& rng, double extent) {
    return {extent * (2 * rng.next_double() - 1), extent * (2 * rng.next_double() - 1),
            extent * (2 * rng.next_double() - 1)};
}

// Closed forms written directly from the definitions in ../shared/scenes/README.md.
glm::dvec3 point_closed_form(glm::dvec3 p, glm::dvec3 n, glm::dvec3 l, glm::dvec3 intensity) {
    const glm::dvec3 d = l - p;
    const double dist = glm::length(d), cos_theta = glm::dot(n, d) / dist;
    return cos_theta > 0 ? intensity * cos_theta / (dist * dist) : glm::dvec3(0);
}

// Float kernels carry a few roundings of O(1) relative size each: 1e-5 relative is ~100 ulp.
bool close_rel(glm::dvec3 a, glm::dvec3 b, double rel) {
    return glm::length(a - b) <= rel * std::max(glm::length(b), 1e-30);
}

}  // namespace

TEST_CASE("a point light follows the inverse-square cosine law", "[lights][point]") {
    const auto i = GENERATE(range(0, 300));
    pcg32 rng(1000 + std::uint64_t(i));
    const glm::dvec3 p = random_point(rng, 5), n = random_unit(rng), l = random_point(rng, 5);
    const glm::dvec3 intensity(rng.next_double() * 10, rng.next_double() * 10, rng.next_double() * 10);
    const glm::dvec3 expected = point_closed_form(p, n, l, intensity);

    const glm::dvec3 got_d = point_light_irradiance<double, glm::dvec3>(p, n, l, intensity);
    CHECK(close_rel(got_d, expected, 1e-12));
    const glm::dvec3 got_f(point_light_irradiance<float, glm::vec3>(glm::vec3(p), glm::vec3(n), glm::vec3(l),
                                                                     glm::vec3(intensity)));
    // Float inputs are themselves rounded; a grazing cosine amplifies that, so compare
    // absolutely at the scale of I / d^2.
    const double d2 = glm::dot(l - p, l - p);
    CHECK(glm::length(got_f - expected) <= 1e-5 * glm::length(intensity) / d2);

    // Moving the light twice as far along the same ray divides E by four.
    const glm::dvec3 far = point_light_irradiance<double, glm::dvec3>(p, n, p + 2.0 * (l - p), intensity);
    CHECK(close_rel(far * 4.0, got_d, 1e-12));
}

TEST_CASE("a point light at the receiver or behind it delivers nothing, finitely", "[lights][point]") {
    const glm::dvec3 p(0.3, -0.2, 1.0), n(0, 0, 1), i(1, 2, 3);
    const auto at = point_light_irradiance<double, glm::dvec3>(p, n, p, i);
    CHECK(at == glm::dvec3(0));
    CHECK(point_light_irradiance<double, glm::dvec3>(p, n, p - glm::dvec3(0, 0, 1), i) == glm::dvec3(0));
    // Exactly in the tangent plane: cos theta = 0.
    CHECK(point_light_irradiance<double, glm::dvec3>(p, n, p + glm::dvec3(1, 0, 0), i) == glm::dvec3(0));
    const auto tiny = point_light_irradiance<float, glm::vec3>(glm::vec3(0), glm::vec3(0, 0, 1),
                                                               glm::vec3(0, 0, 1e-18f), glm::vec3(1));
    CHECK(std::isfinite(tiny.x));
}

TEST_CASE("the spot profile is dark beyond the cone and none or cosine inside", "[lights][spot]") {
    const double cone_deg = GENERATE(5.0, 30.0, 45.0, 89.0, 120.0, 180.0);
    const double cos_cone = std::cos(cone_deg * std::numbers::pi / 180);
    pcg32 rng(std::uint64_t(cone_deg * 10));
    for (int k = 0; k < 400; ++k) {
        const double c = 2 * rng.next_double() - 1;
        const bool inside = c >= cos_cone;
        CHECK(spot_profile<double>(c, cos_cone, 0.0) == (inside ? 1.0 : 0.0));
        CHECK(spot_profile<double>(c, cos_cone, 1.0) == (inside ? std::max(0.0, c) : 0.0));
    }
    // Exactly on the axis both falloffs give the full intensity.
    CHECK(spot_profile<double>(1.0, cos_cone, 0.0) == 1.0);
    CHECK(spot_profile<double>(1.0, cos_cone, 1.0) == 1.0);
}

TEST_CASE("a spot light is a point light times its profile", "[lights][spot]") {
    const auto i = GENERATE(range(0, 300));
    pcg32 rng(5000 + std::uint64_t(i));
    const glm::dvec3 p = random_point(rng, 3), n = random_unit(rng), l = random_point(rng, 3), axis = random_unit(rng);
    const glm::dvec3 intensity(1.5, 0.5, 2.5);
    const double cone = (5 + 170 * rng.next_double()) * std::numbers::pi / 180, cos_cone = std::cos(cone);
    const double cos_axis = glm::dot(axis, glm::normalize(p - l));
    const glm::dvec3 point = point_closed_form(p, n, l, intensity);
    for (double falloff : {0.0, 1.0}) {
        const double profile = cos_axis >= cos_cone ? (falloff > 0 ? std::max(0.0, cos_axis) : 1.0) : 0.0;
        const glm::dvec3 got = spot_light_irradiance<double, glm::dvec3>(p, n, l, axis, intensity, cos_cone, falloff);
        if (std::abs(cos_axis - cos_cone) < 1e-12) continue;  // on the cone's edge either answer is right
        CHECK(close_rel(got, point * profile, 1e-12));
        if (std::abs(cos_axis - cos_cone) > 1e-5) {  // float rounding cannot flip the cone test
            const glm::dvec3 got_f(spot_light_irradiance<float, glm::vec3>(
                glm::vec3(p), glm::vec3(n), glm::vec3(l), glm::vec3(axis), glm::vec3(intensity), float(cos_cone),
                float(falloff)));
            CHECK(glm::length(got_f - point * profile) <= 1e-5 * glm::length(intensity) / glm::dot(l - p, l - p));
        }
    }
}

TEST_CASE("a directional light delivers E cos theta to surfaces that face it", "[lights][directional]") {
    const auto i = GENERATE(range(0, 200));
    pcg32 rng(9000 + std::uint64_t(i));
    const glm::dvec3 n = random_unit(rng), d = random_unit(rng), e(2, 3, 4);
    const glm::dvec3 got = directional_light_irradiance<double, glm::dvec3>(n, d, e);
    CHECK(close_rel(got, e * std::max(0.0, -glm::dot(n, d)), 1e-14));
    // A surface facing the light head-on receives the full irradiance.
    CHECK(close_rel(directional_light_irradiance<double, glm::dvec3>(-d, d, e), e, 1e-14));
}

TEST_CASE("a packed light's irradiance is its model's kernel on the light's fields", "[lights]") {
    const auto i = GENERATE(range(0, 100));
    pcg32 rng(15000 + std::uint64_t(i));
    const glm::vec3 p(random_point(rng, 3)), n(random_unit(rng)), position(random_point(rng, 3));
    const glm::vec3 direction(2.f * glm::vec3(random_unit(rng))), value(1.5f, 0.5f, 2.5f);
    const float cone_deg = float(5 + 170 * rng.next_double());
    // Bitwise: light_irradiance only chooses the kernel and hands it the packed fields.
    CHECK(light_irradiance(pack(point_light{position, value}), p, n) ==
          point_light_irradiance<float, glm::vec3>(p, n, position, value));
    for (const auto falloff : {spot_light::falloff_kind::none, spot_light::falloff_kind::cosine}) {
        const float cos_cone = float(std::cos(glm::radians(double(cone_deg))));  // as pack rounds it
        CHECK(light_irradiance(pack(spot_light{position, direction, value, cone_deg, falloff}), p, n) ==
              spot_light_irradiance<float, glm::vec3>(p, n, position, glm::normalize(direction), value, cos_cone,
                                                      falloff == spot_light::falloff_kind::cosine ? 1.f : 0.f));
    }
    CHECK(light_irradiance(pack(directional_light{direction, value}), p, n) ==
          directional_light_irradiance<float, glm::vec3>(n, glm::normalize(direction), value));
}

TEST_CASE("the area-light sample is symmetric in its two ends", "[lights][area]") {
    // G(p, q) = cos cos / d^2 is symmetric: the form-factor reciprocity A_p F_pq = A_q F_qp.
    const auto i = GENERATE(range(0, 200));
    pcg32 rng(12000 + std::uint64_t(i));
    const glm::dvec3 p = random_point(rng, 2), q = random_point(rng, 2), n = random_unit(rng), nq = random_unit(rng);
    const glm::dvec3 one(1);
    const auto a = area_light_irradiance_sample<double, glm::dvec3>(p, n, q, nq, one, 1.0);
    const auto b = area_light_irradiance_sample<double, glm::dvec3>(q, nq, p, n, one, 1.0);
    CHECK(close_rel(a, b, 1e-12));
    CHECK(area_light_irradiance_sample<double, glm::dvec3>(p, n, p, nq, one, 1.0) == glm::dvec3(0));
}

TEST_CASE("area-light samples average to Lambert's polygon irradiance", "[lights][area]") {
    // A square emitter of radiance L above a receiver: uniform area samples averaged with
    // 1/pdf = area estimate E = L * lambert_polygon exactly in expectation.
    const auto i = GENERATE(range(0, 20));
    pcg32 rng(15000 + std::uint64_t(i));
    const double h = 0.3 + rng.next_double(), half = 0.2 + 0.8 * rng.next_double();
    const glm::dvec3 centre(rng.next_double() - 0.5, rng.next_double() - 0.5, h);
    const glm::dvec3 p(0), n = glm::normalize(glm::dvec3(0.2 * rng.next_double(), 0.1, 1));
    const std::vector<glm::dvec3> square = {centre + glm::dvec3(-half, -half, 0), centre + glm::dvec3(half, -half, 0),
                                            centre + glm::dvec3(half, half, 0), centre + glm::dvec3(-half, half, 0)};
    // The whole square must lie above the tangent plane for Lambert's formula as written.
    for (const auto& v : square) REQUIRE(glm::dot(v - p, n) > 0);
    const double exact = hand_built::lambert_polygon(p, n, square);
    const double area = 4 * half * half;
    const std::uint32_t side = 64;
    const auto u = stratified2(side, side, 77 + std::uint64_t(i));
    double sum = 0, sum2 = 0;
    for (const auto& s : u) {
        const glm::dvec3 q = square[0] + double(s.x) * (square[1] - square[0]) + double(s.y) * (square[3] - square[0]);
        const double e = area_light_irradiance_sample<double, glm::dvec3>(p, n, q, {0, 0, -1}, glm::dvec3(1), area).x;
        sum += e;
        sum2 += e * e;
    }
    const double N = double(u.size()), mean = sum / N, var = std::max(0.0, sum2 / N - mean * mean);
    // 4 standard errors of independent sampling bound the stratified error (it only does better).
    CHECK(std::abs(mean - exact) <= 4 * std::sqrt(var / N) + 1e-12);
}
