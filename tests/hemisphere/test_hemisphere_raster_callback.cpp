// The raster hemisphere sampler drawing the caller's scene (gl::hemisphere_raster built with a
// plane_drawer, as lightmapper.h draws its user's scene): a callback that draws the half-lit
// ceiling with its own buffers and shader gives the built-in drawer's planes and the closed
// form's records; every call sees the promised state and lands in its own tile only; the
// caller's GL state survives, also when the callback throws; an empty callback is refused.
#include "../core/half_lit_ceiling.hpp"
#include "../gl/shared_context.hpp"
#include "half_lit_ceiling_scene.hpp"
#include "raster_options.hpp"

#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/gl/raster_record_sampler.hpp>
#include <bounce/cpu/plane_estimate.hpp>
#include <bounce/cache/plane_camera.hpp>
#include <bounce/cache/plane_weights.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <glm/glm.hpp>

using namespace bounce;
using hemisphere_test::half_lit_ceiling_scene;

namespace {

constexpr double pi = std::numbers::pi;
constexpr float inf = std::numeric_limits<float>::infinity();

// A renderer's own draw of the half-lit ceiling: its own vertex buffer (position and albedo
// per vertex, no index buffer, nothing of bounce's scene_mesh) and its own program. The
// scene's directional light travels straight up onto the ceiling: normal incidence and no
// occluder, so the radiance leaving the lit half is kd / pi * E_perp without shadows.
struct ceiling_drawer {
    gl::program program;
    gl::buffer vertices;
    gl::vertex_array vao;
    GLsizei count = 0;

    static std::vector<float> interleave(const test::owned_scene& s) {
        std::vector<float> v;
        for (std::size_t t = 0; t < s.triangles.size(); ++t)
            for (int c = 0; c < 3; ++c) {
                const glm::vec3 p = s.positions[s.triangles[t][c]], kd = s.materials[s.material_of[t]].albedo;
                v.insert(v.end(), {p.x, p.y, p.z, kd.r, kd.g, kd.b});
            }
        return v;
    }
    ceiling_drawer(const test::owned_scene& s, float E_perp)
        : program(R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 albedo;
layout(location = 0) uniform mat4 view_projection;
out vec3 world;
flat out vec3 kd;
void main() {
    world = position;
    kd = albedo;
    gl_Position = view_projection * vec4(position, 1.0);
}
)",
                  R"(#version 450 core
layout(location = 1) uniform vec3 eye;
layout(location = 2) uniform float E_perp;
in vec3 world;
flat in vec3 kd;
layout(location = 0) out vec4 radiance_distance;
void main() {
    // The order of bounce's lambertian_radiance(kd, E): kd * E * (1 / pi).
    radiance_distance = vec4(kd * E_perp * 0.31830988618379067, length(world - eye));
}
)"),
          vertices(std::span<const float>(interleave(s))), count(GLsizei(3 * s.triangles.size())) {
        glVertexArrayVertexBuffer(vao.id(), 0, vertices.id(), 0, GLsizei(6 * sizeof(float)));
        for (GLuint a = 0; a < 2; ++a) {
            glEnableVertexArrayAttrib(vao.id(), a);
            glVertexArrayAttribFormat(vao.id(), a, 3, GL_FLOAT, GL_FALSE, GLuint(a * 3 * sizeof(float)));
            glVertexArrayAttribBinding(vao.id(), a, 0);
        }
        program.set(2, E_perp);
    }
    void operator()(const gl::plane_draw& d) const {
        glUseProgram(program.id());
        program.set(0, d.view_projection);
        program.set(1, d.eye);
        glBindVertexArray(vao.id());
        glDrawArrays(GL_TRIANGLES, 0, count);
    }
};

// Whether the ceiling's edge crosses plane pixel (i, j): the lit region is the half plane
// x c + y s > -x0 / h of plane coordinates (ceiling_test::mixed_cells' test).
bool edge_crosses_pixel(const plane_camera& cam, const ceiling_test::half_lit_ceiling& hc, std::uint32_t i,
                        std::uint32_t j) {
    const double c = std::cos(hc.rot), s = std::sin(hc.rot), k = -hc.x0 / hc.h;
    const auto side = [&](double x, double y) { return x * c + y * s > k; };
    const auto r = plane_pixel_bounds<double>(i, j, cam.resolution, cam.half_extent());
    const bool s00 = side(r[0], r[1]);
    return s00 != side(r[2], r[1]) || s00 != side(r[0], r[3]) || s00 != side(r[2], r[3]);
}

