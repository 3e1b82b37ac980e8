// gl::indirect_renderer against cpu::indirect_renderer on the same G-buffer, the same
// reflective shadow map and the same options: the RSM gather and SII, without and with
// interleaving (patterns 2x2, 4x4 and 3x2 on an image whose size is no multiple of them),
// blur on, SII with and without the splat cutoff; the renderers take one
// bounce::indirect_options; the VPLs GL splats are the core's select_vpls; bad input
// refused by name; the caller's GL state kept.
//
// Tolerance. Every pixel is a sum of non-negative terms (pixel-light irradiances), added in
// the same order on both backends, then (interleaved, blurred) a convex combination of such
// sums with weights from the same kernel. Each term's GLSL value is within 1e-5 of its own
// size of the CPU's (tests/rsm/test_rsm_glsl_agreement.cpp: about 2 k ulp for the k <= 40
// operations of the kernel); a sum of non-negative terms keeps the largest relative error of
// its terms plus the float rounding of the additions, which is the same on both sides up to
// the propagated term errors; the tent's weights are ratios of small integers computed in
// a few operations (1e-6). So |gl - cpu| <= 1e-4 |cpu| per pixel and channel holds with a
// margin of about 10. What could break it: a disc sample whose texel index rounds to a
// different texel on the GPU (tu within an ulp of an integer); the shader computes the disc
// centre unfused, in the CPU's order, so that does not happen on these inputs.
#include "../gl/shared_context.hpp"
#include "../rsm/corner_scene.hpp"

#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/gl/indirect_renderer.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/owned_scene.hpp>

#include <catch2/catch.hpp>

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

using namespace bounce;
using rsm_test::corner_scene;

namespace {

// An RGBA32F texture holding `img` (row 0 at the top), alpha `a`.
gl::texture upload(const image<glm::vec3>& img) {
    gl::texture t(gl::texel_format::rgba32f, img.width(), img.height());
    image<glm::vec4> padded(img.width(), img.height());
    for (std::size_t y = 0; y < img.height(); ++y)
        for (std::size_t x = 0; x < img.width(); ++x) padded(x, y) = glm::vec4(img(x, y), 0.f);
    gl::write_texture(t, padded.view());
    return t;
}

// The scene's map as textures, kept alive with the refs.
struct map_textures {
    gl::texture position, normal, flux;
    gl::rsm_textures refs;
    explicit map_textures(const corner_scene& s)
        : position(upload(s.map_position)), normal(upload(s.map_normal)), flux(upload(s.map_flux)) {
        refs = {position, normal, flux, s.light_view_projection};
    }
};

struct comparison {
    double worst_relative = 0;  // max over pixels and channels of |gl - cpu| / |cpu| (cpu > 0)
    double worst_zero = 0;      // max |gl| where the CPU has exactly 0
    double mean = 0;            // mean of the CPU's channel x over covered pixels
};

comparison compare(const corner_scene& s, const image<glm::vec3>& gl_img, const image<glm::vec3>& cpu_img) {
    comparison c;
    std::size_t n = 0;
    for (std::size_t y = 0; y < s.gb.height(); ++y)
        for (std::size_t x = 0; x < s.gb.width(); ++x) {
            if (s.gb.depth(x, y) < std::numeric_limits<float>::infinity()) {
                c.mean += cpu_img(x, y).x;
                ++n;
            }
            for (int k = 0; k < 3; ++k) {
                const double a = gl_img(x, y)[k], b = cpu_img(x, y)[k];
                if (b == 0) c.worst_zero = std::max(c.worst_zero, std::abs(a));
                else c.worst_relative = std::max(c.worst_relative, std::abs(a - b) / std::abs(b));
            }
        }
    c.mean /= double(std::max<std::size_t>(n, 1));
    return c;
}

struct frame {
    image<glm::vec3> gl_img, cpu_img;
    indirect_timings timings;
    indirect_timings cpu_timings;
};

frame render_both(const corner_scene& s, const indirect_options& o, const ism_point_sampler* points = nullptr) {
    gl::gbuffer_upload gb(const_cast<gbuffer<float>&>(s.gb).view());
    map_textures map(s);
    gl::texture out(gl::texel_format::rgba32f, s.gb.width(), s.gb.height());
    gl::indirect_renderer renderer(o);
    renderer.set_point_sampler(points);
    const gl::rsm_textures maps[] = {map.refs};
    frame f;
    f.timings = renderer.render(gb.textures(), s.cam, maps, out);
    f.gl_img = image<glm::vec3>(s.gb.width(), s.gb.height());
    gl::read_texture(out, f.gl_img.view());

    cpu::indirect_renderer cpu_renderer(o, nullptr, points);  // the same options
    f.cpu_img = image<glm::vec3>(s.gb.width(), s.gb.height());
    const rsm_view cpu_maps[] = {s.map()};
    auto gbv = const_cast<gbuffer<float>&>(s.gb).view();
    f.cpu_timings = cpu_renderer.render(gbv, s.cam, cpu_maps, f.cpu_img.view());
    return f;
}

frame check_agreement(const corner_scene& s, const indirect_options& o, const ism_point_sampler* points = nullptr) {
    frame f = render_both(s, o, points);
    const comparison c = compare(s, f.gl_img, f.cpu_img);
    INFO("pattern " << o.pattern.n << "x" << o.pattern.m << ", worst relative " << c.worst_relative
                    << ", worst where the CPU has 0: " << c.worst_zero << ", mean " << c.mean);
    CHECK(c.mean > 0);  // the frame lit something
    CHECK(c.worst_relative <= 1e-4);
    CHECK(c.worst_zero <= 1e-4 * c.mean);
    return f;
}

// The corner scene's floor and wall and a square hovering over the floor (not in the
// G-buffer: it only casts indirect shadows), as the points of imperfect shadow maps.
owned_scene corner_points() {
    owned_scene s;
    s.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0},  {-1, 1, 0}, {1, -1, 0}, {1, 1, 0},
                   {1, 1, 2},   {1, -1, 2}, {-0.4f, -0.4f, 0.4f}, {0.4f, -0.4f, 0.4f}, {0.4f, 0.4f, 0.4f},
                   {-0.4f, 0.4f, 0.4f}};
    s.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}, {8, 9, 10}, {8, 10, 11}};
    s.material_of.assign(6, 0);
    s.materials.resize(1);
    return s;
}

}  // namespace

