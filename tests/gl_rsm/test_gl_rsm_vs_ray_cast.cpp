// gl::rsm_renderer against embree::rsm_ray_caster on one scene and the same lights: the
// same maps in the same order with the same matrices, and texel by texel the same surface
// (position, normal) and flux. Rasterization samples the texel centres the rays pass
// through, so the two differ only where a centre lies within rounding of a triangle's edge
// (the other triangle, or the background, may win there): such texels are counted and must
// stay rare (below 1% of the lit texels); everywhere else positions agree to 1e-5 of the
// scene's size (float interpolation against the ray's o + t d) and fluxes to 1e-4
// relatively (the kernels' rounding and, for spot lights, the profile's slope times the
// position's rounding).
#include "../embree/hand_built_scenes.hpp"
#include "../gl/shared_context.hpp"

#include <bounce/embree/accel.hpp>
#include <bounce/embree/rsm_ray_cast.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/rsm_renderer.hpp>

#include <catch2/catch.hpp>

#include <cmath>

using namespace bounce;

TEST_CASE("GL RSMs of spot, wide spot, point and distant lights equal the ray-cast ones", "[gl][rsm][embree]") {
    gl_test::shared_context();
    hand_built::scene s;
    const auto grey = hand_built::add_material(s, glm::vec3(0.6f, 0.5f, 0.4f));
    const auto red = hand_built::add_material(s, glm::vec3(0.7f, 0.1f, 0.1f));
    hand_built::add_square_z(s, 0.f, 1.f, true, grey);                              // floor
    hand_built::add_quad(s, {-1, 1, 0}, {1, 1, 0}, {1, 1, 2}, {-1, 1, 2}, {0, -1, 0}, red);  // back wall
    hand_built::add_square_z(s, 0.6f, 0.3f, true, red, {0.2f, -0.1f});             // a floating occluder
    spot_light spot;
    spot.position = {0.1f, -0.3f, 1.6f};
    spot.direction = {0.1f, 0.3f, -1.f};
    spot.intensity = {3.f, 2.f, 1.f};
    spot.cone_deg = 40.f;
    spot_light wide = spot;
    wide.cone_deg = 80.f;
    wide.direction = {0.f, 0.2f, -1.f};
    s.lights = {spot, wide, point_light{{-0.2f, -0.4f, 1.3f}, {1.f, 2.f, 3.f}},
                directional_light{{0.3f, 0.4f, -1.f}, {2.f, 2.f, 2.f}}};
    const std::size_t r = 40;

    embree::accel bvh(s.view());
    embree::rsm_ray_caster caster(bvh, s.view(), {r, 60.f});
    caster.render();
    const gl::scene_mesh mesh(s.view());
    gl::rsm_renderer renderer(s.view(), mesh, {r, 60.f});
    renderer.render();
    const auto layout = renderer.layout(s.lights);

    // The ray caster drops faces that see no lit surface; the GL layout keeps every face the
    // cone can reach. Match maps by light and matrix.
    std::size_t matched = 0, lit = 0, differ = 0;
    double worst_position = 0, worst_flux = 0;
    for (const auto& cast : caster.maps()) {
        std::size_t k = 0;
        while (k < layout.size() &&
               !(layout[k].light == cast.light && layout[k].light_view_projection == cast.light_view_projection))
            ++k;
        REQUIRE(k < layout.size());
        ++matched;
        CHECK(layout[k].texel_size == cast.texel_size);
        const gl::rsm_images m(renderer.maps()[k]);
        for (std::size_t y = 0; y < r; ++y)
            for (std::size_t x = 0; x < r; ++x) {
                const glm::vec3 a = m.flux(x, y), b = cast.flux(x, y);
                if (a == glm::vec3(0.f) && b == glm::vec3(0.f)) continue;
                ++lit;
                const double dp = glm::length(m.position(x, y) - cast.position(x, y));
                const double dn = glm::length(m.normal(x, y) - cast.normal(x, y));
                const double df = glm::length(a - b) / std::max(glm::length(b), 1e-30f);
                if (dp > 1e-5 * 3 || dn > 1e-5 || df > 1e-4) {
                    ++differ;
                    continue;
                }
                worst_position = std::max(worst_position, dp);
                worst_flux = std::max(worst_flux, df);
            }
    }
    // Maps GL has and the caster dropped must be dark.
    for (std::size_t k = 0; k < layout.size(); ++k) {
        bool in_caster = false;
        for (const auto& cast : caster.maps())
            in_caster = in_caster || (layout[k].light == cast.light &&
                                      layout[k].light_view_projection == cast.light_view_projection);
        if (in_caster) continue;
        const gl::rsm_images m(renderer.maps()[k]);
        for (std::size_t y = 0; y < r; ++y)
            for (std::size_t x = 0; x < r; ++x) CHECK(m.flux(x, y) == glm::vec3(0.f));
    }
    INFO("maps " << matched << ", lit texels " << lit << ", differing " << differ << ", worst position "
                 << worst_position << ", worst flux " << worst_flux);
    CHECK(matched == caster.maps().size());
    CHECK(lit > 4000);
    CHECK(double(differ) <= 0.01 * double(lit));
    CHECK(worst_position <= 3e-5);
    CHECK(worst_flux <= 1e-4);
}
