// Re-baking what changed on the GL solver (gl::progressive_radiosity::rebake_light and
// rebake_move): the correction is the CPU solver's (cpu::rebake_light, cpu::rebake_move) on
// the same state, and a re-baked solve converges to a fresh GL solve of the changed scene.
// llvmpipe via EGL, small sizes.
#include "../gl/shared_context.hpp"
#include "rebake_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/cpu/radiosity_rebake.hpp>
#include <bounce/gl/radiosity.hpp>

#include <catch2/catch.hpp>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

radiosity_solve_options to(double converge) {
    radiosity_solve_options o;
    o.converge = converge;
    o.measure = radiosity_measure::emitted;
    return o;
}

// The power sums of both solvers agree (relative to the emitted power).
void check_balances(const gl::progressive_radiosity& g, const cpu::progressive_radiosity<cpu::all_visible>& c) {
    const double e = c.emitted_power().x;
    CHECK(g.emitted_power().x == Approx(e).epsilon(1e-5));
    CHECK(g.intercepted_power().x == Approx(c.intercepted_power().x).epsilon(1e-4));
    CHECK(std::abs(g.escaped_power().x - c.escaped_power().x) <= 1e-4 * e);
    CHECK(std::abs(g.absorbed_power().x - c.absorbed_power().x) <= 1e-4 * e);
    CHECK(g.unshot_fraction() == Approx(c.unshot_fraction()).epsilon(1e-3));
}

// The unshot radiosity of two solvers, as relative_l1 compares radiosity.
template <class A, class B>
double unshot_l1(const A& a, const B& b, double scale) {
    double diff = 0;
    for (int side = 0; side < a.sides(); ++side) {
        const auto ua = a.unshot(side), ub = b.unshot(side);
        for (std::size_t i = 0; i < ua.size(); ++i) {
            const glm::dvec3 d = glm::abs(glm::dvec3(ua[i]) - glm::dvec3(ub[i]));
            diff += (d.x + d.y + d.z) * a.atlas().area[i];
        }
    }
    return diff / scale;
}

double radiosity_total(const gl::progressive_radiosity& s) {
    double total = 0;
    for (int side = 0; side < s.sides(); ++side)
        for (const auto& b : s.radiosity(side)) total += (b.x + b.y + b.z);
    return total;
}

}  // namespace

TEST_CASE("the GL re-bake's correction is the CPU solver's on the same state", "[radiosity][rebake][gl]") {
    // Without occlusion both solvers shoot the same shots in the same order, so their states
    // agree before and after each correction (to float rounding of the GPU's sums).
    gl_test::shared_context();
    const owned_scene s = box_with_block();
    const auto atlas = build_lightmap_atlas(s.view(), {.elements = 300, .block_texels = 4});
    gl::progressive_radiosity g(s.view(), atlas, {.visibility = gl::radiosity_visibility::none});
    cpu::progressive_radiosity c(s.view(), atlas, cpu::all_visible{});
    REQUIRE(g.solve(to(0.9)).steps == c.solve(to(0.9)).steps);
    const double scale = radiosity_total(g);

    owned_scene dimmed = s;
    dimmed.lights[0] = point_light{glm::vec3(1.3f, 1.5f, 1.2f), glm::vec3(0.5f)};
    const auto rg = g.rebake_light(0, dimmed.lights[0]);
    const auto rc = cpu::rebake_light(c, 0, dimmed.lights[0]);
    CHECK(rg.unshot_after == Approx(rc.unshot_after).epsilon(1e-3));
    CHECK(negative_unshot(g) < 0);
    CHECK(relative_l1(g, c) <= 1e-4);
    CHECK(unshot_l1(g, c, scale) <= 1e-4);
    check_balances(g, c);

    rigid_move move;
    move.translation = {0.5f, 0.f, 0.3f};
    const owned_scene moved = moved_scene(dimmed, block_triangles(), move);
    const auto mg = g.rebake_move(moved.view(), block_triangles(), move);
    const auto mc = cpu::rebake_move(c, moved.view(), block_triangles(), move, cpu::all_visible{});
    CHECK(mg.moved_elements == mc.moved_elements);
    CHECK(mg.moved_shooters == mc.moved_shooters);
    CHECK(mg.shooters == mc.shooters);
    CHECK(g.atlas().position == c.atlas().position);
    CHECK(relative_l1(g, c) <= 1e-4);
    CHECK(unshot_l1(g, c, scale) <= 1e-4);
    check_balances(g, c);
    // Solved on: the same answer.
    g.solve(to(0.99));
    c.solve(to(0.99));
    CHECK(relative_l1(g, c) <= 1e-3);
}

