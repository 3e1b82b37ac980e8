// gl::progressive_radiosity against cpu::progressive_radiosity on the same atlas with the same
// options and visibility method (llvmpipe through EGL): the same shooters, radiosities within
// float rounding without occlusion, visibility differences only at item-buffer edges with the
// stereographic buffer, energy bookkeeping, the GPU reduction's choice, lights, bad input.
#include "../gl/shared_context.hpp"
#include "../radiosity/radiosity_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/gl/radiosity.hpp>
#include <bounce/radiosity/shooters.hpp>
#include <bounce/radiosity/subdivision.hpp>

#include <catch2/catch.hpp>
#include <epoxy/gl.h>  // GL entry points from whatever context is current (EGL, GLX, WGL)

#include <algorithm>
#include <cmath>
#include <vector>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

// Per-shooter unshot power from the per-element unshot radiosities read back (each side's),
// in double and in element order (the sum both solvers form), and the largest with ties to
// the lowest index. Shooter k is block k % blocks on side k / blocks.
std::pair<std::uint32_t, double> largest_power(const gl::progressive_radiosity& solver) {
    const lightmap_atlas& atlas = solver.atlas();
    std::vector<std::vector<glm::vec3>> unshot;
    for (int side = 0; side < solver.sides(); ++side) unshot.push_back(solver.unshot(side));
    const std::size_t blocks = solver.shooters() / std::size_t(solver.sides());
    std::pair<std::uint32_t, double> best{0, -1.0};
    for (std::size_t k = 0; k < solver.shooters(); ++k) {
        double p = 0;
        const std::size_t b = k % blocks;
        const std::vector<glm::vec3>& u = unshot[k / blocks];
        for (std::uint32_t i = solver.shooter_first(b); i < solver.shooter_first(b + 1); ++i)
            p += (double(u[i].x) + double(u[i].y) + double(u[i].z)) * double(atlas.area[i]);
        if (p > best.second) best = {std::uint32_t(k), p};
    }
    return best;
}

}  // namespace

TEST_CASE("without occlusion, GL and CPU shoot the same shooters and agree to float rounding",
          "[gl][radiosity]") {
    // Both backends run the same float kernels (element_form_factor, shot_scale; emitted GLSL
    // agrees with the CPU to 1e-5 of its terms, tests/radiosity) over the same near-field
    // nodes, in another order. A shot's gain is a sum of positive terms, so each shot is off
    // by at most 1e-5 of what it adds, and the unshot radiosity a later shot spreads carries
    // its sources' relative error along: after s shots an element's radiosity is within
    // 1e-5 (s + 1) of itself. The shooter powers are compared in double; their order is the
    // same unless two are within that relative distance, which this box does not have: its
    // lamp is moved off the centre, since mirror-image shooters of a symmetric box have equal
    // powers, and rounding, which the backends do differently, would pick between them.
    gl_test::shared_context();
    auto scene = closed_box(2.f, 0.7f, 10.f);
    for (std::size_t v = scene.positions.size() - 4; v < scene.positions.size(); ++v)
        scene.positions[v] += glm::vec3(0.13f, 0.f, 0.05f);
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 400});
    // Two-sided, both (the default): the lamp's back and the ceiling above it light each other.
    cpu::progressive_radiosity cpu_solver(scene.view(), atlas, cpu::all_visible{});
    gl::progressive_radiosity gl_solver(scene.view(), atlas, {.visibility = gl::radiosity_visibility::none});
    REQUIRE(gl_solver.shooters() == cpu_solver.shooters());
    CHECK(gl_solver.emitted_power().x == Approx(cpu_solver.emitted_power().x).epsilon(1e-12));
    const int shots = 40;
    for (int s = 0; s < shots; ++s) {
        const auto expected = largest_power(gl_solver);
        INFO("step " << s);
        CHECK(gl_solver.next_shooter() == expected.first);
        CHECK(gl_solver.next_shooter_power() == Approx(expected.second).epsilon(1e-12));
        REQUIRE(gl_solver.step());
        REQUIRE(cpu_solver.step());
    }
    REQUIRE(gl_solver.sides() == 2);
    double worst = 0, back = 0;
    for (int side = 0; side < 2; ++side) {
        const auto bg = gl_solver.radiosity(side);
        const auto bc = cpu_solver.radiosity(side);
        for (std::size_t i = 0; i < bc.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                if (bc[i][c] > 0) worst = std::max(worst, std::abs(double(bg[i][c]) - double(bc[i][c])) / double(bc[i][c]));
                if (side == 1) back += double(bc[i][c]);
            }
    }
    INFO("worst relative difference " << worst);
    CHECK(back > 0);  // the backs took light
    // Shots scaled down to their power (shot_scale; the near field over-delivers into the
    // box's corners) are among them, and scaled alike.
    CHECK(cpu_solver.clamped_shots() > 0);
    CHECK(gl_solver.clamped_shots() == cpu_solver.clamped_shots());
    CHECK(worst <= 1e-5 * (shots + 1));
    CHECK(gl_solver.unshot_fraction() == Approx(cpu_solver.unshot_fraction()).epsilon(1e-5 * (shots + 1)));
    CHECK(gl_solver.progress().shots == std::size_t(shots));
}