// A program that draws one wide point at NDC (0.9, 0.9) in a constant colour: its square
// reaches past the viewport's corner, where only the scissor box stops it.
gl::program corner_point_program() {
    return gl::program(R"(#version 450 core
void main() { gl_Position = vec4(0.9, 0.9, 0.5, 1.0); }
)",
                       R"(#version 450 core
layout(location = 0) uniform float record;
layout(location = 0) out vec4 colour;
void main() { colour = vec4(-record, 7.0, 7.0, -record); }
)");
}

std::string parameter_of(const auto& f) {
    try {
        f();
    } catch (const parameter_error& e) {
        return e.parameter();
    }
    return "(nothing thrown)";
}

}  // namespace

TEST_CASE("a callback drawing the half-lit ceiling gives the built-in drawer's planes and the closed form's records",
          "[hemisphere][gl][callback]") {
    gl_test::shared_context();
    const float H = 1.5f, x_edge = 0.4f, kd = 0.75f, E_perp = 2.f;
    const double L = double(kd / float(pi) * E_perp);
    const auto N = GENERATE(16u, 64u);
    const auto aperture = GENERATE(90.0, 126.0, 150.0);
    const bool hashed = GENERATE(false, true);
    const auto options = raster_options(N, aperture, 7, 1e-3f, hashed ? 10.0 : 0.0, hashed);
    const test::owned_scene scene = half_lit_ceiling_scene(H, x_edge, kd, E_perp);
    const gl::scene_mesh mesh(scene);
    const gl::direct_light light(scene, mesh, 512);
    gl::hemisphere_raster built_in(scene, mesh, light, options);
    const ceiling_drawer drawer(scene, E_perp);
    gl::hemisphere_raster callback(scene, [&drawer](const gl::plane_draw& d) { drawer(d); }, options);
    CHECK(callback.offset() == built_in.offset());
    CHECK(callback.vertex_source().empty());
    CHECK(callback.fragment_source().empty());

    pcg32 rng(N + unsigned(aperture));
    std::vector<glm::vec3> positions, normals;
    for (std::size_t k = 0; k < options.batch; ++k) {
        const float z = float(4 * rng.next_double() - 2);  // two statements: argument order is unspecified
        positions.emplace_back(float(4 * rng.next_double() - 2), 0.f, z);
        normals.emplace_back(0.f, 1.f, 0.f);
    }
    built_in.render(positions, normals);
    built_in.start_read();
    callback.render(positions, normals);
    callback.start_read();
    const auto stretch = make_plane_weights(options.camera, plane_weighting::stretch);
    callback.set_weights(stretch);
    const auto records = callback.reduce();
    const auto want = built_in.finish_read(), got = callback.finish_read();
    REQUIRE(got.size() == options.batch);
    REQUIRE(records.size() == options.batch);

    for (std::size_t k = 0; k < options.batch; ++k) {
        const auto hc = hemisphere_test::ceiling_seen_from(options.camera, positions[k], H, options.offset, x_edge, L);
        // Radiance. Away from the edge both drawers compute kd * E_perp * (1/pi) in float:
        // the built-in through direct_irradiance (E_perp cos, cos = 1 exactly, an unshadowed
        // PCF visibility of 1) and lambertian_radiance, the callback in the same order. Allow
        // each side 4 roundings of half an ulp: |difference| <= 4 ulp(L) ~ 2^-21 L. In
        // texels the edge crosses the two rasterizations may put the texel centre on
        // different sides of the edge (the built-in maps clip space onto the atlas, the
        // callback the viewport onto the tile): there each value lies in [0, L] only.
        const float radiance_tolerance = 0x1p-21f * float(L);
        std::size_t mismatched = 0, out_of_range = 0;
        // Distance. Each drawer interpolates world positions of magnitude up to 2000 (the
        // ceiling's extent; float ulp 1.2e-4) to hit points at distance >= H - offset ~ 1.5:
        // about 1e-4 relative each, the built-in test's budget against the analytic plane,
        // so at most 2e-4 between them.
        double worst_distance = 0;
        for (std::uint32_t j = 0; j < N; ++j)
            for (std::uint32_t i = 0; i < N; ++i) {
                const glm::vec3 a = got.radiance[k](i, j), b = want.radiance[k](i, j);
                if (edge_crosses_pixel(options.camera, hc, i, j)) {
                    for (int c = 0; c < 3; ++c)
                        if (!(a[c] >= 0.f && a[c] <= float(L) + radiance_tolerance)) ++out_of_range;
                } else {
                    for (int c = 0; c < 3; ++c)
                        if (!(std::abs(a[c] - b[c]) <= radiance_tolerance)) ++mismatched;
                }
                worst_distance = std::max(
                    worst_distance, std::abs(double(got.distance[k](i, j)) / double(want.distance[k](i, j)) - 1));
            }
        CAPTURE(k, N, aperture, hashed, mismatched, out_of_range, worst_distance);
        CHECK(mismatched == 0);
        CHECK(out_of_range == 0);
        CHECK(worst_distance <= 2e-4);
        // The record, reduced on the GPU from the callback's plane. The plane differs from
        // the analytic one only in the cells the edge crosses, by at most L each, and the
        // analytic plane's stretched estimate is within L times the mixed cells' weights
        // (bands included) of the closed forms: twice that bound, plus the float sums of the
        // reduction (1e-5 relative, as in the built-in test).
        const auto bound = ceiling_test::mixed_cells(options.camera, hc, true);
        CAPTURE(records[k].irradiance.x, hc.E(), bound.E, bound.rotation);
        CHECK(std::abs(records[k].irradiance.x - hc.E()) <= 2 * L * bound.E + 1e-5 * hc.E());
        CHECK(std::abs(records[k].irradiance.z - hc.E()) <= 2 * L * bound.E + 1e-5 * hc.E());
        CHECK(glm::length(records[k].rotation[0] - hc.rot_y() * hc.across()) <= 2 * L * bound.rotation + 1e-5 * hc.E());
        // The CPU sum of the read-back plane agrees with the reduction (the same plane).
        const auto cpu = cpu::estimate_plane(stretch, got.view(k));
        CHECK(records[k].irradiance.x == Approx(cpu.irradiance.x).epsilon(1e-5));
    }
}

