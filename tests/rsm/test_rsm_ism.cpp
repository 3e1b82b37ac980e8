// Imperfect shadow maps (indirect/imperfect_shadow_maps.hpp, cpu/imperfect_shadow_maps.hpp):
// the paraboloid texel of known directions, the lookup's hard cases (a receiver at the VPL,
// grazing directions, the paraboloid's rim, points behind the VPL), pull-push, the point
// set's strata and subsets, the atlas built from points, and bad parameters refused by name.
// The partition room with ism is in test_rsm_visibility.cpp (it needs Embree's maps).
#include <bounce/cpu/imperfect_shadow_maps.hpp>
#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/errors.hpp>
#include <bounce/owned_scene.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

using namespace bounce;

namespace {

constexpr float empty = ism_empty;

glm::vec3 texel_of(glm::vec3 p, glm::vec3 origin, glm::vec3 n, float res) {
    return ism_map_texel<float, glm::vec3, glm::vec2>(p, origin, n, res);
}

}  // namespace

TEST_CASE("the paraboloid map puts the normal at its centre and 45 degrees at tan(22.5 deg) of its radius",
          "[rsm][ism]") {
    const glm::vec3 o(1.f, 2.f, 3.f);
    for (const glm::vec3 n : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0), glm::normalize(glm::vec3(1, -2, 0.5f))}) {
        INFO("normal " << n.x << ", " << n.y << ", " << n.z);
        // The centre is the corner of four texels: rounding picks any of them.
        const glm::vec3 c = texel_of(o + 2.f * n, o, n, 32.f);
        CHECK((c.x == 15.f || c.x == 16.f));
        CHECK((c.y == 15.f || c.y == 16.f));
        CHECK(c.z == Approx(2.f));
        // 45 degrees off the normal along the frame's tangent: q = tan(22.5 deg).
        const auto tb = orthonormal_basis<float, glm::vec3>(n);
        const glm::vec3 d = glm::normalize(n + tb[0]);
        const glm::vec3 t = texel_of(o + 3.f * d, o, n, 32.f);
        const float q = std::tan(float(std::numbers::pi) / 8.f);
        CHECK(t.x == std::floor((q * 0.5f + 0.5f) * 32.f));
        CHECK((t.y == 15.f || t.y == 16.f));
        CHECK(t.z == Approx(3.f));
    }
}

TEST_CASE("the lookup's hard cases: a receiver at the VPL, grazing directions, the rim, points behind",
          "[rsm][ism]") {
    const glm::vec3 o(0.f), n(0.f, 0.f, 1.f);
    const float res = 16.f;
    // A receiver at the VPL itself: a finite texel, distance 0, and it sees the VPL even
    // against a stored depth of 0 with no bias.
    const glm::vec3 at = texel_of(o, o, n, res);
    CHECK(std::isfinite(at.x));
    CHECK(std::isfinite(at.y));
    CHECK(at.z == 0.f);
    CHECK(ism_visible<float, glm::vec3>(o, n, o, 0.f, res, 0.f, 0.f) == 1.f);
    // Grazing directions (just above the VPL's plane) land on the rim texels, in range.
    for (const float z : {1e-3f, 1e-6f, 1e-12f}) {
        const glm::vec3 r = texel_of({1.f, 0.f, z}, o, n, res);
        const glm::vec3 l = texel_of({-1.f, 0.f, z}, o, n, res);
        const glm::vec3 b = texel_of({0.f, -1.f, z}, o, n, res);
        INFO("z " << z);
        CHECK(r.x == res - 1.f);
        CHECK(l.x == 0.f);
        CHECK((b.y == 0.f || b.y == res - 1.f));
        CHECK(r.y >= 0.f);
        CHECK(r.y <= res - 1.f);
    }
    // On and behind the plane: looked up at the centre (never used), splatted as nothing.
    for (const glm::vec3 p : {glm::vec3(1, 0, 0), glm::vec3(1, 1, -1e-3f), glm::vec3(0, 0, -5)}) {
        const glm::vec3 t = texel_of(p, o, n, res);
        CHECK(t.x == res / 2.f);
        CHECK(t.y == res / 2.f);
        CHECK(ism_splat_texel<float, glm::vec3, glm::vec2>(p, o, n, res).z == empty);
    }
    // The depth test: a receiver at distance 2 behind an occluder at 1 is hidden; in front
    // of it or within the bias it sees the VPL; against an empty texel it always does.
    const glm::vec3 rx(0.f, 0.f, 2.f), rn(0.f, 0.f, -1.f);
    CHECK(ism_visible<float, glm::vec3>(rx, rn, o, 1.f, res, 0.01f, 1.f) == 0.f);
    CHECK(ism_visible<float, glm::vec3>(rx, rn, o, 2.5f, res, 0.01f, 1.f) == 1.f);
    const float bias = ism_bias<float>(2.f, 1.f, res, 0.01f, 1.f);
    CHECK(bias == Approx(0.01f + 2.f * 4.f / 16.f));
    CHECK(ism_visible<float, glm::vec3>(rx, rn, o, 2.f - 0.9f * bias, res, 0.01f, 1.f) == 1.f);
    CHECK(ism_visible<float, glm::vec3>(rx, rn, o, 2.f - 1.1f * bias, res, 0.01f, 1.f) == 0.f);
    CHECK(ism_visible<float, glm::vec3>(rx, rn, o, empty, res, 0.f, 0.f) == 1.f);
    // A grazing receiver (its surface edge-on to the VPL) gets the bias of 78 degrees at most.
    CHECK(ism_bias<float>(2.f, 0.f, res, 0.f, 1.f) == Approx(2.f * 4.f / 16.f / 0.2f));
}

