// gl::rsm_renderer on closed forms: a spot light over a plane, a point light's cube over it
// and a distant light across it, where every texel's position, normal and reflected flux are
// known (the texel-centre ray meets the plane; Phi = rho I profile dw or rho E a); the
// solid angles of a cube's faces sum to 4 pi; bad targets and options refused by name.
#include "../embree/hand_built_scenes.hpp"
#include "../gl/shared_context.hpp"

#include <bounce/camera.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/rsm_renderer.hpp>
#include <bounce/direct_light.hpp>
#include <bounce/rectangle_solid_angle.hpp>
#include <bounce/indirect/rsm.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <string>

using namespace bounce;

namespace {

// The plane z = 0, half-size 50 (a "floor" far wider than any map sees), albedo rho.
hand_built::scene wide_floor(glm::vec3 rho) {
    hand_built::scene s;
    const auto mat = hand_built::add_material(s, rho);
    hand_built::add_square_z(s, 0.f, 50.f, true, mat);
    return s;
}

struct texel_error {
    double position = 0, normal = 0, flux = 0;
    std::size_t lit = 0;
};

// Positions to 1e-5 of the light's height over the plane (float interpolation across a
// 100 m quad: ~50 ulp of 50 m), normals exactly up, flux to 1e-5 relative (the kernels' float
// rounding, a few ulp, and the position's effect on the spot profile).
texel_error compare_with_plane(const gl::rsm_images& m, const gl::rsm_map_layout& layout, const packed_light& l,
                               glm::vec3 rho, std::size_t r) {
    texel_error e;
    camera cam;
    cam.position = layout.position;
    cam.look_at = layout.position + layout.forward;
    cam.up = layout.up;
    cam.fov_y_deg = layout.fov_deg;
    const double t = std::tan(glm::radians(double(layout.fov_deg)) * 0.5);
    for (std::size_t y = 0; y < r; ++y)
        for (std::size_t x = 0; x < r; ++x) {
            const glm::dvec3 d = glm::dvec3(cam.direction(float(x) + 0.5f, float(y) + 0.5f, r, r));
            const glm::dvec3 o(cam.position);
            if (!(d.z < 0)) {
                e.flux = std::max(e.flux, double(glm::length(m.flux(x, y))));  // sees nothing
                continue;
            }
            const glm::dvec3 p = o - d * (o.z / d.z);
            if (std::abs(p.x) > 49 || std::abs(p.y) > 49) continue;
            const double x0 = (2.0 * double(x) / double(r) - 1.0) * t, x1 = (2.0 * double(x + 1) / double(r) - 1.0) * t;
            const double y1 = (1.0 - 2.0 * double(y) / double(r)) * t, y0 = (1.0 - 2.0 * double(y + 1) / double(r)) * t;
            const double dw = rectangle_solid_angle<double>(x0, y0, x1, y1);
            double profile = 1;
            if (l.kind() == light_kind::spot)
                profile = spot_profile<double>(glm::dot(glm::normalize(p - o), glm::dvec3(l.direction())),
                                               double(l.cos_cone()), double(l.cosine_falloff()));
            const glm::dvec3 expected = glm::dvec3(rho) * glm::dvec3(l.intensity()) * (profile * dw);
            e.position = std::max(e.position, glm::length(glm::dvec3(m.position(x, y)) - p) / o.z);
            e.normal = std::max(e.normal, glm::length(glm::dvec3(m.normal(x, y)) - glm::dvec3(0, 0, 1)));
            if (expected.x > 0) {
                ++e.lit;
                e.flux = std::max(e.flux, glm::length(glm::dvec3(m.flux(x, y)) - expected) / glm::length(expected));
            }
        }
    return e;
}

}  // namespace

TEST_CASE("a GL RSM of a spot light over a plane holds the texel-centre hits and rho I profile dw", "[gl][rsm]") {
    gl_test::shared_context();
    const glm::vec3 rho(0.7f, 0.5f, 0.3f);
    auto s = wide_floor(rho);
    spot_light spot;
    spot.position = {0.3f, -0.2f, 1.5f};
    spot.direction = {0.2f, 0.1f, -1.f};
    spot.intensity = {4.f, 3.f, 2.f};
    spot.cone_deg = 35.f;
    s.lights = {spot};
    const gl::scene_mesh mesh(s.view());
    gl::rsm_renderer renderer(s.view(), mesh, {32, 60.f});
    renderer.render();
    REQUIRE(renderer.maps().size() == 1);
    const auto layout = renderer.layout(s.lights);
    const gl::rsm_images m(renderer.maps()[0]);
    CHECK(m.light_view_projection == layout[0].light_view_projection);
    const texel_error e = compare_with_plane(m, layout[0], pack(s.lights[0]), rho, 32);
    INFO("position " << e.position << ", normal " << e.normal << ", flux " << e.flux << ", lit " << e.lit);
    CHECK(e.lit > 500);
    CHECK(e.position <= 1e-5);
    CHECK(e.normal <= 1e-6);
    CHECK(e.flux <= 1e-5);
}

