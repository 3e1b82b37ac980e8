// The GL solver's ambient term shaped by its shots (radiosity_ambient::shots and ::mixed,
// radiosity/ambient.hpp) against the CPU solver's on the same scene and options, its total
// against the shaped total E = U D / (S - R), and the lightmap pass's (GPU) against the
// read-back path's. llvmpipe via EGL.
#include "../gl/agreement_inputs.hpp"
#include "../gl/shared_context.hpp"
#include "radiosity_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/gl/kernel_map.hpp>
#include <bounce/gl/radiosity.hpp>
#include <bounce/radiosity/ambient.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <tuple>
#include <utility>
#include <vector>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

// The CPU solver's ambient irradiance on `side`, from what it displays: (display - B) / rho
// per channel (every albedo here is above 0.05). Its rounding: float B, so about 1e-7 B / rho.
std::vector<glm::vec3> cpu_ambient_field(const cpu::progressive_radiosity<cpu::all_visible>& c, int side) {
    const auto d = c.display_radiosity(side);
    const auto b = c.radiosity(side);
    std::vector<glm::vec3> a(d.size());
    for (std::size_t i = 0; i < a.size(); ++i) a[i] = (d[i] - glm::vec3(b[i])) / c.atlas().albedo[i];
    return a;
}

// sum over both sides and every element of a_i A_i, W per channel.
glm::dvec3 ambient_total(const gl::progressive_radiosity& g) {
    glm::dvec3 t(0.0);
    for (int side = 0; side < g.sides(); ++side) {
        const auto a = g.ambient_field(side);
        for (std::size_t i = 0; i < a.size(); ++i) t += glm::dvec3(a[i]) * double(g.atlas().area[i]);
    }
    return t;
}

}  // namespace

TEST_CASE("the GL solver's shots and mixed ambient fields are the CPU solver's partway through a solve",
          "[radiosity][ambient][gl]") {
    gl_test::shared_context();
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 400, .block_texels = 4});
    for (const auto& [shape, two_sided] : {std::pair(radiosity_ambient::shots, true), std::pair(radiosity_ambient::mixed, true),
                                          std::pair(radiosity_ambient::mixed, false)}) {
        INFO("shape " << int(shape) << ", two-sided " << two_sided);
        radiosity_options shooting{.ambient = true, .ambient_shape = shape};
        shooting.two_sided = two_sided;
        gl::progressive_radiosity g(scene.view(), atlas, {.shooting = shooting, .visibility = gl::radiosity_visibility::none});
        cpu::progressive_radiosity c(scene.view(), atlas, cpu::all_visible{}, shooting);
        for (int s = 0; s < 25; ++s) {
            REQUIRE(g.step());
            REQUIRE(c.step());
        }
        REQUIRE(g.unshot_fraction() > 0.05);  // partway: the ambient term is a large share
        double largest = 0, worst = 0, spread_lo = 1e30, spread_hi = 0;
        REQUIRE(g.sides() == c.sides());
        for (int side = 0; side < g.sides(); ++side) {
            const auto ag = g.ambient_field(side), ac = cpu_ambient_field(c, side);
            const auto b = c.radiosity(side);
            for (std::size_t i = 0; i < ag.size(); ++i)
                for (int k = 0; k < 3; ++k) {
                    largest = std::max(largest, double(ag[i][k]));
                    // The CPU's (display - B) / rho rounds at about 1e-7 B / rho: 10 times that.
                    const double own = 1e-6 * double(b[i][k]) / double(atlas.albedo[i][k]);
                    worst = std::max(worst, std::abs(double(ag[i][k] - ac[i][k])) - own);
                }
            for (const glm::vec3& a : ag) spread_lo = std::min(spread_lo, double(a.x)), spread_hi = std::max(spread_hi, double(a.x));
        }
        REQUIRE(largest > 0);
        // Both solvers shoot the same shots in float, summed in other orders: the fields (h times
        // U / (S - R)) differed by 4e-6 of the largest here; 1e-4, as the GL-vs-CPU solve tests.
        CHECK(worst <= 1e-4 * largest);
        // Shaped by the shots, not uniform: it would be ambient() everywhere without the window.
        CHECK(spread_hi > 1.5 * spread_lo);
        CHECK(!g.ambient_window().empty());
    }
}