TEST_CASE("the GL solver's outputs are the CPU solver's: irradiance or radiance, direct or indirect or all",
          "[gl][radiosity][outputs]") {
    // GL keeps B and the B read back after the lights' shots; irradiance is a part's
    // reflected radiosity over rho (every albedo of this box is positive). Compared against
    // the largest value of each output: the indirect part is a difference of B's.
    gl_test::shared_context();
    auto scene = closed_box(2.f, 0.7f, 10.f);
    scene.lights.push_back(point_light{{0.6f, 1.2f, 0.8f}, glm::vec3(2.f, 1.5f, 1.f)});
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 300});
    for (const bool ambient : {false, true}) {
        cpu::progressive_radiosity cpu_solver(scene.view(), atlas, cpu::all_visible{}, {.ambient = ambient});
        gl::progressive_radiosity gl_solver(scene.view(), atlas,
                                            {.shooting = {.ambient = ambient}, .visibility = gl::radiosity_visibility::none});
        for (int s = 0; s < 20; ++s) {
            REQUIRE(gl_solver.step());
            REQUIRE(cpu_solver.step());
        }
        for (const auto q : {output_quantity::irradiance, output_quantity::radiance})
            for (const auto paths : {light_paths::indirect, light_paths::direct, light_paths::all}) {
                // Both sides against the front's largest value (the backs: the lamp's, the
                // ceiling's corners; no direct light reaches a back here).
                float largest = 0;
                for (const glm::vec3& v : cpu_solver.output(q, paths, 0)) largest = std::max({largest, v.x, v.y, v.z});
                REQUIRE(largest > 0.f);
                for (int side = 0; side < 2; ++side) {
                    const auto c = cpu_solver.output(q, paths, side), g = gl_solver.output(q, paths, side);
                    REQUIRE(c.size() == g.size());
                    INFO(to_string(q) << " " << to_string(paths) << " ambient " << ambient << " side " << side);
                    for (std::size_t i = 0; i < c.size(); ++i)
                        for (int k = 0; k < 3; ++k) CHECK(g[i][k] == Approx(c[i][k]).margin(1e-4 * largest));
                }
            }
        // The output texture is lightmap(quantity, paths), alpha 1 where a chart (or its
        // padding) is; the renderer's sampler reads it with the atlas's corner_uvs.
        const auto expected = gl_solver.lightmap(output_quantity::radiance, light_paths::indirect);
        const gl::texture_ref t = gl_solver.update_output_texture(output_quantity::radiance, light_paths::indirect);
        REQUIRE(t.width == atlas.width);
        REQUIRE(t.height == atlas.height);
        const auto got = t.read_floats();
        for (std::uint32_t y = 0; y < atlas.height; ++y)
            for (std::uint32_t x = 0; x < atlas.width; ++x) {
                const float* texel = &got[4 * (std::size_t(y) * atlas.width + x)];
                const bool chart = atlas.element_at(x, y) >= 0;
                CHECK(texel[3] == (chart ? 1.f : 0.f));
                if (chart) CHECK(glm::vec3(texel[0], texel[1], texel[2]) == expected(x, y));
            }
    }
}

