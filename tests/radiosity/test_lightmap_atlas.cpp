// The lightmap atlas: charts, exact element areas, layout without bleeding, blocks.
#include "radiosity_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/cpu/radiosity_item_buffer.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/radiosity/rebake.hpp>
#include <bounce/radiosity/shooters.hpp>
#include <bounce/radiosity/subdivision.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
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
                // On a planar chart, on the plane: within float rounding of the coordinates
                // (box of size 2: 1e-6). The left wall, 0.99 to 1.02 in x, is one curved
                // chart (its two quads 0.4 degrees apart): its elements lie on its triangles
                // (a test case below checks that on curved charts).
                if (!ch.planar) continue;
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
    named({.cone_degrees = 90}, "atlas_options.cone_degrees");
    named({.cone_degrees = -1}, "atlas_options.cone_degrees");
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

// Charts that follow surfaces (issue 30): generated meshes of many small triangles.
namespace {

// A grid mesh of nu x nv quads (two triangles each, vertices shared) over (s, t) in [0, 1]^2,
// mapped to 3D by f; counter-clockwise seen from the side f's ds x dt points to.
template <class F>
void add_grid(owned_scene& s, int nu, int nv, std::uint32_t m, F&& f) {
    const auto base = std::uint32_t(s.positions.size());
    for (int j = 0; j <= nv; ++j)
        for (int i = 0; i <= nu; ++i) s.positions.push_back(f(float(i) / float(nu), float(j) / float(nv)));
    const auto at = [&](int i, int j) { return base + std::uint32_t(j * (nu + 1) + i); };
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            s.triangles.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
            s.triangles.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
            s.material_of.insert(s.material_of.end(), {m, m});
        }
}

// Half a cylinder of radius 1 about the z axis (angles 0 to pi), `around` x `along` quads,
// facing outwards.
owned_scene half_cylinder(int around, int along) {
    owned_scene s;
    const auto m = s.add_material(glm::vec3(0.5f));
    add_grid(s, along, around, m, [](float a, float b) {
        const float phi = b * float(std::numbers::pi);
        return glm::vec3(std::cos(phi), std::sin(phi), 2.f * a);
    });
    return s;
}

// Two turns of a spiral ramp (a helicoid strip between radii 1 and 2, rising 0.3 a turn):
// its normals stay within 10 degrees of +z, yet a projection onto one plane folds its turns
// over each other.
owned_scene spiral_ramp() {
    owned_scene s;
    const auto m = s.add_material(glm::vec3(0.5f));
    add_grid(s, 4, 96, m, [](float a, float b) {
        const float phi = b * 4.f * float(std::numbers::pi), r = 1.f + a;
        return glm::vec3(r * std::cos(phi), r * std::sin(phi), 0.3f * phi / (2.f * float(std::numbers::pi)));
    });
    return s;
}

// The worst angle between a chart's triangles' normals and its normal (degrees).
double chart_tilt(const owned_scene& s, const lightmap_atlas& atlas, std::size_t c) {
    const auto& ch = atlas.charts[c];
    double worst = 0;
    for (std::uint32_t k = 0; k < ch.triangle_count; ++k) {
        const auto& t = s.triangles[atlas.chart_triangles[ch.first_triangle + k]];
        const glm::dvec3 a(s.positions[t.x]), b(s.positions[t.y]), cc(s.positions[t.z]);
        const glm::dvec3 n = glm::normalize(glm::cross(b - a, cc - a));
        worst = std::max(worst, std::acos(std::clamp(glm::dot(n, glm::dvec3(ch.normal)), -1.0, 1.0)) * 180 / std::numbers::pi);
    }
    return worst;
}

