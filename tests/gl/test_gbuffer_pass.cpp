// The raster G-buffer against closed forms: a quad facing the camera has constant depth,
// the normal facing the eye, its Kd, and covers exactly the pixels whose centre ray hits
// it; an oblique view puts every covered pixel on its centre ray; the nearer surface wins;
// the caller's GL state survives; bad scenes are refused.
#include "shared_context.hpp"

#include "../owned_scene.hpp"

#include <bounce/gl/gbuffer_pass.hpp>


#include <epoxy/gl.h>  // GL entry points from whatever context is current (EGL, GLX, WGL)
#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cmath>
#include <limits>

using namespace bounce;

namespace {

// A square [c - h, c + h]^2 in the plane z = z0 with vertex normals `normal`, material m.
void add_quad(test::owned_scene& s, float z0, float h, glm::vec3 normal, std::uint32_t m, bool reverse_winding = false) {
    const auto base = std::uint32_t(s.positions.size());
    for (const glm::vec2 c : {glm::vec2(-h, -h), glm::vec2(h, -h), glm::vec2(h, h), glm::vec2(-h, h)}) {
        s.positions.emplace_back(c.x, c.y, z0);
        s.normals.push_back(normal);
    }
    if (reverse_winding) {
        s.triangles.emplace_back(base, base + 2, base + 1);
        s.triangles.emplace_back(base, base + 3, base + 2);
    } else {
        s.triangles.emplace_back(base, base + 1, base + 2);
        s.triangles.emplace_back(base, base + 2, base + 3);
    }
    s.material_of.insert(s.material_of.end(), 2, m);
}

test::owned_scene quad_scene(glm::vec3 normal, bool reverse_winding = false) {
    test::owned_scene s;
    s.materials.push_back({glm::vec3(0.2f, 0.4f, 0.6f), glm::vec3(0.f)});
    add_quad(s, 0.f, 1.f, normal, 0, reverse_winding);
    return s;
}

camera front_camera() {
    camera c;
    c.position = {0, 0, 3};
    c.look_at = {0, 0, 0};
    c.up = {0, 1, 0};
    c.fov_y_deg = 45.f;
    return c;
}

// Where the centre ray of pixel (x, y) meets the plane z = z0 (camera.hpp's pixel centres).
glm::dvec3 centre_ray_hit(const camera& c, std::size_t x, std::size_t y, std::size_t w, std::size_t h, double z0) {
    const glm::dvec3 d = c.direction(float(x) + 0.5f, float(y) + 0.5f, w, h), e = c.position;
    return e + d * ((z0 - e.z) / d.z);
}

constexpr float inf = std::numeric_limits<float>::infinity();

}  // namespace

TEST_CASE("a quad facing the camera: constant depth, facing normal, Kd, exact coverage", "[gl][gbuffer]") {
    gl_test::shared_context();
    // Normals toward the camera, away from it (flipped to face it), and the other winding
    // (no culling): the G-buffer is the same.
    const auto normal_z = GENERATE(1.f, -1.f);
    const auto reversed = GENERATE(false, true);
    const gl::scene_mesh mesh(quad_scene({0, 0, normal_z}, reversed));
    gl::gbuffer_pass pass;
    const auto cam = front_camera();
    const std::size_t W = 48, H = 32;  // not square: the aspect ratio matters
    pass.render(mesh, cam, W, H);
    auto g = pass.read();
    REQUIRE(g.width() == W);
    REQUIRE(g.height() == H);
    std::size_t covered = 0;
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            const auto p = centre_ray_hit(cam, x, y, W, H, 0.0);
            const double margin = std::min(1 - std::abs(p.x), 1 - std::abs(p.y));
            INFO("pixel (" << x << ", " << y << "), centre ray hits (" << p.x << ", " << p.y << ")");
            // Pixels whose centre lies within 1e-3 of the edge may go either way (the
            // rasterizer's fixed-point snapping); the nearest centres here are 0.02 away.
            if (std::abs(margin) < 1e-3) continue;
            if (margin > 0) {
                ++covered;
                REQUIRE(g.view().covered(x, y));
                // Depth along forward: the plane is 3 units ahead; float interpolation
                // of positions leaves a few ulp of 3.
                CHECK(std::abs(g.depth(x, y) - 3.f) < 1e-5f);
                CHECK(glm::length(glm::dvec3(g.position(x, y)) - p) < 1e-5);
                CHECK(g.normal(x, y) == glm::vec3(0, 0, 1));
                CHECK(g.albedo(x, y) == glm::vec3(0.2f, 0.4f, 0.6f));
            } else {
                REQUIRE_FALSE(g.view().covered(x, y));
                CHECK(g.depth(x, y) == inf);
                CHECK(g.normal(x, y) == glm::vec3(0));
                CHECK(g.albedo(x, y) == glm::vec3(0));
            }
        }
    // The quad spans |ndc| < 1 / (3 tan 22.5 deg) = 0.805 vertically: 26 of 32 rows.
    CHECK(covered > 0);
}