TEST_CASE("the raster record sampler makes the same records over a callback raster as over the built-in one",
          "[hemisphere][gl][callback][record]") {
    gl_test::shared_context();
    const float H = 1.5f, x_edge = 0.4f, kd = 0.75f, E_perp = 2.f;
    const double L = double(kd / float(pi) * E_perp);
    const auto options = raster_options(32, 126.0, 4, 1e-3f);
    const test::owned_scene scene = half_lit_ceiling_scene(H, x_edge, kd, E_perp);
    const gl::scene_mesh mesh(scene);
    const gl::direct_light light(scene, mesh, 512);
    gl::hemisphere_raster built_in(scene, mesh, light, options);
    const ceiling_drawer drawer(scene, E_perp);
    gl::hemisphere_raster callback(scene, [&drawer](const gl::plane_draw& d) { drawer(d); }, options);
    gl::raster_record_sampler from_built_in(built_in, radius_limits{}), from_callback(callback, radius_limits{});
    pcg32 rng(23);
    std::vector<glm::vec3> p, n;
    std::vector<double> footprint;
    for (int k = 0; k < 9; ++k) {  // batches of 4, 4 and 1
        const float z = float(4 * rng.next_double() - 2);
        p.emplace_back(float(4 * rng.next_double() - 2), 0.f, z);
        n.emplace_back(0.f, 1.f, 0.f);
        footprint.push_back(1e-3);
    }
    std::vector<std::optional<irradiance_record>> a(p.size()), b(p.size());
    from_built_in(p, n, footprint, a);
    from_callback(p, n, footprint, b);
    for (std::size_t k = 0; k < p.size(); ++k) {
        REQUIRE((a[k] && b[k]));
        // The planes differ only in texels the edge crosses, by at most L each (first test
        // case), and a band takes its border pixel's radiance: the records differ by at most
        // L times the weights of the mixed cells, bands included, plus the float sums (1e-5
        // relative each). The radius is the harmonic mean distance (clamped alike on both):
        // a weighted harmonic mean of distances each within 2e-4 relative of the other
        // drawer's is within 2e-4 of its mean, plus the float sums: 3e-4.
        const auto hc = hemisphere_test::ceiling_seen_from(options.camera, p[k], H, options.offset, x_edge, L);
        const auto bound = ceiling_test::mixed_cells(options.camera, hc, true);
        CAPTURE(k, a[k]->irradiance.x, b[k]->irradiance.x, bound.E);
        CHECK(std::abs(double(a[k]->irradiance.x - b[k]->irradiance.x)) <= L * bound.E + 2e-5 * hc.E());
        CHECK(double(glm::length(a[k]->rotation[0] - b[k]->rotation[0])) <= L * bound.rotation + 2e-5 * hc.E());
        CHECK(b[k]->radius == Approx(a[k]->radius).epsilon(3e-4));
    }
}

