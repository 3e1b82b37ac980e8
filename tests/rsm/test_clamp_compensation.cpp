// The RSM gather's clamp compensation (indirect/clamp_compensation.hpp) with Embree's rays:
// the kernel is the exact complement of pixel_light_irradiance's clamp; at a crease (a lit
// wall meeting a receiver floor) the clamped texel sum plus the compensation converges to
// Lambert's unclamped irradiance; no surface within the clamp's distance, or a shadowed one,
// gives exactly zero; without visibility the compensation counts every surface its rays cross
// (a wall behind a screen), with rays only the first; and the renderer refuses the
// compensation without a near-field query.
#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/embree/near_field_rays.hpp>
#include <bounce/embree/occlusion_rays.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/rsm_ray_cast.hpp>
#include <bounce/errors.hpp>

#include "../embree/hand_built_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

using namespace bounce;

namespace {

constexpr float rho = 0.8f, e0 = 2.f;
constexpr float clamp_distance = 0.1f;  // r_c: 20 texels of the 512^2 map

// A wall (x = 0, |y| <= 1, z in [0, 1], facing +x, albedo rho) lit straight on by a
// directional light of irradiance e0 travelling along -x (exitance M = rho e0), meeting a
// floor (z = 0, x in [0, 1], facing +z) the light grazes (it reflects nothing). With
// `shadowed`, a screen at x = 2 (facing +x) keeps the light off the wall.
hand_built::scene crease(bool shadowed) {
    hand_built::scene s;
    const auto mat = hand_built::add_material(s, glm::vec3(rho));
    hand_built::add_quad(s, {0, -1, 0}, {0, 1, 0}, {0, 1, 1}, {0, -1, 1}, {1, 0, 0}, mat);
    hand_built::add_quad(s, {0, -1, 0}, {1, -1, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, mat);
    if (shadowed) hand_built::add_quad(s, {2, -2, -1}, {2, 2, -1}, {2, 2, 2}, {2, -2, 2}, {1, 0, 0}, mat);
    s.lights.push_back(directional_light{{-1, 0, 0}, glm::vec3(e0)});
    return s;
}

// The crease with a black screen (x = screen_x, |y| <= 2, z in [0, screen_top], facing +x)
// between the wall and a receiver on the floor at x = 2 screen_x: the screen keeps the light
// off the wall below screen_top and hides the wall below 2 screen_top from the receiver.
constexpr float screen_x = 0.025f, screen_top = 0.02f;
hand_built::scene screened_crease() {
    hand_built::scene s = crease(false);
    const auto black = hand_built::add_material(s, glm::vec3(0.f));
    hand_built::add_quad(s, {screen_x, -2, 0}, {screen_x, 2, 0}, {screen_x, 2, screen_top},
                         {screen_x, -2, screen_top}, {1, 0, 0}, black);
    return s;
}

// The scene's accel, its 512^2 map, and the gather of one receiver over every lit texel
// exactly once (a pattern of weight-1 offsets from the receiver's disc centre), with
// visibility by rays (or none, `visible` false) and, with `rays` > 0, the clamp's compensation.
struct crease_gather {
    hand_built::scene s;
    embree::accel bvh{s.view()};
    embree::rsm_ray_caster caster{bvh, s.view(), {512, 60.f}};
    embree::occlusion_rays occlusion{bvh};
    embree::near_field_rays near{bvh, s.view()};

    explicit crease_gather(bool shadowed) : crease_gather(crease(shadowed)) {}
    explicit crease_gather(hand_built::scene scene) : s(std::move(scene)) { caster.render(); }

    struct result {
        glm::vec3 e;
        cpu::compensation_totals totals;
    };
    result at(glm::vec3 x, std::uint32_t rays, std::uint64_t seed = 1, bool visible = true) {
        gbuffer<float> g(1, 1);
        g.view().position(0, 0) = x;
        g.view().normal(0, 0) = {0, 0, 1};
        g.view().albedo(0, 0) = glm::vec3(1.f);
        g.view().depth(0, 0) = 1.f;
        const rsm_view& map = caster.views()[0];
        const glm::vec2 centre = cpu::detail::disc_centre(map, x);
        std::vector<glm::vec3> pattern;
        for (std::size_t ty = 0; ty < map.height(); ++ty)
            for (std::size_t tx = 0; tx < map.width(); ++tx)
                pattern.emplace_back((float(tx) + 0.5f) / float(map.width()) - centre.x,
                                     (float(ty) + 0.5f) / float(map.height()) - centre.y, 1.f);
        pixel_light_params lp;
        lp.min_distance2 = clamp_distance * clamp_distance;
        cpu::gather_compensation comp;
        if (rays > 0) comp = {&near, compensation_grid(rays), lp.min_distance2, seed, !visible};
        image<glm::vec3> out(1, 1);
        const auto totals = cpu::rsm_gather(g.view(), cpu::interleave_maps({1, 1}, 1, 1), caster.views(), pattern,
                                            cpu::detail::one_group(pattern.size()), lp, out.view(), true,
                                            visible ? &occlusion : nullptr, comp);
        return {out(0, 0), totals};
    }
};

}  // namespace

TEST_CASE("the compensation's weight is the exact complement of the clamp", "[rsm][clamp_compensation]") {
    const glm::vec3 flux(1.f, 2.f, 3.f), n(0, 0, 1), np(1, 0, 0);
    const float r2 = 0.01f;
    for (const float h : {0.001f, 0.02f, 0.05f, 0.09f, 0.2f}) {
        const glm::vec3 x(h, 0, 0), xp(0, 0, 0.3f * h);
        const glm::vec3 plain = pixel_light_irradiance<float, glm::vec3>(x, n, xp, np, flux, 0.f, 0.f);
        const glm::vec3 clamped = pixel_light_irradiance<float, glm::vec3>(x, n, xp, np, flux, 0.f, r2);
        const float d2 = glm::dot(x - xp, x - xp);
        const glm::vec3 restored = clamped + plain * clamp_complement_weight<float>(d2, r2);
        for (int c = 0; c < 3; ++c) CHECK(restored[c] == Approx(plain[c]).epsilon(1e-5));
    }
    CHECK(clamp_complement_weight<float>(0.02f, 0.01f) == 0.f);
    CHECK(clamp_complement_weight<float>(0.f, 0.f) == 0.f);
    CHECK(clamp_complement_weight<float>(0.f, 0.01f) == 1.f);
    CHECK(compensation_grid(16).count() == 16);  // 2 x 8
    CHECK(compensation_grid(1).count() == 1);
}

TEST_CASE("at a crease the clamped gather plus its compensation converges to the unclamped irradiance",
          "[rsm][embree][clamp_compensation]") {
    crease_gather c(false);
    const double m = double(rho) * double(e0);
    const std::vector<glm::dvec3> wall{{0, -1, 0}, {0, 1, 0}, {0, 1, 1}, {0, -1, 1}};
    const std::uint32_t rays = 16384;
    for (const float h : {0.01f, 0.03f, 0.06f, 0.09f}) {
        const glm::vec3 x(h, 0, 0);
        const double exact = m / std::numbers::pi * hand_built::lambert_polygon(glm::dvec3(x), {0, 0, 1}, wall);
        const auto clamped = c.at(x, 0);
        const auto compensated = c.at(x, rays);
        // Each ray's estimate pi L w lies in [0, M]: the mean of K has a standard deviation
        // of at most M / (2 sqrt K) (stratification only lowers it); 4 of them, plus 1% for
        // the texel sum's midpoint rule on the clamped kernel (texels 1/20 of r_c).
        const double tolerance = 4 * m / (2 * std::sqrt(double(compensated.totals.rays))) + 0.01 * exact;
        CAPTURE(h, exact, clamped.e.x, compensated.e.x, tolerance);
        CHECK(compensated.totals.rays == compensation_grid(rays).count());
        CHECK(std::abs(double(compensated.e.x) - exact) < tolerance);
        if (h <= 0.06f) CHECK(exact - double(clamped.e.x) > 2 * tolerance);  // the removed light, seen
    }
}

TEST_CASE("no surface within the clamp's distance gives exactly zero compensation", "[rsm][embree][clamp_compensation]") {
    crease_gather c(false);
    const glm::vec3 x(0.5f, 0, 0);  // five clamp distances from the wall
    const auto plain = c.at(x, 0);
    const auto compensated = c.at(x, 64);
    CHECK(compensated.totals.rays == compensation_grid(64).count());
    CHECK(compensated.totals.added == 0.0);
    CHECK(compensated.e == plain.e);
}

TEST_CASE("a shadowed surface within the clamp's distance gives zero compensation", "[rsm][embree][clamp_compensation]") {
    crease_gather c(true);
    const glm::vec3 x(0.02f, 0, 0);
    // The rays find the wall within r_c, but it is in the screen's shadow.
    const near_field_ray r{x, {0, 0, 1}, glm::normalize(glm::vec3(-1, 0, 1)), clamp_distance, 7};
    glm::vec3 radiance(1.f);
    float d2 = 0.f;
    c.near.radiance({&r, 1}, {&radiance, 1}, {&d2, 1});
    CHECK(d2 < clamp_distance * clamp_distance);
    CHECK(radiance == glm::vec3(0.f));
    const auto compensated = c.at(x, 256);
    CHECK(compensated.totals.rays == compensation_grid(256).count());
    CHECK(compensated.totals.added == 0.0);
}

TEST_CASE("without visibility the compensation counts every surface its rays cross, with rays the first",
          "[rsm][embree][clamp_compensation]") {
    // Behind the screen the receiver sees no wall (rays), but the unoccluded reference counts
    // the wall's lit part (z >= screen_top) through it: the gather without visibility plus its
    // compensation converges to Lambert's irradiance of that part, the gather with rays plus
    // its compensation to that of the part the receiver sees (z >= 2 screen_top).
    crease_gather c(screened_crease());
    const glm::vec3 x(2 * screen_x, 0, 0);
    const double m = double(rho) * double(e0);
    const auto lit_above = [&](double z) {
        const std::vector<glm::dvec3> part{{0, -1, z}, {0, 1, z}, {0, 1, 1}, {0, -1, 1}};
        return m / std::numbers::pi * hand_built::lambert_polygon(glm::dvec3(x), {0, 0, 1}, part);
    };
    const double unoccluded = lit_above(screen_top), occluded = lit_above(2 * screen_top);
    const std::uint32_t rays = 16384;
    const auto none = c.at(x, rays, 1, false), with_rays = c.at(x, rays, 1, true);
    const auto none_clamped = c.at(x, 0, 1, false);
    const double tolerance = 4 * m / (2 * std::sqrt(double(rays))) + 0.01 * unoccluded;
    CAPTURE(unoccluded, occluded, none.e.x, with_rays.e.x, none_clamped.e.x, tolerance);
    CHECK(unoccluded - occluded > 2 * tolerance);  // the hidden strip is seen
    CHECK(std::abs(double(none.e.x) - unoccluded) < tolerance);
    CHECK(std::abs(double(with_rays.e.x) - occluded) < tolerance);
    CHECK(unoccluded - double(none_clamped.e.x) > 2 * tolerance);  // the clamp's loss, given back
    CHECK(none.totals.added > with_rays.totals.added + 2 * tolerance);

    // One ray through the screen to the wall's lit part: the first surface (the black screen)
    // sends nothing; every surface: the screen, then the wall at M / pi.
    const glm::vec3 wall_point(0, 0, 0.03f);  // seen through the screen (at z 0.015)
    const near_field_ray r{x, {0, 0, 1}, glm::normalize(wall_point - x), clamp_distance, 3};
    glm::vec3 radiance(1.f);
    float d2 = 0.f;
    c.near.radiance({&r, 1}, {&radiance, 1}, {&d2, 1});
    CHECK(radiance == glm::vec3(0.f));
    std::vector<near_field_crossing> crossed;
    c.near.crossings({&r, 1}, crossed);
    REQUIRE(crossed.size() == 2);
    CHECK(crossed[0].radiance == glm::vec3(0.f));
    CHECK(crossed[0].distance2 == Approx(d2).epsilon(1e-4));
    CHECK(crossed[1].ray == 0);
    CHECK(crossed[1].radiance.x == Approx(m / std::numbers::pi).epsilon(1e-4));
    const glm::vec3 origin = x + c.bvh.ray_epsilon() * r.normal;  // where the ray starts
    const glm::vec3 on_wall = origin + r.direction * (-origin.x / r.direction.x);
    CHECK(crossed[1].distance2 == Approx(glm::dot(on_wall - x, on_wall - x)).epsilon(1e-3));

    // Nothing within the clamp's distance: exactly zero, with or without visibility.
    const auto far = c.at(glm::vec3(0.5f, 0, 0), 64, 1, false);
    CHECK(far.totals.rays == compensation_grid(64).count());
    CHECK(far.totals.added == 0.0);
}

TEST_CASE("the gather's compensation with rays needs a near-field query", "[rsm][clamp_compensation]") {
    hand_built::scene s = crease(false);
    const embree::accel bvh(s.view());
    const embree::occlusion_rays occlusion(bvh);
    indirect_options o;
    o.technique = indirect_technique::rsm_gather;
    o.visibility = indirect_visibility::rays;
    o.clamp_compensation_rays = 16;
    CHECK_THROWS_WITH(cpu::indirect_renderer(o, &occlusion), Catch::Contains("clamp_compensation_rays"));
    o.clamp_compensation_rays = 5000;
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("clamp_compensation_rays"));
    const embree::near_field_rays near(bvh, s.view());
    o.clamp_compensation_rays = 16;
    CHECK_NOTHROW(cpu::indirect_renderer(o, &occlusion, nullptr, &near));
    o.visibility = indirect_visibility::none;  // the compensation of every surface
    CHECK_THROWS_WITH(cpu::indirect_renderer(o), Catch::Contains("clamp_compensation_rays"));
    CHECK_NOTHROW(cpu::indirect_renderer(o, nullptr, nullptr, &near));
}

