// The lightmap atlas: charts, exact element areas, layout without bleeding, blocks.
#include "radiosity_scenes.hpp"

#include <bounce/radiosity/lightmap_atlas.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <set>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

double triangle_area(const owned_scene& s, std::size_t t) {
    const auto& tri = s.triangles[t];
    const glm::dvec3 a(s.positions[tri.x]), b(s.positions[tri.y]), c(s.positions[tri.z]);
    return 0.5 * glm::length(glm::cross(b - a, c - a));
}

}  // namespace

TEST_CASE("a closed box of quads makes one chart per quad", "[radiosity][atlas]") {
    const auto box = closed_box(2.f, 0.6f, 5.f);
    const auto atlas = build_lightmap_atlas(box.view(), {.elements = 600});
    CHECK(atlas.charts.size() == 7);
    for (std::size_t q = 0; q < 7; ++q) CHECK(atlas.chart_of_triangle[2 * q] == atlas.chart_of_triangle[2 * q + 1]);
}

TEST_CASE("element areas add up to each chart's area and elements lie on their chart", "[radiosity][atlas]") {
    // Areas are exact overlaps of texel squares with the triangles, computed in double and
    // stored in float: each element is off by at most 2^-24 relative, so a chart's sum is
    // within (elements + 2) 2^-24 of its area (float accumulation of the test's own sum is
    // done in double).
    const auto scene = cornell_box();
    for (std::size_t target : {300u, 3000u}) {
        const auto atlas = build_lightmap_atlas(scene.view(), {.elements = target});
        for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
            const auto& ch = atlas.charts[c];
            double chart_area = 0;
            for (std::uint32_t k = 0; k < ch.triangle_count; ++k)
                chart_area += triangle_area(scene, atlas.chart_triangles[ch.first_triangle + k]);
            double sum = 0;
            for (std::uint32_t e = ch.first_element; e < ch.first_element + ch.element_count; ++e) {
                sum += atlas.area[e];
                CHECK(atlas.chart[e] == c);
                // On the plane: within float rounding of the coordinates (box of size 2: 1e-6).
                CHECK(std::abs(glm::dot(atlas.position[e] - ch.origin, ch.normal)) < 1e-5f);
                CHECK(atlas.normal[e] == ch.normal);
            }
            // Slivers under 1e-6 texel are dropped, at most one per texel of the chart's rectangle.
            const double texel = double(glm::length(ch.axis_u)) * double(glm::length(ch.axis_v));
            CHECK(std::abs(sum - chart_area) <=
                  (ch.element_count + 2) * 0x1p-24 * chart_area + 1e-6 * texel * ch.width * ch.height);
        }
    }
}

TEST_CASE("the element count is close to the one asked for", "[radiosity][atlas]") {
    // Secant steps on the texel size; charts with partial texels at their edges make the count
    // a little uneven. Measured: within 5% on these scenes.
    for (std::size_t target : {500u, 2000u, 10000u}) {
        const auto a = build_lightmap_atlas(cornell_box().view(), {.elements = target});
        INFO("target " << target << ", got " << a.size());
        CHECK(std::abs(double(a.size()) - double(target)) <= 0.05 * double(target));
    }
}

TEST_CASE("the atlas never mixes charts: texels, padding and blocks stay in their chart", "[radiosity][atlas]") {
    const auto scene = cornell_box();
    const int padding = 2;
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 2000, .padding = padding, .block_texels = 4});
    // Padded rectangles are disjoint and inside the atlas.
    std::vector<int> owner(std::size_t(atlas.width) * atlas.height, -1);
    for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
        const auto& ch = atlas.charts[c];
        REQUIRE(ch.atlas_x >= std::uint32_t(padding));
        REQUIRE(ch.atlas_y >= std::uint32_t(padding));
        REQUIRE(ch.atlas_x + ch.width + padding <= atlas.width);
        REQUIRE(ch.atlas_y + ch.height + padding <= atlas.height);
        for (std::uint32_t y = ch.atlas_y - padding; y < ch.atlas_y + ch.height + padding; ++y)
            for (std::uint32_t x = ch.atlas_x - padding; x < ch.atlas_x + ch.width + padding; ++x) {
                int& o = owner[std::size_t(y) * atlas.width + x];
                CHECK(o == -1);
                o = int(c);
                // Every texel of the padded rectangle points to an element of this chart.
                const std::int32_t e = atlas.element_at(x, y);
                REQUIRE(e >= 0);
                CHECK(atlas.chart[std::size_t(e)] == c);
            }
    }
    // Texels outside every chart's rectangle point nowhere; elements own distinct texels.
    std::set<std::pair<std::uint32_t, std::uint32_t>> seen;
    for (std::size_t e = 0; e < atlas.size(); ++e) {
        CHECK(seen.emplace(atlas.texel[e].x, atlas.texel[e].y).second);
        CHECK(atlas.element_at(atlas.texel[e].x, atlas.texel[e].y) == std::int32_t(e));
    }
    for (std::uint32_t y = 0; y < atlas.height; ++y)
        for (std::uint32_t x = 0; x < atlas.width; ++x)
            if (owner[std::size_t(y) * atlas.width + x] < 0) CHECK(atlas.element_at(x, y) == -1);
    // Blocks: contiguous, covering every element once, one chart each, within a 4 x 4 square.
    REQUIRE(atlas.block_first.front() == 0);
    REQUIRE(atlas.block_first.back() == atlas.size());
    for (std::size_t k = 0; k < atlas.blocks(); ++k) {
        const std::uint32_t i0 = atlas.block_first[k], i1 = atlas.block_first[k + 1];
        REQUIRE(i0 < i1);
        glm::uvec2 lo(~0u), hi(0u);
        for (std::uint32_t i = i0; i < i1; ++i) {
            CHECK(atlas.chart[i] == atlas.chart[i0]);
            lo = glm::min(lo, atlas.texel[i]);
            hi = glm::max(hi, atlas.texel[i]);
        }
        CHECK(hi.x - lo.x < 4u);
        CHECK(hi.y - lo.y < 4u);
    }
}