TEST_CASE("absorbed + unshot + escaped power equals emitted power on GL after every step", "[gl][radiosity][energy]") {
    // The GL solver books, per shot, the intercepted power each element reports (float,
    // incident power times visibility times area) and the absorbed share (1 - rho) of it, summed
    // in double by the reduction; the unshot texture grows by the float gain rho x incident.
    // The two differ by the kernel's rounding (a few ulps; allowance 4, as on the CPU) and the
    // unshot texels are rounded once per step, so after s steps the balance holds to
    // 4 (s + 3) 2^-24 of the emitted power, the CPU solver's bound.
    gl_test::shared_context();
    const auto check_balance = [](gl::progressive_radiosity& solver, int steps) {
        for (int s = 0; s < steps && solver.step(); ++s) {
            const glm::dvec3 e = solver.emitted_power();
            const glm::dvec3 sum = solver.absorbed_power() + solver.unshot_power() + solver.escaped_power();
            for (int c = 0; c < 3; ++c) CHECK(std::abs(sum[c] - e[c]) <= (s + 3) * 0x1p-24 * e[c] * 4);
        }
    };
    SECTION("Cornell box, emitting quad, stereographic item buffer, blocks with the near field") {
        const auto scene = cornell_box();
        const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 500});
        gl::progressive_radiosity solver(scene.view(), atlas, {.resolution = 128});
        check_balance(solver, 40);
        CHECK(solver.emitted_power().x > 0);
        CHECK(solver.escaped_power().x > 0);  // the box's open front
    }
    SECTION("Cornell box, the spot light of its scene.json shot first, per-element shooters, hemicube") {
        const auto scene = cornell_box(true);
        const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 300});
        gl::progressive_radiosity solver(
            scene.view(), atlas,
            {.shooting = {.shoot_blocks = false, .two_sided = false}, .visibility = gl::radiosity_visibility::hemicube, .resolution = 64});
        CHECK(solver.emitted_power().x > 0);
        check_balance(solver, 40);
    }
}

