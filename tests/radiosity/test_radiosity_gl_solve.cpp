// The GL solver runs the same solve as the CPU solver (radiosity/solve.hpp): the same stop,
// the same steps, the same checks (reversed winding, the tolerance floor). llvmpipe via EGL.
#include "../gl/shared_context.hpp"
#include "radiosity_scenes.hpp"
#include "unshot_never_rises.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/cpu/radiosity_item_buffer.hpp>
#include <bounce/gl/radiosity.hpp>
#include <bounce/radiosity/solve.hpp>

#include <catch2/catch.hpp>

#include <utility>

using namespace bounce;
using namespace bounce::radiosity_test;

TEST_CASE("the GL solver's solve(options) stops where the CPU solver's does", "[radiosity][solve][gl]") {
    gl_test::shared_context();
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 400, .block_texels = 4});
    gl::progressive_radiosity g(scene.view(), atlas, {.visibility = gl::radiosity_visibility::none});
    cpu::progressive_radiosity c(scene.view(), atlas, cpu::all_visible{});  // two-sided, as the GL by default
    radiosity_solve_options o;
    o.converge = 0.8;
    o.checkpoints = 2;
    int checkpoints = 0;
    o.checkpoint = [&](const radiosity_progress&) { ++checkpoints; };
    const auto rg = g.solve(o);
    const auto rc = c.solve(o);
    CHECK(rg.stop == radiosity_stop::converged);
    CHECK(rg.steps == rc.steps);
    CHECK(rg.unshot_fraction == Approx(rc.unshot_fraction).epsilon(1e-4));
    CHECK(checkpoints >= 2 * 2);  // each solve: after the first step, then at 0.4 and 0.8
    CHECK(g.intercepted_power().x == Approx(c.intercepted_power().x).epsilon(1e-4));
    // Converging on the power surfaces reflect: the same steps again, the same measure.
    o.measure = radiosity_measure::indirect;
    const auto ig = g.solve(o);
    const auto ic = c.solve(o);
    CHECK(ig.steps == ic.steps);
    CHECK(ig.indirect_unshot_fraction <= 0.2);
    CHECK(ig.indirect_unshot_fraction == Approx(ic.indirect_unshot_fraction).epsilon(1e-4));
}

TEST_CASE("the GL solver names reversed winding one-sided and refuses a tolerance below the floor", "[radiosity][solve][gl][errors]") {
    gl_test::shared_context();
    owned_scene box = closed_box(1.f, 0.7f, 2.f);
    for (glm::uvec3& t : box.triangles) std::swap(t.y, t.z);
    const auto atlas = build_lightmap_atlas(box.view(), {.elements = 300, .block_texels = 4});
    gl::progressive_radiosity g(box.view(), atlas, {.shooting = {.two_sided = false}, .resolution = 64});
    CHECK_THROWS_AS(g.solve(0.1), radiosity_error);
    // Two-sided (the default), the same box solves: its walls take the lamp's light on their backs.
    gl::progressive_radiosity two(box.view(), atlas, {.resolution = 64});
    radiosity_solve_options to_90;
    to_90.converge = 0.9;
    CHECK(two.solve(to_90).stop == radiosity_stop::converged);
    CHECK(two.intercepted_power().x > 0);
    const auto good = cornell_box();
    const auto good_atlas = build_lightmap_atlas(good.view(), {.elements = 300, .block_texels = 4});
    CHECK_THROWS_WITH(gl::progressive_radiosity(good.view(), good_atlas, {.resolution = 64, .tolerance_px = 1e-6f}),
                      Catch::Contains("radiosity_options.tolerance_px") && Catch::Contains("0.003906"));
}

TEST_CASE("the GL solver takes clusters of tiny charts: energy never grows, every triangle lit, as on the CPU",
          "[radiosity][solve][gl][clusters]") {
    gl_test::shared_context();
    const auto s = tiny_triangles_under_a_lamp();
    const auto atlas = build_lightmap_atlas(s.view(), {.elements = 300});
    REQUIRE(atlas.statistics.clusters > 0);
    gl::progressive_radiosity g(s.view(), atlas, {.resolution = 128});
    cpu::progressive_radiosity c(s.view(), atlas, cpu::item_buffer_visibility(s.view(), atlas, {.resolution = 128}));
    radiosity_solve_options o;
    o.converge = 0.95;
    double unshot = 1;
    o.progress = unshot_never_rises(unshot, 1e-5);
    CHECK(g.solve(o).stop == radiosity_stop::converged);
    unshot = 1;
    CHECK(c.solve(o).stop == radiosity_stop::converged);
    const auto bg = g.display_radiosity(), bc = c.display_radiosity();
    CHECK(unlit_triangles(s, atlas, bg, 2) == 0);  // after the lamp's two
    double sum_g = 0, sum_c = 0;
    for (std::size_t e = 0; e < atlas.size(); ++e) {
        sum_g += double(bg[e].x + bg[e].y + bg[e].z) * atlas.area[e];
        sum_c += double(bc[e].x + bc[e].y + bc[e].z) * atlas.area[e];
    }
    CHECK(sum_g == Approx(sum_c).epsilon(0.02));  // the same radiant exitance within 2%
}
