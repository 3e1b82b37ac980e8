// The Embree adapter's radiosity parts: ray-cast visibility against the brute-force ray
// caster and the item buffers, and the multi-bounce reference against the closed form of a
// uniformly emitting enclosure.
#include "radiosity_scenes.hpp"
#include "unshot_never_rises.hpp"
#include "ray_cast_visibility.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/cpu/radiosity_item_buffer.hpp>
#include <bounce/embree/lightmap_view.hpp>
#include <bounce/embree/multi_bounce_reference.hpp>
#include <bounce/embree/radiosity_object_visibility.hpp>
#include <bounce/embree/radiosity_visibility.hpp>
#include <bounce/luminance.hpp>
#include <bounce/output.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/radiosity/rebake.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <iostream>
#include <numbers>
#include <vector>

using namespace bounce;
using namespace bounce::radiosity_test;

static_assert(cpu::shot_visibility<embree::radiosity_visibility>);

namespace {

embree::radiosity_visibility embree_visibility(const owned_scene& s, const lightmap_atlas& atlas) {
    return embree::radiosity_visibility(embree::device(), s.view(), atlas.chart_of_triangle);
}

// The shots the comparisons use: four elements of the atlas, the spot light's point (both
// hemispheres) and a directional light.
std::vector<cpu::shot_frame> test_shots(const lightmap_atlas& atlas) {
    std::vector<cpu::shot_frame> shots;
    for (std::size_t e : {std::size_t(0), atlas.size() / 3, atlas.size() / 2, atlas.size() - 1})
        shots.push_back({atlas.position[e], atlas.normal[e], false, atlas.chart[e]});
    shots.push_back({{0.0f, 1.97f, -0.03f}, {0, -1, 0}, false, cpu::shot_frame::none});
    shots.push_back({{0.0f, 1.97f, -0.03f}, {0, 1, 0}, false, cpu::shot_frame::none});
    shots.push_back({{0.f, 0.f, 0.f}, glm::normalize(glm::vec3(0.3f, -1.f, -0.2f)), true, cpu::shot_frame::none});
    return shots;
}

bool in_front(const cpu::shot_frame& s, glm::vec3 p) {
    return s.parallel || glm::dot(p - s.position, s.axis) > 1e-4f;
}

}  // namespace

TEST_CASE("Embree ray-cast visibility gives the brute-force ray caster's answers", "[radiosity][embree]") {
    // Both define visibility the same way (no triangle of a third chart on the segment); they
    // may differ only where a ray passes within float rounding (~1e-7 of the scene) of an
    // occluder's edge, which among a few thousand rays through a box of 38 triangles does not
    // happen: every answer must agree.
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 3000});
    auto vis = embree_visibility(scene, atlas);
    ray_cast_visibility exact{&scene, &atlas};
    std::size_t asked = 0, hidden = 0, wrong = 0;
    for (const auto& shot : test_shots(atlas)) {
        vis.begin_shot(shot);
        exact.begin_shot(shot);
        for (std::size_t e = 0; e < atlas.size(); ++e) {
            if (!in_front(shot, atlas.position[e])) continue;
            ++asked;
            const float a = vis.visible(atlas.position[e], atlas.chart[e]);
            const float b = exact.visible(atlas.position[e], atlas.chart[e]);
            hidden += b == 0.f ? 1 : 0;
            wrong += a != b ? 1 : 0;
        }
    }
    std::cout << "Embree visibility: " << wrong << " of " << asked << " answers differ from the brute-force ray cast ("
              << hidden << " hidden)\n";
    CHECK(asked > 10000);
    CHECK(hidden > asked / 20);  // the boxes and the light's housing do occlude
    CHECK(wrong == 0);
}