TEST_CASE("a GL re-bake converges to the fresh GL solve of the changed scene", "[radiosity][rebake][gl]") {
    gl_test::shared_context();
    const owned_scene s = box_with_block();
    const auto atlas = build_lightmap_atlas(s.view(), {.elements = 300, .block_texels = 4});
    const gl::radiosity_options o{.resolution = 64};
    rigid_move move;
    move.translation = {0.5f, 0.f, 0.3f};
    const owned_scene moved = moved_scene(s, block_triangles(), move);
    lightmap_atlas moved_atlas = atlas;
    move_charts(moved_atlas, moved_charts(atlas, block_triangles()), move);

    SECTION("a light turned off") {
        owned_scene changed = s;
        changed.lights[0] = point_light{glm::vec3(1.3f, 1.5f, 1.2f), glm::vec3(0.f)};
        gl::progressive_radiosity rebaked(s.view(), atlas, o);
        rebaked.solve(to(0.99));
        const auto lit = rebaked.output(output_quantity::irradiance, light_paths::direct);
        rebaked.rebake_light(0, changed.lights[0]);
        CHECK(negative_unshot(rebaked) < 0);
        rebaked.solve(to(0.999));
        gl::progressive_radiosity fresh(changed.view(), atlas, o);
        fresh.solve(to(0.999));
        const double bound = convergence_bound(rebaked, fresh);
        CAPTURE(bound);
        CHECK(relative_l1(rebaked, fresh) <= 2 * bound);
        CHECK(rebaked.emitted_power().x == Approx(fresh.emitted_power().x).epsilon(1e-4));
        // The direct part follows the light: the output's direct irradiance is the fresh solve's
        // (none: the point light was the only light), to float rounding of what it was.
        const auto d0 = rebaked.output(output_quantity::irradiance, light_paths::direct);
        const auto d1 = fresh.output(output_quantity::irradiance, light_paths::direct);
        double diff = 0, was = 0;
        for (std::size_t i = 0; i < d0.size(); ++i) diff += std::abs(d0[i].x - d1[i].x), was += lit[i].x;
        CHECK(diff <= 1e-5 * was);
    }
    SECTION("the block moved, stereographic item buffers or hemicubes") {
        const auto visibility = GENERATE(gl::radiosity_visibility::stereographic, gl::radiosity_visibility::hemicube);
        CAPTURE(int(visibility));
        const gl::radiosity_options o{.visibility = visibility, .resolution = 64};
        gl::progressive_radiosity rebaked(s.view(), atlas, o);
        rebaked.solve(to(0.99));
        const auto r = rebaked.rebake_move(moved.view(), block_triangles(), move);
        CHECK(r.moved_elements > 0);
        CHECK(r.pairs < r.pairs_tested);  // pairs whose segments miss both boxes are left as they are
        CHECK(negative_unshot(rebaked) < 0);
        rebaked.solve(to(0.999));
        gl::progressive_radiosity fresh(moved.view(), moved_atlas, o);
        fresh.solve(to(0.999));
        gl::progressive_radiosity stale(s.view(), atlas, o);
        stale.solve(to(0.999));
        const double error = relative_l1(rebaked, fresh), bound = convergence_bound(rebaked, fresh);
        const double unmoved = relative_l1(stale, fresh);
        CAPTURE(error, bound, unmoved);
        CHECK(error <= 2 * bound);
        CHECK(unmoved > 5 * error);
    }
}

