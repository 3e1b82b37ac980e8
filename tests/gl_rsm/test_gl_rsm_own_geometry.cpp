// A renderer's own geometry and its own maps in the GL RSM passes:
// - gl::rsm_renderer and gl::direct_light drawing the renderer's vertex buffers through a
//   callback (de-indexed, interleaved, in two draws with an albedo offset) give the same
//   maps and the same direct radiance, bit for bit, as the built-in scene_mesh drawer: the
//   same triangles in the same order through the same programs;
// - gl::rsm_upload: a map made on the CPU reads back exactly (float32 in, float32 out, rows
//   flipped twice), and the indirect renderer gathers and splats from uploaded copies of
//   rendered maps exactly what it does from the rendered textures; bad maps refused by name.
#include "../embree/hand_built_scenes.hpp"
#include "../gl/shared_context.hpp"
#include "../parameter_refusal.hpp"
#include "../rsm/corner_scene.hpp"

#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/indirect_renderer.hpp>
#include <bounce/gl/rsm_renderer.hpp>
#include <bounce/gl/rsm_textures.hpp>
#include <bounce/gl/splat_pass.hpp>

#include <catch2/catch.hpp>

#include <epoxy/gl.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

using namespace bounce;

namespace {

constexpr std::size_t W = 40, H = 30;

// A floor, a red wall and a ball over the floor, lit by a point light and a spot light.
hand_built::scene room() {
    hand_built::scene s;
    const auto white = hand_built::add_material(s, {0.8f, 0.8f, 0.8f});
    const auto red = hand_built::add_material(s, {0.7f, 0.2f, 0.1f});
    const auto green = hand_built::add_material(s, {0.2f, 0.6f, 0.3f});
    hand_built::add_square_z(s, 0.f, 1.f, true, white);
    hand_built::add_quad(s, {1, -1, 0}, {1, 1, 0}, {1, 1, 2}, {1, -1, 2}, {-1, 0, 0}, red);
    hand_built::add_icosphere(s, {0.1, 0.2, 0.45}, 0.3, 1, green);
    s.lights.push_back(point_light{{-0.2f, -0.4f, 1.6f}, {3.f, 3.f, 3.f}});
    s.lights.push_back(spot_light{{-0.6f, 0.3f, 1.5f}, {0.4f, -0.1f, -1.f}, {4.f, 3.5f, 3.f}, 35.f});
    s.camera.position = {-0.5f, -2.6f, 1.6f};
    s.camera.look_at = {0.2f, 0.1f, 0.4f};
    s.camera.up = {0, 0, 1};
    s.camera.fov_y_deg = 50.f;
    return s;
}

// The renderer's own buffers: de-indexed vertices, position and normal interleaved, and a
// vec4 albedo per triangle, in plain GL objects bounce knows nothing of.
class own_geometry {
public:
    explicit own_geometry(const hand_built::scene& s) : triangles_(s.triangles.size()) {
        std::vector<float> vertices;
        std::vector<glm::vec4> albedo;
        for (std::size_t t = 0; t < s.triangles.size(); ++t) {
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t i = s.triangles[t][k];
                for (int c = 0; c < 3; ++c) vertices.push_back(s.positions[i][c]);
                for (int c = 0; c < 3; ++c) vertices.push_back(s.normals[i][c]);
            }
            albedo.push_back(glm::vec4(s.materials[s.material_of[t]].albedo, 0.f));
        }
        glCreateBuffers(1, &vertices_);
        glNamedBufferStorage(vertices_, GLsizeiptr(vertices.size() * sizeof(float)), vertices.data(), 0);
        glCreateBuffers(1, &albedo_);
        glNamedBufferStorage(albedo_, GLsizeiptr(albedo.size() * sizeof(glm::vec4)), albedo.data(), 0);
        glCreateVertexArrays(1, &vao_);
        glVertexArrayVertexBuffer(vao_, 0, vertices_, 0, GLsizei(6 * sizeof(float)));
        for (GLuint a : {0u, 1u}) {
            glEnableVertexArrayAttrib(vao_, a);
            glVertexArrayAttribFormat(vao_, a, 3, GL_FLOAT, GL_FALSE, GLuint(3 * a * sizeof(float)));
            glVertexArrayAttribBinding(vao_, a, 0);
        }
    }
    ~own_geometry() {
        glDeleteVertexArrays(1, &vao_);
        glDeleteBuffers(1, &vertices_);
        glDeleteBuffers(1, &albedo_);
    }
    own_geometry(const own_geometry&) = delete;
    own_geometry& operator=(const own_geometry&) = delete;