// Whether two of a chart's triangles, projected onto its texel grid, overlap (brute force).
bool chart_overlaps(const owned_scene& s, const lightmap_atlas& atlas, std::size_t c) {
    const auto& ch = atlas.charts[c];
    std::vector<std::array<glm::dvec2, 3>> q;
    for (std::uint32_t k = 0; k < ch.triangle_count; ++k) {
        const auto& t = s.triangles[atlas.chart_triangles[ch.first_triangle + k]];
        std::array<glm::dvec2, 3> p;
        for (int m = 0; m < 3; ++m) p[std::size_t(m)] = glm::dvec2(atlas.atlas_coords(std::uint32_t(c), s.positions[t[m]]));
        q.push_back(p);
    }
    for (std::size_t i = 0; i < q.size(); ++i)
        for (std::size_t j = i + 1; j < q.size(); ++j)
            if (detail::triangles_overlap(q[i], q[j])) return true;
    return false;
}

// The distance from p to triangle t of s (brute force over the triangle's plane and edges).
double distance_to_triangle(const owned_scene& s, std::uint32_t t, const glm::dvec3& p) {
    const auto& tri = s.triangles[t];
    const glm::dvec3 a(s.positions[tri.x]), b(s.positions[tri.y]), c(s.positions[tri.z]);
    const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    const glm::dvec3 q = p - n * glm::dot(p - a, n);
    const auto inside = [&](glm::dvec3 u, glm::dvec3 v) { return glm::dot(glm::cross(v - u, q - u), n) >= 0; };
    if (inside(a, b) && inside(b, c) && inside(c, a)) return std::abs(glm::dot(p - a, n));
    const auto seg = [&](glm::dvec3 u, glm::dvec3 v) {
        const double h = std::clamp(glm::dot(p - u, v - u) / glm::dot(v - u, v - u), 0.0, 1.0);
        return glm::length(p - (u + (v - u) * h));
    };
    return std::min({seg(a, b), seg(b, c), seg(c, a)});
}

}  // namespace

TEST_CASE("charts merge coplanar neighbours into one chart, and a curved surface into charts of many triangles",
          "[radiosity][atlas][charts]") {
    owned_scene floor;
    const auto m = floor.add_material(glm::vec3(0.5f));
    add_grid(floor, 40, 30, m, [](float a, float b) { return glm::vec3(4.f * a, 3.f * b, 0.f); });
    const auto flat = build_lightmap_atlas(floor.view(), {.elements = 500});
    CHECK(flat.charts.size() == 1);
    CHECK(flat.charts[0].planar);

    // 24 x 20 quads around half a cylinder: 7.5 degrees a quad. Planar charts (before charts
    // followed surfaces) made 24, one per flat strip along the axis.
    const auto cyl = half_cylinder(24, 20);
    const auto atlas = build_lightmap_atlas(cyl.view(), {.elements = 2000});
    INFO("charts " << atlas.charts.size());
    CHECK(atlas.charts.size() <= 6);
    CHECK(atlas.statistics.curved_charts == atlas.charts.size());
    CHECK(atlas.statistics.stretch_max > 1.0);
    CHECK(atlas.statistics.stretch_max <= 1.0 / std::cos(30.0 * std::numbers::pi / 180.0) + 1e-9);
    // Planar charts only (cone 0): one per flat strip, as before.
    CHECK(build_lightmap_atlas(cyl.view(), {.elements = 2000, .cone_degrees = 0}).charts.size() == 24);
}