TEST_CASE("GL SII with imperfect shadow maps equals the CPU's, and the maps shadow", "[gl][rsm][ism]") {
    gl_test::shared_context();
    const corner_scene s(61, 47);
    const ism_point_sampler points(corner_points().view());
    for (const interleave_pattern p : {interleave_pattern{1, 1}, interleave_pattern{4, 4}, interleave_pattern{3, 2}})
        for (const int size : {8, 32}) {
            indirect_options o;
            o.count = 128;
            o.pattern = p;
            o.visibility = indirect_visibility::ism;
            o.ism.map_size = size;
            o.ism.points_per_vpl = 512;
            o.ism.pull_push = size == 32;
            INFO("map size " << size);
            const frame f = check_agreement(s, o, &points);
            o.visibility = indirect_visibility::none;
            const frame open = render_both(s, o);
            // The square hides part of the map from part of the floor: some pixels darker.
            std::size_t darker = 0;
            for (std::size_t y = 0; y < s.gb.height(); ++y)
                for (std::size_t x = 0; x < s.gb.width(); ++x) darker += f.cpu_img(x, y).x < 0.9f * open.cpu_img(x, y).x;
            CHECK(darker > 50);
        }
    // Without the scene's points the renderer refuses the frame by the option's name.
    indirect_options o;
    o.count = 128;
    o.visibility = indirect_visibility::ism;
    gl::indirect_renderer r(o);
    gl::gbuffer_upload gb(const_cast<gbuffer<float>&>(s.gb).view());
    map_textures map(s);
    gl::texture out(gl::texel_format::rgba32f, s.gb.width(), s.gb.height());
    const gl::rsm_textures maps[] = {map.refs};
    CHECK_THROWS_WITH(r.render(gb.textures(), s.cam, maps, out), Catch::Contains("visibility"));
}

TEST_CASE("GL RSM gather equals the CPU's, plain and interleaved with blur", "[gl][rsm]") {
    gl_test::shared_context();
    const corner_scene s(61, 47);  // no multiple of 2, 3 or 4
    indirect_options o;
    o.technique = indirect_technique::rsm_gather;
    o.count = 256;
    // 8x8 and 16x2 take the tent's radii 7 and 15.
    for (const interleave_pattern p : {interleave_pattern{1, 1}, interleave_pattern{2, 2}, interleave_pattern{4, 4},
                                       interleave_pattern{3, 2}, interleave_pattern{8, 8}, interleave_pattern{16, 2}}) {
        o.pattern = p;
        check_agreement(s, o);
    }
    SECTION("with the singularity remedies, DS05's weights and a shift") {
        o.pattern = {2, 2};
        o.light.offset = 0.01f;
        o.light.min_distance2 = 1e-4f;
        o.disc = disc_weighting::xi1_squared;
        o.shift = 3;
        check_agreement(s, o);
    }
}

