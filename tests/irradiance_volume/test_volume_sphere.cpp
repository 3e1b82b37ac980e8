// The moving-sphere measurement of irradiance volumes (study/volume_sphere.hpp): the default
// path lies in free space (checked against the exact distances to a room and a pillar),
// a camera with no free space around it is refused, and in a uniform environment every
// lookup agrees with the reference on the sphere with no popping.
#include "../embree/hand_built_scenes.hpp"

#include <bounce/embree/probe_baker.hpp>
#include <bounce/study/volume_sphere.hpp>
#include <bounce/study/volume_sweep.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

using namespace bounce;

namespace {

// Axis-aligned box [lo, hi], every face wound counter-clockwise seen from outside
// (`outward`) or from inside.
void add_box(hand_built::scene& s, glm::vec3 lo, glm::vec3 hi, bool outward, std::uint32_t m) {
    const glm::vec3 c = 0.5f * (lo + hi), h = 0.5f * (hi - lo);
    for (int k = 0; k < 3; ++k)
        for (const float side : {-1.f, 1.f}) {
            glm::vec3 e(0.f), u(0.f), v(0.f);
            e[k] = 1.f;
            u[(k + 1) % 3] = h[(k + 1) % 3];
            v[(k + 2) % 3] = h[(k + 2) % 3];
            const glm::vec3 f = c + side * h[k] * e;
            glm::vec3 q[4] = {f - u - v, f + u - v, f + u + v, f - u + v};  // counter-clockwise seen from +e
            const bool seen_from_plus_e = outward ? side > 0 : side < 0;
            if (!seen_from_plus_e) std::swap(q[1], q[3]);
            hand_built::add_quad(s, q[0], q[1], q[2], q[3], seen_from_plus_e ? e : -e, m);
        }
}

float distance_to_box(glm::vec3 p, glm::vec3 lo, glm::vec3 hi) {
    const glm::vec3 d = glm::max(glm::max(lo - p, p - hi), glm::vec3(0.f));
    return glm::length(d);
}

camera looking(glm::vec3 from, glm::vec3 to) {
    camera c;
    c.position = from;
    c.look_at = to;
    c.up = {0, 1, 0};
    c.fov_y_deg = 45;
    return c;
}

}  // namespace

TEST_CASE("the default sphere path lies in the free space along the view", "[irradiance_volume][study]") {
    hand_built::scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.5f));
    add_box(s, glm::vec3(-1.f), glm::vec3(1.f), false, m);  // the room
    const glm::vec3 pillar_lo(-0.2f, -1.f, -0.5f), pillar_hi(0.2f, 0.3f, -0.3f);
    add_box(s, pillar_lo, pillar_hi, true, m);  // a pillar across the view axis
    const embree::accel bvh(s);
    const glm::vec3 lo(-0.98f), hi(0.98f);
    const auto path = study::default_sphere_path(bvh, looking({0.f, 0.f, 0.9f}, {0.f, 0.f, -1.f}), lo, hi);
    CHECK(path.radius > 0.f);
    CHECK(path.radius <= 0.02f * glm::length(hi - lo) * 1.0001f);
    CHECK(glm::length(path.b - path.a) >= 4 * path.radius);
    CHECK(study::sphere_path_is_clear(bvh, path));
    // Exact free distances along the path: the room's walls and the pillar.
    for (int k = 0; k <= 200; ++k) {
        const glm::vec3 c = path.centre(std::size_t(k), 201);
        CHECK(glm::all(glm::greaterThanEqual(c, lo)));
        CHECK(glm::all(glm::lessThanEqual(c, hi)));
        const float walls = 1.f - std::max({std::abs(c.x), std::abs(c.y), std::abs(c.z)});
        CHECK(std::min(walls, distance_to_box(c, pillar_lo, pillar_hi)) >= path.radius);
    }
    // A radius asked for is kept.
    const auto fixed = study::default_sphere_path(bvh, looking({0.f, 0.f, 0.9f}, {0.f, 0.f, -1.f}), lo, hi, 0.05f);
    CHECK(fixed.radius == 0.05f);
    CHECK(study::sphere_path_is_clear(bvh, fixed));
}

TEST_CASE("a camera with no free space around it gets no default path", "[irradiance_volume][study]") {
    hand_built::scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.5f));
    add_box(s, glm::vec3(-1.f), glm::vec3(1.f), false, m);
    add_box(s, glm::vec3(-0.001f), glm::vec3(0.001f), false, m);  // a closed cell around the camera
    const embree::accel bvh(s);
    try {
        (void)study::default_sphere_path(bvh, looking({0.f, 0.f, 0.f}, {0.f, 0.f, -1.f}), glm::vec3(-0.98f), glm::vec3(0.98f));
        FAIL("no exception");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "path");
    }
}

