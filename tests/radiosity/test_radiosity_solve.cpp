// The solve of radiosity/solve.hpp (what cpu::progressive_radiosity::solve and the GL
// solver's run): where it stops, its checkpoints and paused clock, its time limit; and what
// it refuses to do silently: create energy, or give a black answer for a scene whose
// surfaces face away from its lights (reversed winding). Also the tolerance floor of the
// stereographic item buffer.
#include "radiosity_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/radiosity/solve.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <thread>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

// `s` with every triangle's winding reversed (each surface's front becomes its back).
owned_scene reversed(owned_scene s) {
    for (glm::uvec3& t : s.triangles) std::swap(t.y, t.z);
    return s;
}

// closed_box with its emitting quad replaced by a point light at the box's centre.
owned_scene box_with_point_light() {
    owned_scene s = closed_box(1.f, 0.7f, 0.f);
    s.triangles.resize(s.triangles.size() - 2);  // the lamp quad
    s.material_of.resize(s.material_of.size() - 2);
    s.lights.push_back(point_light{{0.5f, 0.5f, 0.5f}, {1.f, 1.f, 1.f}});
    return s;
}

// A solver whose unshot fraction follows a script, for the loop's own checks.
struct scripted_solver {
    std::vector<double> fractions;  // after each step
    std::size_t steps = 0;
    double emitted = 1, intercepted = 1;
    bool step() {
        if (steps >= fractions.size()) return false;
        ++steps;
        return true;
    }
    double unshot_fraction() const { return steps == 0 ? 1.0 : fractions[steps - 1]; }
    radiosity_progress progress() const { return {steps, steps, unshot_fraction(), 0.0}; }
    glm::dvec3 emitted_power() const { return glm::dvec3(emitted, 0, 0); }
    glm::dvec3 unshot_power() const { return glm::dvec3(emitted * unshot_fraction(), 0, 0); }
    glm::dvec3 intercepted_power() const { return glm::dvec3(intercepted, 0, 0); }
};

radiosity_solve_report run(scripted_solver& s, const radiosity_solve_options& o) {
    return detail::run_radiosity_solve(s, o, [](std::size_t) { return std::size_t(0); });
}

}  // namespace

TEST_CASE("a solve stops where asked and says why", "[radiosity][solve]") {
    scripted_solver s{{0.8, 0.5, 0.3, 0.2, 0.05, 0.01}};
    radiosity_solve_options o;
    o.converge = 0.7;
    auto r = run(s, o);
    CHECK(r.stop == radiosity_stop::converged);
    CHECK(r.steps == 3);
    CHECK(r.converged == std::vector<double>{1 - 0.8, 1 - 0.5, 1 - 0.3});
    CHECK(r.step_ms.size() == 3);
    CHECK(r.unshot_fraction == 0.3);
    // Nothing left to shoot before the target.
    o.converge = 1;
    r = run(s, o);
    CHECK(r.stop == radiosity_stop::exhausted);
    CHECK(r.steps == 3);
    // A progress callback that says stop.
    scripted_solver t{{0.8, 0.5, 0.3}};
    o.progress = [](const radiosity_progress& p) { return p.steps < 2; };
    r = run(t, o);
    CHECK(r.stop == radiosity_stop::callback);
    CHECK(r.steps == 2);
    CHECK(to_string(r.stop) == std::string("callback"));
}

TEST_CASE("checkpoints fall at fractions of the target, and their time is not the solve's", "[radiosity][solve]") {
    std::vector<double> f;
    for (int k = 1; k <= 64; ++k) f.push_back(1.0 - k / 64.0);  // converged 1/64 .. 1, exactly
    scripted_solver s{f};
    radiosity_solve_options o;
    o.converge = 0.75;
    o.checkpoints = 4;
    std::vector<radiosity_progress> seen;
    o.checkpoint = [&](const radiosity_progress& p) {
        seen.push_back(p);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    };
    const auto r = run(s, o);
    CHECK(r.stop == radiosity_stop::converged);
    CHECK(r.steps == 48);
    // After the first step, then at converged 12/64, 24/64, 36/64, 48/64 (k / 4 of 0.75; the
    // last is also the end).
    std::vector<std::size_t> steps;
    for (const auto& p : seen) steps.push_back(p.steps);
    CHECK(steps == std::vector<std::size_t>{1, 12, 24, 36, 48});
    CHECK(r.checkpoint_ms >= 5 * 20 * 0.9);
    CHECK(r.solve_ms < 50);  // the 100 ms of sleeping is not solving
    for (std::size_t k = 1; k < seen.size(); ++k) CHECK(seen[k].elapsed_ms >= seen[k - 1].elapsed_ms);
}