TEST_CASE("the lights' samples over a curved chart's texel lie on the surface, not on the chart's plane",
          "[radiosity][atlas][charts]") {
    // Half a cylinder of radius 1 in charts of up to 60 degrees: a chart's plane leaves the
    // surface by up to 0.13, a texel (about 0.06 here) bends away from its tangent plane by
    // about (0.06 / 2)^2 / 2 = 5e-4.
    const auto cyl = half_cylinder(24, 20);
    const auto atlas = build_lightmap_atlas(cyl.view(), {.elements = 2000});
    const auto whole = whole_texels(atlas);
    std::size_t samples = 0;
    double worst = 0, worst_on_plane = 0;
    for (std::uint32_t e = 0; e < atlas.size(); ++e) {
        if (!whole[e]) continue;
        const auto& ch = atlas.charts[atlas.chart[e]];
        for (int a = 0; a < 16; ++a) {
            const glm::vec3 q = light_sample_point(atlas, e, a % 4, a / 4, 4);
            const auto to_surface = [&](const glm::vec3& x) {
                double d = 1e30;
                for (std::uint32_t k = 0; k < ch.triangle_count; ++k)
                    d = std::min(d, distance_to_triangle(cyl, atlas.chart_triangles[ch.first_triangle + k], glm::dvec3(x)));
                return d;
            };
            worst = std::max(worst, to_surface(q));
            const glm::vec2 t = glm::vec2(atlas.texel[e] - glm::uvec2(ch.atlas_x, ch.atlas_y)) +
                                (glm::vec2(float(a % 4), float(a / 4)) + 0.5f) / 4.f;
            const glm::vec3 p = ch.origin + ch.axis_u * t.x + ch.axis_v * t.y;  // on the plane
            worst_on_plane = std::max(worst_on_plane, to_surface(p));
            ++samples;
        }
    }
    INFO("samples " << samples << ", worst " << worst << ", on the plane " << worst_on_plane);
    CHECK(samples > 1000);
    CHECK(worst < 2e-3);
    CHECK(worst_on_plane > 0.02);  // what the samples were before the lift
}

TEST_CASE("charts stop at the cone: no triangle leaves its chart's cone", "[radiosity][atlas][charts]") {
    const auto cyl = half_cylinder(36, 10);  // 5 degrees a quad over 180 degrees
    for (double cone : {10.0, 30.0, 45.0}) {
        const auto atlas = build_lightmap_atlas(cyl.view(), {.elements = 1000, .cone_degrees = cone});
        INFO("cone " << cone << ", charts " << atlas.charts.size());
        // Every chart within the cone of its normal, so 180 degrees need at least 180 / (2 cone) charts.
        CHECK(double(atlas.charts.size()) >= std::floor(180.0 / (2.0 * cone)));
        for (std::size_t c = 0; c < atlas.charts.size(); ++c) CHECK(chart_tilt(cyl, atlas, c) <= cone + 1e-6);
        CHECK(atlas.statistics.cone_max_degrees <= cone + 1e-6);
    }
    // A cone of 0 keeps the planar charts of before: one per triangle pair at most.
    const auto planar = build_lightmap_atlas(cyl.view(), {.elements = 1000, .cone_degrees = 0});
    CHECK(planar.charts.size() >= 36);
}

TEST_CASE("a chart never folds over itself: a spiral ramp within the cone is cut where its turns overlap",
          "[radiosity][atlas][charts]") {
    const auto ramp = spiral_ramp();
    const auto atlas = build_lightmap_atlas(ramp.view(), {.elements = 3000});
    INFO("charts " << atlas.charts.size() << ", refused " << atlas.statistics.overlaps_refused);
    CHECK(atlas.charts.size() >= 2);     // two turns cannot share one plane
    CHECK(atlas.charts.size() <= 8);     // but not a chart per triangle or quad (768 triangles)
    CHECK(atlas.statistics.overlaps_refused > 0);
    for (std::size_t c = 0; c < atlas.charts.size(); ++c) CHECK_FALSE(chart_overlaps(ramp, atlas, c));
    // And no texel holds two layers: every element's point lies on its chart's surface.
}