    // The RSM callback: two draws, the second one's triangles starting the albedo buffer's
    // second half, so the offset is exercised.
    void draw_rsm(const gl::rsm_draw& d, bool offset = true) const {
        glBindVertexArray(vao_);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, albedo_);
        const std::size_t half = triangles_ / 2;
        glDrawArrays(GL_TRIANGLES, 0, GLsizei(3 * half));
        if (offset) d.set_first_triangle(std::uint32_t(half));
        glDrawArrays(GL_TRIANGLES, GLint(3 * half), GLsizei(3 * (triangles_ - half)));
    }
    // The shadow callback: positions only, one draw.
    void draw_shadow(const gl::shadow_draw&) const {
        glBindVertexArray(vao_);
        glDrawArrays(GL_TRIANGLES, 0, GLsizei(3 * triangles_));
    }

private:
    GLuint vao_ = 0, vertices_ = 0, albedo_ = 0;
    std::size_t triangles_;
};

bool same_texels(const gl::texture_ref& a, const gl::texture_ref& b) {
    const auto x = a.read_floats(), y = b.read_floats();
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0;
}

double total_flux(const gl::rsm_textures& m) {
    double sum = 0;
    const auto f = m.flux.read_floats();
    for (std::size_t i = 0; i < f.size(); i += 4) sum += f[i] + f[i + 1] + f[i + 2];
    return sum;
}

bool same_images(const image<glm::vec3>& a, const image<glm::vec3>& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.data(), b.data(), a.width() * a.height() * sizeof(glm::vec3)) == 0;
}

}  // namespace

TEST_CASE("the RSM renderer drawing the renderer's own vertex buffers makes the built-in renderer's maps",
          "[gl][rsm][callback]") {
    gl_test::shared_context();
    const auto s = room();
    const gl::scene_mesh mesh(s);
    const own_geometry own(s);
    gl::rsm_render_options options;
    options.resolution = 32;
    gl::rsm_renderer built_in(s, mesh, options);
    std::size_t calls = 0;
    gl::rsm_renderer callback(
        s,
        [&](const gl::rsm_draw& d) {
            ++calls;
            CHECK(d.map.light < s.lights.size());
            own.draw_rsm(d);
        },
        options);
    built_in.render();
    callback.render();
    const auto a = built_in.maps(), b = callback.maps();
    REQUIRE(a.size() == 7);  // six cube faces and one spot map
    REQUIRE(b.size() == a.size());
    CHECK(calls == a.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
        INFO("map " << k);
        CHECK(a[k].light_view_projection == b[k].light_view_projection);
        CHECK(same_texels(a[k].position, b[k].position));
        CHECK(same_texels(a[k].normal, b[k].normal));
        CHECK(same_texels(a[k].flux, b[k].flux));
    }
    // Not vacuous: the spot map sees the lit floor, wall and ball.
    CHECK(total_flux(b.back()) > 0.1);
    // The albedo offset matters: without it the second draw's triangles take the first
    // half's albedo and the maps differ.
    gl::rsm_renderer no_offset(
        s, [&](const gl::rsm_draw& d) { own.draw_rsm(d, /*offset=*/false); }, options);
    no_offset.render();
    bool any_differs = false;
    for (std::size_t k = 0; k < a.size(); ++k) any_differs = any_differs || !same_texels(a[k].flux, no_offset.maps()[k].flux);
    CHECK(any_differs);

    CHECK(test::refusal_message([&] { gl::rsm_renderer(s, gl::rsm_drawer{}, options); }).find("draw") !=
          std::string::npos);
}

TEST_CASE("direct light with shadow maps of the renderer's own vertex buffers equals the built-in pass",
          "[gl][direct][callback]") {
    gl_test::shared_context();
    const auto s = room();
    const gl::scene_mesh mesh(s);
    const own_geometry own(s);
    gl::direct_light_options options;
    options.shadow_resolution = 64;
    gl::gbuffer_pass gpass;
    gpass.render(mesh, s.camera, W, H);
    const auto g = gl::textures_of(gpass);

    gl::direct_light built_in(s, mesh, options);
    std::vector<gl::shadow_draw> draws;
    gl::direct_light callback(
        s,
        [&](const gl::shadow_draw& d) {
            draws.push_back(d);
            own.draw_shadow(d);
        },
        options);
    // One call per 2D map, six per cube map.
    REQUIRE(draws.size() == 7);
    CHECK(draws[0].light == 0);
    CHECK(draws[0].face == 0);
    CHECK(draws[6].light == 1);
    CHECK(draws[6].face == -1);

    built_in.render(g);
    image<glm::vec3> expected(W, H), got(W, H);
    built_in.read(expected.view());
    callback.render(g);
    callback.read(got.view());
    CHECK(same_images(expected, got));
    // Not vacuous: the ball shadows some lit floor, so the shadow maps decided pixels.
    gl::direct_light unshadowed(s, [](const gl::shadow_draw&) {}, options);
    unshadowed.render(g);
    image<glm::vec3> bright(W, H);
    unshadowed.read(bright.view());
    std::size_t shadowed = 0;
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) shadowed += bright(x, y).x > 2.f * got(x, y).x + 1e-3f;
    CHECK(shadowed > 10);
    // render_shadow_maps draws again through the callback.
    callback.render_shadow_maps();
    CHECK(draws.size() == 14);

    CHECK(test::refusal_message([&] { gl::direct_light(s, gl::shadow_drawer{}, options); }).find("draw") !=
          std::string::npos);
}