TEST_CASE("a solve stops at its time limit, checkpoints not counted", "[radiosity][solve]") {
    struct slow : scripted_solver {
        bool step() {
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
            return scripted_solver::step();
        }
    };
    slow s;
    for (int k = 1; k <= 1000; ++k) s.fractions.push_back(1.0 - k / 2048.0);  // 1/2048 more per step
    radiosity_solve_options o;
    o.max_seconds = 0.05;
    o.converge = 0.5;
    o.checkpoints = 1024;  // one mark per 1/2048 converged: a checkpoint after every step
    o.checkpoint = [](const radiosity_progress&) { std::this_thread::sleep_for(std::chrono::milliseconds(10)); };
    const auto r = detail::run_radiosity_solve(s, o, [](std::size_t) { return std::size_t(0); });
    CHECK(r.stop == radiosity_stop::time_limit);
    CHECK(r.steps >= 2);
    // The limit counted only the steps: the steps' own time reached it although every step
    // had its 10 ms checkpoint (had the checkpoints counted, the solve would have stopped with
    // its steps' time below the limit). Not compared with the steps' time: on a loaded machine
    // a 2 ms sleep can last as long as a 10 ms one.
    CHECK(r.solve_ms >= 50);
    CHECK(r.checkpoint_ms >= 10.0 * double(r.steps));
}

TEST_CASE("a solve that creates energy is stopped with the step named", "[radiosity][solve][errors]") {
    // The unshot power may only fall: the first rise (step 2, 0.8 -> 0.9 of the emitted
    // power) stops it, long before it passes the emitted power (step 3).
    const scripted_solver gains{{0.8, 0.9, 1.5, 3.0}};
    scripted_solver s = gains, t = gains;
    CHECK_THROWS_AS(run(s, {}), radiosity_error);
    CHECK_THROWS_WITH(run(t, {}), Catch::Contains("step 2") && Catch::Contains("rose from 0.8 to 0.9"));
    // A rise within float rounding of the sums (2^-20 of them) is not one.
    scripted_solver rounding{{0.8, 0.8 * (1 + 1e-7), 0.5}};
    CHECK_NOTHROW(run(rounding, {}));
    scripted_solver n{{0.8, std::nan("")}};
    CHECK_THROWS_AS(run(n, {}), radiosity_error);
    radiosity_solve_options bad;
    bad.converge = std::nan("");
    scripted_solver u{{0.5}};
    CHECK_THROWS_AS(run(u, bad), parameter_error);
    CHECK_THROWS_WITH(run(u, bad), Catch::Contains("radiosity_solve_options.converge"));
}

TEST_CASE("the CPU solver's solve gives what step() by step gives, with the report", "[radiosity][solve]") {
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 600});
    cpu::progressive_radiosity a(scene.view(), atlas, cpu::all_visible{}), b(scene.view(), atlas, cpu::all_visible{});
    radiosity_solve_options o;
    o.converge = 0.8;
    const auto r = a.solve(o);
    while (b.unshot_fraction() > 0.2 && b.step()) {
    }
    CHECK(r.steps == b.progress().steps);
    CHECK(r.unshot_fraction == b.unshot_fraction());
    CHECK(std::equal(a.radiosity().begin(), a.radiosity().end(), b.radiosity().begin()));
    // With adaptive subdivision after the first steps: splits counted, the atlas refined.
    cpu::progressive_radiosity c(scene.view(), atlas, cpu::all_visible{});
    const auto rc = c.solve(o, scene.view(), subdivision_options{.threshold = 0.1}, 10);
    CHECK(rc.splits > 0);
    CHECK(c.atlas().size() > atlas.size());
}

