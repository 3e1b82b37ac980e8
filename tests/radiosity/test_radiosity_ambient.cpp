// The ambient term shaped by the shots (radiosity/ambient.hpp, radiosity_ambient::shots)
// against what the remaining power really delivers (the converged solve), and against Cohen et
// al. 1988's uniform term on an open scene.
#include "radiosity_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/radiosity/ambient.hpp>

#include <catch2/catch.hpp>

#include <numbers>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

using solver_t = cpu::progressive_radiosity<cpu::all_visible, double>;

// Each channel's ambient power sum_i a_i A_i of `with` (the ambient term on) over both sides:
// its indirect irradiance less that of `without` (the same solve, no ambient term).
glm::dvec3 ambient_power(const solver_t& with, const solver_t& without) {
    glm::dvec3 p(0);
    for (int side = 0; side < with.sides(); ++side) {
        const auto a = with.output(output_quantity::irradiance, light_paths::indirect, side);
        const auto b = without.output(output_quantity::irradiance, light_paths::indirect, side);
        for (std::size_t i = 0; i < a.size(); ++i) {
            const glm::dvec3 d = glm::dvec3(a[i]) - glm::dvec3(b[i]);
            for (int c = 0; c < 3; ++c) CHECK(d[c] >= -1e-6 * (1 + std::abs(double(b[i][c]))));
            p += d * double(with.atlas().area[i]);
        }
    }
    return p;
}

struct ambient_case {
    glm::dvec3 shots, uniform, future;  // ambient power (shots', Cohen's), and what the rest of the solve delivers
};

// `steps` steps of three solvers (no ambient, Cohen's, the shots'), their ambient powers, then
// the power the solve without ambient delivers from there on to convergence.
ambient_case measure(const owned_scene& scene, std::size_t elements, int steps) {
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = elements, .block_texels = 1});
    solver_t none(scene.view(), atlas, {}, {.ambient = false}), uniform(scene.view(), atlas, {}, {.ambient = true}),
        shots(scene.view(), atlas, {}, {.ambient = true, .ambient_shape = radiosity_ambient::shots});
    for (int s = 0; s < steps; ++s) {
        REQUIRE(none.step());
        REQUIRE(uniform.step());
        REQUIRE(shots.step());
    }
    REQUIRE(shots.unshot_fraction() > 0.05);
    ambient_case r{ambient_power(shots, none), ambient_power(uniform, none), none.intercepted_power()};
    none.solve(1e-9);
    r.future = none.intercepted_power() - r.future;
    return r;
}

}  // namespace

TEST_CASE("the shaped ambient factor: unshot over shot less reflected, 0 without unshot power or shots",
          "[radiosity][kernel]") {
    const glm::dvec3 u(2, 0, 1), s(4, 4, 0), r(2, 1, 0);
    const glm::dvec3 f = shot_ambient_factor<double, glm::dvec3>(u, s, r);
    CHECK(f == glm::dvec3(1.0, 0.0, 0.0));  // 2 / (4 - 2); no unshot power; nothing shot
    // Delivered power D: U (D / S) / (1 - R / S).
    CHECK(future_delivered_power<double, glm::dvec3>(u, s, glm::dvec3(3), r).x == Approx(2.0 * 0.75 / 0.5));
    CHECK(shot_ambient_factor<double, glm::dvec3>(glm::dvec3(0), s, r) == glm::dvec3(0));
}

TEST_CASE("in a closed box the shaped ambient power is what the remaining power delivers until convergence",
          "[radiosity][solver]") {
    const auto box = closed_box(1.f, 0.7f, 2.f);
    const ambient_case c = measure(box, 150, 30);
    for (int k = 0; k < 3; ++k) {
        INFO("channel " << k << ": shots " << c.shots[k] << " uniform " << c.uniform[k] << " future " << c.future[k]);
        CHECK(c.shots[k] == Approx(c.future[k]).epsilon(0.1));
    }
}