TEST_CASE("Embree rays through a moved object alone: the whole scene blocks a ray where the rest or the object does",
          "[radiosity][embree][rebake]") {
    // cpu::rebake_move skips the unmoved pairs whose ray the object blocks in both places or
    // in neither (embree::object_visibility): exact only if the whole scene's answer is the
    // rest's and the object's together, ray by ray, before and after the move.
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 3000});
    std::vector<std::uint32_t> tall(10);  // the tall box: quads 10-14
    for (std::uint32_t t = 0; t < 10; ++t) tall[t] = 20 + t;
    rigid_move move;
    move.translation = {0.25f, 0.f, 0.2f};
    owned_scene moved = scene;
    for (const std::uint32_t t : tall)  // add_quad's triangles share no vertex with another quad's
        for (int k = 0; k < 3; ++k) moved.positions[scene.triangles[t][k]] = move.point(scene.positions[scene.triangles[t][k]]);
    std::vector<std::uint32_t> rest_charts(atlas.chart_of_triangle.begin(), atlas.chart_of_triangle.end());
    for (const std::uint32_t t : tall) rest_charts[t] = embree::radiosity_shot::none;
    const embree::device dev;
    embree::radiosity_visibility before(dev, scene.view(), atlas.chart_of_triangle), after(dev, moved.view(), atlas.chart_of_triangle);
    embree::radiosity_visibility rest_before(dev, scene.view(), rest_charts), rest_after(dev, moved.view(), rest_charts);
    auto object = embree::object_visibility(scene.view(), before, moved.view(), after, tall, atlas.chart_of_triangle);
    const auto moved_chart = moved_charts(atlas, tall);
    std::size_t asked = 0, changed = 0, wrong = 0;
    for (std::size_t e = 0; e < atlas.size(); e += 7) {  // shots from unmoved elements to unmoved elements
        if (moved_chart[atlas.chart[e]]) continue;
        const cpu::shot_frame shot{atlas.position[e], atlas.normal[e], false, atlas.chart[e]};
        for (auto* v : {&before, &after, &rest_before, &rest_after, &object.before, &object.after}) v->begin_shot(shot);
        for (std::size_t i = 0; i < atlas.size(); i += 3) {
            if (moved_chart[atlas.chart[i]] || !in_front(shot, atlas.position[i])) continue;
            const glm::vec3 p = atlas.position[i];
            const std::uint32_t c = atlas.chart[i];
            ++asked;
            const float was = object.before.visible(p, c), is = object.after.visible(p, c);
            changed += was != is ? 1 : 0;
            wrong += before.visible(p, c) != std::min(rest_before.visible(p, c), was) ? 1 : 0;
            wrong += after.visible(p, c) != std::min(rest_after.visible(p, c), is) ? 1 : 0;
        }
    }
    CAPTURE(asked, changed);
    CHECK(asked > 100000);
    CHECK(changed > asked / 100);
    CHECK(wrong == 0);
    // The object's rays end where the whole scene's do: its offset is the scene's, not its own BVH's.
    CHECK(object.before.ray_epsilon() == before.ray_epsilon());
    CHECK(object.before.bvh().triangle_count() == tall.size());
    CHECK_THROWS_WITH(embree::object_visibility(scene.view(), before, moved.view(), after, {}, atlas.chart_of_triangle),
                      Catch::Contains("moved_triangles"));
}

TEST_CASE("Embree visibility in packets of eight equals one ray at a time", "[radiosity][embree]") {
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 1000});
    auto vis = embree_visibility(scene, atlas);
    for (const auto& shot : test_shots(atlas)) {
        vis.begin_shot(shot);
        std::vector<glm::vec3> points;
        std::vector<std::uint32_t> charts;
        for (std::size_t e = 0; e < atlas.size(); ++e)
            if (in_front(shot, atlas.position[e])) {
                points.push_back(atlas.position[e]);
                charts.push_back(atlas.chart[e]);
            }
        points.resize(points.size() - points.size() % 8 + 3);  // a last packet of three
        charts.resize(points.size());
        std::vector<float> packed(points.size());
        vis.visible(points, charts, packed);
        for (std::size_t i = 0; i < points.size(); ++i) REQUIRE(packed[i] == vis.visible(points[i], charts[i]));
    }
}

TEST_CASE("the solver with Embree visibility equals the solver with the brute-force ray caster",
          "[radiosity][embree][solver]") {
    const auto scene = cornell_box(true);  // the spot light too: its shot uses visibility as well
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 600});
    cpu::progressive_radiosity a(scene.view(), atlas, embree_visibility(scene, atlas));
    cpu::progressive_radiosity b(scene.view(), atlas, ray_cast_visibility{&scene, &atlas});
    a.solve(0.05);
    b.solve(0.05);
    REQUIRE(a.progress().shots == b.progress().shots);
    // Same answers, same order of operations: the same floats.
    for (std::size_t i = 0; i < atlas.size(); ++i) REQUIRE(a.radiosity()[i] == b.radiosity()[i]);
}