TEST_CASE("reversed winding is an error naming it, not a black answer, on one-sided surfaces", "[radiosity][solve][errors]") {
    // An emitting quad in a box, every triangle wound the other way: the lamp faces the
    // ceiling's back and every wall faces out, so nothing the lamp shoots is received.
    const radiosity_options one_sided{.two_sided = false};
    const auto box = reversed(closed_box(1.f, 0.7f, 2.f));
    const auto atlas = build_lightmap_atlas(box.view(), {.elements = 400});
    cpu::progressive_radiosity solver(box.view(), atlas, cpu::item_buffer_visibility(box.view(), atlas, {.resolution = 64}),
                                      one_sided);
    CHECK_THROWS_AS(solver.solve(0.1), radiosity_error);
    CHECK_THROWS_WITH(solver.solve(0.1), Catch::Contains("reversed winding"));
    // The same box wound the right way solves.
    const auto good = closed_box(1.f, 0.7f, 2.f);
    const auto good_atlas = build_lightmap_atlas(good.view(), {.elements = 400});
    cpu::progressive_radiosity fine(good.view(), good_atlas, cpu::all_visible{});
    CHECK_NOTHROW(fine.solve(0.5));

    // A point light inside a reversed box reaches only the walls' backs: the constructor says so.
    const auto lit = reversed(box_with_point_light());
    const auto lit_atlas = build_lightmap_atlas(lit.view(), {.elements = 300});
    CHECK_THROWS_AS(cpu::progressive_radiosity(lit.view(), lit_atlas, cpu::all_visible{}, one_sided), radiosity_error);
    CHECK_THROWS_WITH(cpu::progressive_radiosity(lit.view(), lit_atlas, cpu::all_visible{}, one_sided),
                      Catch::Contains("reversed winding") && Catch::Contains("back of"));
    // Two-sided (the default), the reversed box is lit on its walls' backs.
    cpu::progressive_radiosity two(lit.view(), lit_atlas, cpu::all_visible{});
    CHECK(two.emitted_power().x > 0);
    const auto right = box_with_point_light();
    const auto right_atlas = build_lightmap_atlas(right.view(), {.elements = 300});
    cpu::progressive_radiosity ok(right.view(), right_atlas, cpu::all_visible{});
    CHECK(ok.emitted_power().x > 0);
    // A point light outside the box: it faces the outer side of the back wall (its back) and
    // the inside of the front wall, which the back wall hides from it.
    auto outside = box_with_point_light();
    outside.lights[0] = point_light{{0.5f, 0.5f, -3.f}, {1.f, 1.f, 1.f}};
    const auto out_atlas = build_lightmap_atlas(outside.view(), {.elements = 300});
    const auto hidden = [&] {
        return cpu::progressive_radiosity(outside.view(), out_atlas,
                                          cpu::item_buffer_visibility(outside.view(), out_atlas, {.resolution = 64}),
                                          one_sided);
    };
    CHECK_THROWS_WITH(hidden(), Catch::Contains("occluded"));
    // A spot aimed away from everything reaches no surface.
    auto away = box_with_point_light();
    spot_light spot;
    spot.position = {0.5f, 0.5f, -3.f};
    spot.direction = {0, 0, -1};
    spot.intensity = glm::vec3(1.f);
    spot.cone_deg = 30.f;
    away.lights[0] = spot;
    const auto away_atlas = build_lightmap_atlas(away.view(), {.elements = 300});
    CHECK_THROWS_WITH(cpu::progressive_radiosity(away.view(), away_atlas, cpu::all_visible{}),
                      Catch::Contains("reaches no surface"));
}

