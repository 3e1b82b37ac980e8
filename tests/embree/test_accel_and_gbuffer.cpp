// The Embree adapter's device, BVH queries and ray-cast G-buffer: closed-form hits on
// hand-made geometry, Embree's errors surfaced with its message, and bad input refused.
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/sampling.hpp>

#include "hand_built_scenes.hpp"
#include "../scoped_environment.hpp"

#include <catch2/catch.hpp>
#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace bounce;
using namespace bounce::embree;

namespace {

// A unit square [-1,1]^2 in the plane through the origin with normal (sin a, 0, cos a),
// its vertex normals pointing *away* from a camera on +z (the G-buffer must flip them).
test::owned_scene tilted_square(double tilt) {
    test::owned_scene s;
    s.name = "tilted-square";
    const auto m = hand_built::add_material(s, {0.25f, 0.5f, 0.75f});
    const glm::dvec3 n(std::sin(tilt), 0, std::cos(tilt)), u(std::cos(tilt), 0, -std::sin(tilt)), v(0, 1, 0);
    auto corner = [&](double a, double b) { return glm::vec3(a * u + b * v); };
    hand_built::add_quad(s, corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1), glm::vec3(-n), m);
    return s;
}

// Two parallel squares z = 1 and z = 2, 4 wide: rays from below hit z = 1 first.
test::owned_scene two_parallel_squares() {
    test::owned_scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.5f));
    hand_built::add_square_z(s, 1.f, 4.f, false, m);
    hand_built::add_square_z(s, 2.f, 4.f, false, m);
    return s;
}

// `count` rays from the unit square around the origin in z = 0, within 60 degrees of +z, so
// they stay inside two_parallel_squares (tan 60 * 2 < 4 - 0.5).
std::vector<ray> rays_up_into_the_squares(std::uint64_t seed, int count) {
    pcg32 rng(seed);
    std::vector<ray> rays;
    for (int i = 0; i < count; ++i) {
        const glm::vec3 o(float(rng.next_double() - 0.5), float(rng.next_double() - 0.5), 0.f);
        const double cz = 0.5 + 0.5 * rng.next_double(), r = std::sqrt(1 - cz * cz), phi = 6.283185307 * rng.next_double();
        rays.push_back({o, glm::vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(cz))});
    }
    return rays;
}

}  // namespace

TEST_CASE("an Embree error surfaces as embree_error with the callback's message", "[embree][errors]") {
    const device dev;
    REQUIRE_NOTHROW(dev.check("nothing yet"));
    RTCScene scene = rtcNewScene(dev.native());
    // An out-of-range build quality is an invalid argument Embree reports by callback.
    rtcSetSceneBuildQuality(scene, static_cast<RTCBuildQuality>(77));
    try {
        dev.check("rtcSetSceneBuildQuality");
        FAIL("no error raised");
    } catch (const embree_error& e) {
        CHECK(e.code() != RTC_ERROR_NONE);
        CHECK_FALSE(e.message().empty());
        CHECK(std::string(e.what()).find("rtcSetSceneBuildQuality") != std::string::npos);
        CHECK(std::string(e.what()).find(e.message()) != std::string::npos);
    }
    // The check consumed the error.
    CHECK_NOTHROW(dev.check("after"));
    rtcReleaseScene(scene);
    // It is a bounce::error, so callers can catch the library's errors in one place.
    CHECK(std::is_base_of_v<bounce::error, embree_error>);
}

TEST_CASE("a device's configuration pins Embree's kernels and is checked before Embree sees it",
          "[embree][device]") {
    // Every kernel set must find the lower square at t = 1 / d.z, to the few ulps its float
    // intersection allows.
    const test::owned_scene s = two_parallel_squares();
    const std::string config = GENERATE(as<std::string>{}, "", "max_isa=sse2", "max_isa=sse4.2,threads=1",
                                        "max_isa=avx,verbose=0", "start_threads=1,set_affinity=0,hugepages=0");
    CAPTURE(config);
    const device dev(config);
    CHECK(dev.config() == config);
    const accel bvh(dev, s);
    for (const ray& q : rays_up_into_the_squares(5, 200)) {
        const hit h = bvh.intersect(q);
        REQUIRE(h.found());
        CHECK(h.t == Approx(1.0 / q.direction.z).epsilon(1e-5));
        CHECK(h.triangle < 2u);
    }
}

