// The whole GL path on several maps: a scene rasterized into a G-buffer (gl::gbuffer_pass)
// and into the six cube faces of a point light plus a spot light's map (gl::rsm_renderer),
// then gl::indirect_renderer, against cpu::indirect_renderer on the same G-buffer and maps
// read back: the gather adds one draw per map and SII shares its VPLs between the maps by
// their flux, as the CPU does. Tolerance as in test_gl_indirect_agreement.cpp (1e-4 relative
// per pixel and channel: sums of non-negative terms, each within 1e-5 of its size).
#include "../embree/hand_built_scenes.hpp"
#include "../gl/shared_context.hpp"

#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/indirect_renderer.hpp>
#include <bounce/gl/rsm_renderer.hpp>
#include <bounce/gl/splat_pass.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace bounce;

TEST_CASE("GL maps and GL indirect light of a point and a spot light equal the CPU's on the same maps",
          "[gl][rsm]") {
    gl_test::shared_context();
    hand_built::scene s;
    const auto grey = hand_built::add_material(s, glm::vec3(0.6f, 0.5f, 0.4f));
    const auto red = hand_built::add_material(s, glm::vec3(0.7f, 0.1f, 0.1f));
    hand_built::add_square_z(s, 0.f, 1.f, true, grey);
    hand_built::add_quad(s, {-1, 1, 0}, {1, 1, 0}, {1, 1, 2}, {-1, 1, 2}, {0, -1, 0}, red);
    spot_light spot;
    spot.position = {0.3f, -0.5f, 1.6f};
    spot.direction = {-0.2f, 0.4f, -1.f};
    spot.intensity = {3.f, 2.f, 1.f};
    spot.cone_deg = 35.f;
    s.lights = {point_light{{-0.2f, -0.3f, 1.2f}, {1.f, 2.f, 3.f}}, spot};
    camera cam;
    cam.position = {0.f, -3.f, 1.5f};
    cam.look_at = {0.f, 0.f, 0.6f};
    cam.up = {0, 0, 1};
    cam.fov_y_deg = 55.f;
    const std::size_t w = 53, h = 41;

    const gl::scene_mesh mesh(s.view());
    gl::gbuffer_pass gpass;
    gpass.render(mesh, cam, w, h);
    gl::rsm_renderer maps_gl(s.view(), mesh, {24, 60.f});
    maps_gl.render();
    REQUIRE(maps_gl.maps().size() == 7);

    gbuffer<float> gb = gpass.read();
    std::vector<gl::rsm_images> images;
    for (const auto& m : maps_gl.maps()) images.emplace_back(m);
    std::vector<rsm_view> views;
    for (const auto& im : images) views.push_back(im.view());

    for (const auto technique : {indirect_technique::rsm_gather, indirect_technique::sii}) {
        for (const interleave_pattern p : {interleave_pattern{1, 1}, interleave_pattern{4, 2}}) {
            indirect_options o;
            o.technique = technique;
            o.count = 96;
            o.pattern = p;
            o.light.min_distance2 = 1e-4f;
            gl::indirect_renderer renderer(o);
            gl::texture out(gl::texel_format::rgba32f, w, h);
            renderer.render(gl::textures_of(gpass), cam, maps_gl.maps(), out);
            image<glm::vec3> gl_img(w, h);
            gl::read_texture(out, gl_img.view());

            cpu::indirect_renderer cpu_renderer(o);  // the same options
            image<glm::vec3> cpu_img(w, h);
            const indirect_timings ct = cpu_renderer.render(gb.view(), cam, views, cpu_img.view());
            if (technique == indirect_technique::sii) CHECK(ct.vpls > std::size_t(80));

            double worst = 0, mean = 0;
            for (std::size_t y = 0; y < h; ++y)
                for (std::size_t x = 0; x < w; ++x)
                    for (int k = 0; k < 3; ++k) {
                        const double a = gl_img(x, y)[k], b = cpu_img(x, y)[k];
                        mean += b / double(3 * w * h);
                        worst = std::max(worst, b == 0 ? std::abs(a) : std::abs(a - b) / std::abs(b));
                    }
            INFO("technique " << int(technique) << ", pattern " << p.n << "x" << p.m << ": worst " << worst
                              << ", mean " << mean);
            CHECK(mean > 0);
            CHECK(worst <= 1e-4);
        }
    }
}