TEST_CASE("each call of the callback sees the promised state and draws into its own tile only",
          "[hemisphere][gl][callback]") {
    gl_test::shared_context();
    const std::uint32_t N = 8;
    auto options = raster_options(N, 120.0, 7, 1e-3f);  // 3 x 3 atlas: tiles 7 and 8 unused
    options.environment = glm::vec3(0.1f, 0.2f, 0.3f);
    const test::owned_scene scene = half_lit_ceiling_scene(1.5f, 0.4f, 0.75f, 2.f);
    const gl::program point = corner_point_program();
    const gl::vertex_array no_attributes;
    GLint max_clip = 0;
    glGetIntegerv(GL_MAX_CLIP_DISTANCES, &max_clip);

    struct seen_state {
        gl::plane_draw draw;
        GLint framebuffer = 0, depth_func = 0, clip_depth = 0, viewport[4] = {}, scissor[4] = {};
        GLboolean scissor_test = GL_FALSE, depth_test = GL_FALSE, blend = GL_TRUE, cull = GL_TRUE, clip = GL_TRUE,
                  depth_mask = GL_FALSE;
    };
    std::vector<seen_state> seen;
    GLuint atlas_framebuffer = 0;
    gl::hemisphere_raster raster(
        scene,
        [&](const gl::plane_draw& d) {
            seen_state s;
            s.draw = d;
            glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &s.framebuffer);
            glGetIntegerv(GL_DEPTH_FUNC, &s.depth_func);
            glGetIntegerv(GL_CLIP_DEPTH_MODE, &s.clip_depth);
            glGetIntegerv(GL_VIEWPORT, s.viewport);
            glGetIntegerv(GL_SCISSOR_BOX, s.scissor);
            glGetBooleanv(GL_DEPTH_WRITEMASK, &s.depth_mask);
            s.scissor_test = glIsEnabled(GL_SCISSOR_TEST);
            s.depth_test = glIsEnabled(GL_DEPTH_TEST);
            s.blend = glIsEnabled(GL_BLEND);
            s.cull = glIsEnabled(GL_CULL_FACE);
            s.clip = GL_FALSE;
            for (GLint i = 0; i < max_clip; ++i) s.clip = GLboolean(s.clip || glIsEnabled(GLenum(GL_CLIP_DISTANCE0 + i)));
            seen.push_back(s);
            atlas_framebuffer = GLuint(s.framebuffer);
            // A clear ignores the viewport: only the scissor box keeps it in the tile.
            const float colour[4] = {float(d.record + 1), 0.5f, 0.25f, float(100 + d.record)};
            glClearBufferfv(GL_COLOR, 0, colour);
            // A point of N texels centred at 0.95 N of the tile: half of it lies beyond the
            // tile's top-right corner, in the neighbours, were nothing to stop it.
            glUseProgram(point.id());
            point.set(0, float(d.record));
            glBindVertexArray(no_attributes.id());
            glPointSize(float(N));
            glDrawArrays(GL_POINTS, 0, 1);
            // Leave a mess: the next call must still get the promised state.
            glDepthFunc(GL_LESS);
            glEnable(GL_BLEND);
            glEnable(GL_CULL_FACE);
            glEnable(GL_CLIP_DISTANCE0);
            glDisable(GL_SCISSOR_TEST);
            glViewport(0, 0, 1, 1);
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        },
        options);
    std::vector<glm::vec3> positions, normals;
    for (std::size_t k = 0; k < options.batch; ++k) {
        positions.emplace_back(float(k), 0.f, -float(k));
        normals.push_back(glm::normalize(glm::vec3(0.1f * float(k), 1.f, 0.f)));
    }
    raster.render(positions, normals);
    glPointSize(1.f);
    REQUIRE(seen.size() == options.batch);
    const float near = raster.offset() / 100.f;
    for (std::size_t k = 0; k < seen.size(); ++k) {
        const seen_state& s = seen[k];
        const gl::plane_draw& d = s.draw;
        CAPTURE(k);
        CHECK(d.record == k);
        CHECK(d.position == positions[k]);
        CHECK(d.normal == normals[k]);
        CHECK(glm::length(d.eye - (positions[k] + raster.offset() * normals[k])) < 1e-6f);
        const gl::plane_draw::rect tile{std::int32_t(k % 3 * N), std::int32_t(k / 3 * N), std::int32_t(N),
                                        std::int32_t(N)};
        CHECK((d.tile.x == tile.x && d.tile.y == tile.y && d.tile.width == tile.width && d.tile.height == tile.height));
        CHECK((s.viewport[0] == tile.x && s.viewport[1] == tile.y && s.viewport[2] == tile.width &&
               s.viewport[3] == tile.height));
        CHECK((s.scissor[0] == tile.x && s.scissor[1] == tile.y && s.scissor[2] == tile.width &&
               s.scissor[3] == tile.height));
        CHECK(GLuint(s.framebuffer) == atlas_framebuffer);
        CHECK(atlas_framebuffer != 0);
        CHECK(s.scissor_test == GL_TRUE);
        CHECK(s.depth_test == GL_TRUE);
        CHECK(s.depth_mask == GL_TRUE);
        CHECK(s.depth_func == GL_GREATER);
        CHECK(s.clip_depth == GL_ZERO_TO_ONE);
        CHECK(s.blend == GL_FALSE);
        CHECK(s.cull == GL_FALSE);
        CHECK(s.clip == GL_FALSE);
        // The camera: the eye at the view's origin looking down -z = n; the product as given;
        // reversed depth near / t at distance t in front, so 0 is infinitely far. Float
        // rounding of |eye| <= 7 (ulp 4.8e-7) and matrix products of unit rows: 1e-5.
        const glm::vec4 e = d.view * glm::vec4(d.eye, 1.f), ahead = d.view * glm::vec4(d.eye + 2.f * d.normal, 1.f);
        CHECK(glm::length(glm::vec3(e)) < 1e-5f);
        CHECK(glm::length(glm::vec3(ahead) - glm::vec3(0, 0, -2)) < 1e-5f);
        const glm::mat4 product = d.projection * d.view;
        for (int c = 0; c < 4; ++c) CHECK(glm::length(product[c] - d.view_projection[c]) < 1e-6f);
        const glm::vec4 clip = d.projection * glm::vec4(0, 0, -2, 1);
        CHECK(clip.z / clip.w == Approx(near / 2).epsilon(1e-6));
        CHECK(d.projection == seen[0].draw.projection);
    }

    // The atlas: each record's tile holds its clear colour, and its point in the texels whose
    // centres lie in the point's square [3.6, 11.6) x [3.6, 11.6) of the tile (GL rows from
    // the bottom, as the viewport counts them): i, j >= 4. Tiles 7 and 8 keep the
    // environment and +infinity. Any bleeding, of the clears or of the points, shows here.
    const std::vector<float> atlas = raster.atlas().read_floats();
    const std::size_t W = raster.atlas().width();
    REQUIRE(W == 3 * N);
    std::size_t wrong = 0, point_texels = 0;
    for (std::size_t y = 0; y < 3 * N; ++y)
        for (std::size_t x = 0; x < 3 * N; ++x) {
            const std::size_t k = (y / N) * 3 + x / N, i = x % N, j = y % N;
            glm::vec4 expected(options.environment, inf);
            if (k < options.batch) {
                const bool in_point = i >= 4 && j >= 4;
                point_texels += in_point;
                expected = in_point ? glm::vec4(-float(k), 7.f, 7.f, -float(k))
                                    : glm::vec4(float(k + 1), 0.5f, 0.25f, float(100 + k));
            }
            const glm::vec4 texel(atlas[4 * (y * W + x)], atlas[4 * (y * W + x) + 1], atlas[4 * (y * W + x) + 2],
                                  atlas[4 * (y * W + x) + 3]);
            if (texel != expected) ++wrong;
        }
    CHECK(point_texels == options.batch * 16);
    CHECK(wrong == 0);
    // The read-back sees the same tiles (row 0 of a plane is the tile's first row in memory).
    raster.start_read();
    const auto planes = raster.finish_read();
    REQUIRE(planes.size() == options.batch);
    CHECK(planes.radiance[3](0, 0) == glm::vec3(4.f, 0.5f, 0.25f));
    CHECK(planes.distance[3](7, 7) == -3.f);
}