namespace {

// The CPU solver with item-buffer visibility (the hemicube or the stereographic buffer) of
// `res` texels a side, and the GL solver's options for the same.
cpu::progressive_radiosity<cpu::item_buffer_visibility> cpu_item_buffer_solver(const owned_scene& scene,
                                                                              const lightmap_atlas& atlas, bool hemicube,
                                                                              int res) {
    return cpu::progressive_radiosity<cpu::item_buffer_visibility>(
        scene.view(), atlas,
        cpu::item_buffer_visibility(scene.view(), atlas,
                                    {.projection = hemicube ? cpu::item_projection::hemicube : cpu::item_projection::stereographic,
                                     .resolution = res}),
        {});  // two-sided, as the GL solver's default
}
gl::radiosity_options gl_item_buffer_options(bool hemicube, int res) {
    return {.visibility = hemicube ? gl::radiosity_visibility::hemicube : gl::radiosity_visibility::stereographic,
            .resolution = res};
}

// One shot (from the lamp, the first shooter on both) on GL and on the CPU with the same
// projection and resolution: the elements answered differently, and how many of them do not
// look through an edge pixel of the CPU's buffer (one whose 3 x 3 neighbourhood holds another
// id, the pixel itself included, since it may be the one that flipped).
struct one_shot_comparison {
    std::size_t lit = 0, differing = 0, off_edge = 0;
};

one_shot_comparison compare_one_shot(bool hemicube, int res) {
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 600});
    auto cpu_solver = cpu_item_buffer_solver(scene, atlas, hemicube, res);
    gl::progressive_radiosity gl_solver(scene.view(), atlas, gl_item_buffer_options(hemicube, res));
    const auto b0 = cpu_solver.radiosity();
    const std::vector<glm::vec3> before(b0.begin(), b0.end());
    // The shooter's disc: its elements' area-weighted centroid and its chart's normal.
    const std::uint32_t k = gl_solver.next_shooter();
    const glm::vec3 centre = shooter_disc_of(atlas, gl_solver.shooter_first(k), gl_solver.shooter_first(k + 1)).centre;
    const glm::vec3 n = atlas.normal[gl_solver.shooter_first(k)];
    const auto tb = orthonormal_basis<float, glm::vec3>(n);
    REQUIRE(cpu_solver.step());
    REQUIRE(gl_solver.step());
    const auto bc = cpu_solver.radiosity();
    const auto bg = gl_solver.radiosity();
    const auto buffers = cpu_solver.visibility().buffers();
    one_shot_comparison out;
    for (std::size_t i = 0; i < atlas.size(); ++i) {
        const float gain_cpu = bc[i].x - before[i].x, gain_gl = bg[i].x - before[i].x;
        const float scale = std::max(gain_cpu, gain_gl);
        if (scale > 0) ++out.lit;
        if (std::abs(gain_cpu - gain_gl) <= 1e-5f * scale) continue;
        ++out.differing;
        const glm::vec3 l = to_shooter_frame<float, glm::vec3>(atlas.position[i], centre, tb[0], tb[1], n);
        std::size_t face = 0;
        glm::vec2 xy;
        if (hemicube) {
            const glm::vec3 f = hemicube_item_texel<float, glm::vec3>(l, float(res));
            face = std::size_t(f.x);
            xy = {f.y, f.z};
        } else xy = stereographic_item_texel<float, glm::vec3, glm::vec2>(l, float(res));
        const cpu::item_buffer& buf = buffers[face];
        const auto id_at = [&](int x, int y) {
            x = std::clamp(x, 0, buf.width - 1);
            y = std::clamp(y, 0, buf.height - 1);
            return buf.id[std::size_t(y) * std::size_t(buf.width) + std::size_t(x)];
        };
        const int x = int(xy.x), y = int(xy.y);
        bool edge = false;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) edge = edge || id_at(x + dx, y + dy) != id_at(x, y);
        if (!edge) ++out.off_edge;
    }
    return out;
}

}  // namespace

TEST_CASE("GL and CPU item-buffer visibility differ only at item-buffer edges", "[gl][radiosity][visibility]") {
    // Both draw the same geometry into buffers of the same size: the stereographic one the
    // same tessellated pieces (the sagitta rule), the hemicube the triangles on five
    // perspective faces. GL's rasterizer gets the corners projected in the vertex shader (the
    // emitted kernels) and snaps them itself, so a pixel whose centre lies within a rounding of
    // an edge may fall to the other side: an element can only be answered differently when
    // its pixel borders a pixel of another id. Everywhere else the one shot gives the same
    // gain to float rounding (1e-5). Most elements see the lamp.
    gl_test::shared_context();
    for (const bool hemicube : {false, true}) {
        const auto r = compare_one_shot(hemicube, 128);
        INFO((hemicube ? "hemicube" : "stereographic") << ": lit " << r.lit << ", differing " << r.differing
                                                       << ", of them off an edge " << r.off_edge);
        CHECK(r.lit > 300);
        CHECK(r.off_edge == 0);
    }
}