TEST_CASE("the item buffers differ from Embree visibility only on a small share of elements", "[radiosity][embree]") {
    // docs/radiosity.md section 3: the item buffers' wrong answers lie next to chart edges in
    // the buffer; with 256^2 pixels and 3,000 elements they are under 1% (48 and 14 of 10,189
    // in the test against the brute-force caster).
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 3000});
    auto rays = embree_visibility(scene, atlas);
    for (const auto projection : {cpu::item_projection::stereographic, cpu::item_projection::hemicube}) {
        cpu::item_buffer_visibility buffer(scene.view(), atlas, {.projection = projection, .resolution = 256});
        std::size_t asked = 0, wrong = 0;
        for (const auto& shot : test_shots(atlas)) {
            if (shot.chart == cpu::shot_frame::none) continue;
            rays.begin_shot(shot);
            buffer.begin_shot(shot);
            for (std::size_t e = 0; e < atlas.size(); ++e) {
                if (!in_front(shot, atlas.position[e])) continue;
                ++asked;
                wrong += rays.visible(atlas.position[e], atlas.chart[e]) != buffer.visible(atlas.position[e], atlas.chart[e]);
            }
        }
        std::cout << (projection == cpu::item_projection::stereographic ? "stereographic" : "hemicube") << " 256 vs Embree: "
                  << wrong << " of " << asked << " differ\n";
        CHECK(wrong * 100 < asked);
    }
}

TEST_CASE("bad Embree visibility input raises parameter_error naming it", "[radiosity][embree][errors]") {
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 200});
    const std::vector<std::uint32_t> short_charts(atlas.chart_of_triangle.begin(), atlas.chart_of_triangle.end() - 1);
    CHECK_THROWS_WITH(embree::radiosity_visibility(embree::device(), scene.view(), short_charts),
                      Catch::Contains("chart_of_triangle"));
    CHECK_THROWS_WITH(embree::radiosity_visibility(embree::device(), scene.view(), atlas.chart_of_triangle,
                                                   {.end_tolerance = -1.f}),
                      Catch::Contains("end_tolerance"));
    auto vis = embree_visibility(scene, atlas);
    CHECK_THROWS_WITH(vis.set_shot({glm::vec3(NAN), {0, 0, 1}, false, 0}), Catch::Contains("shot.position"));
    std::vector<glm::vec3> p(3);
    std::vector<std::uint32_t> c(2);
    std::vector<float> out(3);
    CHECK_THROWS_WITH(vis.visible(p, c, out), Catch::Contains("charts"));
}

namespace {

// The inside of the cube [0, a]^3, every wall emitting radiance `le` and reflecting `rho`
// (all channels): a closed enclosure of uniform emission and albedo.
owned_scene glowing_box(float a, float rho, float le) {
    owned_scene s;
    const auto m = s.add_material(glm::vec3(rho), glm::vec3(le));
    s.add_quad({0, 0, 0}, {0, 0, a}, {a, 0, a}, {a, 0, 0}, m);
    s.add_quad({0, a, 0}, {a, a, 0}, {a, a, a}, {0, a, a}, m);
    s.add_quad({0, 0, 0}, {a, 0, 0}, {a, a, 0}, {0, a, 0}, m);
    s.add_quad({0, 0, a}, {0, a, a}, {a, a, a}, {a, 0, a}, m);
    s.add_quad({0, 0, 0}, {0, a, 0}, {0, a, a}, {0, 0, a}, m);
    s.add_quad({a, 0, 0}, {a, 0, a}, {a, a, a}, {a, a, 0}, m);
    return s;
}

// Mean and standard error of the radiance at `count` random points on the box's walls.
std::pair<double, double> mean_radiance(const embree::multi_bounce_reference& ref, float a, int count) {
    pcg32 rng(7);
    double sum = 0, sum2 = 0;
    for (int i = 0; i < count; ++i) {
        // Points on the floor (y = 0, normal +y, triangles 0 and 1), away from the edges.
        const glm::vec3 p(a * (0.1f + 0.8f * rng.next_float()), 0.f, a * (0.1f + 0.8f * rng.next_float()));
        const std::uint32_t tri = p.x > p.z ? 1u : 0u;  // abc (x <= z side) or acd
        const double l = ref.radiance(p, {0, 1, 0}, tri, embree::derive_seed(3, 0, std::uint64_t(i))).x;
        sum += l;
        sum2 += l * l;
    }
    const double mean = sum / count, var = std::max(0.0, sum2 / count - mean * mean);
    return {mean, std::sqrt(var / count)};
}

}  // namespace