TEST_CASE("the GL solver's shaped ambient totals E = U D / (S - R); the lightmap pass shows it",
          "[radiosity][ambient][gl]") {
    gl_test::shared_context();
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 300, .block_texels = 4});
    for (const radiosity_ambient shape : {radiosity_ambient::shots, radiosity_ambient::mixed}) {
        INFO("shape " << int(shape));
        gl::progressive_radiosity g(scene.view(), atlas,
                                    {.shooting = {.ambient = true, .ambient_shape = shape}, .resolution = 64});
        for (int s = 0; s < 15; ++s) REQUIRE(g.step());
        const shot_ambient_window& w = g.ambient_window();
        const glm::dvec3 u = g.unshot_power(), total = ambient_total(g);
        for (int k = 0; k < 3; ++k) {
            const double e = u[k] * w.delivered()[k] / (w.shot()[k] - w.reflected()[k]);
            INFO("channel " << k << ": total " << total[k] << " E " << e);
            REQUIRE(e > 0);
            // h is the window's received irradiance, summed in float on the GPU; D its power
            // summed in double by the reduction: they agree to float rounding.
            CHECK(total[k] == Approx(e).epsilon(1e-4));
        }
        // The lightmap pass (the mixed deficit summed on the GPU) shows what the read-back path shows.
        for (int side = 0; side < 2; ++side) {
            const image<glm::vec3> want = g.radiosity_lightmap(0, side);
            const std::vector<float> got = g.update_lightmap_texture(side).read_floats();
            double largest = 0, worst = 0;
            for (std::uint32_t y = 0; y < atlas.height; ++y)
                for (std::uint32_t x = 0; x < atlas.width; ++x) {
                    if (atlas.element_at(x, y) < 0) continue;
                    const std::size_t at = 4 * (std::size_t(y) * atlas.width + x);
                    for (int k = 0; k < 3; ++k) {
                        largest = std::max(largest, double(want(x, y)[k]));
                        worst = std::max(worst, std::abs(double(got[at + std::size_t(k)]) - double(want(x, y)[k])));
                    }
                }
            REQUIRE(largest > 0);
            CHECK(worst <= 1e-5 * largest);
        }
    }
}

TEST_CASE("the GL solver's shaped ambient term is 0 once no unshot power is left", "[radiosity][ambient][gl]") {
    gl_test::shared_context();
    // Black surfaces: the emitter's shots leave nothing to shoot.
    const auto scene = facing_squares(1.f, 0.5f, 0.f, 1.f);
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 64, .block_texels = 4});
    for (const radiosity_ambient shape : {radiosity_ambient::shots, radiosity_ambient::mixed}) {
        gl::progressive_radiosity g(scene.view(), atlas, {.shooting = {.ambient = true, .ambient_shape = shape},
                                                          .visibility = gl::radiosity_visibility::none});
        REQUIRE(g.step());
        const bool more = g.next_shooter_power() > 0;
        if (more) CHECK(ambient_total(g).x > 0);  // unshot power left: some ambient
        while (g.step()) {
        }
        CHECK(!g.ambient_window().empty());
        CHECK(g.unshot_power() == glm::dvec3(0.0));
        CHECK(ambient_total(g) == glm::dvec3(0.0));
        for (const glm::vec3& a : g.ambient_field(0)) CHECK(a == glm::vec3(0.f));
    }
}

TEST_CASE("the GL solver records surface shots only: after its lights, Cohen's term", "[radiosity][ambient][gl]") {
    gl_test::shared_context();
    const auto scene = cornell_box(true);  // lit by its spot light
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 200, .block_texels = 4});
    gl::progressive_radiosity g(scene.view(), atlas, {.shooting = {.ambient = true, .ambient_shape = radiosity_ambient::mixed},
                                                      .resolution = 64});
    CHECK(g.ambient_window().empty());  // the light was shot, not recorded (as on the CPU)
    const glm::vec3 cohen(g.ambient());
    REQUIRE(cohen.x > 0);
    for (const glm::vec3& a : g.ambient_field(1)) CHECK(a == cohen);
    REQUIRE(g.step());
    CHECK(!g.ambient_window().empty());
}

TEST_CASE("the mixed ambient and its deficit agree on the GPU and the CPU, shaped term and floor equal included",
          "[glsl][radiosity][ambient]") {
    gl_test::shared_context();
    pcg32 rng(57);
    const auto random3 = [&] { return glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()); };
    std::vector<std::tuple<glm::vec3, glm::vec3, glm::vec3>> mixed;
    std::vector<std::tuple<glm::vec3, glm::vec3, float>> deficit;
    for (int k = 0; k < 5000; ++k) {
        const glm::vec3 shaped = random3() * 5.f, floor = k % 10 == 0 ? shaped : random3() * 5.f;
        mixed.emplace_back(shaped, floor, random3());
        deficit.emplace_back(shaped, floor, rng.next_float() * 2.f);
    }
    std::vector<glm::vec3> cpu_mixed, cpu_deficit;
    for (const auto& a : mixed) cpu_mixed.push_back(std::apply(mixed_ambient<float, glm::vec3>, a));
    for (const auto& a : deficit) cpu_deficit.push_back(std::apply(mixed_ambient_deficit<float, glm::vec3>, a));
    // One product (of a max or a difference): a few ulp of terms up to 5 (the agreement tests' 1e-5).
    const auto scale = [](std::size_t) { return 10.0; };
    CHECK(gl_test::worst_scaled(gl::map_kernel(mixed_ambient<glsl::f32, glsl::vec3>, mixed), cpu_mixed, scale) <= 1e-5);
    CHECK(gl_test::worst_scaled(gl::map_kernel(mixed_ambient_deficit<glsl::f32, glsl::vec3>, deficit), cpu_deficit, scale) <=
          1e-5);
}
