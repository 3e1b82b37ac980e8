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
    // Both halves of the rays see the same constant: the noise is the halves' quadrature
    // error, a few 1/N of E (1% allowed), and no more than that.
    CHECK(p.noise < 0.01f * std::numbers::pi_v<float> * (0.2126f * 1 + 0.7152f * 2 + 0.0722f * 3));
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

namespace {

// A closed box [-1, 1]^3 of six quads with a point light inside. `inward`: each quad wound
// counter-clockwise seen from inside (a room); otherwise seen from outside (the room wound
// the wrong way: every triangle faces away from the light and the volume).
hand_built::scene lit_box(bool inward) {
    hand_built::scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.6f));
    for (int k = 0; k < 3; ++k)
        for (const float side : {-1.f, 1.f}) {
            glm::vec3 e(0.f), u(0.f), v(0.f);
            e[k] = 1.f;
            u[(k + 1) % 3] = 1.f;
            v[(k + 2) % 3] = 1.f;
            const glm::vec3 c = side * e;
            glm::vec3 q[4] = {c - u - v, c + u - v, c + u + v, c - u + v};  // counter-clockwise seen from +e
            const bool seen_from_plus_e = inward ? side < 0 : side > 0;
            if (!seen_from_plus_e) std::swap(q[1], q[3]);
            hand_built::add_quad(s, q[0], q[1], q[2], q[3], seen_from_plus_e ? e : -e, m);
        }
    s.lights.push_back(bounce::point_light{{0.f, 0.5f, 0.f}, glm::vec3(5.f)});
    return s;
}

irradiance_volume build_in_box(const hand_built::scene& s) {
    const embree::accel bvh(s);
    const embree::reference_integrator light(bvh, s);
    embree::probe_baker_settings bs;
    bs.rays = 64;
    const embree::probe_baker baker(light, bvh, s, bs);
    irradiance_volume_settings vs;
    vs.min_depth = 1;
    vs.max_depth = 2;
    return irradiance_volume::build(s, glm::vec3(-0.9f), glm::vec3(0.9f), vs, baker);
}

}  // namespace

TEST_CASE("a volume whose every probe is inside geometry (reversed winding) is refused", "[irradiance_volume][embree]") {
    // The same box wound as a room: every probe sees the fronts of the walls and lights.
    const irradiance_volume room = build_in_box(lit_box(true));
    std::size_t inside = 0;
    for (const auto& p : room.probes()) inside += p.inside ? 1 : 0;
    CHECK(inside == 0);
    // A point light seen off the walls: the halves of the rays differ, so probes report noise.
    std::size_t noisy = 0;
    for (const auto& p : room.probes()) noisy += p.noise > 0 ? 1 : 0;
    CHECK(noisy > 0);
    CHECK(room.trilinear(glm::vec3(0.f), glm::vec3(0, -1, 0)).x > 0.f);
    // Wound the wrong way: every ray of every probe hits the back of a wall.
    try {
        (void)build_in_box(lit_box(false));
        FAIL("no exception for a volume whose probes are all inside");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "scene");
        CHECK(std::string(e.what()).find("probes is inside geometry") != std::string::npos);
        CHECK(std::string(e.what()).find("wound the wrong way") != std::string::npos);
    }
}

TEST_CASE("a build that would exceed its memory limit is refused before the bake", "[irradiance_volume][embree]") {
    const auto s = lit_box(true);
    const embree::accel bvh(s);
    const embree::reference_integrator light(bvh, s);
    std::size_t baked = 0;
    const auto source = [&](std::span<const glm::vec3> positions, std::span<irradiance_probe> out) {
        for (std::size_t i = 0; i < positions.size(); ++i) out[i].position = positions[i];
        baked += positions.size();
    };
    irradiance_volume_settings vs;
    vs.min_depth = vs.max_depth = 6;  // 274,625 probes: about 270 MB
    vs.memory_limit_bytes = std::uint64_t(irradiance_volume::estimated_bytes(3));
    try {
        (void)irradiance_volume::build(s, glm::vec3(-0.9f), glm::vec3(0.9f), vs, source);
        FAIL("no exception for a build over its memory limit");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "settings.max_depth");
        CHECK(std::string(e.what()).find("depth 4 would hold 4913 probes") != std::string::npos);
    }
    CHECK(baked == 729);  // levels 0 .. 3 (9^3 probes), nothing of level 4
    CHECK(irradiance_volume::uniform_probe_count(6) == 274625.0);
}