TEST_CASE("elements of curved charts lie on their triangles and add up to the surface's area",
          "[radiosity][atlas][charts]") {
    for (const auto& s : {half_cylinder(24, 20), spiral_ramp()}) {
        const auto atlas = build_lightmap_atlas(s.view(), {.elements = 1500});
        double scene_area = 0, sum = 0;
        for (std::size_t t = 0; t < s.triangles.size(); ++t) scene_area += triangle_area(s, t);
        for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
            const auto& ch = atlas.charts[c];
            for (std::uint32_t e = ch.first_element; e < ch.first_element + ch.element_count; ++e) {
                sum += atlas.area[e];
                double nearest = 1e30;
                for (std::uint32_t k = 0; k < ch.triangle_count; ++k)
                    nearest = std::min(nearest, distance_to_triangle(s, atlas.chart_triangles[ch.first_triangle + k],
                                                                     glm::dvec3(atlas.position[e])));
                CHECK(nearest < 1e-5);  // on the surface, not on the chart's plane (up to 0.13 off it)
                CHECK(std::abs(glm::length(atlas.normal[e]) - 1.f) < 1e-5f);
                CHECK(glm::dot(atlas.normal[e], ch.normal) > 0.5f);
                // The element's point maps into its own texel.
                const glm::vec2 uv = atlas.atlas_coords(std::uint32_t(c), atlas.position[e]);
                CHECK(std::abs(uv.x - (float(atlas.texel[e].x) + 0.5f)) <= 0.5f + 1e-3f);
                CHECK(std::abs(uv.y - (float(atlas.texel[e].y) + 0.5f)) <= 0.5f + 1e-3f);
            }
        }
        CHECK(std::abs(sum - scene_area) <= 1e-5 * scene_area);
    }
}

TEST_CASE("the element budget holds within 10% on a scene of many small triangles", "[radiosity][atlas][charts]") {
    // A floor, and 60 small spheres (480 triangles each, 2 cm across) standing on it: 28,800
    // small triangles. Before charts followed surfaces, each flat quad of a sphere was a chart
    // of one element at least: 14,401 elements or more for any count asked.
    owned_scene s;
    const auto m = s.add_material(glm::vec3(0.5f));
    const auto ball = s.add_material(glm::vec3(0.7f, 0.2f, 0.2f));
    s.add_quad({0, 0, 0}, {4, 0, 0}, {4, 4, 0}, {0, 4, 0}, m);
    for (int k = 0; k < 60; ++k) {
        const glm::vec3 centre(0.3f + 0.5f * float(k % 8), 0.3f + 0.5f * float(k / 8), 0.01f);
        add_grid(s, 24, 10, ball, [&](float a, float b) {
            const float phi = 2.f * float(std::numbers::pi) * a, theta = float(std::numbers::pi) * (1.f - b);
            return centre + 0.01f * glm::vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
        });
    }
    for (std::size_t asked : {3000u, 10000u}) {
        const auto atlas = build_lightmap_atlas(s.view(), {.elements = asked});
        INFO("asked " << asked << ", made " << atlas.size() << ", charts " << atlas.charts.size());
        CHECK(std::abs(double(atlas.size()) - double(asked)) <= 0.10 * double(asked));
        // Every chart has an element.
        for (const auto& ch : atlas.charts) CHECK(ch.element_count >= 1);
    }
    // Planar charts only (cone 0, as before) and no clusters: a chart per flat quad, the
    // budget missed; clusters of the quads smaller than a texel keep it.
    CHECK(build_lightmap_atlas(s.view(), {.elements = 10000, .cone_degrees = 0, .clusters = tiny_chart_clusters::never})
              .size() > 14000);
    const auto planar = build_lightmap_atlas(s.view(), {.elements = 10000, .cone_degrees = 0});
    CHECK(std::abs(double(planar.size()) - 10000.0) <= 0.10 * 10000.0);
    CHECK(planar.statistics.clusters > 0);
}