TEST_CASE("a device configuration Embree would silently ignore is refused, naming the option",
          "[embree][device][bad-input]") {
    // rtcNewDevice skips unknown keys and values (checked: it returns a device for each of
    // these), so a misspelt max_isa would quietly leave the kernels unpinned.
    // {configuration, the option the message must quote}
    const auto [bad, option] = GENERATE(table<std::string, std::string>({
        {"bogus=1", "bogus=1"}, {"max_isa=nonsense", "max_isa=nonsense"}, {"max_isa=AVX2", "max_isa=AVX2"},
        {"threads=-3", "threads=-3"}, {"threads=", "threads="}, {"verbose", "verbose"}, {"=1", "=1"},
        {"verbose=4", "verbose=4"}, {"max_isa=sse4.2,", ""}, {"threads=1,,verbose=1", ""},
        {" max_isa=sse4.2", " max_isa=sse4.2"}, {"threads=1,hugepages=yes", "hugepages=yes"},
        {"frequency_level=simd64", "frequency_level=simd64"}}));
    CAPTURE(bad);
    CHECK_THROWS_AS(device(bad), parameter_error);
    CHECK_THROWS_WITH(device(bad),
                      Catch::Contains("embree::device config") && Catch::Contains("option '" + option + "'"));
}

TEST_CASE("BOUNCE_EMBREE_CONFIG configures default devices and is checked under its name",
          "[embree][device][bad-input]") {
    const bounce::test::scoped_environment config("BOUNCE_EMBREE_CONFIG");
    config.set("max_isa=sse4.2");
    CHECK(device().config() == "max_isa=sse4.2");
    const test::owned_scene empty;
    CHECK(accel(empty).owner().config() == "max_isa=sse4.2");
    config.set("max_isa=sse4");
    CHECK_THROWS_WITH(device(), Catch::Contains("BOUNCE_EMBREE_CONFIG") && Catch::Contains("'max_isa=sse4'"));
    config.set("");
    CHECK(device().config().empty());
    config.unset();
    CHECK(device().config().empty());
}

TEST_CASE("building from an invalid scene names the faulty field", "[embree][bad-input]") {
    test::owned_scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.5f));
    hand_built::add_square_z(s, 0.f, 1.f, true, m);

    SECTION("index out of range") {
        s.triangles[1].z = 99;
        CHECK_THROWS_WITH(accel(s), Catch::Contains("scene.triangles"));
    }
    SECTION("non-finite vertex") {
        s.positions[2].y = std::numeric_limits<float>::quiet_NaN();
        CHECK_THROWS_AS(accel(s), parameter_error);
        CHECK_THROWS_WITH(accel(s), Catch::Contains("scene.positions"));
    }
    SECTION("material index out of range") {
        s.material_of[0] = 3;
        CHECK_THROWS_WITH(accel(s), Catch::Contains("scene.material_of"));
    }
    SECTION("material_of of the wrong length") {
        s.material_of.pop_back();
        CHECK_THROWS_WITH(accel(s), Catch::Contains("scene.material_of"));
    }
    SECTION("normals of the wrong length") {
        s.normals.pop_back();
        CHECK_THROWS_WITH(accel(s), Catch::Contains("scene.normals"));
    }
    SECTION("negative reflectance") {
        s.materials[0].albedo.y = -0.1f;
        CHECK_THROWS_WITH(accel(s), Catch::Contains("scene.materials"));
    }
    SECTION("a scene other than the one the accel was built from") {
        const accel bvh(s);
        test::owned_scene other = s;
        hand_built::add_square_z(other, 1.f, 1.f, true, m);
        CHECK_THROWS_AS(ray_cast_gbuffer(bvh, other, other.camera, 8, 8), parameter_error);
    }
}

