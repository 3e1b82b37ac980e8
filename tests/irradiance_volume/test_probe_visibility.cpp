// Visibility-aware probes (volume/probe_visibility.hpp, DDGI): the octahedral map's
// encoding at its poles, edges and corners, its wrapped bilinear reads, the Chebyshev
// weight, the cosine-power filter, a lookup at a probe (distance 0) that stays finite, and
// the thin wall between a lit and a dark room: without visibility the dark room's floor near
// the wall gets light, with it none.
#include "../embree/hand_built_scenes.hpp"
#include "far_triangle.hpp"

#include <bounce/cpu/irradiance_volume.hpp>
#include <bounce/embree/probe_baker.hpp>
#include <bounce/embree/probe_relocation.hpp>
#include <bounce/embree/probe_visibility_baker.hpp>
#include <bounce/luminance.hpp>
#include <bounce/volume/probe_visibility.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

using namespace bounce;

TEST_CASE("octahedral encoding: poles, equator, corners and round trips", "[irradiance_volume][visibility]") {
    const auto enc = [](glm::vec3 d) { return octahedral_encode<float, glm::vec3>(d); };
    const auto dec = [](float u, float v) { return octahedral_decode<float, glm::vec3>(u, v); };
    CHECK(enc({0, 0, 1}) == std::pair<float, float>(0.f, 0.f));
    CHECK(enc({0, 0, -1}) == std::pair<float, float>(1.f, 1.f));  // -z: a corner
    CHECK(enc({1, 0, 0}) == std::pair<float, float>(1.f, 0.f));   // the equator: the diamond's edge
    CHECK(enc({0, -1, 0}) == std::pair<float, float>(0.f, -1.f));
    CHECK(enc({0, 0, 0}) == std::pair<float, float>(0.f, 0.f));   // a zero vector stays finite
    // Every corner of the square is -z.
    for (const float u : {-1.f, 1.f})
        for (const float v : {-1.f, 1.f}) CHECK(glm::length(dec(u, v) - glm::vec3(0, 0, -1)) < 1e-6f);
    // Mirrored points on an edge of the square are one direction (the fold).
    for (const float t : {-0.7f, -0.2f, 0.3f, 0.9f}) {
        CHECK(glm::length(dec(1.f, t) - dec(1.f, -t)) < 1e-6f);
        CHECK(glm::length(dec(t, -1.f) - dec(-t, -1.f)) < 1e-6f);
    }
    std::mt19937 rng(3);
    std::normal_distribution<float> g;
    for (int i = 0; i < 2000; ++i) {
        const glm::vec3 d = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
        const auto [u, v] = enc(d);
        CHECK(std::abs(u) <= 1.f);
        CHECK(std::abs(v) <= 1.f);
        CHECK(glm::length(dec(u, v) - d) < 1e-5f);
    }
}

TEST_CASE("octahedral texels wrap across edges and corners", "[irradiance_volume][visibility]") {
    const float n = 8;
    const auto index = [&](float x, float y) { return octahedral_texel_index<float>(x, y, n); };
    CHECK(index(3, 5) == 5 * 8 + 3);
    CHECK(index(-1, 2) == (8 - 1 - 2) * 8 + 0);  // column -1, row j: column 0, row N-1-j
    CHECK(index(8, 2) == (8 - 1 - 2) * 8 + 7);
    CHECK(index(2, -1) == 0 * 8 + (8 - 1 - 2));  // row -1, column i: row 0, column N-1-i
    CHECK(index(2, 8) == 7 * 8 + (8 - 1 - 2));
    CHECK(index(-1, -1) == 7 * 8 + 7);  // a corner beyond both edges: the opposite corner
    CHECK(index(8, 8) == 0);
    // The texel read beyond an edge is a neighbour on the sphere: its centre is nearer the
    // edge texel's than the texel two columns in.
    const auto centre = [&](float x, float y) {
        return octahedral_decode<float, glm::vec3>(2 * (x + 0.5f) / n - 1, 2 * (y + 0.5f) / n - 1);
    };
    for (float j = 0; j < n; ++j) {
        const float i = index(-1, j);
        CHECK(glm::dot(centre(0, j), centre(std::fmod(i, n), std::floor(i / n))) >= glm::dot(centre(0, j), centre(2, j)));
    }
    // A read at the pole and at a corner stays inside the map.
    for (const glm::vec3 d : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(0.f, -1.f, -1e-7f)}) {
        const auto [u, v] = octahedral_encode<float, glm::vec3>(d);
        const auto b = octahedral_bilinear<float>(u, v, n);
        for (int k = 0; k < 4; ++k) {
            const float i = index(b[0] + float(k & 1), b[1] + float(k >> 1));
            CHECK(i >= 0);
            CHECK(i < n * n);
        }
    }
}