TEST_CASE("in a closed uniformly glowing box the multi-bounce reference gives L = Le sum rho^k", "[radiosity][embree][reference]") {
    // Every point of a closed enclosure with uniform emission Le and albedo rho sees radiance
    // Le everywhere from emission alone, so its direct irradiance is pi Le and each bounce
    // multiplies by rho: L = Le (1 + rho + ... + rho^(B+1)) with B indirect bounces, and
    // Le / (1 - rho) with all of them (the furnace: radiosity B = E / (1 - rho)). The
    // estimator is unbiased, so the mean over points lies within a few standard errors
    // (measured from the points' spread) of it; 5 standard errors fail by chance once in
    // 1.7 million.
    const float a = 2.f, rho = 0.6f, le = 1.5f;
    const auto scene = glowing_box(a, rho, le);
    const embree::accel bvh(scene.view());
    for (std::uint32_t bounces : {0u, 2u, 64u}) {
        embree::multi_bounce_settings s;
        s.paths = 16;
        s.area_samples = 4;
        s.max_bounces = bounces;
        s.roulette_after = bounces == 64 ? 3 : bounces + 1;  // all bounces: roulette keeps it unbiased
        const embree::multi_bounce_reference ref(bvh, scene.view(), s);
        double expected = 0;
        for (std::uint32_t k = 0; k <= bounces + 1; ++k) expected += le * std::pow(double(rho), double(k));
        const auto [mean, se] = mean_radiance(ref, a, 400);
        INFO("bounces " << bounces << ": mean " << mean << " +- " << se << ", expected " << expected);
        CHECK(std::abs(mean - expected) < 5 * se + 1e-6 * expected);
        CHECK(se < 0.01 * expected);  // a test that could tell 1% apart
    }
}

TEST_CASE("bad multi-bounce settings raise parameter_error naming them", "[radiosity][embree][reference][errors]") {
    const auto scene = glowing_box(1.f, 0.5f, 1.f);
    const embree::accel bvh(scene.view());
    embree::multi_bounce_settings no_paths, no_area;
    no_paths.paths = 0;
    no_area.area_samples = 0;
    CHECK_THROWS_WITH(embree::multi_bounce_reference(bvh, scene.view(), no_paths), Catch::Contains("paths"));
    CHECK_THROWS_WITH(embree::multi_bounce_reference(bvh, scene.view(), no_area), Catch::Contains("area_samples"));
    const embree::multi_bounce_reference ref(bvh, scene.view(), {});
    CHECK_THROWS_WITH(ref.radiance({0.5f, 0.f, 0.5f}, {0, 1, 0}, 99, 1), Catch::Contains("triangle"));
}