TEST_CASE("on an open scene the shaped ambient is smaller than Cohen's and nearer what the solve delivers",
          "[radiosity][solver]") {
    // Two facing squares as far apart as they are wide: most light leaves through the sides.
    const auto squares = facing_squares(1.f, 1.f, 0.8f, 1.f);
    const ambient_case c = measure(squares, 128, 12);
    for (int k = 0; k < 3; ++k) {
        INFO("channel " << k << ": shots " << c.shots[k] << " uniform " << c.uniform[k] << " future " << c.future[k]);
        CHECK(c.shots[k] < 0.5 * c.uniform[k]);
        CHECK(std::abs(c.shots[k] - c.future[k]) < 0.5 * std::abs(c.uniform[k] - c.future[k]));
    }
}

TEST_CASE("the shaped ambient shows as the uniform one does: B + rho a, a added to the indirect irradiance",
          "[radiosity][outputs]") {
    const auto box = closed_box(1.f, 0.7f, 2.f);
    const auto atlas = build_lightmap_atlas(box.view(), {.elements = 100, .block_texels = 1});
    solver_t none(box.view(), atlas, {}, {.ambient = false}), shots(box.view(), atlas, {}, {.ambient = true, .ambient_shape = radiosity_ambient::shots});
    // Before any shot: Cohen's term.
    const auto first = shots.display_radiosity();
    const glm::dvec3 cohen = shots.ambient();
    for (std::size_t i = 0; i < atlas.size(); ++i)
        CHECK(double(first[i].y) == Approx(shots.radiosity()[i].y + atlas.albedo[i].y * cohen.y).epsilon(1e-6));
    for (int s = 0; s < 10; ++s) REQUIRE((none.step() && shots.step()));
    const auto shown = shots.display_radiosity();
    const auto with = shots.output(output_quantity::irradiance, light_paths::indirect);
    const auto without = none.output(output_quantity::irradiance, light_paths::indirect);
    const auto all = shots.output(output_quantity::radiance, light_paths::all);
    std::size_t shaped = 0;
    for (std::size_t i = 0; i < atlas.size(); ++i) {
        const double a = double(with[i].z) - double(without[i].z), rho = atlas.albedo[i].z;
        CHECK(double(shown[i].z) == Approx(shots.radiosity()[i].z + rho * a).epsilon(1e-5).margin(1e-6));
        CHECK(std::numbers::pi * double(all[i].z) == Approx(double(shown[i].z)).epsilon(1e-5).margin(1e-6));
        if (std::abs(a - cohen.z) > 0.05 * cohen.z) ++shaped;
    }
    CHECK(shaped > 0);  // not Cohen's uniform value everywhere
    // Converged: nothing left, no ambient.
    shots.solve(1e-14);
    none.solve(1e-14);
    CHECK(glm::length(ambient_power(shots, none)) < 1e-9);
}

// The mixed term (radiosity_ambient::mixed): the shots' shape where it stands above the even
// spread of the reflections' share, that floor elsewhere, scaled to the shaped term's total.

TEST_CASE("the mixed ambient's floor is the reflections' share spread evenly; its total the shaped term's",
          "[radiosity][kernel]") {
    const glm::dvec3 f(0.5, 1, 2), s(8, 8, 0), d(4, 4, 4), r(2, 4, 1);
    // E = f D = (2, 4, 8); R / S = (1/4, 1/2, -): floors E R / S / A over A = 4; nothing shot in z.
    const glm::dvec3 floor = mixed_ambient_floor<double, glm::dvec3>(f, s, d, r, 4.0);
    CHECK(floor.x == Approx(2 * 0.25 / 4));
    CHECK(floor.y == Approx(4 * 0.5 / 4));
    CHECK(floor.z == 0.0);
    // Two sides of areas 1 and 3 whose shaped values integrate to E: one above the floor, one below.
    const glm::dvec3 e = f * d, hi(1.7, 3.4, 2), lo((e - hi) / 3.0);  // 1 hi + 3 lo = E
    glm::dvec3 deficit(0);
    for (const auto& [a, h] : {std::pair{1.0, hi}, std::pair{3.0, lo}}) deficit += a * glm::max(floor - h, glm::dvec3(0));
    REQUIRE(deficit.x > 0);  // lo is below the floor in x
    const glm::dvec3 k = mixed_ambient_scale<double, glm::dvec3>(e, deficit);
    const glm::dvec3 p = mixed_ambient<double, glm::dvec3>(hi, floor, k) + 3.0 * mixed_ambient<double, glm::dvec3>(lo, floor, k);
    for (int c = 0; c < 3; ++c) CHECK(p[c] == Approx(e[c]));
    CHECK(mixed_ambient<double, glm::dvec3>(lo, floor, k).x == Approx(k.x * floor.x));  // the floor where lower
    CHECK(mixed_ambient_scale<double, glm::dvec3>(glm::dvec3(0), glm::dvec3(0)) == glm::dvec3(1));
}