TEST_CASE("the Chebyshev weight and the filter of ray distances", "[irradiance_volume][visibility]") {
    CHECK(chebyshev_visibility(0.f, 1.f, 1.f) == 1.f);           // in front of the mean: seen
    CHECK(chebyshev_visibility(2.f, 1.f, 1.f) == 0.f);           // behind a surface with no variance
    CHECK(chebyshev_visibility(0.f, 0.f, 0.f) == 1.f);           // a probe on a surface, point at it
    const float p = chebyshev_visibility(1.5f, 1.f, 1.f + 0.01f);  // var 0.01, (d - mean)^2 0.25
    CHECK(p == Approx(std::pow(0.01f / 0.26f, 3.f)).epsilon(1e-4));
    // A constant distance fills every texel with (d, d^2); a hemisphere at 1 and the other at
    // 3 gives texels near each pole the near pole's distance.
    const auto dirs64 = embree::spherical_fibonacci_directions(4096);
    std::vector<glm::vec3> dirs;
    for (const auto& d : dirs64) dirs.push_back(glm::vec3(d));
    std::vector<float> dist(dirs.size(), 2.f), out(2 * 8 * 8);
    filter_ray_distances(dirs, dist, 8, 50.f, out);
    for (std::size_t t = 0; t < 64; ++t) {
        CHECK(out[2 * t] == Approx(2.f).epsilon(1e-5));
        CHECK(out[2 * t + 1] == Approx(4.f).epsilon(1e-5));
    }
    for (std::size_t j = 0; j < dirs.size(); ++j) dist[j] = dirs[j].z > 0 ? 1.f : 3.f;
    filter_ray_distances(dirs, dist, 8, 50.f, out);
    const probe_visibility vis(8, out);
    CHECK(vis.sample(0, {0, 0, 1}).first == Approx(1.f).epsilon(1e-3));
    CHECK(vis.sample(0, {0, 0, -1}).first == Approx(3.f).epsilon(1e-3));
    CHECK(vis.sample(0, glm::normalize(glm::vec3(1, 1, -1))).first > 2.9f);
    CHECK_THROWS_AS(filter_ray_distances(dirs, dist, 8, 0.f, out), parameter_error);
    CHECK_THROWS_AS(probe_visibility(0, {}), parameter_error);
    CHECK_THROWS_AS(probe_visibility(2, std::vector<float>(7, 1.f)), parameter_error);
}

