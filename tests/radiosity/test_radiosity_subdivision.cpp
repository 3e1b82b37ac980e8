// Adaptive subdivision: the second-difference test, conservative splitting of leaves, and
// the solver carrying on after it.
#include "radiosity_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/radiosity/subdivision.hpp>

#include <catch2/catch.hpp>

#include <numeric>

#include <glm/vector_relational.hpp>

using namespace bounce;
using namespace bounce::radiosity_test;

TEST_CASE("the second difference flags a step, not a linear ramp", "[radiosity][subdivision][kernel]") {
    CHECK(radiosity_second_difference<double>(1, 2, 3, 1e-9) == 0.0);    // ramp
    CHECK(radiosity_second_difference<double>(1, 1, 5, 1.0) == 1.0);     // step
    CHECK(radiosity_second_difference<double>(2, 1, 2, 1.5) == 1.0);     // dip
    CHECK(radiosity_second_difference<double>(2, 1, 2, 2.5) == 0.0);
}

TEST_CASE("splitting a leaf conserves each element's area and stays on its chart", "[radiosity][subdivision]") {
    // Children's exact overlaps are rescaled to add up to their parent's area: to float
    // rounding of each child's area (2^-24 relative, at most 4 per 2 x 2 split... per texel
    // of the grid: children of one parent are at most 4).
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 1500, .block_texels = 4});
    std::vector<std::uint32_t> all(atlas.blocks());
    std::iota(all.begin(), all.end(), 0u);
    const auto r = refine_lightmap_atlas(scene.view(), atlas, all);
    const lightmap_atlas& fine = r.atlas;
    CHECK(fine.size() >= 3 * atlas.size());
    CHECK(fine.size() <= 4 * atlas.size());
    CHECK(fine.blocks() >= atlas.blocks());
    std::vector<double> sum(atlas.size(), 0.0);
    for (std::size_t i = 0; i < fine.size(); ++i) {
        const std::uint32_t p = r.parent[i];
        sum[p] += fine.area[i];
        CHECK(fine.chart[i] == atlas.chart[p]);
        CHECK(fine.texel[i] == atlas.texel[p]);  // a child lies in its parent's base texel
        const auto& ch = fine.charts[fine.chart[i]];
        if (ch.planar) {
            CHECK(std::abs(glm::dot(fine.position[i] - ch.origin, ch.normal)) < 1e-5f);
            continue;
        }
        // A curved chart (the left wall, 0.4 degrees between its quads): on one of its
        // triangles' planes, within that triangle's bounding box.
        bool on = false;
        for (std::uint32_t k = 0; k < ch.triangle_count; ++k) {
            const auto& t = scene.triangles[fine.chart_triangles[ch.first_triangle + k]];
            const glm::vec3 a = scene.positions[t.x], b = scene.positions[t.y], c = scene.positions[t.z];
            const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a)), q = fine.position[i];
            const glm::vec3 lo = glm::min(a, glm::min(b, c)) - 1e-5f, hi = glm::max(a, glm::max(b, c)) + 1e-5f;
            on = on || (std::abs(glm::dot(q - a, n)) < 1e-5f && glm::all(glm::greaterThanEqual(q, lo)) &&
                        glm::all(glm::lessThanEqual(q, hi)));
        }
        CHECK(on);
    }
    for (std::size_t e = 0; e < atlas.size(); ++e) CHECK(sum[e] == Approx(atlas.area[e]).epsilon(4 * 0x1p-24));
    for (std::size_t k = 0; k < fine.blocks(); ++k) {
        CHECK(fine.block_level[k] == 1);
        for (std::uint32_t i = fine.block_first[k]; i < fine.block_first[k + 1]; ++i)
            CHECK(fine.chart[i] == fine.chart[fine.block_first[k]]);
    }
    // Every atlas texel that pointed to an element points to one of its children.
    for (std::uint32_t y = 0; y < atlas.height; ++y)
        for (std::uint32_t x = 0; x < atlas.width; ++x) {
            const std::int32_t before = atlas.element_at(x, y), after = fine.element_at(x, y);
            CHECK((before < 0) == (after < 0));
            if (after >= 0) CHECK(fine.chart[std::size_t(after)] == atlas.chart[std::size_t(before)]);
        }
    // Splitting again only the first block of the fine atlas reaches level 2 there.
    const std::uint32_t first[] = {0};
    const auto again = refine_lightmap_atlas(scene.view(), fine, first);
    CHECK(again.atlas.block_level[0] == 2);
    CHECK(again.atlas.blocks() >= fine.blocks() + 1);
}

