// Re-baking what changed (cpu/radiosity_rebake.hpp, radiosity/rebake.hpp): after a light
// changes or a block moves in a closed box, the solver corrected from its previous solution
// converges to what a fresh solve of the changed scene converges to; negative unshot power is
// shot; the energy check counts the unshot power in magnitude and still fires.
#include "rebake_scenes.hpp"
#include "ray_cast_visibility.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/cpu/radiosity_rebake.hpp>
#include <bounce/radiosity/rebake.hpp>

#include <catch2/catch.hpp>
#include <glm/vector_relational.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

using solver_type = cpu::progressive_radiosity<ray_cast_visibility>;

radiosity_solve_options to(double converge) {
    radiosity_solve_options o;
    o.converge = converge;
    o.measure = radiosity_measure::emitted;
    return o;
}

// A solver whose unshot fraction (in magnitude) follows a script from `start`.
struct scripted_solver {
    double start;
    std::vector<double> fractions;
    std::size_t steps = 0;
    bool step() { return steps < fractions.size() ? (++steps, true) : false; }
    double unshot_fraction() const { return steps == 0 ? start : fractions[steps - 1]; }
    radiosity_progress progress() const { return {steps, steps, unshot_fraction(), 0.0}; }
    glm::dvec3 emitted_power() const { return glm::dvec3(1, 0, 0); }
    glm::dvec3 unshot_power() const { return glm::dvec3(unshot_fraction(), 0, 0); }
    glm::dvec3 intercepted_power() const { return glm::dvec3(1, 0, 0); }
};

}  // namespace

TEST_CASE("a re-bake after a light change converges to the fresh solve of the changed scene", "[radiosity][rebake]") {
    const owned_scene s = box_with_block();
    const lightmap_atlas atlas = build_lightmap_atlas(s.view(), {.elements = 600});
    for (const float scale : {0.25f, 0.f, 3.f}) {
        CAPTURE(scale);
        owned_scene changed = s;
        changed.lights[0] = point_light{glm::vec3(1.3f, 1.5f, 1.2f), glm::vec3(2.f * scale)};
        solver_type rebaked(s.view(), atlas, ray_cast_visibility{&s, &atlas});
        rebaked.solve(to(0.99));
        const std::size_t shots_before = rebaked.progress().shots;
        const auto r = cpu::rebake_light(rebaked, 0, changed.lights[0]);
        CHECK(r.unshot_after != r.unshot_before);
        // Dimmed, the lit elements hold negative unshot power, which the solve shoots away.
        if (scale < 1) CHECK(negative_unshot(rebaked) < 0);
        rebaked.solve(to(0.999));
        CHECK(rebaked.progress().shots > shots_before);
        CHECK(rebaked.unshot_fraction() <= 1e-3);
        solver_type fresh(changed.view(), atlas, ray_cast_visibility{&changed, &atlas});
        fresh.solve(to(0.999));
        const double bound = convergence_bound(rebaked, fresh);
        CAPTURE(bound);
        CHECK(relative_l1(rebaked, fresh) <= 2 * bound);
        CHECK(rebaked.emitted_power().x == Approx(fresh.emitted_power().x).epsilon(1e-5));
    }
}