TEST_CASE("an empty scene builds and every ray misses", "[embree]") {
    test::owned_scene s;
    const accel bvh(s);
    CHECK(bvh.triangle_count() == 0);
    CHECK_FALSE(bvh.intersect({{0, 0, 0}, {0, 0, 1}}).found());
    CHECK_FALSE(bvh.occluded({{0, 0, 0}, {0, 0, 1}}));
}

TEST_CASE("closest hits and occlusion agree with the plane equation", "[embree][queries]") {
    const test::owned_scene squares = two_parallel_squares();
    const accel bvh(squares);
    const std::vector<ray> rays = rays_up_into_the_squares(21, 500);
    std::vector<hit> stream(rays.size());
    bvh.intersect(rays, stream);
    std::vector<std::uint8_t> blocked(rays.size());
    bvh.occluded(rays, blocked);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const hit h = bvh.intersect(rays[i]);
        REQUIRE(h.found());
        // t = (1 - o.z) / d.z; Embree's float intersection is accurate to a few ulp of t.
        CHECK(h.t == Approx(1.0 / rays[i].direction.z).epsilon(1e-5));
        CHECK(h.triangle < 2u);  // the lower square's two triangles
        CHECK(stream[i].triangle == h.triangle);
        CHECK(stream[i].t == h.t);
        CHECK(blocked[i] == 1);
        CHECK(bvh.occluded(rays[i]));
        // A segment that ends before the first plane is free.
        ray shortened = rays[i];
        shortened.tfar = 0.9f / rays[i].direction.z;
        CHECK_FALSE(bvh.occluded(shortened));
    }
    std::vector<hit> wrong(3);
    CHECK_THROWS_AS(bvh.intersect(rays, wrong), parameter_error);
}

TEST_CASE("the ray-cast G-buffer of a quad matches the closed-form hit at every pixel", "[embree][gbuffer]") {
    const double tilt = GENERATE(0.0, 0.5, -1.0);
    const test::owned_scene s = tilted_square(tilt);
    const accel bvh(s);
    camera cam;
    cam.position = {0.2f, -0.1f, 4.f};
    cam.look_at = {0.f, 0.f, 0.f};
    cam.up = {0.f, 1.f, 0.f};
    cam.fov_y_deg = 40.f;
    const std::size_t w = 64, h = 48;  // not square: the aspect ratio enters the directions
    auto g = ray_cast_gbuffer(bvh, s, cam, w, h);

    // Camera frame and plane in double, from the definitions in camera.hpp.
    const glm::dvec3 eye(cam.position), fwd = glm::normalize(glm::dvec3(cam.look_at) - eye);
    const glm::dvec3 right = glm::normalize(glm::cross(fwd, glm::dvec3(cam.up))), up = glm::cross(right, fwd);
    const double t_half = std::tan(double(cam.fov_y_deg) * std::numbers::pi / 360), aspect = double(w) / double(h);
    const glm::dvec3 n(std::sin(tilt), 0, std::cos(tilt)), u(std::cos(tilt), 0, -std::sin(tilt)), v(0, 1, 0);
    // The closed form follows the very ray of each pixel centre, so only float rounding
    // (~1e-6 here) can put a hit on the other side of the border: skip 1e-3 around it.
    const double margin = 1e-3;
    std::size_t inside = 0, outside = 0;
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            const double sx = (2 * (x + 0.5) / w - 1) * t_half * aspect, sy = (1 - 2 * (y + 0.5) / h) * t_half;
            const glm::dvec3 d = fwd + sx * right + sy * up;
            const double t = -glm::dot(n, eye) / glm::dot(n, d);
            const glm::dvec3 p = eye + t * d;
            const double a = glm::dot(p, u), b = glm::dot(p, v);
            const double edge = std::max(std::abs(a), std::abs(b));
            if (edge < 1 - margin && t > 0) {
                ++inside;
                REQUIRE(g.view().covered(x, y));
                // Float ray setup and intersection: relative error ~1e-6 of |p| ~ 1-4.
                CHECK(glm::length(glm::dvec3(g.position(x, y)) - p) < 2e-5);
                CHECK(double(g.depth(x, y)) == Approx(t * glm::dot(d, fwd)).epsilon(1e-5));
                // The vertex normals point away from the camera: flipped, they face it.
                const glm::dvec3 facing = glm::dot(n, d) < 0 ? n : -n;
                CHECK(glm::length(glm::dvec3(g.normal(x, y)) - facing) < 1e-6);
                CHECK(g.albedo(x, y) == glm::vec3(0.25f, 0.5f, 0.75f));
            } else if (edge > 1 + margin || t <= 0) {
                ++outside;
                CHECK(std::isinf(g.depth(x, y)));
                CHECK(g.normal(x, y) == glm::vec3(0.f));
            }
        }
    CHECK(inside > 200);
    CHECK(outside > 200);
}

