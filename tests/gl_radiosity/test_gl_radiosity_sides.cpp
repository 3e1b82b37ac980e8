// Two-sided elements on GL (issue 30): triangles wound away from the light are lit on their
// backs by gl::progressive_radiosity as by cpu::progressive_radiosity (the same convention,
// radiosity/sides.hpp), and the one-sided option leaves them black. llvmpipe via EGL.
#include "../gl/shared_context.hpp"
#include "../radiosity/radiosity_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/gl/radiosity.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <utility>
#include <vector>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

// The Cornell box with its floor, back wall and green wall wound the other way: their fronts
// face out of the box, away from the lamp and everything else, as in published scenes
// modelled for two-sided renderers.
owned_scene partly_reversed_box() {
    owned_scene s = cornell_box();
    for (const std::size_t t : {0u, 1u, 4u, 5u, 6u, 7u}) std::swap(s.triangles[t].y, s.triangles[t].z);
    return s;
}

// Per element, whether its chart is one of the reversed triangles'.
std::vector<bool> on_reversed(const lightmap_atlas& atlas) {
    std::vector<bool> reversed_chart(atlas.charts.size(), false);
    for (const std::size_t t : {0u, 1u, 4u, 5u, 6u, 7u}) reversed_chart[atlas.chart_of_triangle[t]] = true;
    std::vector<bool> out(atlas.size());
    for (std::size_t i = 0; i < atlas.size(); ++i) out[i] = reversed_chart[atlas.chart[i]];
    return out;
}

// Area-weighted sum of B's channels over the elements `which` selects, on `side`.
template <class Solver>
double power_on(const Solver& solver, const std::vector<bool>& which, int side) {
    const auto b = solver.radiosity(side);
    double sum = 0;
    for (std::size_t i = 0; i < which.size(); ++i)
        if (which[i]) sum += (double(b[i].x) + double(b[i].y) + double(b[i].z)) * double(solver.atlas().area[i]);
    return sum;
}

}  // namespace

TEST_CASE("GL lights triangles wound away from the light on their backs as the CPU does; one-sided leaves them black",
          "[gl][radiosity][sides]") {
    // The same scene, atlas, visibility method and buffer on both backends, two-sided: the
    // tolerance is the one of the k-shot test of test_gl_radiosity.cpp (item-buffer answers
    // may differ only at a buffer's edges, and there none does): the same shooter at every
    // step (block and side) and a relative L1 difference of B, over both sides, within the
    // float bound 1e-5 (s + 1).
    gl_test::shared_context();
    const auto scene = partly_reversed_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 600});
    const auto reversed = on_reversed(atlas);
    const int res = 128, shots = 30;
    const bool hemicube = GENERATE(false, true);
    INFO((hemicube ? "hemicube" : "stereographic"));
    cpu::progressive_radiosity cpu_solver(
        scene.view(), atlas,
        cpu::item_buffer_visibility(scene.view(), atlas,
                                    {.projection = hemicube ? cpu::item_projection::hemicube : cpu::item_projection::stereographic,
                                     .resolution = res}));
    const gl::radiosity_visibility method = hemicube ? gl::radiosity_visibility::hemicube : gl::radiosity_visibility::stereographic;
    gl::progressive_radiosity gl_solver(scene.view(), atlas, {.visibility = method, .resolution = res});
    REQUIRE(gl_solver.sides() == 2);
    REQUIRE(gl_solver.shooters() == cpu_solver.shooters());
    std::size_t same_shooter = 0, back_shots = 0;
    for (int s = 0; s < shots; ++s) {
        const std::size_t next = gl_solver.next_shooter();
        REQUIRE(gl_solver.step());
        REQUIRE(cpu_solver.step());
        same_shooter += cpu_solver.last_shot().shooter == next ? 1 : 0;
        back_shots += next >= gl_solver.shooters() / 2 ? 1 : 0;
    }
    CHECK(same_shooter == std::size_t(shots));
    CHECK(back_shots > 0);  // the reversed walls' backs shot what they received
    double diff = 0, sum = 0;
    for (int side = 0; side < 2; ++side) {
        const auto bg = gl_solver.radiosity(side);
        const auto bc = cpu_solver.radiosity(side);
        for (std::size_t i = 0; i < bc.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                diff += std::abs(double(bg[i][c]) - double(bc[i][c])) * double(atlas.area[i]);
                sum += double(bc[i][c]) * double(atlas.area[i]);
            }
    }
    INFO("relative L1 difference " << diff / sum);
    CHECK(diff / sum <= 1e-5 * (shots + 1));
    CHECK(gl_solver.unshot_fraction() == Approx(cpu_solver.unshot_fraction()).epsilon(1e-5 * (shots + 1)));
    // The reversed triangles are lit on their backs (and not on their fronts, which face
    // away from everything inside the box), as much on GL as on the CPU.
    const double lit_back = power_on(gl_solver, reversed, 1);
    CHECK(lit_back > 0);
    CHECK(power_on(gl_solver, reversed, 0) == 0);
    CHECK(lit_back == Approx(power_on(cpu_solver, reversed, 1)).epsilon(1e-5 * (shots + 1)));

    // One-sided (the option), the same scene leaves them black: their fronts face away from
    // every shooter, and nothing they would have reflected reaches the rest.
    gl::progressive_radiosity one(scene.view(), atlas, {.shooting = {.two_sided = false}, .visibility = method, .resolution = res});
    REQUIRE(one.sides() == 1);
    for (int s = 0; s < shots; ++s) REQUIRE(one.step());
    CHECK(power_on(one, reversed, 0) == 0);
    std::vector<bool> rest(reversed.size());
    for (std::size_t i = 0; i < rest.size(); ++i) rest[i] = !reversed[i];
    INFO("the rest: one-sided " << power_on(one, rest, 0) << ", two-sided " << power_on(gl_solver, rest, 0));
    CHECK(power_on(one, rest, 0) < power_on(gl_solver, rest, 0));
}