namespace {

struct move_result {
    radiosity_rebake_report report;
    double error, bound, stale;  // relative_l1 from the fresh solve: the re-bake's, and the unmoved solution's
};

// How rebake_move tests an unmoved pair: its ray against the boxes only; against the object
// alone too (the brute-force caster with every other triangle left without a chart, the
// object where it was and where it is); or, wrong on purpose, against the object where it was
// both times (every unmoved pair skipped: what a correction that missed changed pairs does).
enum class pair_test { boxes, object, blind };

// The scene `s` with triangles `tris` moved by (0.5, 0, 0.3), and its atlas.
struct moved_box {
    rigid_move move;
    owned_scene scene;
    lightmap_atlas atlas;     // the bake's atlas moved
    lightmap_atlas object;    // the bake's atlas, charts only on `tris`
    moved_box(const owned_scene& s, const lightmap_atlas& at, const std::vector<std::uint32_t>& tris)
        : move(rigid_move{glm::mat3(1.f), glm::vec3(0.5f, 0.f, 0.3f)}), scene(moved_scene(s, tris, move)), atlas(at), object(at) {
        move_charts(atlas, moved_charts(at, tris), move);
        std::vector<std::uint8_t> keep(at.chart_of_triangle.size(), 0);
        for (const std::uint32_t t : tris) keep[t] = 1;
        for (std::size_t t = 0; t < keep.size(); ++t)
            if (!keep[t]) object.chart_of_triangle[t] = lightmap_atlas::none;
    }
};

struct object_rays {
    ray_cast_visibility before, after;
};

radiosity_rebake_report rebake(solver_type& solver, const owned_scene& s, const moved_box& m, const std::vector<std::uint32_t>& tris,
                               pair_test test, double share = 1) {
    const ray_cast_visibility after{&m.scene, &m.atlas};
    if (test == pair_test::boxes) return cpu::rebake_move(solver, m.scene.view(), tris, m.move, after, share);
    const object_rays object{{&s, &m.object}, {test == pair_test::object ? &m.scene : &s, &m.object}};
    return cpu::rebake_move(solver, m.scene.view(), tris, m.move, after, object, share);
}

// Bakes `s` to 99%, moves its triangles `tris` (moved_box), re-bakes (rebake_move with `share`) and solves to 99.9%, and compares
// the result with a fresh solve of the moved scene on the same elements; `bound`: what their
// unshot power allows (convergence_bound).
move_result move_block(const owned_scene& s, const std::vector<std::uint32_t>& tris, double share = 1,
                       pair_test test = pair_test::boxes) {
    const lightmap_atlas atlas = build_lightmap_atlas(s.view(), {.elements = 600});
    // The fresh solve on the same elements moved (the atlas of the moved scene may differ by rounding).
    const moved_box m(s, atlas, tris);
    solver_type rebaked(s.view(), atlas, ray_cast_visibility{&s, &atlas});
    rebaked.solve(to(0.99));
    const auto r = rebake(rebaked, s, m, tris, test, share);
    CHECK(r.moved_elements > 0);
    CHECK(r.shooters > 0);
    // Pairs whose rays miss the block's two boxes were skipped.
    CHECK(r.pairs < r.pairs_tested);
    CHECK(negative_unshot(rebaked) < 0);  // the block's old shadow's light taken back and its old place's light
    rebaked.solve(to(0.999));
    CHECK(rebaked.atlas().position == m.atlas.position);

    solver_type fresh(m.scene.view(), m.atlas, ray_cast_visibility{&m.scene, &m.atlas});
    fresh.solve(to(0.999));
    const double bound = convergence_bound(rebaked, fresh);
    // Without the correction (the moved state solved on), the error is the block's move itself.
    solver_type stale(s.view(), atlas, ray_cast_visibility{&s, &atlas});
    stale.solve(to(0.999));
    return {r, relative_l1(rebaked, fresh), bound, relative_l1(stale, fresh)};
}

// The re-bake re-shoots what the past shots delivered (their scales applied: the closed box's
// corners scale many), so it agrees with the fresh solve within what their unshot power allows.
void check_move(const owned_scene& s, const std::vector<std::uint32_t>& tris, pair_test test = pair_test::boxes) {
    const move_result m = move_block(s, tris, 1, test);
    CAPTURE(m.error, m.bound, m.stale);
    CHECK(m.report.uncorrected == 0);
    CHECK(m.error <= 2 * m.bound);
    CHECK(m.stale > 5 * m.error);
}

}  // namespace

TEST_CASE("a re-bake after moving the block converges to the fresh solve of the moved scene", "[radiosity][rebake]") {
    check_move(box_with_block(), block_triangles());
}