TEST_CASE("fine lightmaps show each subdivided element in the cells it covers", "[radiosity][subdivision]") {
    // A closed box (rectangular charts: every texel whole) with every leaf split once: at
    // level 1 each fine texel is exactly its child element's value; at level 0 each base texel
    // is the area-weighted mean of its children; level 2 repeats level 1 in 2 x 2 squares.
    const auto box = closed_box(1.f, 0.5f, 1.f);
    const auto atlas = build_lightmap_atlas(box.view(), {.elements = 300, .block_texels = 4});
    std::vector<std::uint32_t> all(atlas.blocks());
    std::iota(all.begin(), all.end(), 0u);
    const auto fine = refine_lightmap_atlas(box.view(), atlas, all).atlas;
    std::vector<float> v(fine.size());
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = float(i % 97) + 1.f;
    const auto one = fine.to_fine_texels(std::span<const float>(v), 1);
    const auto two = fine.to_fine_texels(std::span<const float>(v), 2);
    const auto zero = fine.to_fine_texels(std::span<const float>(v), 0);
    std::vector<int> hits(one.width() * one.height(), 0);
    for (std::size_t i = 0; i < fine.size(); ++i) {
        const glm::vec2 c = fine.atlas_coords(fine.chart[i], fine.position[i]) * 2.f;  // level-1 coordinates
        const std::size_t x = std::size_t(c.x), y = std::size_t(c.y);
        CHECK(one(x, y) == v[i]);
        ++hits[y * one.width() + x];
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) CHECK(two(2 * x + std::size_t(dx), 2 * y + std::size_t(dy)) == v[i]);
    }
    for (const int h : hits) CHECK(h <= 1);
    for (std::size_t e = 0; e < atlas.size(); ++e) {
        double s = 0, a = 0;
        for (std::size_t i = 0; i < fine.size(); ++i)
            if (fine.texel[i] == atlas.texel[e]) {
                s += double(v[i]) * fine.area[i];
                a += fine.area[i];
            }
        CHECK(zero(atlas.texel[e].x, atlas.texel[e].y) == Approx(s / a).epsilon(1e-6));
    }
}

TEST_CASE("the test splits the leaves a step crosses and leaves ramps alone", "[radiosity][subdivision]") {
    // A floor of 16 x 16 texels in one 16 x 16 leaf... as four leaves of 8 x 8: a radiosity
    // ramp along x flags nothing; a step at x = 0.3 of the floor flags the leaves it crosses.
    owned_scene s;
    const auto m = s.add_material(glm::vec3(0.5f));
    s.add_quad({0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, m);
    const auto atlas = build_lightmap_atlas(s.view(), {.elements = 256, .block_texels = 8});
    REQUIRE(atlas.size() == 256);
    REQUIRE(atlas.blocks() == 4);
    std::vector<glm::vec3> ramp(atlas.size()), step(atlas.size());
    for (std::size_t i = 0; i < atlas.size(); ++i) {
        ramp[i] = glm::vec3(1.f + 3.f * atlas.position[i].x);
        step[i] = glm::vec3(atlas.position[i].x < 0.3f ? 1.f : 4.f);
    }
    const subdivision_options o{.threshold = 0.25, .min_texels = 2, .max_level = 1};
    CHECK(blocks_to_subdivide(atlas, std::span<const glm::vec3>(ramp), o).empty());
    const auto split = blocks_to_subdivide(atlas, std::span<const glm::vec3>(step), o);
    REQUIRE(split.size() == 2);  // the two leaves (of four) the line x = 0.3 crosses
    for (const std::uint32_t k : split) {
        bool low = false, high = false;
        for (std::uint32_t i = atlas.block_first[k]; i < atlas.block_first[k + 1]; ++i) {
            low = low || atlas.position[i].x < 0.3f;
            high = high || atlas.position[i].x >= 0.3f;
        }
        CHECK((low && high));
    }
    // At max_level nothing splits any more.
    const auto fine = refine_lightmap_atlas(s.view(), atlas, split).atlas;
    std::vector<glm::vec3> fine_step(fine.size());
    for (std::size_t i = 0; i < fine.size(); ++i) fine_step[i] = glm::vec3(fine.position[i].x < 0.3f ? 1.f : 4.f);
    for (const std::uint32_t k : blocks_to_subdivide(fine, std::span<const glm::vec3>(fine_step), o))
        CHECK(fine.block_level[k] == 0);
}

TEST_CASE("subdividing during a solve keeps the power balance and refines where the light changes",
          "[radiosity][subdivision][solver]") {
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 2000, .block_texels = 8});
    cpu::progressive_radiosity solver(scene.view(), atlas,
                                      cpu::item_buffer_visibility(scene.view(), atlas, {.resolution = 128}));
    const subdivision_options o{.threshold = 0.25, .min_texels = 2, .max_level = 2};
    std::size_t splits = 0;
    for (int s = 0; s < 60; ++s) {
        solver.step();
        const glm::dvec3 before = solver.unshot_power();
        std::vector<glm::vec3> b(solver.radiosity().begin(), solver.radiosity().end());
        double power_before = 0;
        for (std::size_t i = 0; i < b.size(); ++i) power_before += double(b[i].x) * solver.atlas().area[i];
        splits += solver.subdivide(scene.view(), o);
        // Children inherit per-area values over areas that add up to their parent's: power
        // is unchanged to float rounding of the areas (2^-24 each, 4 allowed).
        const glm::dvec3 after = solver.unshot_power();
        CHECK(after.x == Approx(before.x).epsilon(4 * 0x1p-24));
        double power_after = 0;
        for (std::size_t i = 0; i < solver.radiosity().size(); ++i)
            power_after += double(solver.radiosity()[i].x) * solver.atlas().area[i];
        CHECK(power_after == Approx(power_before).epsilon(4 * 0x1p-24));
        const glm::dvec3 balance = solver.absorbed_power() + solver.unshot_power() + solver.escaped_power();
        CHECK(balance.x == Approx(solver.emitted_power().x).epsilon(4 * (s + 3) * 0x1p-24));
    }
    INFO(splits << " leaves split; " << solver.atlas().size() << " elements from " << atlas.size());
    CHECK(splits > 0);
    CHECK(solver.atlas().size() > atlas.size());
    int deepest = 0;
    for (const auto level : solver.atlas().block_level) deepest = std::max(deepest, int(level));
    CHECK(deepest <= o.max_level);
    // The lightmap still covers the atlas: every element's base texel holds the area-weighted
    // mean of the elements in it.
    const auto lm = solver.radiosity_lightmap();
    CHECK(lm.width() == atlas.width);
    solver.solve(0.1);
    CHECK(solver.unshot_fraction() <= 0.1);
}