TEST_CASE("GL RSM gather at low resolution, upsampled with the full-resolution fallback, equals the CPU's",
          "[gl][rsm]") {
    gl_test::shared_context();
    const corner_scene s(61, 47);
    indirect_options o;
    o.technique = indirect_technique::rsm_gather;
    o.count = 128;
    for (const int f : {2, 3})
        for (const interleave_pattern p : {interleave_pattern{1, 1}, interleave_pattern{2, 2}}) {
            o.low_resolution = f;
            o.pattern = p;
            const frame r = check_agreement(s, o);
            // The floor-wall edge and the image border leave pixels without three suitable
            // samples: both backends gather the same ones at full resolution.
            CHECK(r.cpu_timings.fallback_pixels > 0);
            CHECK(r.timings.fallback_pixels == r.cpu_timings.fallback_pixels);
        }
}

TEST_CASE("GL SII equals the CPU's, plain and interleaved with blur, with and without the cutoff", "[gl][rsm]") {
    gl_test::shared_context();
    const corner_scene s(61, 47);
    indirect_options o;
    o.technique = indirect_technique::sii;
    o.count = 128;
    // The corner map's VPLs carry about 0.02 W each: a cutoff of 1 W/m^2 over 128 VPLs bounds
    // each splat by a sphere of radius 0.4 m in a 2 m scene, so the rectangles matter.
    for (const float cutoff : {0.f, 1.f}) {
        o.sii_cutoff = cutoff;
        for (const interleave_pattern p : {interleave_pattern{1, 1}, interleave_pattern{2, 2},
                                           interleave_pattern{4, 4}, interleave_pattern{3, 2}}) {
            o.pattern = p;
            check_agreement(s, o);
        }
    }
    SECTION("the cutoff changes the image (the rectangles were exercised)") {
        o.pattern = {2, 2};
        o.sii_cutoff = 0.f;
        const frame whole = render_both(s, o);
        o.sii_cutoff = 1.f;
        const frame cut = render_both(s, o);
        const comparison c = compare(s, cut.gl_img, whole.gl_img);
        CHECK(c.worst_relative > 1e-2);
    }
    SECTION("each VPL clamped at its own footprint (position.w on GL), and the clamp acts") {
        o.sii_cutoff = 0.f;
        o.light.footprint_scale = 1.f;
        for (const interleave_pattern p : {interleave_pattern{1, 1}, interleave_pattern{2, 2}}) {
            o.pattern = p;
            check_agreement(s, o);
        }
        const frame footprint = render_both(s, o);
        o.light.footprint_scale = 0.f;
        const frame fixed = render_both(s, o);
        CHECK(compare(s, footprint.gl_img, fixed.gl_img).worst_relative > 1e-2);
    }
    SECTION("grid VPLs, similarity assignment, weight 1 (the thesis's)") {
        o.pattern = {2, 2};
        o.selection = vpl_selection::grid;
        o.assignment = light_assignment::similarity;
        o.energy_correct = false;
        check_agreement(s, o);
    }
}

TEST_CASE("GL interleaving without blur is the split, shaded and gathered image of the CPU", "[gl][rsm]") {
    gl_test::shared_context();
    const corner_scene s(37, 29);
    indirect_options o;
    o.technique = indirect_technique::sii;
    o.count = 64;
    o.blur = false;
    o.pattern = {4, 3};
    check_agreement(s, o);
}

TEST_CASE("the GL renderer splats the core's VPLs (select_vpls), dealt and weighted as the CPU's", "[gl][rsm]") {
    gl_test::shared_context();
    const corner_scene s(16, 12, 8);
    gl::gbuffer_upload gb(const_cast<gbuffer<float>&>(s.gb).view());
    map_textures map(s);
    gl::texture out(gl::texel_format::rgba32f, 16, 12);
    const gl::rsm_textures maps[] = {map.refs};
    const rsm_view views[] = {s.map()};
    for (const vpl_selection selection : {vpl_selection::flux_warping, vpl_selection::grid}) {
        indirect_options o;
        o.technique = indirect_technique::sii;
        o.count = 60;
        o.seed = 5;
        o.pattern = {2, 2};
        o.selection = selection;
        gl::indirect_renderer r(o);
        const indirect_timings t = r.render(gb.textures(), s.cam, maps, out);
        // The host-side choices are the core's (indirect/rsm_sampling.hpp), on the read-back map.
        const auto all = select_vpls(views, o);
        const light_groups g = assign_lights(all.size(), 4, light_assignment::interleaved);
        REQUIRE(t.vpls == all.size());
        REQUIRE(r.splatted_vpls().size() == all.size());
        for (std::size_t k = 0; k < all.size(); ++k) {
            const vpl& want = all[g.order[k]];
            CHECK(r.splatted_vpls()[k].position == want.position);
            CHECK(r.splatted_vpls()[k].flux == want.flux * 4.f);
        }
    }
}

