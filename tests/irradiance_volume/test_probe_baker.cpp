// Embree-baked probes (embree/probe_baker.hpp): a uniform environment gives E = pi L at
// every normal, no gradient and an infinite harmonic mean distance; a probe inside a closed
// outward-facing sphere is flagged inside, one outside it is not and records the distance;
// bad settings throw.
#include "../embree/hand_built_scenes.hpp"

#include <bounce/embree/probe_baker.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace bounce;

TEST_CASE("a probe in a uniform environment sees E = pi L and no gradient", "[irradiance_volume][embree]") {
    hand_built::scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.5f));
    hand_built::add_icosphere(s, {50, 50, 50}, 0.01, 0, m);  // far and tiny: no ray of 512 hits it
    const embree::accel bvh(s);
    embree::reference_settings rs;
    rs.environment = glm::vec3(1.f, 2.f, 3.f);
    const embree::reference_integrator light(bvh, s, rs);
    embree::probe_baker_settings bs;
    bs.rays = 512;
    bs.gradient_step = 0.1f;
    const embree::probe_baker baker(light, bvh, s, bs);
    const irradiance_probe p = baker.bake({0.f, 0.f, 0.f});
    CHECK_FALSE(p.inside);
    CHECK(std::isinf(p.harmonic_mean_distance));
    // c_00 = (4 pi / N) sum L Y00 = L sqrt(4 pi) exactly (the weights sum to 4 pi); the
    // band-1 and -2 coefficients are L times the Fibonacci set's quadrature error for
    // degree-1 and -2 polynomials, whose centroid and second moments are within ~1/N of
    // the sphere's: E(n) = pi L within a few 1/N = 0.006 relative; 1% allowed.
    const float sqrt_4pi = std::sqrt(4 * std::numbers::pi_v<float>);
    for (int k = 0; k < 3; ++k) CHECK(p.radiance[0][k] == Approx(rs.environment[k] * sqrt_4pi).epsilon(1e-5));
    for (const glm::vec3 n : {glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::normalize(glm::vec3(-1, 2, -3))}) {
        const glm::vec3 e = sh_irradiance<3, float, glm::vec3>(p.radiance, n);
        for (int k = 0; k < 3; ++k) CHECK(e[k] == Approx(std::numbers::pi_v<float> * rs.environment[k]).epsilon(0.01));
    }
    // Every displaced probe sees the same constant: the difference quotients are exactly 0.
    for (const auto& g : p.gradient)
        for (const auto& c : g) CHECK(c == glm::vec3(0.f));
}

TEST_CASE("a probe inside a closed sphere is flagged inside, one outside is not", "[irradiance_volume][embree]") {
    hand_built::scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.5f));
    hand_built::add_icosphere(s, {0, 0, 0}, 1.0, 2, m);
    s.lights.push_back(bounce::point_light{{0.f, 5.f, 0.f}, glm::vec3(10.f)});
    const embree::accel bvh(s);
    const embree::reference_integrator light(bvh, s);
    embree::probe_baker_settings bs;
    bs.rays = 256;
    bs.gradient_step = 0.05f;
    const embree::probe_baker baker(light, bvh, s, bs);
    const glm::vec3 positions[2] = {{0.f, 0.1f, 0.f}, {3.f, 0.f, 0.f}};
    irradiance_probe out[2];
    baker.bake(positions, out);
    CHECK(out[0].inside);
    CHECK_FALSE(out[1].inside);
    // Seen from (3, 0, 0) the unit sphere covers the cone of half-angle asin(1/3): about
    // 1 - cos = 5.7% of the sphere of directions, at distances 2 .. 2.83; the harmonic mean
    // over all rays (misses count 1/d = 0) is N / sum 1/d, so ~ 2.3 / 0.057 = 40.
    CHECK(out[1].harmonic_mean_distance > 20.f);
    CHECK(out[1].harmonic_mean_distance < 80.f);
    // The lit sphere is seen from outside: light arrives, and it comes from -x.
    CHECK(out[1].radiance[0].x > 0.f);
    CHECK(sh_irradiance<3, float, glm::vec3>(out[1].radiance, {-1, 0, 0}).x >
          sh_irradiance<3, float, glm::vec3>(out[1].radiance, {1, 0, 0}).x);
}

TEST_CASE("the probe baker refuses bad settings and positions", "[irradiance_volume][embree]") {
    hand_built::scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.5f));
    hand_built::add_icosphere(s, {0, 0, 0}, 1.0, 0, m);
    const embree::accel bvh(s);
    const embree::reference_integrator light(bvh, s);
    const auto name_of = [&](embree::probe_baker_settings bs) -> std::string {
        try {
            embree::probe_baker b(light, bvh, s, bs);
        } catch (const parameter_error& e) {
            return e.parameter();
        }
        return "(nothing thrown)";
    };
    embree::probe_baker_settings bs;
    bs.rays = 0;
    CHECK(name_of(bs) == "rays");
    bs = {};
    bs.gradient_step = std::nanf("");
    CHECK(name_of(bs) == "gradient_step");
    bs = {};
    bs.inside_fraction = 1.5f;
    CHECK(name_of(bs) == "inside_fraction");
    const embree::probe_baker baker(light, bvh, s, {});
    CHECK_THROWS_AS(baker.bake(glm::vec3(std::nanf(""), 0.f, 0.f)), parameter_error);
}