TEST_CASE("an oblique view puts every covered pixel on its centre ray, at its view depth", "[gl][gbuffer]") {
    gl_test::shared_context();
    const gl::scene_mesh mesh(quad_scene({0, 0, 1}));
    camera cam;
    cam.position = {2.f, 1.5f, 3.f};
    cam.look_at = {0.2f, -0.1f, 0.f};
    cam.up = {0, 1, 0};
    cam.fov_y_deg = 50.f;
    const std::size_t W = 40, H = 30;
    gl::gbuffer_pass pass;
    pass.render(mesh, cam, W, H);
    auto g = pass.read();
    const glm::dvec3 forward = cam.forward(), eye = cam.position;
    std::size_t covered = 0;
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            const auto p = centre_ray_hit(cam, x, y, W, H, 0.0);
            const double margin = std::min(1 - std::abs(p.x), 1 - std::abs(p.y));
            INFO("pixel (" << x << ", " << y << ")");
            // A pixel's footprint on the plane is about 0.1 here; stay 0.01 off the edges.
            if (std::abs(margin) < 1e-2) continue;
            REQUIRE(g.view().covered(x, y) == (margin > 0));
            if (margin <= 0) continue;
            ++covered;
            // Perspective-correct interpolation in float: relative error ~1e-6 of
            // coordinates of order 4.
            CHECK(glm::length(glm::dvec3(g.position(x, y)) - p) < 2e-5);
            CHECK(std::abs(double(g.depth(x, y)) - glm::dot(p - eye, forward)) < 2e-5);
            CHECK(glm::length(glm::dvec3(g.normal(x, y)) - glm::dvec3(0, 0, 1)) < 1e-6);
        }
    CHECK(covered > 100);
}

TEST_CASE("the nearer of two surfaces wins, with its own material", "[gl][gbuffer]") {
    gl_test::shared_context();
    test::owned_scene s;
    s.materials.push_back({glm::vec3(0.f, 1.f, 0.f), glm::vec3(0.f)});
    s.materials.push_back({glm::vec3(1.f, 0.f, 0.f), glm::vec3(0.f)});
    add_quad(s, 1.f, 0.25f, {0, 0, 1}, 1);  // drawn first, nearer
    add_quad(s, 0.f, 1.f, {0, 0, 1}, 0);
    const gl::scene_mesh mesh(s);
    gl::gbuffer_pass pass;
    pass.render(mesh, front_camera(), 32, 32);
    auto g = pass.read();
    // The centre pixels see the near quad (2 units ahead); a pixel a quarter of the way
    // in sees only the far one (its centre ray meets z = 1 at |x| ~ 0.3 > 0.25).
    CHECK(std::abs(g.depth(16, 16) - 2.f) < 1e-5f);
    CHECK(g.albedo(16, 16) == glm::vec3(1, 0, 0));
    CHECK(std::abs(g.depth(8, 16) - 3.f) < 1e-5f);
    CHECK(g.albedo(8, 16) == glm::vec3(0, 1, 0));
}

TEST_CASE("rows are read back top first: the upper half of the image sees +y", "[gl][gbuffer]") {
    gl_test::shared_context();
    test::owned_scene s;
    s.materials.push_back({glm::vec3(0.f, 0.f, 1.f), glm::vec3(0.f)});
    s.materials.push_back({glm::vec3(1.f, 1.f, 0.f), glm::vec3(0.f)});
    // Two strips: y in [-1, 0] (material 0) and y in [0, 1] (material 1).
    s.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 0, 0}, {-1, 0, 0}, {1, 1, 0}, {-1, 1, 0}};
    s.normals.assign(6, glm::vec3(0, 0, 1));
    s.triangles = {{0, 1, 2}, {0, 2, 3}, {3, 2, 4}, {3, 4, 5}};
    s.material_of = {0, 0, 1, 1};
    const gl::scene_mesh mesh(s);
    gl::gbuffer_pass pass;
    pass.render(mesh, front_camera(), 16, 16);
    auto g = pass.read();
    CHECK(g.albedo(8, 5) == glm::vec3(1, 1, 0));
    CHECK(g.position(8, 5).y > 0.f);
    CHECK(g.albedo(8, 10) == glm::vec3(0, 0, 1));
    CHECK(g.position(8, 10).y < 0.f);
}