TEST_CASE("the GL indirect renderer refuses bad input by name", "[gl][rsm]") {
    gl_test::shared_context();
    const corner_scene s(16, 12, 8);
    gl::gbuffer_upload gb(const_cast<gbuffer<float>&>(s.gb).view());
    map_textures map(s);
    gl::texture out(gl::texel_format::rgba32f, 16, 12);
    const gl::rsm_textures maps[] = {map.refs};
    const auto throws_naming = [](auto&& f, const std::string& name) {
        try {
            f();
            FAIL("no exception");
        } catch (const parameter_error& e) {
            CHECK(std::string(e.what()).find(name) != std::string::npos);
        }
    };
    gl::indirect_renderer r;
    SECTION("visibility this backend does not have") {
        indirect_options o;
        o.visibility = indirect_visibility::rays;
        throws_naming([&] { gl::indirect_renderer bad(o); }, "visibility");
    }
    SECTION("completing isolated pixels, which runs on the CPU only") {
        indirect_options o;
        o.discontinuity.complete_below = 0.5f;
        throws_naming([&] { gl::indirect_renderer bad(o); }, "complete_below");
    }
    SECTION("output of another size") {
        gl::texture small(gl::texel_format::rgba32f, 15, 12);
        throws_naming([&] { r.render(gb.textures(), s.cam, maps, small); }, "irradiance");
    }
    SECTION("output of another format") {
        gl::texture r32(gl::texel_format::r32f, 16, 12);
        throws_naming([&] { r.render(gb.textures(), s.cam, maps, r32); }, "irradiance");
    }
    SECTION("a map with a texture of another size or format, or none") {
        gl::texture odd(gl::texel_format::rgba32f, 8, 7);
        gl::rsm_textures bad = map.refs;
        bad.normal = odd;
        const gl::rsm_textures bad_maps[] = {bad};
        throws_naming([&] { r.render(gb.textures(), s.cam, bad_maps, out); }, "maps");
        gl::texture r32(gl::texel_format::r32f, 8, 8);
        bad.normal = r32;
        const gl::rsm_textures bad_format[] = {bad};
        throws_naming([&] { r.render(gb.textures(), s.cam, bad_format, out); }, "maps");
        bad.normal = gl::texture_ref{};
        const gl::rsm_textures missing[] = {bad};
        throws_naming([&] { r.render(gb.textures(), s.cam, missing, out); }, "maps");
    }
    SECTION("a zero-sized G-buffer") {
        gl::gbuffer_textures empty = gb.textures();
        empty.position_depth.width = 0;
        throws_naming([&] { r.render(empty, s.cam, maps, out); }, "gbuffer");
    }
    SECTION("zero-sized textures cannot be made") {
        throws_naming([] { gl::texture t(gl::texel_format::rgba32f, 0, 4); }, "");
    }
    SECTION("maps of two sizes for the gather") {
        indirect_options o;
        o.technique = indirect_technique::rsm_gather;
        gl::indirect_renderer gather(o);
        const corner_scene other(16, 12, 4);
        map_textures small(other);
        const gl::rsm_textures two[] = {map.refs, small.refs};
        throws_naming([&] { gather.render(gb.textures(), s.cam, two, out); }, "maps");
    }
    SECTION("options") {
        indirect_options o;
        o.low_resolution = 2;  // SII has no low-resolution pass
        throws_naming([&] { gl::indirect_renderer x(o); }, "low_resolution");
        o.technique = indirect_technique::rsm_gather;
        o.low_resolution = 9;
        throws_naming([&] { gl::indirect_renderer x(o); }, "low_resolution");
        o = {};
        o.pattern = {0, 4};
        throws_naming([&] { gl::indirect_renderer x(o); }, "pattern.n");
        o = {};
        o.shift = 16;
        throws_naming([&] { gl::indirect_renderer x(o); }, "shift");
        o = {};
        o.light.offset = -1.f;
        throws_naming([&] { gl::indirect_renderer x(o); }, "offset");
    }
}