TEST_CASE("subdivision evaluates the lights' direct light again at the children", "[radiosity][subdivision][lights]") {
    // The Cornell box lit by its spot light only: right after construction an element's
    // radiosity is rho E_direct. Split leaves, and each child must hold rho E_direct at its own
    // position, as a solver built on the refined atlas computes it, not its parent's value;
    // the change is counted as emitted power, so the balance still holds. The children's
    // value is rho E_p + rho (E_c - E_p) in float: within 4 ulps of the larger of rho E_c and
    // rho E_p (a child in shadow keeps the rounding of its lit parent's value), bounded by
    // the largest radiosity.
    const auto scene = cornell_box(true);
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 1500, .block_texels = 8});
    cpu::item_buffer_visibility vis(scene.view(), atlas, {.resolution = 128});
    cpu::progressive_radiosity solver(scene.view(), atlas, vis);
    std::size_t splits = 0;
    for (int pass = 0; pass < 2; ++pass) splits += solver.subdivide(scene.view(), {.threshold = 0.25, .min_texels = 2, .max_level = 2});
    REQUIRE(splits > 0);
    cpu::progressive_radiosity fresh(scene.view(), solver.atlas(), vis);
    REQUIRE(fresh.radiosity().size() == solver.radiosity().size());
    glm::vec3 largest(0.f);
    for (const glm::vec3& b : fresh.radiosity()) largest = glm::max(largest, b);
    for (std::size_t i = 0; i < solver.radiosity().size(); ++i) {
        const glm::vec3 a = solver.radiosity()[i], b = fresh.radiosity()[i];
        for (int c = 0; c < 3; ++c) REQUIRE(std::abs(a[c] - b[c]) <= 4 * 0x1p-24f * largest[c]);
    }
    // (Inherited values would miss by far more: a leaf split across the boxes' shadow on the
    // red wall has lit and shadowed children.)
    const glm::dvec3 balance = solver.absorbed_power() + solver.unshot_power() + solver.escaped_power();
    CHECK(balance.x == Approx(solver.emitted_power().x).epsilon(1e-6));
    CHECK(solver.emitted_power().x == Approx(fresh.emitted_power().x).epsilon(1e-5));
}

TEST_CASE("bad subdivision input raises parameter_error naming it", "[radiosity][subdivision][errors]") {
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 300});
    std::vector<glm::vec3> b(atlas.size(), glm::vec3(1.f));
    const auto named = [&](const subdivision_options& o, const char* name) {
        try {
            blocks_to_subdivide(atlas, std::span<const glm::vec3>(b), o);
            FAIL("no exception");
        } catch (const parameter_error& e) {
            CHECK(e.parameter() == name);
        }
    };
    named({.threshold = 0}, "subdivision_options.threshold");
    named({.min_texels = -1}, "subdivision_options.min_texels");
    named({.max_level = 9}, "subdivision_options.max_level");
    const std::uint32_t bad[] = {std::uint32_t(atlas.blocks())};
    try {
        refine_lightmap_atlas(scene.view(), atlas, bad);
        FAIL("no exception");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "split");
    }
}