TEST_CASE("two-sided elements light a reversed box from inside as one-sided ones light the right one",
          "[radiosity][solve][sides]") {
    // A point light in a box wound inwards (one-sided) and in the same box wound outwards
    // (two-sided, the default): the second's back sides must carry what the first's fronts do
    // (the same texels, perhaps in another order: compared by the power they hold), and its
    // front sides, which face out of the box, nothing.
    const auto right = box_with_point_light(), wrong = reversed(box_with_point_light());
    const auto right_atlas = build_lightmap_atlas(right.view(), {.elements = 300});
    const auto wrong_atlas = build_lightmap_atlas(wrong.view(), {.elements = 300});
    REQUIRE(right_atlas.size() == wrong_atlas.size());
    cpu::progressive_radiosity<cpu::all_visible, double> one(right.view(), right_atlas, {}, {.two_sided = false});
    cpu::progressive_radiosity<cpu::all_visible, double> two(wrong.view(), wrong_atlas, {});
    CHECK(two.sides() == 2);
    one.solve(1e-9);
    two.solve(1e-9);
    const auto power = [](const auto& solver, int side) {
        glm::dvec3 sum(0);
        const auto b = solver.radiosity(side);
        for (std::size_t i = 0; i < b.size(); ++i) sum += glm::dvec3(b[i]) * double(solver.atlas().area[i]);
        return sum;
    };
    const glm::dvec3 expected = power(one, 0), got = power(two, 1);
    for (int c = 0; c < 3; ++c) CHECK(got[c] == Approx(expected[c]).epsilon(1e-6));
    CHECK(power(two, 0) == glm::dvec3(0));
    CHECK(two.emitted_power().x == Approx(one.emitted_power().x).epsilon(1e-9));
    // The balance holds over both sides.
    const glm::dvec3 balance = two.absorbed_power() + two.unshot_power() + two.escaped_power() - two.emitted_power();
    CHECK(std::abs(balance.x) < 1e-9 * two.emitted_power().x);
    CHECK_THROWS_AS(one.radiosity(1), parameter_error);  // a one-sided solver has no back
    // The box wound inwards, two-sided: its backs never face a shooter, so its fronts are the
    // one-sided answer bit for bit.
    cpu::progressive_radiosity<cpu::all_visible, double> both(right.view(), right_atlas, {});
    both.solve(1e-9);
    const auto b1 = one.radiosity(0), b2 = both.radiosity(0);
    CHECK(std::equal(b1.begin(), b1.end(), b2.begin(), b2.end()));
    CHECK(power(both, 1) == glm::dvec3(0));
}

TEST_CASE("a stereographic tolerance below what the buffer resolves is refused with the floor", "[radiosity][solve][errors]") {
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 500});
    const float floor = stereographic_tolerance_floor(scene.view(), atlas.size(), 128);
    CHECK(floor == Approx(1.0 / 256.0));  // a scene near the origin in metres: the snap decides
    const auto buffer = [&](float tolerance) {
        return cpu::item_buffer_visibility(scene.view(), atlas, {.resolution = 128, .tolerance_px = tolerance});
    };
    CHECK_THROWS_AS(buffer(1e-7f), parameter_error);
    CHECK_THROWS_WITH(buffer(1e-7f), Catch::Contains("options.tolerance_px") && Catch::Contains("0.003906"));
    CHECK_NOTHROW(buffer(0.01f));
    // Far from the origin, float32 positions resolve less than the snap.
    auto far = cornell_box();
    for (glm::vec3& p : far.positions) p += glm::vec3(1e5f, 0.f, 0.f);
    const float far_floor = stereographic_tolerance_floor(far.view(), atlas.size(), 128);
    CHECK(far_floor > 0.1f);
}

namespace {

// A floor 10 m wide of a few large elements under a lamp, with `count` sliver triangles
// (1 mm wide, half a metre long) a millimetre to a centimetre above it: every other one faces
// the floor, the rest face the lamp or stand across the floor, each its own chart of one tiny
// element. A tiny shooter a millimetre from a floor element metres wide is the case where the
// disc factor at the receiver's centre, times the receiver's area, hands the receiver many
// times the shot's power (issue 30's conference room).
owned_scene slivers_over_a_floor(int count) {
    owned_scene s;
    const auto floor = s.add_material(glm::vec3(0.8f));
    const auto sliver = s.add_material(glm::vec3(0.9f, 0.85f, 0.8f));
    const auto lamp = s.add_material(glm::vec3(0.5f), glm::vec3(5.f));
    s.add_quad({-5, 0, -5}, {-5, 0, 5}, {5, 0, 5}, {5, 0, -5}, floor);  // faces +y
    s.add_quad({-1, 4, -1}, {1, 4, -1}, {1, 4, 1}, {-1, 4, 1}, lamp);   // faces -y
    pcg32 rng(30);
    for (int k = 0; k < count; ++k) {
        const glm::vec3 at(8 * rng.next_float() - 4, 0.001f + 0.009f * rng.next_float(), 8 * rng.next_float() - 4);
        const glm::vec3 along(0.5f, 0.f, 0.f), across(0.f, 0.f, 0.001f), up(0.f, 0.001f, 0.f);
        const auto base = std::uint32_t(s.positions.size());
        switch (k % 4) {
            case 0:  // faces the floor
            case 1: s.positions.insert(s.positions.end(), {at, at + along, at + across}); break;
            case 2: s.positions.insert(s.positions.end(), {at, at + across, at + along}); break;  // faces the lamp
            default: s.positions.insert(s.positions.end(), {at, at + along, at + up}); break;  // stands across
        }
        s.triangles.emplace_back(base, base + 1, base + 2);
        s.material_of.push_back(sliver);
    }
    return s;
}

}  // namespace