TEST_CASE("render with a callback leaves the caller's GL state as it found it, also when the callback throws",
          "[hemisphere][gl][callback]") {
    gl_test::shared_context();
    auto options = raster_options(8, 120.0, 3, 1e-3f);
    options.environment = glm::vec3(0.5f);
    const test::owned_scene scene = half_lit_ceiling_scene(1.5f, 0.4f, 0.75f, 2.f);
    const ceiling_drawer drawer(scene, 2.f);
    bool fail_on_second = false;
    gl::hemisphere_raster raster(
        scene,
        [&](const gl::plane_draw& d) {
            if (fail_on_second && d.record == 1) throw std::runtime_error("the caller's draw failed");
            drawer(d);
            glEnable(GL_BLEND);  // the callback's own state changes: restored by render
            glDepthFunc(GL_ALWAYS);
        },
        options);

    // A renderer's own state: its framebuffer, viewport, scissor, program, vertex array,
    // capabilities, clip distances, depth convention.
    gl::texture colour(gl::texel_format::rgba8, 8, 8);
    gl::framebuffer fbo;
    fbo.attach_color(0, colour);
    const gl::program own_program = corner_point_program();
    const gl::vertex_array own_vao;
    GLint max_clip = 0;
    glGetIntegerv(GL_MAX_CLIP_DISTANCES, &max_clip);
    REQUIRE(max_clip >= 8);  // GL 4.5 guarantees 8
    const auto set_callers_state = [&] {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
        glViewport(1, 2, 3, 4);
        glScissor(2, 3, 1, 1);
        glEnable(GL_SCISSOR_TEST);
        glUseProgram(own_program.id());
        glBindVertexArray(own_vao.id());
        glEnable(GL_CULL_FACE);
        glDisable(GL_DEPTH_TEST);
        glDepthFunc(GL_LEQUAL);
        glEnable(GL_CLIP_DISTANCE0);
        glEnable(GL_CLIP_DISTANCE5);
    };
    const auto check_callers_state = [&] {
        GLint draw_fb = 0, read_fb = 0, viewport[4] = {}, scissor[4] = {}, program = 0, vao = 0, depth_func = 0,
              clip_depth = 0;
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_fb);
        glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_fb);
        glGetIntegerv(GL_VIEWPORT, viewport);
        glGetIntegerv(GL_SCISSOR_BOX, scissor);
        glGetIntegerv(GL_CURRENT_PROGRAM, &program);
        glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &vao);
        glGetIntegerv(GL_DEPTH_FUNC, &depth_func);
        glGetIntegerv(GL_CLIP_DEPTH_MODE, &clip_depth);
        CHECK(GLuint(draw_fb) == fbo.id());
        CHECK(GLuint(read_fb) == fbo.id());
        CHECK((viewport[0] == 1 && viewport[1] == 2 && viewport[2] == 3 && viewport[3] == 4));
        CHECK((scissor[0] == 2 && scissor[1] == 3 && scissor[2] == 1 && scissor[3] == 1));
        CHECK(glIsEnabled(GL_SCISSOR_TEST) == GL_TRUE);
        CHECK(GLuint(program) == own_program.id());
        CHECK(GLuint(vao) == own_vao.id());
        CHECK(glIsEnabled(GL_CULL_FACE) == GL_TRUE);
        CHECK(glIsEnabled(GL_BLEND) == GL_FALSE);
        CHECK(glIsEnabled(GL_DEPTH_TEST) == GL_FALSE);
        CHECK(depth_func == GL_LEQUAL);
        CHECK(clip_depth == GL_NEGATIVE_ONE_TO_ONE);
        for (GLint i = 0; i < max_clip; ++i)
            CHECK(glIsEnabled(GLenum(GL_CLIP_DISTANCE0 + i)) == ((i == 0 || i == 5) ? GL_TRUE : GL_FALSE));
    };
    const std::vector<glm::vec3> positions = {{10, 0, 0}, {-10, 0, 0}, {20, 0, 0}}, up(3, glm::vec3(0, 1, 0));

    set_callers_state();
    raster.render(positions, up);
    check_callers_state();
    // The caller's scissor test was on with a 1 x 1 box: the atlas clear must not have
    // obeyed it. Tile 3 (no record) keeps the environment; record 0 sees the lit half.
    {
        const std::vector<float> atlas = raster.atlas().read_floats();
        // 2 x 2 tiles of 8: tile 3 spans texels [8, 16)^2; its last texel is (15, 15).
        const std::size_t W = raster.atlas().width(), last = 4 * (15 * W + 15);
        CHECK(atlas[last] == 0.5f);
        CHECK(atlas[last + 3] == inf);
    }
    raster.start_read();
    const auto planes = raster.finish_read();
    CHECK(planes.radiance[0](4, 4).x == Approx(0.75 / pi * 2).epsilon(1e-6));
    CHECK(planes.radiance[1](4, 4).x == 0.f);

    // A callback that throws: the exception reaches the caller, the state is restored and
    // nothing counts as rendered.
    fail_on_second = true;
    set_callers_state();
    CHECK_THROWS_AS(raster.render(positions, up), std::runtime_error);
    check_callers_state();
    CHECK(raster.rendered() == 0);
    CHECK(parameter_of([&] { raster.start_read(); }) == "hemisphere_raster");
    fail_on_second = false;

    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    glBindVertexArray(0);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CLIP_DISTANCE0);
    glDisable(GL_CLIP_DISTANCE5);
    gl::check_error("callback state test");
}