TEST_CASE("the GL indirect renderer keeps the caller's GL state", "[gl][rsm]") {
    gl_test::shared_context();
    const corner_scene s(16, 12, 8);
    gl::gbuffer_upload gb(const_cast<gbuffer<float>&>(s.gb).view());
    map_textures map(s);
    gl::texture out(gl::texel_format::rgba32f, 16, 12);
    const gl::rsm_textures maps[] = {map.refs};
    gl::framebuffer fb;
    gl::texture colour(gl::texel_format::rgba32f, 5, 5);
    fb.attach_color(0, colour);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fb.id());
    glViewport(1, 2, 3, 4);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glBindTextureUnit(3, colour.id());
    for (const int variant : {0, 1, 2}) {
        indirect_options o;
        o.technique = variant == 0 ? indirect_technique::sii : indirect_technique::rsm_gather;
        o.low_resolution = variant == 2 ? 2 : 1;  // the downsampling, upsampling and fallback passes too
        o.count = 16;
        gl::indirect_renderer r(o);
        r.render(gb.textures(), s.cam, maps, out);
        GLint fbo = 0, viewport[4] = {}, src = 0, unit3 = 0, program = 0;
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fbo);
        glGetIntegerv(GL_VIEWPORT, viewport);
        glGetIntegerv(GL_BLEND_SRC_RGB, &src);
        glGetIntegerv(GL_CURRENT_PROGRAM, &program);
        glActiveTexture(GL_TEXTURE3);
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &unit3);
        glActiveTexture(GL_TEXTURE0);
        CHECK(GLuint(fbo) == fb.id());
        CHECK((viewport[0] == 1 && viewport[1] == 2 && viewport[2] == 3 && viewport[3] == 4));
        CHECK(glIsEnabled(GL_BLEND) == GL_TRUE);
        CHECK(src == GL_SRC_ALPHA);
        CHECK(program == 0);
        CHECK(GLuint(unit3) == colour.id());
    }
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glDisable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ZERO);
    glBindTextureUnit(3, 0);
}

TEST_CASE("gl::offscreen_indirect_renderer on host images equals the CPU renderer, across option changes",
          "[gl][rsm]") {
    // Its own context: what rsm_sii --backend gl and a study use, with the call of
    // cpu::indirect_renderer. One object renders a sequence of option sets (the renderer is
    // rebuilt only when they differ) and each frame agrees with a fresh CPU renderer.
    const corner_scene s(45, 33);
    auto gbv = const_cast<gbuffer<float>&>(s.gb).view();
    const rsm_view maps[] = {s.map()};
    gl::offscreen_indirect_renderer gl_renderer;
    CHECK_FALSE(gl_renderer.gl_renderer().empty());
    std::vector<indirect_options> runs;
    for (const auto technique : {indirect_technique::sii, indirect_technique::rsm_gather})
        for (const interleave_pattern p : {interleave_pattern{1, 1}, interleave_pattern{4, 4}}) {
            indirect_options o;
            o.technique = technique;
            o.count = 128;
            o.pattern = p;
            runs.push_back(o);
            runs.push_back(o);  // the same options again: the kept renderer
            o.seed = 5;         // one field changed: a new one
            runs.push_back(o);
        }
    for (const auto& o : runs) {
        image<glm::vec3> gl_img(s.gb.width(), s.gb.height()), cpu_img(s.gb.width(), s.gb.height());
        gl_renderer.render(o, gbv, s.cam, maps, gl_img.view());
        cpu::indirect_renderer(o).render(gbv, s.cam, maps, cpu_img.view());
        const comparison c = compare(s, gl_img, cpu_img);
        INFO("technique " << int(o.technique) << ", pattern " << o.pattern.n << "x" << o.pattern.m << ", seed "
                          << o.seed << ", worst relative " << c.worst_relative);
        CHECK(c.mean > 0);
        CHECK(c.worst_relative <= 1e-4);
        CHECK(c.worst_zero <= 1e-4 * c.mean);
    }
    // Bad options are refused before any GL work, as by the CPU renderer.
    indirect_options bad;
    bad.count = 8;
    bad.pattern = {4, 4};
    image<glm::vec3> out(s.gb.width(), s.gb.height());
    CHECK_THROWS_AS(gl_renderer.render(bad, gbv, s.cam, maps, out.view()), parameter_error);
    image<glm::vec3> wrong(s.gb.width() + 1, s.gb.height());
    CHECK_THROWS_AS(gl_renderer.render({}, gbv, s.cam, maps, wrong.view()), parameter_error);
}