TEST_CASE("pull-push averages the filled texels and fills only the empty ones", "[rsm][ism]") {
    CHECK(ism_pull<float>(empty, empty, empty, empty) == empty);
    CHECK(ism_pull<float>(1.f, empty, 3.f, empty) == 2.f);
    CHECK(ism_pull<float>(1.f, 2.f, 3.f, 6.f) == 3.f);
    CHECK(ism_push<float>(empty, 4.f) == 4.f);
    CHECK(ism_push<float>(1.f, 4.f) == 1.f);
    CHECK(ism_push<float>(empty, empty) == empty);
}

TEST_CASE("the point set is stratified by area and each VPL's subset covers the scene", "[rsm][ism]") {
    // Two unit squares far apart, one of area 1 and one of area 3: a quarter of every
    // subset on the first.
    owned_scene s;
    s.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {10, 0, 0}, {13, 0, 0}, {13, 1, 0}, {10, 1, 0}};
    s.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
    s.material_of.assign(4, 0);
    s.materials.resize(1);
    const ism_point_sampler sampler(s.view());
    CHECK(sampler.area() == Approx(4.0));
    const std::size_t v = 8, k = 64;
    const auto pts = sampler.points(v * k, 3);
    REQUIRE(pts.size() == v * k);
    CHECK(pts == sampler.points(v * k, 3));  // deterministic
    for (std::size_t j = 0; j < v; ++j) {
        std::size_t first = 0;
        for (std::size_t i = j; i < pts.size(); i += v) first += pts[i].x < 5.f ? 1 : 0;
        CHECK(first == k / 4);
    }
    for (const auto& p : pts) {
        CHECK(p.z == 0.f);
        CHECK(((p.x >= 0.f && p.x <= 1.f) || (p.x >= 10.f && p.x <= 13.f)));
    }
    CHECK(ism_point_spacing(4.0, 64) == Approx(0.25f));
}

TEST_CASE("one point fills its VPL's whole map after pull-push; a map without points hides nothing",
          "[rsm][ism]") {
    const std::vector<vpl> vpls = {{{0, 0, 0}, {0, 0, 1}, glm::vec3(1.f)}, {{5, 0, 0}, {0, 0, 1}, glm::vec3(1.f)}};
    // Point 0 belongs to VPL 0 (i % 2 == 0), point 1 to VPL 1 but lies behind it.
    const std::vector<glm::vec3> points = {{0.f, 0.f, 1.f}, {5.f, 0.f, -1.f}};
    ism_params p;
    p.map_size = 8;
    cpu::imperfect_shadow_maps maps;
    maps.build(vpls, points, p, 0.f);
    const ism_atlas_layout& a = maps.layout();
    REQUIRE(a.columns == 2);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            CHECK(maps.depths()[a.index(0, x, y)] == Approx(1.f));
            CHECK(maps.depths()[a.index(1, x, y)] == empty);
        }
    // Above the point: hidden; below it: seen; anything from VPL 1: seen.
    CHECK(maps.visible(0, {0.5f, 0.f, 3.f}, {0, 0, -1}, vpls[0]) == 0.f);
    CHECK(maps.visible(0, {0.f, 0.2f, 0.5f}, {0, 0, -1}, vpls[0]) == 1.f);
    CHECK(maps.visible(1, {5.f, 0.f, 3.f}, {0, 0, -1}, vpls[1]) == 1.f);
    // Without pull-push only the point's texel holds a depth.
    p.pull_push = false;
    maps.build(vpls, points, p, 0.f);
    std::size_t filled = 0;
    for (const float d : maps.depths()) filled += d < empty ? 1 : 0;
    CHECK(filled == 1);
}

TEST_CASE("bad imperfect shadow map parameters are refused by their names", "[rsm][ism]") {
    indirect_options o;
    o.count = 1024;
    o.visibility = indirect_visibility::ism;
    for (const int size : {0, 2, 24, 512}) {
        o.ism.map_size = size;
        CHECK_THROWS_WITH(o.validate(), Catch::Contains("ism.map_size"));
    }
    o.ism.map_size = 16;
    o.ism.points_per_vpl = 0;
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("ism.points_per_vpl"));
    o.ism.points_per_vpl = 65536;  // 1024 x 65536 > 2^24
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("2^24"));
    o.ism.points_per_vpl = 1024;
    for (const float b : {-1.f, std::nanf(""), INFINITY}) {
        o.ism.bias_scale = b;
        CHECK_THROWS_WITH(o.validate(), Catch::Contains("ism.bias_scale"));
    }
    o.ism.bias_scale = 1.f;
    o.validate();
    o.technique = indirect_technique::rsm_gather;
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("SII only"));
    o.technique = indirect_technique::sii;
    // The renderer needs the scene's point sampler.
    CHECK_THROWS_AS(cpu::indirect_renderer(o), parameter_error);
    cpu::indirect_renderer r;
    CHECK_THROWS_WITH(r.set_options(o), Catch::Contains("ism_point_sampler"));
    CHECK(r.options().visibility == indirect_visibility::none);
    CHECK(parse_visibility("ism") == indirect_visibility::ism);
    CHECK(visibility_name(indirect_visibility::ism) == "ism");
}