TEST_CASE("atlas coordinates of a chart's corners land on its texel rectangle", "[radiosity][atlas]") {
    const auto box = closed_box(1.f, 0.5f, 1.f);
    const auto atlas = build_lightmap_atlas(box.view(), {.elements = 500});
    for (std::size_t t = 0; t < box.triangles.size(); ++t) {
        const std::uint32_t c = atlas.chart_of_triangle[t];
        const auto& ch = atlas.charts[c];
        for (int k = 0; k < 3; ++k) {
            const glm::vec2 uv = atlas.atlas_coords(c, box.positions[box.triangles[t][k]]);
            // Quads fit their rectangle exactly: corners at its corners, to float rounding.
            CHECK(uv.x >= float(ch.atlas_x) - 1e-3f);
            CHECK(uv.x <= float(ch.atlas_x + ch.width) + 1e-3f);
            CHECK(uv.y >= float(ch.atlas_y) - 1e-3f);
            CHECK(uv.y <= float(ch.atlas_y + ch.height) + 1e-3f);
        }
    }
}

TEST_CASE("each element's position maps into its own texel, and corner UVs are atlas coordinates",
          "[radiosity][atlas]") {
    // An element's position is the centroid of its texel's overlap with the chart, which lies
    // inside the texel: its atlas coordinates fall in that texel (to float rounding of a
    // coordinate below 1000: 1e-4 texel).
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 1500});
    for (std::size_t e = 0; e < atlas.size(); ++e) {
        const glm::vec2 c = atlas.atlas_coords(atlas.chart[e], atlas.position[e]);
        CHECK(c.x >= float(atlas.texel[e].x) - 1e-4f);
        CHECK(c.x <= float(atlas.texel[e].x + 1) + 1e-4f);
        CHECK(c.y >= float(atlas.texel[e].y) - 1e-4f);
        CHECK(c.y <= float(atlas.texel[e].y + 1) + 1e-4f);
    }
    const auto uv = atlas.corner_uvs(scene.view());
    REQUIRE(uv.size() == 3 * scene.triangles.size());
    for (std::size_t t = 0; t < scene.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            const glm::vec2 expected = atlas.atlas_coords(atlas.chart_of_triangle[t], scene.positions[scene.triangles[t][k]]) /
                                       glm::vec2(float(atlas.width), float(atlas.height));
            CHECK(uv[3 * t + std::size_t(k)] == expected);
        }
    CHECK_THROWS_AS(atlas.corner_uvs(closed_box(1.f, 0.5f, 1.f).view()), parameter_error);
}

TEST_CASE("emitting materials give elements the radiosity pi L_e", "[radiosity][atlas]") {
    const auto box = closed_box(1.f, 0.5f, 3.f);
    const auto atlas = build_lightmap_atlas(box.view(), {.elements = 300});
    int emitting = 0;
    for (std::size_t e = 0; e < atlas.size(); ++e)
        if (atlas.emission[e].x > 0.f) {
            ++emitting;
            CHECK(atlas.emission[e] == glm::vec3(float(3.0 * std::numbers::pi)));
        }
    CHECK(emitting > 0);
}

TEST_CASE("bad atlas options and scenes raise parameter_error naming them", "[radiosity][atlas][errors]") {
    const auto box = closed_box(1.f, 0.5f, 1.f);
    const auto named = [&](const atlas_options& o, const char* name) {
        try {
            build_lightmap_atlas(box.view(), o);
            FAIL("no exception");
        } catch (const parameter_error& e) {
            CHECK(e.parameter() == name);
        }
    };
    named({.elements = 0}, "atlas_options.elements");
    named({.padding = -1}, "atlas_options.padding");
    named({.block_texels = 0}, "atlas_options.block_texels");
    named({.coplanar_degrees = 90}, "atlas_options.coplanar_degrees");
    auto broken = box;
    broken.material_of[3] = 99;
    CHECK_THROWS_AS(build_lightmap_atlas(broken.view()), parameter_error);
    owned_scene flat;
    const auto m = flat.add_material(glm::vec3(0.5f));
    flat.add_quad({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, m);  // zero area
    try {
        build_lightmap_atlas(flat.view());
        FAIL("no exception");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "scene.triangles");
    }
}