TEST_CASE("with item-buffer visibility, k shots on GL and CPU agree", "[gl][radiosity][visibility]") {
    // Same atlas, options and buffer resolution. Where every visibility answer is the same
    // (the previous test: answers may differ only at item-buffer edges), the solutions are
    // within the float bound 1e-5 (s + 1) of the test without occlusion. An element answered
    // differently in one shot would differ by that shot's whole gain; the share of the
    // solution's power in such elements is what the relative L1 difference measures, and it is
    // held to 1e-5 (s + 1) too: no element may be answered differently here.
    gl_test::shared_context();
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 600});
    const int res = 128, shots = 30;
    const bool hemicube = GENERATE(false, true);
    INFO((hemicube ? "hemicube" : "stereographic"));
    auto cpu_solver = cpu_item_buffer_solver(scene, atlas, hemicube, res);
    gl::progressive_radiosity gl_solver(scene.view(), atlas, gl_item_buffer_options(hemicube, res));
    std::size_t same_shooter = 0;
    for (int s = 0; s < shots; ++s) {
        const auto expected = largest_power(gl_solver);
        same_shooter += expected.first == gl_solver.next_shooter() ? 1 : 0;
        REQUIRE(gl_solver.step());
        REQUIRE(cpu_solver.step());
    }
    CHECK(same_shooter == std::size_t(shots));
    const auto bg = gl_solver.radiosity();
    const auto bc = cpu_solver.radiosity();
    double diff = 0, sum = 0, worst = 0;
    for (std::size_t i = 0; i < bc.size(); ++i) {
        const double a = double(atlas.area[i]);
        for (int c = 0; c < 3; ++c) {
            diff += std::abs(double(bg[i][c]) - double(bc[i][c])) * a;
            sum += double(bc[i][c]) * a;
            if (bc[i][c] > 0) worst = std::max(worst, std::abs(double(bg[i][c]) - double(bc[i][c])) / double(bc[i][c]));
        }
    }
    INFO("relative L1 difference " << diff / sum << ", worst element " << worst);
    CHECK(diff / sum <= 1e-5 * (shots + 1));
    CHECK(gl_solver.unshot_fraction() == Approx(cpu_solver.unshot_fraction()).epsilon(1e-5 * (shots + 1)));
    const auto escaped_gl = gl_solver.escaped_power(), escaped_cpu = cpu_solver.escaped_power();
    CHECK(escaped_gl.x == Approx(escaped_cpu.x).epsilon(1e-4));
}

TEST_CASE("a directional light shot first gives the CPU's direct radiosity, shadows included", "[gl][radiosity][lights]") {
    // Sun through the Cornell box's open front: both backends draw an orthographic buffer of
    // the same size along the light and apply the same plane rule; the irradiance kernel is
    // the same emitted function. As for the item buffers, answers may differ only where the
    // element's pixel borders another id; they are counted and held to 1% of the elements
    // (the buffer's edge pixels), and the direct power booked as emitted agrees to that share.
    gl_test::shared_context();
    auto scene = cornell_box();
    scene.use_emission = false;
    directional_light sun;
    sun.direction = glm::normalize(glm::vec3(0.2f, -0.5f, -1.f));
    sun.irradiance = {2.f, 1.5f, 1.f};
    scene.lights.push_back(sun);
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 600});
    cpu::progressive_radiosity cpu_solver(
        scene.view(), atlas, cpu::item_buffer_visibility(scene.view(), atlas, {.resolution = 64, .parallel_resolution = 256}));
    gl::progressive_radiosity gl_solver(scene.view(), atlas, {.resolution = 64, .parallel_resolution = 256});
    const auto bc = cpu_solver.radiosity();
    const auto bg = gl_solver.radiosity();
    std::size_t lit = 0, dark = 0, differing = 0;
    for (std::size_t i = 0; i < atlas.size(); ++i) {
        const float scale = std::max(bc[i].x, bg[i].x);
        if (scale > 0) ++lit;
        else ++dark;
        if (std::abs(bc[i].x - bg[i].x) > 1e-5f * scale) ++differing;
    }
    INFO("lit " << lit << ", dark " << dark << ", differing " << differing);
    CHECK(lit > atlas.size() / 4);
    CHECK(dark > atlas.size() / 10);  // the walls facing away and the boxes' shadows
    CHECK(differing <= atlas.size() / 100);
    CHECK(gl_solver.emitted_power().x == Approx(cpu_solver.emitted_power().x).epsilon(0.01));
    CHECK(gl_solver.emitted_power().x > 0);
}