TEST_CASE("a re-bake that tests pairs against the object alone corrects as the boxes do, from fewer pairs", "[radiosity][rebake]") {
    // Between unmoved elements only the rays the object blocks in exactly one of its places
    // change; the rest are skipped, and the corrected state is the box filter's (to rounding).
    const owned_scene s = box_with_block();
    const auto tris = block_triangles();
    const lightmap_atlas atlas = build_lightmap_atlas(s.view(), {.elements = 600});
    const moved_box m(s, atlas, tris);
    std::vector<std::vector<glm::vec3>> state;
    std::vector<radiosity_rebake_report> report;
    for (const pair_test test : {pair_test::boxes, pair_test::object, pair_test::blind}) {
        solver_type solver(s.view(), atlas, ray_cast_visibility{&s, &atlas});
        solver.solve(to(0.99));
        report.push_back(rebake(solver, s, m, tris, test));
        state.emplace_back();
        for (int side = 0; side < solver.sides(); ++side)
            for (const auto& b : solver.radiosity(side)) state.back().push_back(b);
    }
    // |difference| over |state| (area ignored: the same elements), from the box filter's.
    const auto apart = [&](std::size_t k) {
        double d = 0, t = 0;
        for (std::size_t j = 0; j < state[0].size(); ++j)
            for (int c = 0; c < 3; ++c) d += std::abs(double(state[k][j][c]) - state[0][j][c]), t += std::abs(state[0][j][c]);
        return d / t;
    };
    CAPTURE(report[0].pairs, report[1].pairs, report[1].object_tests, report[2].pairs, apart(1), apart(2));
    CHECK(report[0].object_tests == 0);
    CHECK(report[1].object_tests > 0);
    CHECK(report[1].pairs < report[0].pairs);
    CHECK(apart(1) <= 1e-5);
    // Skipping the changed pairs too leaves the block's old shadow and its new one as they were.
    CHECK(report[2].pairs < report[1].pairs);
    CHECK(apart(2) > 1e3 * std::max(apart(1), 1e-7));
    check_move(s, tris, pair_test::object);
}

TEST_CASE("a re-bake converges with faces repeated, whose shots are scaled hard", "[radiosity][rebake]") {
    // The OBJ Cornell box's tallBox repeats its front face (its "bottom face" indexes the front
    // face's vertices): coincident charts, so every shooter that sees the face delivers to it
    // twice, its deliveries sum above its power and it is scaled (shot_scale). On the moved
    // block (its top, facing the lamp, repeated: triangles 24-25), and on the floor (two more
    // copies, unmoved: the lamp's and most shots are scaled, and re-shot in the correction).
    owned_scene s = box_with_block();
    const glm::vec3 lo(0.5f, 0.f, 0.5f), hi(0.9f, 0.4f, 0.9f);
    s.add_quad({lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}, s.material_of.back());
    auto tris = block_triangles();
    tris.push_back(24), tris.push_back(25);
    check_move(s, tris);
    for (int copy = 0; copy < 2; ++copy) s.add_quad({0, 0, 0}, {0, 0, 2}, {2, 0, 2}, {2, 0, 0}, s.material_of[0]);
    check_move(s, tris);
}

TEST_CASE("a re-bake that re-shoots only the largest shooters leaves out at most what the rest would correct", "[radiosity][rebake]") {
    const move_result exact = move_block(box_with_block(), block_triangles());
    const move_result part = move_block(box_with_block(), block_triangles(), 0.9);
    CAPTURE(exact.error, part.error, part.report.uncorrected, part.report.pairs, exact.report.pairs);
    CHECK(part.report.uncorrected > 0);
    CHECK(part.report.uncorrected <= 0.1);
    CHECK(part.report.pairs < exact.report.pairs);
    // What the left-out shooters would have corrected is at most their share of the shot power.
    CHECK(part.error <= 2 * part.bound + part.report.uncorrected);
    CHECK(part.error < part.stale);
}