TEST_CASE("in a closed box the mixed ambient's power is its estimate and what the remaining power delivers",
          "[radiosity][solver]") {
    const auto box = closed_box(1.f, 0.7f, 2.f);
    const auto atlas = build_lightmap_atlas(box.view(), {.elements = 150, .block_texels = 1});
    solver_t none(box.view(), atlas, {}, {.ambient = false}),
        shots(box.view(), atlas, {}, {.ambient = true, .ambient_shape = radiosity_ambient::shots}),
        mixed(box.view(), atlas, {}, {.ambient = true, .ambient_shape = radiosity_ambient::mixed});
    for (int s = 0; s < 30; ++s) REQUIRE((none.step() && shots.step() && mixed.step()));
    REQUIRE(mixed.unshot_fraction() > 0.05);
    const glm::dvec3 power = ambient_power(mixed, none), estimate = ambient_power(shots, none),
                     before = none.intercepted_power();
    for (int k = 0; k < 3; ++k) CHECK(power[k] == Approx(estimate[k]).epsilon(1e-4));  // U D / (S - R)
    none.solve(1e-9);
    const glm::dvec3 future = none.intercepted_power() - before;
    for (int k = 0; k < 3; ++k) {
        INFO("channel " << k << ": mixed " << power[k] << " future " << future[k]);
        CHECK(power[k] == Approx(future[k]).epsilon(0.1));
    }
}

TEST_CASE("the mixed ambient lights a side no shot reached, and vanishes with the unshot power",
          "[radiosity][solver]") {
    // Two facing squares, two-sided: their outer sides face nothing, so no shot reaches them.
    const auto squares = facing_squares(1.f, 1.f, 0.8f, 1.f);
    const auto atlas = build_lightmap_atlas(squares.view(), {.elements = 128, .block_texels = 1});
    solver_t none(squares.view(), atlas, {}, {.ambient = false}),
        shots(squares.view(), atlas, {}, {.ambient = true, .ambient_shape = radiosity_ambient::shots}),
        mixed(squares.view(), atlas, {}, {.ambient = true, .ambient_shape = radiosity_ambient::mixed});
    REQUIRE(mixed.two_sided());
    for (int s = 0; s < 12; ++s) REQUIRE((none.step() && shots.step() && mixed.step()));
    REQUIRE(mixed.unshot_fraction() > 0.01);
    const auto without = none.output(output_quantity::irradiance, light_paths::indirect, 1);
    const auto with_shots = shots.output(output_quantity::irradiance, light_paths::indirect, 1);
    const auto with_mixed = mixed.output(output_quantity::irradiance, light_paths::indirect, 1);
    const glm::dvec3 cohen = mixed.ambient();
    for (std::size_t i = 0; i < atlas.size(); ++i) {  // side 1, the back of both squares, faces out
        CHECK(without[i] == glm::vec3(0.f));  // no shot reached it
        CHECK(with_shots[i] == glm::vec3(0.f));
        for (int c = 0; c < 3; ++c) {
            CHECK(with_mixed[i][c] > 0.f);
            CHECK(double(with_mixed[i][c]) < cohen[c]);  // the floor: a share of the shots' (smaller) amount
        }
    }
    // The total is the shaped term's, the floor's share moved from where the shots delivered.
    const glm::dvec3 ps = ambient_power(shots, none), pm = ambient_power(mixed, none);
    for (int c = 0; c < 3; ++c) CHECK(pm[c] == Approx(ps[c]).epsilon(1e-4));
    mixed.solve(1e-14);
    none.solve(1e-14);
    CHECK(glm::length(ambient_power(mixed, none)) < 1e-9);
}