TEST_CASE("the G-buffer normal is the normalized barycentric blend of the vertex normals", "[embree][gbuffer]") {
    test::owned_scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.5f));
    const std::array<glm::vec3, 3> p = {glm::vec3(-1, -1, 0), glm::vec3(1.5f, -1, 0), glm::vec3(0, 1.5f, 0)};
    const std::array<glm::vec3, 3> nv = {glm::normalize(glm::vec3(0.5f, 0, 1)), glm::normalize(glm::vec3(-0.3f, 0.4f, 1)),
                                         glm::normalize(glm::vec3(0, -0.6f, 1))};
    hand_built::add_triangle(s, p, nv, m);
    const accel bvh(s);
    camera cam;
    cam.position = {0.f, 0.f, 3.f};
    cam.look_at = {0.f, 0.f, 0.f};
    auto g = ray_cast_gbuffer(bvh, s, cam, 40, 40);
    std::size_t checked = 0;
    for (std::size_t y = 0; y < 40; ++y)
        for (std::size_t x = 0; x < 40; ++x) {
            if (!g.view().covered(x, y)) continue;
            // Barycentrics of the G-buffer position in double (the triangle lies in z = 0).
            const glm::dvec2 q(glm::dvec3(g.position(x, y))), a(p[0]), b(p[1]), c(p[2]);
            const double det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
            const double l1 = ((q.x - a.x) * (c.y - a.y) - (c.x - a.x) * (q.y - a.y)) / det;
            const double l2 = ((b.x - a.x) * (q.y - a.y) - (q.x - a.x) * (b.y - a.y)) / det;
            const glm::dvec3 blend =
                glm::normalize((1 - l1 - l2) * glm::dvec3(nv[0]) + l1 * glm::dvec3(nv[1]) + l2 * glm::dvec3(nv[2]));
            CHECK(glm::length(glm::dvec3(g.normal(x, y)) - blend) < 1e-5);
            CHECK(std::abs(glm::length(g.normal(x, y)) - 1.f) < 1e-6f);
            ++checked;
        }
    CHECK(checked > 100);
}

TEST_CASE("the G-buffer refuses mismatched views and invalid cameras", "[embree][gbuffer][bad-input]") {
    test::owned_scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.5f));
    hand_built::add_square_z(s, 0.f, 1.f, true, m);
    const accel bvh(s);
    gbuffer<float> a(8, 8), b(9, 8);
    gbuffer_view<float> mixed = a.view();
    mixed.normal = b.view().normal;
    CHECK_THROWS_AS(ray_cast_gbuffer(bvh, s, s.camera, mixed), parameter_error);
    camera bad = s.camera;
    bad.fov_y_deg = 0.f;
    CHECK_THROWS_AS(ray_cast_gbuffer(bvh, s, bad, a.view()), parameter_error);
    CHECK_THROWS_AS(ray_cast_gbuffer(bvh, s, s.camera, 0, 8), parameter_error);
}