TEST_CASE("after a dimming re-bake the negative ambient is shown at most down to no indirect light", "[radiosity][rebake][ambient]") {
    // The ambient term estimates the light still to come, which after a dimming is negative;
    // the converged indirect irradiance is not. Clamping what is shown (gathered + ambient) at
    // 0 projects the estimate onto a set that holds the converged answer, so no element moves
    // away from it, and the display never goes negative.
    const owned_scene s = box_with_block();
    const lightmap_atlas atlas = build_lightmap_atlas(s.view(), {.elements = 600});
    owned_scene changed = s;
    changed.lights[0] = point_light{glm::vec3(1.3f, 1.5f, 1.2f), glm::vec3(0.f)};
    solver_type rebaked(s.view(), atlas, ray_cast_visibility{&s, &atlas});
    rebaked.solve(to(0.99));
    cpu::rebake_light(rebaked, 0, changed.lights[0]);
    const glm::dvec3 ambient = rebaked.ambient();
    REQUIRE(ambient.x < 0);  // Cohen's term from the negative unshot power
    solver_type fresh(changed.view(), atlas, ray_cast_visibility{&changed, &atlas});
    fresh.solve(to(0.999));
    std::size_t clamped = 0;
    double closer = 0;  // summed over elements: how much nearer the converged answer the clamp shows
    for (int side = 0; side < rebaked.sides(); ++side) {
        const auto shown = rebaked.display_radiosity(side);
        const auto indirect = rebaked.output(output_quantity::irradiance, light_paths::indirect, side);
        const auto b = rebaked.radiosity(side), answer = fresh.radiosity(side);
        for (std::size_t i = 0; i < shown.size(); ++i) {
            CHECK(glm::all(glm::greaterThanEqual(indirect[i], glm::vec3(0.f))));
            const glm::dvec3 unclamped = glm::dvec3(b[i]) + glm::dvec3(atlas.albedo[i]) * ambient;
            for (int c = 0; c < 3; ++c) {
                CHECK(shown[i][c] >= -1e-4f * std::abs(b[i][c]));
                const double before = std::abs(unclamped[c] - answer[i][c]), after = std::abs(shown[i][c] - answer[i][c]);
                CHECK(after <= before + 1e-3 * std::abs(answer[i][c]) + 1e-6);
                if (shown[i][c] > unclamped[c] + 1e-6) ++clamped, closer += before - after;
            }
        }
    }
    CHECK(clamped > 0);
    CHECK(closer > 0);
}

TEST_CASE("a re-bake's bad input is refused by name", "[radiosity][rebake][errors]") {
    const owned_scene s = box_with_block();
    const lightmap_atlas atlas = build_lightmap_atlas(s.view(), {.elements = 300});
    solver_type solver(s.view(), atlas, ray_cast_visibility{&s, &atlas});
    CHECK_THROWS_WITH(cpu::rebake_light(solver, 1, s.lights[0]), Catch::Contains("index"));
    CHECK_THROWS_WITH(cpu::rebake_light(solver, 0, point_light{glm::vec3(0.f), glm::vec3(-1.f)}), Catch::Contains("changed"));
    rigid_move m;
    // A wall's triangle without its other half: the chart would tear.
    const std::vector<std::uint32_t> half{0};
    CHECK_THROWS_WITH(cpu::rebake_move(solver, s.view(), half, m, ray_cast_visibility{&s, &atlas}),
                      Catch::Contains("moved_triangles"));
    CHECK_THROWS_WITH(cpu::rebake_move(solver, s.view(), block_triangles(), m, ray_cast_visibility{&s, &atlas}, 0.0),
                      Catch::Contains("share"));
    m.rotation[0][0] = 2;
    CHECK_THROWS_WITH(cpu::rebake_move(solver, s.view(), block_triangles(), m, ray_cast_visibility{&s, &atlas}),
                      Catch::Contains("rigid_move.rotation"));
}

TEST_CASE("the energy check counts the unshot power in magnitude: a re-bake may start above the emitted power, never rise",
          "[radiosity][rebake][errors]") {
    const auto run = [](scripted_solver& s) { return detail::run_radiosity_solve(s, {}, [](std::size_t) { return std::size_t(0); }); };
    // A dimmed light leaves more unshot power (in magnitude) than the scene now emits; it falls.
    scripted_solver falling{2.5, {2.0, 1.1, 0.6, 0.05}};
    CHECK_NOTHROW(run(falling));
    // A rise from there is energy created, named.
    scripted_solver rising{2.5, {2.0, 2.2}};
    CHECK_THROWS_WITH(run(rising), Catch::Contains("step 2") && Catch::Contains("rose from 2 to 2.2"));
    // Above where the solve began: also refused, even without a rise between the sums checked.
    scripted_solver above{0.5, {0.6}};
    CHECK_THROWS_AS(run(above), radiosity_error);
}
