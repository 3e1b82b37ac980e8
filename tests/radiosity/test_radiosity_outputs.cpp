// The CPU solver's outputs (output.hpp): irradiance or radiance, the lights' direct part or
// the rest or both, and how they add up to the radiosity B the solver solves for.
#include "radiosity_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/output.hpp>

#include <catch2/catch.hpp>

#include <numbers>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

// A closed box with its emitting quad and a point light, so that every part is non-zero.
owned_scene lit_box() {
    owned_scene s = closed_box(1.f, 0.7f, 2.f);
    s.use_emission = true;
    s.lights.push_back(point_light{{0.3f, 0.6f, 0.4f}, glm::vec3(0.5f, 0.4f, 0.3f)});
    return s;
}

}  // namespace

TEST_CASE("right after construction the direct irradiance is the lights' and nothing is indirect",
          "[radiosity][outputs]") {
    const auto box = lit_box();
    const auto atlas = build_lightmap_atlas(box.view(), {.elements = 200, .block_texels = 1});
    cpu::progressive_radiosity<cpu::all_visible> solver(box.view(), atlas, {}, {.ambient = false});
    const auto direct = solver.output(output_quantity::irradiance, light_paths::direct);
    const auto indirect = solver.output();  // the default: indirect irradiance
    for (std::size_t i = 0; i < atlas.size(); ++i) {
        const glm::vec3 e = point_light_irradiance<float, glm::vec3>(atlas.position[i], atlas.normal[i],
                                                                      {0.3f, 0.6f, 0.4f}, {0.5f, 0.4f, 0.3f});
        CHECK(direct[i] == e);
        CHECK(indirect[i] == glm::vec3(0.f));
    }
}

TEST_CASE("the parts add up to B: radiance of all is B / pi, direct radiance is (B_e + rho E_d) / pi",
          "[radiosity][outputs]") {
    const auto box = lit_box();
    const auto atlas = build_lightmap_atlas(box.view(), {.elements = 200, .block_texels = 1});
    for (const bool ambient : {false, true}) {
        cpu::progressive_radiosity<cpu::all_visible, double> solver(box.view(), atlas, {}, {.ambient = ambient});
        for (int s = 0; s < 40; ++s) REQUIRE(solver.step());
        const auto shown = solver.display_radiosity();
        const auto all = solver.output(output_quantity::radiance, light_paths::all);
        const auto direct_l = solver.output(output_quantity::radiance, light_paths::direct);
        const auto direct_e = solver.output(output_quantity::irradiance, light_paths::direct);
        const auto indirect_e = solver.output(output_quantity::irradiance, light_paths::indirect);
        const auto indirect_l = solver.output(output_quantity::radiance, light_paths::indirect);
        const auto all_e = solver.output(output_quantity::irradiance, light_paths::all);
        const double pi = std::numbers::pi;
        for (std::size_t i = 0; i < atlas.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                const double rho = atlas.albedo[i][c], be = atlas.emission[i][c];
                CHECK(pi * all[i][c] == Approx(shown[i][c]).epsilon(1e-5).margin(1e-6));
                CHECK(pi * direct_l[i][c] == Approx(be + rho * direct_e[i][c]).epsilon(1e-5).margin(1e-6));
                CHECK(pi * indirect_l[i][c] == Approx(rho * indirect_e[i][c]).epsilon(1e-5).margin(1e-6));
                CHECK(all_e[i][c] == Approx(direct_e[i][c] + indirect_e[i][c]).epsilon(1e-6).margin(1e-6));
                // What the shots delivered is B less emission and the lights' part, over rho.
                CHECK(rho * indirect_e[i][c] ==
                      Approx(shown[i][c] - be - rho * direct_e[i][c]).epsilon(1e-5).margin(1e-6));
            }
        // The lightmap lays the output out at each element's texel.
        const auto lm = solver.lightmap(output_quantity::irradiance, light_paths::indirect);
        for (std::size_t i = 0; i < atlas.size(); ++i) CHECK(lm(atlas.texel[i].x, atlas.texel[i].y) == indirect_e[i]);
    }
}

TEST_CASE("indirect irradiance reaches a surface whose albedo is zero", "[radiosity][outputs]") {
    // A black floor reflects nothing, so its B is its emission (none), yet light arrives:
    // the irradiance a renderer multiplies by its own albedo texture must not be 0 there.
    owned_scene s = closed_box(1.f, 0.7f, 2.f);
    s.use_emission = true;
    s.materials[0].albedo = glm::vec3(0.f);  // every wall black ...
    const auto grey = s.add_material(glm::vec3(0.6f));
    for (std::size_t t = 2; t < 12; ++t) s.material_of[t] = grey;  // ... but the floor (triangles 0, 1)
    const auto atlas = build_lightmap_atlas(s.view(), {.elements = 200, .block_texels = 1});
    cpu::progressive_radiosity<cpu::all_visible> solver(s.view(), atlas, {});
    solver.solve(0.05);
    const auto e = solver.output();
    std::size_t floor_elements = 0;
    for (std::size_t i = 0; i < atlas.size(); ++i) {
        if (atlas.albedo[i] != glm::vec3(0.f)) continue;
        ++floor_elements;
        CHECK(solver.radiosity()[i] == glm::vec3(0.f));
        CHECK(e[i].x > 0.f);
    }
    CHECK(floor_elements > 10);
}