TEST_CASE("an empty callback and bad input are refused with parameter_error naming the parameter",
          "[hemisphere][gl][callback][bad-input]") {
    gl_test::shared_context();
    const test::owned_scene scene = half_lit_ceiling_scene(1.5f, 0.4f, 0.75f, 2.f);
    const auto options = raster_options(8, 120.0, 2, 0.f);
    CHECK(parameter_of([&] { gl::hemisphere_raster r(scene, gl::plane_drawer{}, options); }) == "draw");
    void (*null_function)(const gl::plane_draw&) = nullptr;
    CHECK(parameter_of([&] { gl::hemisphere_raster r(scene, gl::plane_drawer(null_function), options); }) == "draw");
    std::size_t calls = 0;
    const gl::plane_drawer count = [&](const gl::plane_draw&) { ++calls; };
    auto bad = options;
    bad.batch = 0;
    CHECK(parameter_of([&] { gl::hemisphere_raster r(scene, count, bad); }) == "batch");
    bad = options;
    bad.offset = -1.f;
    CHECK(parameter_of([&] { gl::hemisphere_raster r(scene, count, bad); }) == "offset");

    gl::hemisphere_raster raster(scene, count, options);
    // The default offset comes from the scene's bounds, as for the built-in drawer.
    const auto [lo, hi] = scene.bounds();
    CHECK(raster.offset() == std::max(1e-4f * glm::length(hi - lo), 1e-6f));
    const std::vector<glm::vec3> p = {{0, 0, 0}, {1, 0, 0}}, up(2, glm::vec3(0, 1, 0)),
                                 not_unit(2, glm::vec3(0, 2, 0));
    CHECK(parameter_of([&] { raster.render(p, not_unit); }) == "normals");
    CHECK(parameter_of([&] { raster.render(p, std::span(up).first(1)); }) == "normals");
    CHECK(parameter_of([&] { raster.render({}, {}); }) == "positions");
    CHECK(calls == 0);  // refused before anything is drawn
    raster.render(p, up);
    CHECK(calls == 2);
    CHECK(raster.rendered() == 2);
}