TEST_CASE("tiny separate charts share elements in clusters: the budget holds, each triangle in one texel",
          "[radiosity][atlas][clusters]") {
    const auto s = tiny_triangles_under_a_lamp();
    const auto area_of = [&](std::uint32_t t) { return triangle_area(s, t); };
    for (std::size_t asked : {200u, 1000u}) {
        const auto atlas = build_lightmap_atlas(s.view(), {.elements = asked});
        INFO("asked " << asked << ", made " << atlas.size() << ", clusters " << atlas.statistics.clusters);
        CHECK(std::abs(double(atlas.size()) - double(asked)) <= 0.10 * double(asked));
        CHECK(atlas.statistics.clusters > 0);
        std::vector<double> chart_area(atlas.charts.size(), 0.0);
        const auto uv = atlas.corner_uvs(s.view());
        for (std::uint32_t t = 0; t < s.triangles.size(); ++t) {
            const std::uint32_t c = atlas.chart_of_triangle[t];
            REQUIRE(c != lightmap_atlas::none);
            chart_area[c] += area_of(t);
            const lightmap_chart& ch = atlas.charts[c];
            if (!ch.cluster()) continue;
            // Every corner in the cluster's one texel, whose element is the cluster's.
            for (int k = 0; k < 3; ++k) {
                const glm::vec2 p = uv[3 * t + std::size_t(k)] * glm::vec2(float(atlas.width), float(atlas.height));
                CHECK(p.x >= float(ch.atlas_x) - 1e-3f);
                CHECK(p.x <= float(ch.atlas_x + 1) + 1e-3f);
                CHECK(p.y >= float(ch.atlas_y) - 1e-3f);
                CHECK(p.y <= float(ch.atlas_y + 1) + 1e-3f);
            }
            CHECK(atlas.element_at(ch.atlas_x, ch.atlas_y) == std::int32_t(ch.first_element));
        }
        std::set<std::uint32_t> material_of_cluster;
        for (std::uint32_t c = 0; c < atlas.charts.size(); ++c) {
            const lightmap_chart& ch = atlas.charts[c];
            if (!ch.cluster()) continue;
            REQUIRE(ch.element_count == 1);
            CHECK(ch.width == 1);
            CHECK(ch.height == 1);
            CHECK(ch.clustered_charts >= 2);
            CHECK(ch.triangle_count == ch.clustered_charts);  // a chart per triangle here
            const std::uint32_t e = ch.first_element;
            // Its area is its triangles' sum; its point lies on one of them; one material.
            CHECK(std::abs(double(atlas.area[e]) - chart_area[c]) <= 1e-5 * chart_area[c]);
            CHECK(ch.tilt_degrees <= 30.f + 1e-3f);
            double nearest = 1;
            for (std::uint32_t k = 0; k < ch.triangle_count; ++k) {
                const std::uint32_t t = atlas.chart_triangles[ch.first_triangle + k];
                CHECK(s.material_of[t] == ch.material);
                const glm::vec3 a = s.positions[s.triangles[t].x], b = s.positions[s.triangles[t].y],
                                cc = s.positions[s.triangles[t].z];
                const glm::vec3 n = glm::normalize(glm::cross(b - a, cc - a));
                const glm::vec3 q = atlas.position[e];
                const float plane = std::abs(glm::dot(q - a, n));
                const float u = glm::dot(glm::cross(b - a, q - a), n), v = glm::dot(glm::cross(cc - b, q - b), n),
                            w = glm::dot(glm::cross(a - cc, q - cc), n);
                const float tol = -1e-9f;
                if (plane < 1e-6f && u >= tol && v >= tol && w >= tol) nearest = 0;
            }
            CHECK(nearest == 0);
            CHECK(glm::dot(atlas.normal[e], ch.normal) > 0.999f);
        }
        // A cluster never mixes the floor's and the wall's triangles (90 degrees apart).
        for (const auto& ch : atlas.charts) {
            if (!ch.cluster()) continue;
            std::set<std::uint32_t> mats;
            for (std::uint32_t k = 0; k < ch.triangle_count; ++k) mats.insert(s.material_of[atlas.chart_triangles[ch.first_triangle + k]]);
            CHECK(mats.size() == 1);
        }
        // The element areas add up to the scene's area.
        double sum = 0, scene_area = 0;
        for (const float a : atlas.area) sum += a;
        for (std::uint32_t t = 0; t < s.triangles.size(); ++t) scene_area += area_of(t);
        CHECK(std::abs(sum - scene_area) <= 1e-4 * scene_area);
    }
    // Without clusters a chart per triangle: 3,751 elements at least, whatever is asked.
    CHECK(build_lightmap_atlas(s.view(), {.elements = 200, .clusters = tiny_chart_clusters::never}).size() > 3750);
    // A scene whose budget holds without clusters makes none unless asked for them.
    const auto box = closed_box(2.f, 0.6f, 5.f);
    CHECK(build_lightmap_atlas(box.view(), {.elements = 600}).statistics.clusters == 0);
}