TEST_CASE("in a uniform environment every lookup matches the reference on the sphere", "[irradiance_volume][study]") {
    hand_built::scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.5f));
    hand_built::add_icosphere(s, {50, 50, 50}, 0.01, 0, m);  // far and tiny: a volume needs a triangle
    const embree::accel bvh(s);
    embree::reference_settings rs;
    rs.environment = glm::vec3(1.f, 2.f, 3.f);
    const embree::reference_integrator light(bvh, s, rs);
    embree::probe_baker_settings bs;
    bs.rays = 256;
    bs.gradient_step = 0.05f;
    const embree::probe_baker baker(light, bvh, s, bs);
    irradiance_volume_settings vs;
    vs.min_depth = vs.max_depth = 2;
    const irradiance_volume volume = irradiance_volume::build(s, glm::vec3(-1.f), glm::vec3(1.f), vs, baker);
    study::volume_sphere_settings ss;
    ss.frames = 4;
    ss.sphere_points = 32;
    ss.popping_steps = 16;
    ss.reference_samples = 64;
    ss.repeat = 1;
    const study::volume_sphere_study sphere(light, {{-0.6f, 0.1f, 0.2f}, {0.7f, -0.1f, 0.3f}, 0.1f}, ss);
    CHECK(sphere.reference_popping() == Approx(0).margin(1e-6));
    for (const auto interpolation : {cpu::volume_interpolation::trilinear, cpu::volume_interpolation::weighted}) {
        const auto f = sphere.measure(volume, "x", {interpolation, {2.f, true, 1.5f}});
        CHECK(f.error.pixels == 4 * 32);
        // Probes hold E = pi L within the Fibonacci set's ~1/N quadrature error (1% allowed).
        CHECK(f.error.rel_rms < 0.01);
        CHECK(f.popping < 0.01);
        CHECK(f.popping_series.size() == 16);
        CHECK(f.lookup_ns > 0);
    }
    CHECK_THROWS_AS(study::volume_sphere_study(light, {{0, 0, 0}, {1, 0, 0}, 0.f}, ss), parameter_error);
}