TEST_CASE("the GL lightmap texture is the solver's radiosity lightmap, padding filled, with and without the ambient term",
          "[gl][radiosity]") {
    // Both lay out display_radiosity by element_at: the same float values (each texel holds one
    // element's value, no division) through the same kernel radiosity_with_ambient; with the
    // ambient term GLSL may fuse its multiply-add, 1e-6 of the value.
    gl_test::shared_context();
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 300, .padding = 2});
    // One-sided, a back lightmap is refused by name.
    gl::progressive_radiosity one(scene.view(), atlas, {.shooting = {.two_sided = false}, .resolution = 64});
    CHECK(one.sides() == 1);
    CHECK_THROWS_WITH(one.radiosity_lightmap(0, 1), Catch::Contains("side"));
    CHECK_THROWS_WITH(one.update_lightmap_texture(1), Catch::Contains("side"));
    for (const bool ambient : {false, true}) {
        gl::progressive_radiosity solver(scene.view(), atlas, {.shooting = {.ambient = ambient}, .resolution = 64});
        REQUIRE(solver.sides() == 2);
        for (int s = 0; s < 10; ++s) REQUIRE(solver.step());
        for (int side = 0; side < 2; ++side) {
            const auto expected = solver.radiosity_lightmap(0, side);
            const gl::texture_ref t = solver.update_lightmap_texture(side);
            REQUIRE(t.width == atlas.width);
            REQUIRE(t.height == atlas.height);
            const auto got = t.read_floats();
            double worst = 0;
            std::size_t charted = 0;
            for (std::uint32_t y = 0; y < atlas.height; ++y)
                for (std::uint32_t x = 0; x < atlas.width; ++x) {
                    const float* g = &got[4 * (std::size_t(y) * atlas.width + x)];
                    const glm::vec3 e = expected(x, y);
                    const bool on_chart = atlas.element_at(x, y) >= 0;
                    charted += on_chart ? 1 : 0;
                    CHECK(g[3] == (on_chart ? 1.f : 0.f));
                    for (int c = 0; c < 3; ++c)
                        worst = std::max(worst, std::abs(double(g[c]) - double(e[c])) / std::max(1e-30, double(std::abs(e[c]))));
                }
            INFO("ambient " << ambient << ", side " << side << ", worst relative difference " << worst);
            CHECK(charted > atlas.size());  // padding texels were filled
            CHECK(worst <= (ambient ? 1e-6 : 0.0));
        }
    }
}