TEST_CASE("a cluster's texel is never sampled as a whole texel, and subdivision refuses to split it",
          "[radiosity][atlas][clusters]") {
    const auto s = tiny_triangles_under_a_lamp();
    const auto atlas = build_lightmap_atlas(s.view(), {.elements = 200});
    const auto whole = whole_texels(atlas);
    std::uint32_t cluster_block = std::numeric_limits<std::uint32_t>::max();
    for (std::uint32_t k = 0; k < atlas.blocks(); ++k)
        if (atlas.charts[atlas.chart[atlas.block_first[k]]].cluster()) {
            cluster_block = k;
            CHECK(atlas.block_first[k + 1] == atlas.block_first[k] + 1);
            CHECK(whole[atlas.block_first[k]] == 0);
        }
    REQUIRE(cluster_block < atlas.blocks());
    const std::vector<std::uint32_t> split{cluster_block};
    CHECK_THROWS_AS(refine_lightmap_atlas(s.view(), atlas, split), parameter_error);
    CHECK_THROWS_WITH(refine_lightmap_atlas(s.view(), atlas, split), Catch::Contains("atlas_options::clusters"));
    // A re-bake moving part of a cluster is refused, naming the option; the whole cluster moves.
    const lightmap_chart& ch = atlas.charts[atlas.chart[atlas.block_first[cluster_block]]];
    const std::vector<std::uint32_t> part{atlas.chart_triangles[ch.first_triangle]};
    CHECK_THROWS_AS(moved_charts(atlas, part), parameter_error);
    CHECK_THROWS_WITH(moved_charts(atlas, part), Catch::Contains("atlas_options::clusters"));
    const auto all = std::span(atlas.chart_triangles).subspan(ch.first_triangle, ch.triangle_count);
    CHECK(moved_charts(atlas, all)[atlas.chart[atlas.block_first[cluster_block]]] == 1);
}

TEST_CASE("a solve over clusters of tiny charts conserves energy and lights every triangle",
          "[radiosity][atlas][clusters][solve]") {
    const auto s = tiny_triangles_under_a_lamp();
    const auto atlas = build_lightmap_atlas(s.view(), {.elements = 300});
    REQUIRE(atlas.statistics.clusters > 0);
    cpu::progressive_radiosity solver(s.view(), atlas, cpu::item_buffer_visibility(s.view(), atlas, {.resolution = 128}));
    double unshot = solver.unshot_fraction();
    radiosity_solve_options o;
    o.converge = 0.99;
    o.progress = [&](const radiosity_progress& p) {
        CHECK(p.unshot_fraction <= unshot * (1 + 1e-6));  // the unshot power never rises
        CHECK(p.unshot_fraction >= 0);
        CHECK(solver.last_shot().top_share <= 1 + 1e-6);
        unshot = p.unshot_fraction;
        return true;
    };
    REQUIRE_NOTHROW(solver.solve(o));
    // Energy: absorbed + unshot + escaped = emitted, per channel.
    const glm::dvec3 balance = solver.absorbed_power() + solver.unshot_power() + solver.escaped_power() - solver.emitted_power();
    for (int c = 0; c < 3; ++c) CHECK(std::abs(balance[c]) <= 1e-4 * solver.emitted_power()[c]);
    // Every tiny triangle's element (the texel its centroid maps to) is lit.
    CHECK(unlit_triangles(s, atlas, solver.display_radiosity(), 2) == 0);  // after the lamp's two
}