namespace {

// A room (4 x 3 x 4 m) modelled as published scenes often are: the floor and the front wall
// wound inwards, the ceiling, the back and the left wall outwards, and a right wall 0.2 m
// thick whose two faces and the four reveals of its slit (`slit` wide, 1 m high) are wound
// into the wall; the sun shines in through the slit only (nothing else emits).
owned_scene room_with_slit(float slit) {
    owned_scene s;
    s.use_emission = false;
    const auto m = s.add_material(glm::vec3(0.6f));
    const float a = 4.f, h = 3.f, t = 0.2f, z0 = 2.f - slit / 2, z1 = 2.f + slit / 2, y0 = 1.5f, y1 = 2.5f;
    s.add_quad({0, 0, 0}, {0, 0, a}, {a, 0, a}, {a, 0, 0}, m);  // floor, +y (inwards)
    s.add_quad({0, h, 0}, {0, h, a}, {a, h, a}, {a, h, 0}, m);  // ceiling, +y (outwards)
    s.add_quad({0, 0, 0}, {0, h, 0}, {a, h, 0}, {a, 0, 0}, m);  // back, -z (outwards)
    s.add_quad({0, 0, a}, {0, h, a}, {a, h, a}, {a, 0, a}, m);  // front, -z (inwards)
    s.add_quad({0, 0, 0}, {0, 0, a}, {0, h, a}, {0, h, 0}, m);  // left, -x (outwards)
    for (const float x : {a, a + t}) {  // the thick wall's inner and outer faces around the slit
        const float w = x == a ? -1.f : 1.f;  // inner face wound towards +x, outer towards -x
        const auto quad = [&](float za, float zb, float ya, float yb) {
            if (w < 0) s.add_quad({x, ya, za}, {x, yb, za}, {x, yb, zb}, {x, ya, zb}, m);
            else s.add_quad({x, ya, za}, {x, ya, zb}, {x, yb, zb}, {x, yb, za}, m);
        };
        quad(0, z0, 0, h);
        quad(z1, a, 0, h);
        quad(z0, z1, 0, y0);
        quad(z0, z1, y1, h);
    }
    s.add_quad({a, y0, z0}, {a + t, y0, z0}, {a + t, y0, z1}, {a, y0, z1}, m);  // sill, -y (into the wall)
    s.add_quad({a, y1, z0}, {a, y1, z1}, {a + t, y1, z1}, {a + t, y1, z0}, m);  // lintel, +y (into the wall)
    s.add_quad({a, y0, z0}, {a, y1, z0}, {a + t, y1, z0}, {a + t, y0, z0}, m);  // jambs
    s.add_quad({a, y0, z1}, {a + t, y0, z1}, {a + t, y1, z1}, {a, y1, z1}, m);
    // The wall's top, bottom and ends close it (wound outwards), so no light gets inside it.
    s.add_quad({a, h, 0}, {a, h, a}, {a + t, h, a}, {a + t, h, 0}, m);
    s.add_quad({a, 0, 0}, {a + t, 0, 0}, {a + t, 0, a}, {a, 0, a}, m);
    s.add_quad({a, 0, 0}, {a, h, 0}, {a + t, h, 0}, {a + t, 0, 0}, m);
    s.add_quad({a, 0, a}, {a + t, 0, a}, {a + t, h, a}, {a, h, a}, m);
    s.lights.push_back(directional_light{glm::normalize(glm::vec3(-1.f, -0.45f, 0.f)), glm::vec3(20.f)});
    return s;
}

// Points (three per triangle, on each side) where the reference is lit (its luminance above
// 1% of its mean over the points) but the lightmap is black there (the texel's radiance
// B / pi below 1e-3 of that mean), for a solve with `sides` sides: the program's
// black_pixels rule, on every triangle rather than on a view. The sun on the wall's outer
// face carries almost all of the power and leaves the scene in the first shots, so the solve
// runs to 99.999%: what is black then is a hole, not light still to shoot.
std::size_t black_where_lit(const owned_scene& scene, int sides, int light_samples = 1) {
    const lightmap_atlas atlas = build_lightmap_atlas(scene.view(), {.elements = 3000});
    cpu::progressive_radiosity solver(scene.view(), atlas, embree_visibility(scene, atlas),
                                      {.two_sided = sides == 2, .light_samples = light_samples});
    radiosity_solve_options o;
    o.converge = 0.99999;
    solver.solve(o);
    const embree::accel bvh(scene.view());
    embree::multi_bounce_settings settings;
    settings.paths = 64;
    const embree::multi_bounce_reference ref(bvh, scene.view(), settings);
    struct point {
        glm::vec3 p;
        std::uint32_t triangle;
        int side;
        float reference;
    };
    std::vector<point> points;
    double mean = 0;
    for (std::uint32_t t = 0; t < scene.triangles.size(); ++t) {
        const glm::vec3 a = scene.positions[scene.triangles[t].x], b = scene.positions[scene.triangles[t].y],
                        c = scene.positions[scene.triangles[t].z];
        const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
        for (const glm::vec3 w : {glm::vec3(4, 1, 1) / 6.f, glm::vec3(1, 4, 1) / 6.f, glm::vec3(1, 1, 4) / 6.f})
            for (int side = 0; side < 2; ++side) {
                const glm::vec3 p = w.x * a + w.y * b + w.z * c;
                const float l = ref.radiance(p, side ? -n : n, t, embree::derive_seed(5, t, std::uint64_t(side))).y;
                points.push_back({p, t, side, l});
                mean += l;
            }
    }
    mean /= double(points.size());
    std::size_t black = 0, lit = 0;
    for (const point& q : points) {
        if (!(q.reference > 0.01 * mean)) continue;
        ++lit;
        const glm::vec2 uv = atlas.atlas_coords(atlas.chart_of_triangle[q.triangle], q.p);
        const std::int32_t e = atlas.element_at(std::size_t(uv.x), std::size_t(uv.y));
        const float b = e >= 0 && q.side < sides ? solver.radiosity(q.side)[std::size_t(e)].y : 0.f;
        black += b / float(std::numbers::pi) < 1e-3 * mean ? 1 : 0;
    }
    INFO(sides << " sides: " << black << " of " << lit << " lit points black");
    CHECK(lit > 40);
    return black;
}

}  // namespace

