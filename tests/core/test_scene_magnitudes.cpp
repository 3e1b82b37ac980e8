// World coordinates and light values beyond what float32 rays and sums carry are refused by
// the core's validation, naming the field, before any backend sees them (Embree asserted on
// a camera or light at 1e19; a vertex at 1e30 was dropped as "degenerate").
#include "../parameter_refusal.hpp"

#include <bounce/camera.hpp>
#include <bounce/scene_view.hpp>

#include <catch2/catch.hpp>

#include <vector>

using namespace bounce;
using bounce::test::refusal_message;
using Catch::Matchers::Contains;

TEST_CASE("coordinates up to 1e18 pass, beyond it the field is named", "[core][scene][bad-input]") {
    std::vector<glm::vec3> p = {{0, 0, 0}, {1e18f, 0, 0}, {0, -1e18f, 0}};
    const std::vector<glm::uvec3> t = {{0, 1, 2}};
    const std::vector<std::uint32_t> m = {0};
    const std::vector<material> mats = {material{}};
    scene_view s{p, {}, t, m, mats, {}, false};
    CHECK_NOTHROW(s.validate_mesh());
    p[1].x = 1e19f;  // finite in float, beyond Embree's 1.844e18
    s.positions = p;
    CHECK_THAT(refusal_message([&] { s.validate_mesh(); }), Contains("scene.positions") && Contains("vertex 1") && Contains("1e18"));
}

TEST_CASE("lights far away or absurdly bright are refused naming the light and field", "[core][light][bad-input]") {
    std::vector<light> lights = {point_light{{0, 1e18f, 0}, glm::vec3(1e30f)}};
    CHECK_NOTHROW(validate_lights(lights));
    lights[0] = point_light{{0, 1e19f, 0}, glm::vec3(1)};
    CHECK_THAT(refusal_message([&] { validate_lights(lights); }), Contains("scene.lights[0]") && Contains("position"));
    lights[0] = spot_light{{0, 1, 0}, {0, -1, 0}, glm::vec3(1e38f, 1, 1), 45.f};
    CHECK_THAT(refusal_message([&] { validate_lights(lights); }), Contains("scene.lights[0]") && Contains("intensity"));
    lights[0] = directional_light{{0, -1, 0}, glm::vec3(2e30f)};
    CHECK_THAT(refusal_message([&] { validate_lights(lights); }), Contains("irradiance"));
}

TEST_CASE("a camera beyond 1e18 is refused naming camera.position or camera.look_at", "[core][camera][bad-input]") {
    camera c;
    c.position = {0, 0, 1e19f};
    CHECK_THAT(refusal_message([&] { c.validate(); }), Contains("camera.position"));
    c.position = {0, 0, 1};
    c.look_at = {-1e19f, 0, 0};
    CHECK_THAT(refusal_message([&] { c.validate(); }), Contains("camera.look_at"));
}