namespace {

// Two rooms [0, 1.1] and [1.11, 2] x [0, 1] x [0, 1] (y up) inside one box, parted by a wall
// 1 cm thick; a point light in the first. Every quad faces into its room.
hand_built::scene two_rooms() {
    hand_built::scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.6f));
    const auto inward_box = [&](glm::vec3 lo, glm::vec3 hi) {
        for (int k = 0; k < 3; ++k)
            for (const int side : {0, 1}) {
                const int a = (k + 1) % 3, b = (k + 2) % 3;
                glm::vec3 q[4];
                for (int c = 0; c < 4; ++c) {
                    q[c][k] = side ? hi[k] : lo[k];
                    q[c][a] = (c == 1 || c == 2) ? hi[a] : lo[a];
                    q[c][b] = (c >= 2) ? hi[b] : lo[b];
                }
                glm::vec3 e(0.f);
                e[k] = side ? -1.f : 1.f;  // into the box
                if (side) std::swap(q[1], q[3]);
                hand_built::add_quad(s, q[0], q[1], q[2], q[3], e, m);
            }
    };
    inward_box({0, 0, 0}, {1.1f, 1, 1});
    inward_box({1.11f, 0, 0}, {2, 1, 1});
    s.lights.push_back(bounce::point_light{{0.5f, 0.8f, 0.5f}, glm::vec3(2.f)});
    return s;
}

}  // namespace

TEST_CASE("a thin wall: without visibility the dark room's floor gets light, with it none", "[irradiance_volume][visibility][embree]") {
    const hand_built::scene s = two_rooms();
    const embree::accel bvh(s);
    const embree::reference_integrator light(bvh, s);
    embree::probe_baker_settings bs;
    bs.rays = 128;
    const embree::probe_baker baker(light, bvh, s, bs);
    irradiance_volume_settings vs;
    vs.min_depth = vs.max_depth = 3;  // probes at x = 0.01 + 0.2475 i: x = 1.0 and 1.2475 straddle the wall
    const irradiance_volume volume = irradiance_volume::build(s, {0.01f, 0.01f, 0.01f}, {1.99f, 0.99f, 0.99f}, vs, baker);
    embree::probe_visibility_settings ps;
    ps.resolution = 8;
    ps.rays = 512;
    const probe_visibility vis = embree::bake_probe_visibility(bvh, volume, ps);
    REQUIRE(vis.probe_count() == volume.probes().size());

    // Floor points of each room near the wall, lit from above; the eye in the dark room.
    std::vector<glm::vec3> lit, dark;
    for (int i = 0; i < 12; ++i)
        for (int k = 0; k < 9; ++k) {
            const float z = 0.1f + 0.1f * float(k);
            lit.push_back({0.6f + 0.04f * float(i), 0.f, z});   // 0.6 .. 1.04
            dark.push_back({1.115f + 0.01f * float(i), 0.f, z});  // 1.115 .. 1.225: in the cell across the wall
        }
    const std::vector<glm::vec3> up(lit.size(), glm::vec3(0, 1, 0));
    const glm::vec3 eye(1.9f, 0.9f, 0.5f);
    const auto luminance_of = [&](const std::vector<glm::vec3>& pts, volume_visibility mode, bool mean) {
        std::vector<glm::vec3> e(pts.size());
        cpu::volume_lookup how;
        how.visibility.mode = mode;
        cpu::light_points(volume, vis, eye, pts, up, e, how);
        double acc = 0;
        for (const auto& v : e) {
            const double y = rec709_luminance<float, glm::vec3>(v);
            acc = mean ? acc + y / double(e.size()) : std::max(acc, y);
        }
        return acc;
    };
    const double lit_mean = luminance_of(lit, volume_visibility::chebyshev, true);
    REQUIRE(lit_mean > 0);
    const double leak_without = luminance_of(dark, volume_visibility::none, false);
    const double leak_with = luminance_of(dark, volume_visibility::chebyshev, false);
    INFO("lit floor " << lit_mean << ", dark floor max without visibility " << leak_without << ", with " << leak_with);
    CHECK(leak_without > 0.1 * lit_mean);  // the leak the test is about
    CHECK(leak_with < 0.01 * lit_mean);    // no lit texel behind the wall
    // The lit room keeps its light (visibility does not darken what the probes see).
    CHECK(lit_mean > 0.7 * luminance_of(lit, volume_visibility::none, true));
}