TEST_CASE("a probe memo bakes each position once, and a sweep's octrees come from the grid's probes",
          "[irradiance_volume][study]") {
    // A lit room: a uniform grid of depth 2, then merged octrees of the same lattice from the
    // memo: they bake nothing new, and each is the octree built from the baker directly.
    hand_built::scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.6f));
    add_box(s, glm::vec3(-1.f), glm::vec3(1.f), false, m);
    s.lights.push_back(bounce::point_light{{0.f, 0.5f, 0.f}, glm::vec3(5.f)});
    const embree::accel bvh(s);
    const embree::reference_integrator light(bvh, s);
    embree::probe_baker_settings bs;
    bs.rays = 64;
    bs.noise = embree::probe_noise_estimate::rotated_repeat;
    const embree::probe_baker baker(light, bvh, s, bs);
    std::size_t calls = 0;
    study::probe_memo memo([&](std::span<const glm::vec3> at, std::span<irradiance_probe> out) {
        ++calls;
        baker(at, out);
    });
    irradiance_volume_settings vs;
    vs.min_depth = vs.max_depth = 2;
    const glm::vec3 lo(-0.9f), hi(0.9f);
    const irradiance_volume grid = irradiance_volume::build(s, lo, hi, vs, memo);
    CHECK(memo.baked() == 125);
    CHECK(memo.reused() == 0);
    const std::size_t grid_calls = calls;
    study::volume_sphere_settings ss;
    ss.frames = 2;
    ss.sphere_points = 16;
    ss.popping_steps = 4;
    ss.reference_samples = 16;
    ss.repeat = 1;
    const study::volume_sphere_study sphere(light, {{-0.5f, -0.3f, 0.f}, {0.5f, -0.3f, 0.f}, 0.1f}, ss);
    vs.min_depth = 1;
    vs.calibrate_noise = false;
    const std::vector<float> budgets{1.f, 1000.f};
    const auto sweep = study::bias_budget_sweep(s, lo, hi, vs, memo, sphere, budgets);
    CHECK(memo.baked() == 125);  // every probe of the merged octrees came from memory
    CHECK(memo.reused() == 2 * 125);
    CHECK(calls == grid_calls);
    REQUIRE(sweep.size() == 2);
    vs.refinement = volume_refinement::merge;
    vs.bias_budget = 1000.f;
    const irradiance_volume direct = irradiance_volume::build(s, lo, hi, vs, baker);
    CHECK(sweep[1].probes == direct.probes().size());
    CHECK(sweep[1].leaves == direct.leaf_count());
    CHECK(sweep[1].probes <= sweep[0].probes);  // a larger budget merges at least as much
    CHECK(sweep[1].probes < grid.probes().size());
    CHECK(study::to_json(sweep).size() == 2);
    CHECK_THROWS_AS(study::bias_budget_sweep(s, lo, hi, vs, memo, sphere, std::vector<float>{-1.f}), parameter_error);
    CHECK_THROWS_AS(study::bias_budget_sweep(s, lo, hi, vs, memo, sphere, budgets, std::vector<float>{-1.f}), parameter_error);
    const auto by_sigmas = study::bias_budget_sweep(s, lo, hi, vs, memo, sphere, std::vector<float>{1.f}, std::vector<float>{0.f, 8.f});
    REQUIRE(by_sigmas.size() == 2);
    CHECK(by_sigmas[0].probes >= by_sigmas[1].probes);  // more slack merges at least as much
    CHECK(study::to_json(by_sigmas)[1]["noise_sigmas"] == 8.f);
    // Grids and merges at several depths of the same lattice bake nothing new (a point of
    // depth 1 is one of depth 2), grids first, then each depth's budgets and tolerances.
    const std::vector<int> depths{1, 2};
    const auto by_depth = study::volume_depth_sweep(s, lo, hi, vs, memo, sphere, depths, std::vector<float>{1.f},
                                                    std::vector<float>{0.05f, 10.f});
    CHECK(memo.baked() == 125);
    REQUIRE(by_depth.size() == 2 + 2 * 3);
    CHECK((by_depth[0].uniform && by_depth[0].max_depth == 1 && by_depth[0].probes == 27));
    CHECK((by_depth[1].uniform && by_depth[1].max_depth == 2 && by_depth[1].probes == 125));
    CHECK(by_depth[1].trilinear.error.rel_rms == Approx(sphere.measure(grid, "t", cpu::volume_lookup{}).error.rel_rms));
    CHECK((by_depth[5].max_depth == 2 && by_depth[5].bias_budget == 1.f && by_depth[5].bias_tolerance == 0.f));
    CHECK((by_depth[7].bias_tolerance == 10.f && by_depth[7].bias_budget == 0.f && by_depth[7].max_depth == 2));
    CHECK(by_depth[7].probes <= by_depth[6].probes);
    CHECK(by_depth[7].probes < 125);  // a tolerance of ten times the light merges
    CHECK(study::to_json(by_depth)[7]["bias_tolerance"] == 10.f);
    CHECK((by_depth[1].hanging == 0 && by_depth[7].hanging < by_depth[7].probes));
    CHECK_THROWS_AS(study::volume_depth_sweep(s, lo, hi, vs, memo, sphere, std::vector<int>{11}, {}, {}), parameter_error);
    CHECK_THROWS_AS(study::bias_tolerance_sweep(s, lo, hi, vs, memo, sphere, std::vector<float>{0.f}), parameter_error);
    CHECK_THROWS_AS(study::probe_memo(nullptr), parameter_error);
    // Equal total rays: each merged octree again with its stored probes baked with the
    // grid's 125 x 64 rays spread over them, and with 64 each; computed hanging corners
    // are not among the probes. Stored ones are refused by name.
    std::vector<std::uint32_t> asked;
    const study::volume_rebake rebake{[&](std::uint32_t rays, std::span<const glm::vec3> at, std::span<irradiance_probe> out) {
        asked.push_back(rays);
        embree::probe_baker_settings more = bs;
        more.rays = rays;
        embree::probe_baker(light, bvh, s, more)(at, out);
    }, 125 * 64, 64};
    vs.hanging_corners = hanging_corner_storage::computed;
    const auto rebaked = study::bias_tolerance_sweep(s, lo, hi, vs, memo, sphere, std::vector<float>{10.f}, {}, nullptr, &rebake);
    REQUIRE(rebaked.size() == 3);
    CHECK(memo.baked() == 125);  // the rebakes do not go through the memo
    CHECK(rebaked[0].rays_per_probe == 0);
    CHECK(rebaked[1].rays_per_probe == 125 * 64 / rebaked[0].probes);
    CHECK(rebaked[1].rays_per_probe > 64);
    CHECK(rebaked[2].rays_per_probe == 64);
    CHECK((rebaked[1].probes == rebaked[0].probes && rebaked[1].leaves == rebaked[0].leaves));
    CHECK(asked == std::vector<std::uint32_t>{rebaked[1].rays_per_probe, 64u});
    CHECK(rebaked[1].trilinear.error.rel_rms != rebaked[0].trilinear.error.rel_rms);  // other probes, the same layout
    CHECK(study::to_json(rebaked)[1]["rays_per_probe"] == rebaked[1].rays_per_probe);
    vs.hanging_corners = hanging_corner_storage::stored;
    try {
        (void)study::bias_tolerance_sweep(s, lo, hi, vs, memo, sphere, std::vector<float>{10.f}, {}, nullptr, &rebake);
        if (by_depth[7].hanging > 0) FAIL("a rebake of stored hanging corners was accepted");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "volume");
    }
}