TEST_CASE("GL two-sided lights a box wound outwards from inside as one-sided GL lights the box wound inwards",
          "[gl][radiosity][sides]") {
    // A point light in a box wound outwards (every front faces away from it), two-sided, and
    // the same box wound inwards, one-sided, without occlusion: the backs of the first carry
    // what the fronts of the second do (the same texels, perhaps in another order: compared
    // by the power they hold), the fronts of the first nothing. Both are solved to an unshot
    // fraction u = 1e-4; what is still to come adds at most u E rho / (1 - rho) to a solve's
    // power B A, which is at least rho E (rho in [0.5, 0.7] here): 2.4 u of it, so the two
    // agree to 5 u plus float rounding.
    gl_test::shared_context();
    owned_scene right = closed_box(1.f, 0.7f, 0.f);
    right.triangles.resize(right.triangles.size() - 2);  // no lamp quad: a point light instead
    right.material_of.resize(right.material_of.size() - 2);
    right.lights.push_back(point_light{{0.5f, 0.45f, 0.55f}, {1.f, 0.8f, 0.6f}});
    owned_scene wrong = right;
    for (glm::uvec3& t : wrong.triangles) std::swap(t.y, t.z);
    const auto right_atlas = build_lightmap_atlas(right.view(), {.elements = 300});
    const auto wrong_atlas = build_lightmap_atlas(wrong.view(), {.elements = 300});
    REQUIRE(right_atlas.size() == wrong_atlas.size());
    const gl::radiosity_options one_sided{.shooting = {.two_sided = false}, .visibility = gl::radiosity_visibility::none};
    gl::progressive_radiosity one(right.view(), right_atlas, one_sided);
    gl::progressive_radiosity two(wrong.view(), wrong_atlas, {.visibility = gl::radiosity_visibility::none});
    // One-sided, the box wound outwards gets nothing from its light: an error naming it.
    CHECK_THROWS_AS(gl::progressive_radiosity(wrong.view(), wrong_atlas, one_sided), radiosity_error);
    const double u = 1e-4;
    one.solve(u);
    two.solve(u);
    const auto power = [](const gl::progressive_radiosity& solver, int side) {
        glm::dvec3 sum(0);
        const auto b = solver.radiosity(side);
        for (std::size_t i = 0; i < b.size(); ++i) sum += glm::dvec3(b[i]) * double(solver.atlas().area[i]);
        return sum;
    };
    const glm::dvec3 expected = power(one, 0), got = power(two, 1);
    for (int c = 0; c < 3; ++c) CHECK(got[c] == Approx(expected[c]).epsilon(5 * u + 1e-5));
    CHECK(power(two, 0) == glm::dvec3(0));  // the outer sides face no shooter
    CHECK(two.emitted_power().x == Approx(one.emitted_power().x).epsilon(1e-5));
    // The balance holds over both sides (the bound of the energy test, test_gl_radiosity.cpp).
    const glm::dvec3 e = two.emitted_power();
    const glm::dvec3 balance = two.absorbed_power() + two.unshot_power() + two.escaped_power() - e;
    const double s = double(two.progress().steps);
    for (int c = 0; c < 3; ++c) CHECK(std::abs(balance[c]) <= (s + 3) * 0x1p-24 * e[c] * 4);
}