TEST_CASE("no texel is black where the reference is lit: a room with a slit and mixed winding",
          "[radiosity][embree][holes]") {
    // Two-sided elements (the default) are lit wherever the all-bounce reference is, the
    // ceiling and the walls wound outwards and the slit's reveals (5 cm deep strips wound into
    // the wall) included; one-sided ones leave the surfaces wound outwards black (what the
    // issue saw). The slit, 0.3 m wide, is wider than a texel (about 0.17 m).
    const auto scene = room_with_slit(0.3f);
    CHECK(black_where_lit(scene, 2) == 0);
    CHECK(black_where_lit(scene, 1) > 10);
}

TEST_CASE("a sun strip narrower than a texel: missed at element points, caught by light samples",
          "[radiosity][embree][holes]") {
    // Through a slit 5 cm wide the sun lights a 5 cm strip of the floor, which no element's
    // point (17 cm apart) falls in: the lights' shot taken at element points delivers none of
    // it, the room gets only what the sill reflects (about 1/20 of what enters) and points the
    // reference lights stay black. Taken at 4 x 4 points of each whole texel
    // (radiosity_options::light_samples), the strip lights the texels it crosses.
    const auto scene = room_with_slit(0.05f);
    CHECK(black_where_lit(scene, 2, 1) > 5);
    CHECK(black_where_lit(scene, 2, 4) == 0);
}

TEST_CASE("a floor running around a column's base is lit: its element's point lies on it, not under the column",
          "[radiosity][embree][holes]") {
    // Sponza's column bases and the living room's furniture: a chart of one texel whose
    // overlap (the floor around the column) is not convex has its centroid, (1, 0, 1), inside
    // the column, where every shot finds it occluded, so the whole floor rendered black. The
    // point moves to the centroid of its largest triangle's overlap, which lies on the floor.
    const auto scene = floor_around_column(0.5f);
    // One texel a chart, the floor's own (no cluster with the column's top, which faces up too).
    const lightmap_atlas atlas =
        build_lightmap_atlas(scene.view(), {.elements = 1, .clusters = tiny_chart_clusters::never});
    const lightmap_chart& floor = atlas.charts[atlas.chart_of_triangle[0]];
    REQUIRE(floor.triangle_count == 8);
    REQUIRE(floor.element_count == 1);
    const glm::vec3 p = atlas.position[floor.first_element];
    CHECK(std::max(std::abs(p.x - 1.f), std::abs(p.z - 1.f)) >= 0.2f);  // not in the column's hole
    CHECK(std::abs(p.y) < 1e-6f);
    cpu::progressive_radiosity solver(scene.view(), atlas, embree_visibility(scene, atlas), {.two_sided = true});
    radiosity_solve_options o;
    o.converge = 0.999;
    solver.solve(o);
    CHECK(solver.radiosity(0)[floor.first_element].y > 1.f);
}