TEST_CASE("a visibility lookup at a probe stays finite", "[irradiance_volume][visibility]") {
    const auto s = test::far_triangle();
    irradiance_volume_settings vs;
    vs.min_depth = vs.max_depth = 1;
    const auto source = [](std::span<const glm::vec3> pos, std::span<irradiance_probe> out) {
        for (std::size_t i = 0; i < pos.size(); ++i) {
            out[i].position = pos[i];
            out[i].radiance[0] = glm::vec3(1.f + pos[i].x);
        }
    };
    const irradiance_volume volume = irradiance_volume::build(s, {0, 0, 0}, {1, 1, 1}, vs, source);
    // Every texel at distance 0 with no variance: the worst case for the test.
    const probe_visibility zero(4, std::vector<float>(volume.probes().size() * 2 * 16, 0.f));
    for (const auto& pr : volume.probes())
        for (const glm::vec3 n : {glm::vec3(0, 0, 1), glm::vec3(1, 0, 0)}) {
            for (const float bias : {0.f, 0.3f}) {
                const glm::vec3 e = trilinear_visible(volume, zero, pr.position, n, n, {volume_visibility::chebyshev, bias});
                CHECK(std::isfinite(e.x));
                CHECK(e.x > 0);
            }
        }
}

TEST_CASE("relocation moves a probe out of a solid box within its cell, and leaves free probes", "[irradiance_volume][visibility][embree]") {
    // A solid box [-0.1, 0.1]^3 wound outwards (seen from outside), lit from above, on no floor.
    hand_built::scene s;
    const auto m = hand_built::add_material(s, glm::vec3(0.5f));
    for (int k = 0; k < 3; ++k)
        for (const float side : {-1.f, 1.f}) {
            glm::vec3 e(0.f), u(0.f), v(0.f);
            e[k] = side;
            u[(k + 1) % 3] = 0.1f;
            v[(k + 2) % 3] = 0.1f;
            const glm::vec3 c = 0.1f * e;
            glm::vec3 q[4] = {c - u - v, c + u - v, c + u + v, c - u + v};  // counter-clockwise seen from +e
            if (side < 0) std::swap(q[1], q[3]);
            hand_built::add_quad(s, q[0], q[1], q[2], q[3], e, m);
        }
    s.lights.push_back(bounce::point_light{{0.f, 2.f, 0.f}, glm::vec3(1.f)});
    const embree::accel bvh(s);
    const embree::reference_integrator light(bvh, s);
    embree::probe_baker_settings bs;
    bs.rays = 64;
    const embree::probe_baker baker(light, bvh, s, bs);
    const float cell = 0.5f;
    embree::relocating_probe_source relocating(baker, bvh, s, cell);
    const glm::vec3 inside(0.02f, 0.03f, -0.01f), free(0.4f, 0.f, 0.f);
    const glm::vec3 moved = relocating.relocate(inside);
    INFO("moved to " << moved.x << " " << moved.y << " " << moved.z);
    CHECK(glm::any(glm::greaterThan(glm::abs(moved), glm::vec3(0.1f))));               // out of the box
    CHECK(glm::all(glm::lessThanEqual(glm::abs(moved - inside), glm::vec3(0.45f * cell))));  // within its cell
    CHECK(relocating.relocate(free) == free);
    // Baked through the source: returned at the lattice point, outside geometry, and the
    // place it was baked is remembered.
    const glm::vec3 positions[2] = {inside, free};
    irradiance_probe out[2];
    relocating(positions, out);
    CHECK(out[0].position == inside);
    CHECK_FALSE(out[0].inside);
    CHECK(baker.bake(inside).inside);  // without relocation it is inside
    CHECK(relocating.moved() == 1);
    // A cell too small to leave the box in: the probe stays (and stays inside).
    embree::relocating_probe_source tight(baker, bvh, s, 0.05f);
    CHECK(tight.relocate(inside) == inside);
}