TEST_CASE("the renderer's compensation is per pixel, the same interleaved or not, zero away from the crease",
          "[rsm][embree][clamp_compensation]") {
    // The crease seen from above the floor: every pixel's compensation (the frame with it less
    // the frame without) is >= 0, is 0 where the floor lies beyond r_c from the wall, and is
    // the same at 4 x 4 (before the blur) as plain: its rays depend on the receiver alone.
    crease_gather c(false);
    camera cam;
    cam.position = {0.3f, 0.f, 1.2f};
    cam.look_at = {0.3f, 0.f, 0.f};
    cam.fov_y_deg = 60.f;
    gbuffer<float> g = embree::ray_cast_gbuffer(c.bvh, c.s.view(), cam, 32, 32);
    indirect_options o;
    o.technique = indirect_technique::rsm_gather;
    o.visibility = indirect_visibility::rays;
    o.count = 64;
    o.blur = false;
    o.light.min_distance2 = clamp_distance * clamp_distance;
    cpu::indirect_renderer renderer(o, &c.occlusion, nullptr, &c.near);
    std::size_t covered = 0;
    for (std::size_t y = 0; y < 32; ++y)
        for (std::size_t x = 0; x < 32; ++x) covered += g.view().covered(x, y) ? 1 : 0;
    const auto added = [&](interleave_pattern p) {
        image<glm::vec3> with(32, 32), without(32, 32), diff(32, 32);
        o.pattern = p;
        o.clamp_compensation_rays = 0;
        renderer.render(o, g.view(), cam, c.caster.views(), without.view());
        o.clamp_compensation_rays = 16;
        const indirect_timings t = renderer.render(o, g.view(), cam, c.caster.views(), with.view());
        CHECK(t.compensation_rays == covered * 16);
        CHECK(t.compensation_share > 0.0);
        for (std::size_t y = 0; y < 32; ++y)
            for (std::size_t x = 0; x < 32; ++x) diff(x, y) = with(x, y) - without(x, y);
        return diff;
    };
    const image<glm::vec3> plain = added({1, 1}), interleaved = added({4, 4});
    std::size_t near = 0;
    for (std::size_t y = 0; y < 32; ++y)
        for (std::size_t x = 0; x < 32; ++x) {
            const glm::vec3 p = g.view().position(x, y);
            CHECK(plain(x, y).x >= 0.f);
            CHECK(interleaved(x, y).x == Approx(plain(x, y).x).margin(1e-5));
            if (p.x > clamp_distance * 1.01f) CHECK(plain(x, y).x == 0.f);
            if (g.view().covered(x, y) && p.z < 1e-4f && p.x < 0.5f * clamp_distance) {
                CHECK(plain(x, y).x > 0.f);
                ++near;
            }
        }
    CHECK(near > 0);
}