namespace {

// A view's luminance error against `ref` over the pixels that see geometry: rms / rms.
double view_error(const image<glm::vec3>& v, const image<glm::vec3>& ref) {
    double d = 0, r = 0;
    for (std::size_t y = 0; y < ref.height(); ++y)
        for (std::size_t x = 0; x < ref.width(); ++x) {
            const double a = rec709_luminance<double, glm::dvec3>(glm::dvec3(v(x, y)));
            const double b = rec709_luminance<double, glm::dvec3>(glm::dvec3(ref(x, y)));
            d += (a - b) * (a - b);
            r += b * b;
        }
    return std::sqrt(d / r);
}

}  // namespace

TEST_CASE("the direct+indirect view draws a sun strip narrower than a texel, which the lightmap's lookup blurs",
          "[radiosity][embree][view]") {
    // The room's 5 cm sun strip on the floor (x in [0, 0.67], z in [1.975, 2.025]) crosses
    // texels about 17 cm wide: looked up in the lightmap it is spread over them (at most about
    // a third of its radiance), drawn per pixel with shadow rays it is exact. A camera 1 m
    // above the strip, 64 x 64 pixels of 8.4 mm.
    const auto scene = room_with_slit(0.05f);
    const lightmap_atlas atlas = build_lightmap_atlas(scene.view(), {.elements = 3000});
    cpu::progressive_radiosity solver(scene.view(), atlas, embree_visibility(scene, atlas),
                                      {.two_sided = true, .light_samples = 4});
    radiosity_solve_options o;
    o.converge = 0.999;
    solver.solve(o);
    std::vector<image<glm::vec3>> b, rest;
    for (int side = 0; side < 2; ++side) {
        std::vector<glm::vec3> r(solver.display_radiosity(side));
        const auto d = solver.output(output_quantity::irradiance, light_paths::direct, side);
        for (std::size_t i = 0; i < r.size(); ++i) r[i] -= atlas.albedo[i] * d[i];  // B less rho E_d
        b.push_back(solver.radiosity_lightmap(0, side));
        rest.push_back(atlas.to_fine_texels(std::span<const glm::vec3>(r), 0, glm::vec3(0.f), true));
    }
    const embree::accel bvh(scene.view());
    camera cam;
    cam.position = {0.35f, 1.f, 2.f};
    cam.look_at = {0.35f, 0.f, 2.f};
    cam.up = {1.f, 0.f, 0.f};
    cam.fov_y_deg = 30.f;
    const std::size_t n = 64;
    const auto lookup = embree::lightmap_view(bvh, scene.view(), atlas, b[0].view(), b[1].view(), 0, cam, n, n);
    const auto direct = embree::lightmap_direct_view(bvh, scene.view(), atlas, rest[0].view(), rest[1].view(), 0, cam, n, n);
    // The sun's radiance off the floor: rho / pi * 20 * cos, cos = 0.45 / |(1, 0.45, 0)|.
    const float sun = 0.6f / float(std::numbers::pi) * 20.f * 0.45f / std::sqrt(1.f + 0.45f * 0.45f);
    const glm::vec3 rest_centre = direct(n / 2, n / 2) - sun;
    INFO("direct+indirect " << direct(n / 2, n / 2).y << ", lookup " << lookup(n / 2, n / 2).y << ", sun " << sun);
    CHECK(rest_centre.y >= 0.f);
    CHECK(rest_centre.y < 0.1f * sun);  // the rest is what the floor gets bounced
    CHECK(lookup(n / 2, n / 2).y < 0.6f * sun);
    // 12 pixels (10 cm) off the strip the floor is in the wall's shadow, lit only by the
    // bounces; the lookup spreads the strip's light into it.
    CHECK(direct(n / 2 + 12, n / 2).y > 0.f);
    CHECK(direct(n / 2 + 12, n / 2).y < 0.5f * lookup(n / 2 + 12, n / 2).y);
    embree::multi_bounce_settings settings;
    settings.paths = 64;
    const auto ref = embree::multi_bounce_reference(bvh, scene.view(), settings).render(cam, n, n);
    const double e_lookup = view_error(lookup, ref.radiance), e_direct = view_error(direct, ref.radiance);
    INFO("rel_rms: lookup " << e_lookup << ", direct+indirect " << e_direct);
    CHECK(e_direct < 0.5 * e_lookup);
    // With no rest, the view is the lights' direct light alone: the sun where the strip is.
    const image<glm::vec3> zero(rest[0].width(), rest[0].height(), glm::vec3(0.f));
    const auto sun_only = embree::lightmap_direct_view(bvh, scene.view(), atlas, zero.view(), zero.view(), 0, cam, n, n);
    CHECK(sun_only(n / 2, n / 2).y == Approx(sun).epsilon(1e-4));
    CHECK(sun_only(n / 2 + 12, n / 2).y == 0.f);
}