TEST_CASE("the pass leaves the caller's GL state as it found it", "[gl][gbuffer]") {
    gl_test::shared_context();
    const gl::scene_mesh mesh(quad_scene({0, 0, 1}));
    gl::gbuffer_pass pass;
    // A renderer's own state: its framebuffer, viewport, vertex array, blending, culling.
    gl::texture colour(gl::texel_format::rgba8, 8, 8);
    gl::framebuffer fbo;
    fbo.attach_color(0, colour);
    gl::vertex_array vao;
    glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
    glViewport(1, 2, 3, 4);
    glBindVertexArray(vao.id());
    glEnable(GL_BLEND);
    glEnable(GL_CULL_FACE);
    glDepthFunc(GL_GREATER);
    glDisable(GL_DEPTH_TEST);

    pass.render(mesh, front_camera(), 16, 16);
    (void)pass.read();

    GLint draw_fb = 0, read_fb = 0, viewport[4] = {}, bound_vao = 0, depth_func = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_fb);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_fb);
    glGetIntegerv(GL_VIEWPORT, viewport);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &bound_vao);
    glGetIntegerv(GL_DEPTH_FUNC, &depth_func);
    CHECK(GLuint(draw_fb) == fbo.id());
    CHECK(GLuint(read_fb) == fbo.id());
    CHECK(viewport[0] == 1);
    CHECK(viewport[3] == 4);
    CHECK(GLuint(bound_vao) == vao.id());
    CHECK(glIsEnabled(GL_BLEND) == GL_TRUE);
    CHECK(glIsEnabled(GL_CULL_FACE) == GL_TRUE);
    CHECK(glIsEnabled(GL_DEPTH_TEST) == GL_FALSE);
    CHECK(depth_func == GL_GREATER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDepthFunc(GL_LESS);
    gl::check_error("state test");
}

TEST_CASE("an empty scene renders background everywhere", "[gl][gbuffer]") {
    gl_test::shared_context();
    const gl::scene_mesh mesh(test::owned_scene{});
    gl::gbuffer_pass pass;
    pass.render(mesh, front_camera(), 8, 4);
    auto g = pass.read();
    for (std::size_t y = 0; y < 4; ++y)
        for (std::size_t x = 0; x < 8; ++x) CHECK(g.depth(x, y) == inf);
}

TEST_CASE("bad scenes and sizes are refused with parameter_error naming the field", "[gl][gbuffer][bad-input]") {
    gl_test::shared_context();
    const auto field_of = [](auto&& f) {
        try {
            f();
        } catch (const parameter_error& e) {
            return e.parameter();
        }
        return std::string("(no exception)");
    };
    auto s = quad_scene({0, 0, 1});
    s.triangles[1].z = 4;
    CHECK(field_of([&] { gl::scene_mesh m(s); }) == "scene.triangles");
    s = quad_scene({0, 0, 1});
    s.normals.pop_back();
    CHECK(field_of([&] { gl::scene_mesh m(s); }) == "scene.normals");
    s = quad_scene({0, 0, 1});
    s.material_of[0] = 3;
    CHECK(field_of([&] { gl::scene_mesh m(s); }) == "scene.material_of");
    s.material_of.pop_back();
    CHECK(field_of([&] { gl::scene_mesh m(s); }) == "scene.material_of");

    const gl::scene_mesh mesh(quad_scene({0, 0, 1}));
    gl::gbuffer_pass pass;
    CHECK(field_of([&] { (void)pass.read(); }) == "gbuffer_pass");
    CHECK(field_of([&] { pass.render(mesh, front_camera(), 0, 8); }) == "width/height");
    auto cam = front_camera();
    cam.fov_y_deg = 180.f;
    CHECK(field_of([&] { pass.render(mesh, cam, 8, 8); }) == "fov_y_deg");
    pass.render(mesh, front_camera(), 8, 8);
    gbuffer<float> wrong(8, 9);
    CHECK(field_of([&] { pass.read(wrong.view()); }) == "out");
}