TEST_CASE("slivers and near-touching elements: no shot delivers more than its power, the unshot power only falls",
          "[radiosity][solve][energy]") {
    const auto scene = slivers_over_a_floor(200);
    // A chart per sliver (no clusters of tiny charts), floor elements much larger.
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 40, .clusters = tiny_chart_clusters::never});
    REQUIRE(atlas.size() > 200);
    cpu::progressive_radiosity solver(scene.view(), atlas, cpu::all_visible{});
    glm::dvec3 escaped = solver.escaped_power();
    double unshot = solver.unshot_fraction();
    radiosity_solve_options o;
    o.converge = 1;  // 400 steps: the slivers shoot too
    o.progress = [&](const radiosity_progress& p) {
        // Each shot hands out at most its power: what escapes never falls (to float rounding).
        const glm::dvec3 e = solver.escaped_power(), emitted = solver.emitted_power();
        for (int c = 0; c < 3; ++c) CHECK(e[c] >= escaped[c] - 1e-6 * emitted[c]);
        escaped = e;
        CHECK(p.unshot_fraction <= unshot * (1 + 1e-6));
        CHECK(p.unshot_fraction >= 0);
        unshot = p.unshot_fraction;
        // No receiver takes more than the shot.
        CHECK(solver.last_shot().top_share <= 1 + 1e-6);
        return p.steps < 400;
    };
    radiosity_solve_report r;
    REQUIRE_NOTHROW(r = solver.solve(o));
    CHECK(r.stop == radiosity_stop::callback);
    CHECK(solver.unshot_fraction() < 1e-3);
    // Either bound alone keeps this scene's energy (element_form_factor leaves no shot to
    // scale here; with the receiver's point factor instead, shot_scale scales most of them);
    // with neither, the first floor shot hands a sliver-covered floor element 1.8 times its
    // power and the solve stops at step 1 naming shooter and element (checked by hand).
    CHECK(solver.clamped_shots() == 0);
}

TEST_CASE("the convergence measure that counts bounced light: a dark room lit by a lamp is not converged before a bounce",
          "[radiosity][solve]") {
    // The measure itself: 1 before any shot, 0 once nothing is left, the bounces to come counted.
    CHECK(indirect_unshot_fraction(5.0, 0.0, 0.5) == 1.0);
    CHECK(indirect_unshot_fraction(0.0, 5.0, 0.5) == 0.0);
    CHECK(indirect_unshot_fraction(1.0, 8.0, 0.5) == Approx(0.2));  // r = 2 of 10
    CHECK(indirect_unshot_fraction(0.0, 0.0, 0.5) == 0.0);
    // Walls of albedo about 0.07 around a point light: 93% of the emitted power (the lights'
    // direct light counts as emitted) is absorbed where it lands, so the older measure calls
    // the room 90% converged before any shot; the new one asks for the bounces.
    owned_scene s = closed_box(1.f, 0.08f, 0.f);
    s.triangles.resize(s.triangles.size() - 2);  // the lamp quad
    s.material_of.resize(s.material_of.size() - 2);
    s.lights.push_back(point_light{{0.4f, 0.6f, 0.5f}, {1.f, 1.f, 1.f}});
    const auto atlas = build_lightmap_atlas(s.view(), {.elements = 600});
    cpu::progressive_radiosity solver(s.view(), atlas, cpu::all_visible{});
    CHECK(solver.unshot_fraction() < 0.1);
    CHECK(solver.indirect_unshot_fraction() == 1.0);
    radiosity_solve_options o;
    o.converge = 0.9;
    o.measure = radiosity_measure::emitted;
    CHECK(solver.solve(o).steps == 0);
    o.measure = radiosity_measure::indirect;
    const auto r = solver.solve(o);
    CHECK(r.steps > 10);
    CHECK(r.indirect_unshot_fraction <= 0.1);
    CHECK(r.converged.back() == Approx(1 - r.indirect_unshot_fraction));
    // It only falls.
    for (std::size_t k = 1; k < r.converged.size(); ++k) CHECK(r.converged[k] >= r.converged[k - 1]);
}