TEST_CASE("a layer of another chart closer to an element than the ray epsilon does not shadow it, as in the reference",
          "[radiosity][embree][holes]") {
    // The conference room (millimetres, ray_epsilon 3 mm): tables whose top carries a
    // coplanar face of another chart a fraction of a millimetre above it. The reference's
    // rays leave the table ray_epsilon above it and see the room; the solver's rays, ending
    // at the element's point, met the layer, and the texels stayed black where the
    // reference is lit (3 of the conference room's 4 black pixels, docs/radiosity.md).
    owned_scene s;
    const auto m = s.add_material(glm::vec3(0.5f));
    s.add_quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, m);  // the table, y = 0, facing +y
    const float eps = embree::accel(embree::device(), s.view()).ray_epsilon();
    const float h = 0.3f * eps;  // the layer: a quad of its own chart, h above the table
    s.add_quad({-0.5f, h, -0.5f}, {-0.5f, h, 0.5f}, {0.5f, h, 0.5f}, {0.5f, h, -0.5f}, m);
    const lightmap_atlas atlas = build_lightmap_atlas(s.view(), {.elements = 64});
    REQUIRE(atlas.chart_of_triangle[0] != atlas.chart_of_triangle[2]);
    embree::radiosity_visibility vis = embree_visibility(s, atlas);
    const glm::vec3 under(0.1f, 0.f, 0.1f), lamp(0.3f, 2.f, -0.2f);
    const std::uint32_t table = atlas.chart_of_triangle[0];
    CHECK(vis.visible_from(lamp, lightmap_atlas::none, under, table) == 1.f);
    vis.set_shot({lamp, glm::vec3(0, -1, 0), false, embree::radiosity_shot::none});
    CHECK(vis.visible(under, table) == 1.f);
    vis.set_shot({glm::vec3(0.f), glm::vec3(0, -1, 0), true, embree::radiosity_shot::none});  // a sun overhead
    CHECK(vis.visible(under, table) == 1.f);
    // A layer ten epsilons up still shadows the table, from the lamp and from the sun.
    owned_scene t = s;
    for (std::size_t i = t.positions.size() - 4; i < t.positions.size(); ++i) t.positions[i].y = 10.f * eps;
    const lightmap_atlas atlas_t = build_lightmap_atlas(t.view(), {.elements = 64});
    embree::radiosity_visibility vis_t = embree_visibility(t, atlas_t);
    CHECK(vis_t.visible_from(lamp, lightmap_atlas::none, under, atlas_t.chart_of_triangle[0]) == 0.f);
    vis_t.set_shot({glm::vec3(0.f), glm::vec3(0, -1, 0), true, embree::radiosity_shot::none});
    CHECK(vis_t.visible(under, atlas_t.chart_of_triangle[0]) == 0.f);
}

TEST_CASE("ray visibility over clusters of tiny charts: every triangle lit, no energy gained",
          "[radiosity][embree][clusters]") {
    // Each cluster's point lies on one of its triangles; a ray to it leaves out its own
    // cluster's triangles (one chart), so no sibling a millimetre away shadows it.
    const auto scene = tiny_triangles_under_a_lamp();
    const lightmap_atlas atlas = build_lightmap_atlas(scene.view(), {.elements = 300});
    REQUIRE(atlas.statistics.clusters > 0);
    cpu::progressive_radiosity solver(scene.view(), atlas, embree_visibility(scene, atlas));
    radiosity_solve_options o;
    o.converge = 0.99;
    double unshot = 1;
    o.progress = unshot_never_rises(unshot, 1e-6);
    CHECK(solver.solve(o).stop == radiosity_stop::converged);
    CHECK(unlit_triangles(scene, atlas, solver.display_radiosity(), 2) == 0);  // after the lamp's two
}
