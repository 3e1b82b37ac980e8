// One Embree device and BVH for several uses: radiosity_visibility through the caller's accel
// gives the answers of one that builds its own, and record_sampler's default grid.
#include "hand_built_scenes.hpp"

#include <bounce/embree/radiosity_visibility.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <vector>

using namespace bounce;

namespace {

// A floor (chart 0, z = 0), a slab above it (chart 1, z = 1) and a roof (chart 2, z = 3),
// each a square of half-size 2, all facing down but the floor; a point light at z = 2.
hand_built::scene floor_slab_roof() {
    hand_built::scene s;
    const std::uint32_t grey = hand_built::add_material(s, glm::vec3(0.5f));
    hand_built::add_square_z(s, 0.f, 2.f, true, grey);
    hand_built::add_square_z(s, 1.f, 1.f, false, grey);
    hand_built::add_square_z(s, 3.f, 2.f, false, grey);
    s.lights.push_back(point_light{{0.5f, 0.5f, 2.f}, glm::vec3(4.f)});
    return s;
}

// Two triangles a square: floor, slab, roof.
const std::vector<std::uint32_t> charts = {0, 0, 1, 1, 2, 2};

}  // namespace

TEST_CASE("radiosity_visibility on a caller's accel shares its device and BVH", "[embree][radiosity]") {
    const auto scene = floor_slab_roof();
    const embree::accel bvh(scene.view());
    const embree::radiosity_visibility vis(bvh, charts);
    CHECK(vis.bvh().native() == bvh.native());
    CHECK(vis.bvh().owner().native() == bvh.owner().native());
    const embree::radiosity_visibility own(bvh.owner(), scene.view(), charts);
    CHECK(own.bvh().owner().native() == bvh.owner().native());
    CHECK(own.bvh().native() != bvh.native());
}

TEST_CASE("radiosity_visibility answers alike on a shared accel and on its own", "[embree][radiosity]") {
    const auto scene = floor_slab_roof();
    const embree::accel bvh(scene.view());
    embree::radiosity_visibility shared(bvh, charts), own(embree::device(), scene.view(), charts);
    // Floor points, seen from the roof's centre, from the light's point and against a
    // directional light travelling down (which the roof shades everywhere).
    std::vector<glm::vec3> points;
    for (float x = -1.75f; x < 2.f; x += 0.5f)
        for (float y = -1.75f; y < 2.f; y += 0.5f) points.push_back({x, y, 0.f});
    const std::vector<std::uint32_t> floor_chart(points.size(), 0u);
    // Whether the ray of `shot` and floor point p crosses the slab or the roof where that is
    // not the shooter (no point lies within a hundredth of an edge's shadow).
    const auto hidden_from = [](const embree::radiosity_shot& shot, glm::vec3 p) {
        for (const auto& [z, half, chart] : {std::tuple{1.f, 1.f, 1u}, std::tuple{3.f, 2.f, 2u}}) {
            if (chart == shot.chart || (!shot.parallel && z >= shot.position.z)) continue;
            const glm::vec3 c = shot.parallel ? p : p * (1.f - z / shot.position.z);
            if (std::abs(c.x) < half && std::abs(c.y) < half) return true;
        }
        return false;
    };
    const std::array<embree::radiosity_shot, 3> shots = {
        embree::radiosity_shot{{0.f, 0.f, 3.f}, {0, 0, -1}, false, 2},
        embree::radiosity_shot{{0.f, 0.f, 2.f}, {0, 0, -1}, false, embree::radiosity_shot::none},
        embree::radiosity_shot{{0.f, 0.f, 0.f}, {0, 0, -1}, true, embree::radiosity_shot::none}};
    const std::array<std::size_t, 3> hidden_count = {36, 64, 64};
    for (std::size_t s = 0; s < shots.size(); ++s) {
        shared.set_shot(shots[s]);
        own.set_shot(shots[s]);
        std::vector<float> batch(points.size());
        shared.visible(points, floor_chart, batch);
        std::size_t hidden = 0;
        for (std::size_t i = 0; i < points.size(); ++i) {
            const float expected = hidden_from(shots[s], points[i]) ? 0.f : 1.f;
            CHECK(shared.visible(points[i], 0) == expected);
            CHECK(own.visible(points[i], 0) == expected);
            CHECK(batch[i] == expected);
            hidden += expected == 0.f ? 1 : 0;
        }
        CHECK(hidden == hidden_count[s]);
    }
}

TEST_CASE("radiosity_visibility lets rays pass the shooter's chart and triangles without one", "[embree][radiosity]") {
    const auto scene = floor_slab_roof();
    const embree::accel bvh(scene.view());
    const glm::vec3 under_slab(0.25f, 0.25f, 0.f);
    // The slab shooting at the floor does not shadow itself.
    embree::radiosity_visibility vis(bvh, charts);
    vis.set_shot({{0.f, 0.f, 1.f}, {0, 0, -1}, false, 1});
    CHECK(vis.visible(under_slab, 0) == 1.f);
    // A slab without a chart blocks nothing.
    std::vector<std::uint32_t> no_slab = charts;
    no_slab[2] = no_slab[3] = embree::radiosity_shot::none;
    embree::radiosity_visibility open(bvh, no_slab);
    open.set_shot({{0.f, 0.f, 3.f}, {0, 0, -1}, false, 2});
    CHECK(open.visible(under_slab, 0) == 1.f);
    vis.set_shot({{0.f, 0.f, 3.f}, {0, 0, -1}, false, 2});
    CHECK(vis.visible(under_slab, 0) == 0.f);
}

TEST_CASE("radiosity_visibility on an accel refuses charts of another size", "[embree][radiosity][errors]") {
    const auto scene = floor_slab_roof();
    const embree::accel bvh(scene.view());
    const std::vector<std::uint32_t> short_charts(charts.begin(), charts.end() - 1);
    CHECK_THROWS_WITH(embree::radiosity_visibility(bvh, short_charts), Catch::Contains("chart_of_triangle"));
    CHECK_THROWS_WITH(embree::radiosity_visibility(bvh, charts, {.end_tolerance = 0.5f}),
                      Catch::Contains("end_tolerance"));
}

TEST_CASE("record_sampler's default grid is hemisphere_grid_for the integrator's rays", "[embree][record_sampler]") {
    const auto scene = floor_slab_roof();
    const embree::accel bvh(scene.view());
    const embree::reference_integrator integrator(bvh, scene.view());
    const embree::record_sampler s(integrator);
    CHECK(s.grid().m == 18);  // 1024 rays: round(sqrt(1024 / pi)) rings
    CHECK(s.grid().n == 57);  // by round(1024 / 18) wedges
    CHECK_FALSE(s.adaptive().enabled);

    embree::reference_settings few;
    few.hemisphere_samples = 64;
    const embree::reference_integrator cheap(bvh, scene.view(), few);
    const embree::record_sampler d(cheap), e(cheap, embree::hemisphere_grid_for(64), radius_limits{});
    CHECK(d.grid().m == e.grid().m);
    CHECK(d.grid().n == e.grid().n);
    // The same records as with the grid spelled out.
    const glm::vec3 p(0.3f, -0.4f, 0.f), n(0.f, 0.f, 1.f);
    const auto a = d(p, n, 0.01), b = e(p, n, 0.01);
    REQUIRE(a.has_value());
    REQUIRE(b.has_value());
    CHECK(a->irradiance == b->irradiance);
    CHECK(a->radius == b->radius);
}