TEST_CASE("a CPU-made RSM uploaded reads back exactly", "[gl][rsm][upload]") {
    gl_test::shared_context();
    const rsm_test::corner_scene corner(8, 6, 24);
    const rsm_test::corner_scene small(8, 6, 12);
    const rsm_view maps[] = {corner.map(), small.map()};
    gl::rsm_upload up(maps);
    REQUIRE(up.textures().size() == 2);
    for (std::size_t k = 0; k < 2; ++k) {
        const gl::rsm_images back(up.textures()[k]);
        CHECK(back.light_view_projection == maps[k].light_view_projection);
        REQUIRE(back.flux.width() == maps[k].width());
        for (std::size_t y = 0; y < back.flux.height(); ++y)
            for (std::size_t x = 0; x < back.flux.width(); ++x) {
                CHECK(back.position(x, y) == maps[k].position(x, y));
                CHECK(back.normal(x, y) == maps[k].normal(x, y));
                CHECK(back.flux(x, y) == maps[k].flux(x, y));
            }
    }
    // Uploading again with one map fewer keeps the first one's textures and drops the other.
    const auto first_id = up.textures()[0].flux.id;
    up.upload(std::span(maps).first(1));
    REQUIRE(up.textures().size() == 1);
    CHECK(up.textures()[0].flux.id == first_id);
}

TEST_CASE("the indirect renderer gathers and splats from uploaded copies of rendered maps as from the maps",
          "[gl][rsm][upload]") {
    gl_test::shared_context();
    const auto s = room();
    const gl::scene_mesh mesh(s);
    gl::rsm_render_options rsm_options;
    rsm_options.resolution = 24;
    gl::rsm_renderer rsm(s, mesh, rsm_options);
    rsm.render();
    // The CPU's copy, as a renderer holding CPU-made maps has them, uploaded.
    std::vector<gl::rsm_images> copies;
    std::vector<rsm_view> views;
    for (const auto& m : rsm.maps()) copies.emplace_back(m);
    for (const auto& c : copies) views.push_back(c.view());
    const gl::rsm_upload uploaded(views);

    gl::gbuffer_pass gpass;
    gpass.render(mesh, s.camera, W, H);
    const auto g = gl::textures_of(gpass);
    for (const auto technique : {indirect_technique::rsm_gather, indirect_technique::sii}) {
        INFO("technique " << int(technique));
        indirect_options options;
        options.technique = technique;
        options.count = 64;
        options.pattern = {2, 2};
        gl::indirect_renderer renderer(options);
        gl::texture from_rendered(gl::texel_format::rgba32f, W, H), from_uploaded(gl::texel_format::rgba32f, W, H);
        renderer.render(g, s.camera, rsm.maps(), from_rendered);
        renderer.render(g, s.camera, uploaded.textures(), from_uploaded);
        CHECK(same_texels(from_rendered, from_uploaded));
        double sum = 0;
        for (const float v : from_uploaded.read_floats()) sum += v;
        CHECK(sum > 0);  // the maps light the room
    }
}

TEST_CASE("rsm_upload refuses bad maps, naming the map", "[gl][rsm][upload][bad-input]") {
    gl_test::shared_context();
    rsm_test::corner_scene good(8, 6, 8), bad(8, 6, 8);
    const auto refusal = [&] {
        const rsm_view maps[] = {good.map(), bad.map()};
        return test::refusal_message([&] { gl::rsm_upload up(maps); });
    };
    CHECK(refusal().empty());
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    bad.map_position(3, 2).y = nan;
    CHECK(refusal().find("maps[1]") != std::string::npos);
    CHECK(refusal().find("position") != std::string::npos);
    bad.map_position(3, 2).y = 0.f;
    bad.map_normal(0, 7).z = inf;
    CHECK(refusal().find("normal") != std::string::npos);
    bad.map_normal(0, 7).z = 0.f;
    bad.map_flux(5, 5).x = -1e-3f;
    CHECK(refusal().find("flux") != std::string::npos);
    bad.map_flux(5, 5).x = 0.f;
    bad.light_view_projection[3][0] = nan;
    CHECK(refusal().find("light_view_projection") != std::string::npos);
    bad.light_view_projection = good.light_view_projection;
    CHECK(refusal().empty());
    // Views of different sizes, and an empty map.
    const image<glm::vec3> other(4, 4);
    const rsm_view mixed{good.map_position.view(), other.view(), good.map_flux.view(), good.light_view_projection};
    CHECK(test::refusal_message([&] { gl::rsm_upload up(std::span(&mixed, 1)); }).find("maps[0]") != std::string::npos);
    const rsm_view empty{};
    CHECK(test::refusal_message([&] { gl::rsm_upload up(std::span(&empty, 1)); }).find("maps[0]") != std::string::npos);
}