TEST_CASE("after a dimming GL re-bake the ambient is shown at most down to no indirect light, as on the CPU",
          "[radiosity][rebake][gl][ambient]") {
    // The light turned off: Cohen's term of the negative unshot power is negative, and both
    // solvers show it clamped where it would take away more than the shots delivered. Without
    // occlusion their states are the same, so what they show is too; the GPU's lightmap pass
    // shows what the read-back path does.
    gl_test::shared_context();
    const owned_scene s = box_with_block();
    const auto atlas = build_lightmap_atlas(s.view(), {.elements = 300, .block_texels = 4});
    gl::progressive_radiosity g(s.view(), atlas, {.visibility = gl::radiosity_visibility::none});
    cpu::progressive_radiosity c(s.view(), atlas, cpu::all_visible{});
    REQUIRE(g.solve(to(0.99)).steps == c.solve(to(0.99)).steps);
    const light off = point_light{glm::vec3(1.3f, 1.5f, 1.2f), glm::vec3(0.f)};
    g.rebake_light(0, off);
    cpu::rebake_light(c, 0, off);
    REQUIRE(c.ambient().x < 0);
    std::size_t clamped = 0;
    for (int side = 0; side < 2; ++side) {
        const auto shown_g = g.display_radiosity(side), shown_c = c.display_radiosity(side);
        const auto indirect = g.output(output_quantity::irradiance, light_paths::indirect, side);
        const auto b = g.radiosity(side);
        double largest = 0;
        for (const auto& v : shown_c) largest = std::max(largest, double(v.x));
        for (std::size_t i = 0; i < shown_g.size(); ++i) {
            CHECK(std::abs(shown_g[i].x - shown_c[i].x) <= 1e-4 * largest);
            CHECK(indirect[i].x >= 0.f);
            clamped += shown_g[i].x > b[i].x + float(atlas.albedo[i].x * g.ambient().x) + 1e-6f ? 1 : 0;
        }
        const auto expected = g.radiosity_lightmap(0, side);
        const auto got = g.update_lightmap_texture(side).read_floats();
        double worst = 0;
        for (std::uint32_t y = 0; y < atlas.height; ++y)
            for (std::uint32_t x = 0; x < atlas.width; ++x)
                if (atlas.element_at(x, y) >= 0)
                    worst = std::max(worst, double(std::abs(got[4 * (std::size_t(y) * atlas.width + x)] - expected(x, y).x)));
        CHECK(worst <= 1e-5 * largest);
    }
    CHECK(clamped > 0);
}

TEST_CASE("a GL re-bake's bad input is refused by name", "[radiosity][rebake][gl][errors]") {
    gl_test::shared_context();
    const owned_scene s = box_with_block();
    const auto atlas = build_lightmap_atlas(s.view(), {.elements = 300, .block_texels = 4});
    gl::progressive_radiosity g(s.view(), atlas, {.resolution = 64});
    CHECK_THROWS_WITH(g.rebake_light(1, s.lights[0]), Catch::Contains("index"));
    CHECK_THROWS_WITH(g.rebake_light(0, point_light{glm::vec3(0.f), glm::vec3(-1.f)}), Catch::Contains("changed"));
    const std::vector<std::uint32_t> half{0};  // a wall's triangle without its other half
    CHECK_THROWS_WITH(g.rebake_move(s.view(), half, rigid_move{}), Catch::Contains("moved_triangles"));
    CHECK_THROWS_WITH(g.rebake_move(s.view(), block_triangles(), rigid_move{}, 0.0), Catch::Contains("share"));
    rigid_move bad;
    bad.rotation[0][0] = 2;
    CHECK_THROWS_WITH(g.rebake_move(s.view(), block_triangles(), bad), Catch::Contains("rigid_move.rotation"));
    owned_scene fewer = s;
    fewer.triangles.pop_back(), fewer.material_of.pop_back();
    CHECK_THROWS_WITH(g.rebake_move(fewer.view(), block_triangles(), rigid_move{}), Catch::Contains("moved_scene"));
    // Refused before any change: the solver still solves.
    CHECK(g.solve(to(0.5)).stop == radiosity_stop::converged);
}