TEST_CASE("a GL RSM of a point light is six cube faces, the one facing the plane exact", "[gl][rsm]") {
    gl_test::shared_context();
    const glm::vec3 rho(0.6f);
    auto s = wide_floor(rho);
    s.lights = {point_light{{0.1f, 0.2f, 1.2f}, {2.f, 1.f, 0.5f}}};
    const gl::scene_mesh mesh(s.view());
    gl::rsm_renderer renderer(s.view(), mesh, {24, 60.f});
    renderer.render();
    const auto layout = renderer.layout(s.lights);
    REQUIRE(layout.size() == 6);
    REQUIRE(renderer.maps().size() == 6);
    // -z is face 5: it sees the plane everywhere.
    const gl::rsm_images down(renderer.maps()[5]);
    const texel_error e = compare_with_plane(down, layout[5], pack(s.lights[0]), rho, 24);
    INFO("position " << e.position << ", normal " << e.normal << ", flux " << e.flux);
    CHECK(e.lit == 24 * 24);
    CHECK(e.position <= 1e-5);
    CHECK(e.flux <= 1e-5);
    // +z sees nothing: flux 0 and the background normal.
    const gl::rsm_images up(renderer.maps()[4]);
    for (std::size_t y = 0; y < 24; ++y)
        for (std::size_t x = 0; x < 24; ++x) {
            CHECK(up.flux(x, y) == glm::vec3(0.f));
            CHECK(up.normal(x, y) == glm::vec3(0, 0, -1));
        }
}

TEST_CASE("a GL RSM of a distant light reflects rho E a per texel across the beam", "[gl][rsm]") {
    gl_test::shared_context();
    const glm::vec3 rho(0.5f);
    hand_built::scene s;
    const auto mat = hand_built::add_material(s, rho);
    hand_built::add_square_z(s, 0.f, 1.f, true, mat);
    s.lights = {directional_light{{0.f, 0.f, -1.f}, {3.f, 2.f, 1.f}}};
    const gl::scene_mesh mesh(s.view());
    const std::size_t r = 32;
    gl::rsm_renderer renderer(s.view(), mesh, {r, 60.f});
    renderer.render();
    const auto layout = renderer.layout(s.lights);
    REQUIRE(layout.size() == 1);
    const gl::rsm_images m(renderer.maps()[0]);
    // The beam straight down onto the square: the lit texels' flux sums to rho E times the
    // square's area, 4 m^2, up to the texels the square's edges cut (a texel is counted whole
    // when its centre is inside): at most the perimeter's texels, 4 * 2 / texel_size.
    glm::dvec3 sum(0.0);
    std::size_t lit = 0;
    const double a = double(layout[0].texel_size) * double(layout[0].texel_size);
    for (std::size_t y = 0; y < r; ++y)
        for (std::size_t x = 0; x < r; ++x) {
            if (m.flux(x, y) == glm::vec3(0.f)) continue;
            ++lit;
            sum += glm::dvec3(m.flux(x, y));
            CHECK(std::abs(double(m.flux(x, y).x) - 0.5 * 3 * a) <= 1e-6 * 0.5 * 3 * a);
            CHECK(m.normal(x, y) == glm::vec3(0, 0, 1));
            CHECK(std::abs(m.position(x, y).z) <= 1e-6f);
        }
    const double edge_texels = 8.0 / double(layout[0].texel_size);
    CHECK(std::abs(sum.x - 0.5 * 3 * 4) <= 0.5 * 3 * a * edge_texels);
    CHECK(lit > 100);
}

TEST_CASE("a wide GL spot light gets the cube faces its cone can reach", "[gl][rsm]") {
    gl_test::shared_context();
    auto s = wide_floor(glm::vec3(0.5f));
    spot_light spot;
    spot.position = {0.f, 0.f, 1.f};
    spot.direction = {0.f, 0.f, -1.f};
    spot.cone_deg = 80.f;
    s.lights = {spot};
    const gl::scene_mesh mesh(s.view());
    gl::rsm_renderer renderer(s.view(), mesh, {16, 60.f});
    const auto layout = renderer.layout(s.lights);
    // All but +z (its directions lie at least 45 degrees above the horizon; the cone reaches
    // 10 degrees below it).
    REQUIRE(layout.size() == 5);
    for (const auto& m : layout) CHECK(m.forward != glm::vec3(0, 0, 1));
}

TEST_CASE("the GL RSM renderer refuses bad targets and options by name", "[gl][rsm]") {
    gl_test::shared_context();
    auto s = wide_floor(glm::vec3(0.5f));
    s.lights = {spot_light{}};
    const gl::scene_mesh mesh(s.view());
    gl::rsm_renderer renderer(s.view(), mesh, {8, 60.f});
    const auto throws_naming = [](auto&& f, const std::string& name) {
        try {
            f();
            FAIL("no exception");
        } catch (const parameter_error& e) {
            CHECK(std::string(e.what()).find(name) != std::string::npos);
        }
    };
    gl::texture p(gl::texel_format::rgba32f, 8, 8), n(gl::texel_format::rgba32f, 8, 8), f(gl::texel_format::rgba32f, 8, 8);
    gl::texture small(gl::texel_format::rgba32f, 4, 8), r32(gl::texel_format::r32f, 8, 8);
    std::vector<gl::rsm_textures> none;
    throws_naming([&] { renderer.render(s.lights, none); }, "targets");
    std::vector<gl::rsm_textures> wrong_size{{p, n, small, {}}};
    throws_naming([&] { renderer.render(s.lights, wrong_size); }, "targets");
    std::vector<gl::rsm_textures> wrong_format{{p, r32, f, {}}};
    throws_naming([&] { renderer.render(s.lights, wrong_format); }, "targets");
    std::vector<gl::rsm_textures> good{{p, n, f, {}}};
    renderer.render(s.lights, good);
    CHECK(good[0].light_view_projection == renderer.layout(s.lights)[0].light_view_projection);
    const std::vector<light> bad_light{spot_light{{0, 0, 0}, {0, 0, 0}, {1, 1, 1}, 45.f}};
    throws_naming([&] { renderer.render(bad_light, good); }, "lights[0]");
    throws_naming([&] { gl::rsm_renderer x(s.view(), mesh, {0, 60.f}); }, "resolution");
    throws_naming([&] { gl::rsm_renderer x(s.view(), mesh, {8, 90.f}); }, "max_single_map_cone_deg");
}