TEST_CASE("the GL solver leaves the caller's GL state as it found it", "[gl][radiosity][state]") {
    // A renderer's own state: program, framebuffer, viewport, vertex array, raster state, the
    // storage-buffer bindings and image units the passes use.
    gl_test::shared_context();
    const auto scene = cornell_box(true);
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 200});
    gl::texture colour(gl::texel_format::rgba32f, 8, 8);
    gl::framebuffer fbo;
    fbo.attach_color(0, colour);
    gl::vertex_array vao;
    gl::buffer ssbo(64);
    const gl::program prog = gl::program::compute("#version 450\nlayout(local_size_x = 1) in;\nvoid main() {}\n");
    glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
    glViewport(1, 2, 3, 4);
    glBindVertexArray(vao.id());
    glUseProgram(prog.id());
    glEnable(GL_BLEND);
    glEnable(GL_CULL_FACE);
    glDisable(GL_DEPTH_TEST);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 2, ssbo.id(), 0, 32);
    glBindImageTexture(3, colour.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    for (const auto v : {gl::radiosity_visibility::stereographic, gl::radiosity_visibility::hemicube}) {
        gl::progressive_radiosity solver(scene.view(), atlas, {.visibility = v, .resolution = 32});
        solver.solve(0.5);
        (void)solver.radiosity();
    }
    GLint draw_fb = 0, viewport[4] = {}, bound_vao = 0, program = 0, storage = 0, image = 0, access = 0;
    GLint64 size = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_fb);
    glGetIntegerv(GL_VIEWPORT, viewport);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &bound_vao);
    glGetIntegerv(GL_CURRENT_PROGRAM, &program);
    glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, 2, &storage);
    glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_SIZE, 2, &size);
    glGetIntegeri_v(GL_IMAGE_BINDING_NAME, 3, &image);
    glGetIntegeri_v(GL_IMAGE_BINDING_ACCESS, 3, &access);
    CHECK(GLuint(draw_fb) == fbo.id());
    CHECK(viewport[0] == 1);
    CHECK(viewport[3] == 4);
    CHECK(GLuint(bound_vao) == vao.id());
    CHECK(GLuint(program) == prog.id());
    CHECK(GLuint(storage) == ssbo.id());
    CHECK(size == 32);
    CHECK(GLuint(image) == colour.id());
    CHECK(access == GL_WRITE_ONLY);
    CHECK(glIsEnabled(GL_BLEND) == GL_TRUE);
    CHECK(glIsEnabled(GL_CULL_FACE) == GL_TRUE);
    CHECK(glIsEnabled(GL_DEPTH_TEST) == GL_FALSE);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, 0);
    glBindImageTexture(3, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
    gl::check_error("state test");
}

TEST_CASE("bad GL solver input raises parameter_error naming it", "[gl][radiosity][errors]") {
    gl_test::shared_context();
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 200});
    const auto throws_naming = [&](gl::radiosity_options o, const char* name) {
        CHECK_THROWS_WITH(gl::progressive_radiosity(scene.view(), atlas, o), Catch::Contains(name));
    };
    throws_naming({.shooting = {.near_field = -1, .two_sided = false}}, "radiosity_options.near_field");
    throws_naming({.shooting = {.shooters_per_step = 2, .two_sided = false}}, "radiosity_options.shooters_per_step");
    throws_naming({.shooting = {.two_sided = false, .light_samples = 2}}, "radiosity_options.light_samples");
    throws_naming({.resolution = 4}, "radiosity_options.resolution");
    throws_naming({.visibility = gl::radiosity_visibility::hemicube, .resolution = 65}, "radiosity_options.resolution");
    throws_naming({.tolerance_px = 0.f}, "radiosity_options.tolerance_px");
    throws_naming({.max_tessellation_depth = 17}, "radiosity_options.max_tessellation_depth");
    const auto other = closed_box(1.f, 0.5f, 1.f);
    CHECK_THROWS_AS(gl::progressive_radiosity(other.view(), atlas), parameter_error);
    throws_naming({.parallel_resolution = 4}, "radiosity_options.parallel_resolution");
    const std::vector<std::uint32_t> split{0};
    const auto refined = refine_lightmap_atlas(scene.view(), atlas, split);
    CHECK_THROWS_WITH(gl::progressive_radiosity(scene.view(), refined.atlas), Catch::Contains("subdivided"));
    const auto wide = build_lightmap_atlas(scene.view(), {.elements = 200, .block_texels = 32});
    CHECK_THROWS_WITH(gl::progressive_radiosity(scene.view(), wide), Catch::Contains("atlas.block_texels"));
    gl::progressive_radiosity solver(scene.view(), atlas, {.resolution = 64});
    CHECK_THROWS_WITH(solver.solve(1.0), Catch::Contains("fraction"));
    CHECK_THROWS_WITH(solver.solve(-0.1), Catch::Contains("fraction"));
}
