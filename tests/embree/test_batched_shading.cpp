// The batched queries and the batched shading of hemisphere rays (issue 19, cheaper records):
// accel's packet queries return what its single-ray queries return; the reference
// integrator's batched incoming_radiance and sample_hemisphere return bitwise what one ray at
// a time returns; choosing one light per hit (secondary_light_choice) changes nothing where
// one light reaches the hit and keeps every hit's expected radiance where several do.
#include <bounce/embree/accel.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/direct_light.hpp>
#include <bounce/sampling.hpp>

#include "hand_built_scenes.hpp"

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

using namespace bounce;
using namespace bounce::embree;

namespace {

// A floor, a low ceiling strip and a pillar (shadows of both lights fall on the floor), lit
// by a point light and a directional light of different colours (both reach the pillar's -x
// and -y faces), with an emissive square
// when `emission` (area samples then add shadow rays too).
test::owned_scene two_light_room(bool emission) {
    test::owned_scene s;
    s.name = "two-light room";
    const auto grey = hand_built::add_material(s, glm::vec3(0.6f, 0.5f, 0.4f));
    const auto white = hand_built::add_material(s, glm::vec3(0.8f));
    hand_built::add_square_z(s, 0.f, 4.f, true, grey);
    hand_built::add_square_z(s, 1.5f, 1.f, false, white, {1.5f, 0.f});
    // A pillar: four vertical quads around x in [-0.6, -0.4], y in [-0.1, 0.1], z in [0, 1].
    const glm::vec3 a(-0.6f, -0.1f, 0.f), b(-0.4f, -0.1f, 0.f), c(-0.4f, 0.1f, 0.f), d(-0.6f, 0.1f, 0.f),
        up(0.f, 0.f, 1.f);
    hand_built::add_quad(s, a, b, b + up, a + up, {0, -1, 0}, white);
    hand_built::add_quad(s, b, c, c + up, b + up, {1, 0, 0}, white);
    hand_built::add_quad(s, c, d, d + up, c + up, {0, 1, 0}, white);
    hand_built::add_quad(s, d, a, a + up, d + up, {-1, 0, 0}, white);
    s.lights.push_back(bounce::point_light{{-1.5f, -1.f, 1.2f}, glm::vec3(3.f, 2.f, 1.f)});
    s.lights.push_back(bounce::directional_light{glm::normalize(glm::vec3(0.5f, 0.2f, -1.f)), glm::vec3(1.f, 1.5f, 2.f)});
    if (emission) {
        const auto lamp = hand_built::add_material(s, glm::vec3(0.f), glm::vec3(2.f, 2.f, 1.f));
        hand_built::add_square_z(s, 1.4f, 0.2f, false, lamp, {-1.5f, 0.5f});
        s.use_emission = true;
    }
    return s;
}

// Rays from points on the floor into random upward directions (cosine-weighted), some
// towards the ceiling strip and the pillar, some into the open.
std::vector<ray> floor_rays(std::size_t count, float epsilon, std::uint64_t seed) {
    pcg32 rng(seed);
    std::vector<ray> rays(count);
    for (auto& r : rays) {
        r.origin = {float(4 * rng.next_double() - 2), float(4 * rng.next_double() - 2), epsilon};
        const float u = rng.next_float(), v = rng.next_float();
        r.direction = glm::normalize(stratified_cosine_direction<float, glm::vec3>(0.f, 0.f, 1.f, 1.f, u, v));
    }
    return rays;
}

// Rays from the floor on the lit side of the pillar towards points on its -x and -y faces.
std::vector<ray> pillar_rays(std::size_t count, float epsilon, std::uint64_t seed) {
    pcg32 rng(seed);
    std::vector<ray> rays(count);
    for (auto& r : rays) {
        r.origin = {float(-1.5 + rng.next_double()), float(-1.5 + rng.next_double()), epsilon};
        const glm::vec3 target(float(-0.6 + 0.2 * rng.next_double()), float(-0.1 + 0.2 * rng.next_double()),
                               float(0.1 + 0.8 * rng.next_double()));
        r.direction = glm::normalize(target - r.origin);
    }
    return rays;
}

bool same_bits(glm::vec3 a, glm::vec3 b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST_CASE("packet queries return the hits and occlusion of single-ray queries", "[embree][queries][batched]") {
    const test::owned_scene s = two_light_room(true);
    const accel bvh(s);
    // Sizes around the packet width: empty, a partial packet, whole packets and a tail.
    const auto count = GENERATE(std::size_t(0), std::size_t(5), std::size_t(8), std::size_t(203));
    std::vector<ray> rays = floor_rays(count, bvh.ray_epsilon(), 11 + count);
    // Half of them as segments that stop before the far side (the occlusion queries' tfar).
    for (std::size_t i = 0; i < count; i += 2) rays[i].tfar = 0.8f;
    std::vector<hit> hits(count);
    std::vector<std::uint8_t> blocked(count);
    bvh.intersect_packets(rays, hits);
    bvh.occluded_packets(rays, blocked);
    std::size_t found = 0, occluded = 0;
    for (std::size_t i = 0; i < count; ++i) {
        const hit h = bvh.intersect(rays[i]);
        CHECK(hits[i].triangle == h.triangle);
        CHECK(same_bits(hits[i].t, h.t));
        CHECK(same_bits(hits[i].u, h.u));
        CHECK(same_bits(hits[i].v, h.v));
        CHECK(bool(blocked[i]) == bvh.occluded(rays[i]));
        found += h.found() ? 1 : 0;
        occluded += blocked[i];
    }
    if (count > 100) {
        CHECK(found > 10);           // some rays hit the ceiling strip or the pillar ...
        CHECK(found < count - 10);   // ... and the others escape
        CHECK(occluded > 0);
    }
    std::vector<hit> short_hits(count + 1);
    CHECK_THROWS_WITH(bvh.intersect_packets(rays, short_hits), Catch::Contains("rays"));
}

TEST_CASE("batched incoming radiance is bitwise the single-ray radiance", "[reference][batched]") {
    const bool emission = GENERATE(false, true);
    const bool choice = GENERATE(false, true);
    const test::owned_scene s = two_light_room(emission);
    const accel bvh(s);
    reference_settings settings;
    settings.environment = {0.1f, 0.2f, 0.3f};
    settings.secondary_area_samples = 9;  // 9 shadow rays per hit: the shadow queue fills and flushes
    settings.secondary_light_choice = choice;
    const reference_integrator ri(bvh, s, settings);
    // More rays than one batch, with a partial batch at the end.
    const std::vector<ray> rays = floor_rays(1000, ri.ray_epsilon(), 21);
    std::vector<std::uint64_t> seeds(rays.size());
    for (std::size_t i = 0; i < seeds.size(); ++i) seeds[i] = derive_seed(5, 6, i);
    std::vector<glm::vec3> radiance(rays.size());
    std::vector<float> distance(rays.size());
    ri.incoming_radiance(rays, seeds, radiance, distance);
    std::size_t lit = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        float d = 0.f;
        const glm::vec3 l = ri.incoming_radiance(rays[i], seeds[i], &d);
        CHECK(same_bits(radiance[i], l));
        CHECK(same_bits(distance[i], d));
        lit += std::isfinite(d) && l != glm::vec3(0.f) ? 1 : 0;
    }
    CHECK(lit > 50);
    std::vector<float> short_distance(rays.size() - 1);
    CHECK_THROWS_WITH(ri.incoming_radiance(rays, seeds, radiance, short_distance), Catch::Contains("rays"));
}

TEST_CASE("sample_hemisphere shades sample i as incoming_radiance with stream derive_seed(seed, 3, i)",
          "[reference][batched][hemisphere]") {
    const bool choice = GENERATE(false, true);
    const test::owned_scene s = two_light_room(true);
    const accel bvh(s);
    reference_settings settings;
    settings.secondary_light_choice = choice;
    const reference_integrator ri(bvh, s, settings);
    const hemisphere_grid grid = hemisphere_grid_for(1024);
    pcg32 rng(31);
    for (int k = 0; k < 4; ++k) {
        const glm::vec3 p(float(3 * rng.next_double() - 1.5), float(3 * rng.next_double() - 1.5), 0.f);
        const std::uint64_t seed = 40 + k;
        const hemisphere_samples hs = ri.sample_hemisphere(p, {0, 0, 1}, grid, seed);
        ray r;
        r.origin = p + ri.ray_epsilon() * glm::vec3(0, 0, 1);
        std::size_t mismatches = 0, found = 0;
        for (std::size_t i = 0; i < hs.direction.size(); ++i) {
            r.direction = hs.direction[i];
            float d = 0.f;
            const glm::vec3 l = ri.incoming_radiance(r, derive_seed(seed, 3, i), &d);
            mismatches += same_bits(l, hs.radiance[i]) && same_bits(d, hs.distance[i]) ? 0 : 1;
            found += std::isfinite(d) ? 1 : 0;
        }
        CHECK(mismatches == 0);
        CHECK(found > 0);
        CHECK(ri.trace_hemisphere(p, {0, 0, 1}, grid, seed) == found);
    }
}

TEST_CASE("choosing one light per hit changes nothing where one light reaches it", "[reference][light-choice]") {
    const io::scene scene = io::cornell_box();  // one spot light
    REQUIRE(scene.lights.size() == 1);
    const accel bvh(scene);
    reference_settings all, one;
    one.secondary_light_choice = true;
    const reference_integrator ri_all(bvh, scene, all), ri_one(bvh, scene, one);
    const auto [lo, hi] = scene.bounds();
    const glm::vec3 p(0.5f * (lo.x + hi.x), lo.y + 1e-3f * (hi.y - lo.y), 0.5f * (lo.z + hi.z));
    const hemisphere_grid grid = hemisphere_grid_for(512);
    const hemisphere_samples a = ri_all.sample_hemisphere(p, {0, 1, 0}, grid, 9),
                             b = ri_one.sample_hemisphere(p, {0, 1, 0}, grid, 9);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.radiance.size(); ++i) differ += same_bits(a.radiance[i], b.radiance[i]) ? 0 : 1;
    CHECK(differ == 0);
}

TEST_CASE("choosing one light per hit keeps each hit's expected radiance", "[reference][light-choice]") {
    // Without emitters a hit's radiance is deterministic with every light; with one light
    // chosen per hit it is a random variable whose mean must be that value. Per ray, the
    // mean over 400 seeds lies within 5 standard errors of it (the sample variance over
    // the seeds gives the standard error) plus 1e-5 relative for float sums.
    const test::owned_scene s = two_light_room(false);
    const accel bvh(s);
    reference_settings all, one;
    one.secondary_light_choice = true;
    const reference_integrator ri_all(bvh, s, all), ri_one(bvh, s, one);
    std::vector<ray> rays = floor_rays(150, ri_all.ray_epsilon(), 77);
    const std::vector<ray> towards_pillar = pillar_rays(150, ri_all.ray_epsilon(), 78);
    rays.insert(rays.end(), towards_pillar.begin(), towards_pillar.end());
    const int seeds = 400;
    std::size_t noisy = 0, checked = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const glm::dvec3 exact(ri_all.incoming_radiance(rays[i], 1));
        glm::dvec3 sum(0.0), sum2(0.0);
        for (int k = 0; k < seeds; ++k) {
            const glm::dvec3 l(ri_one.incoming_radiance(rays[i], derive_seed(3, 4, std::uint64_t(k))));
            sum += l;
            sum2 += l * l;
        }
        const glm::dvec3 mean = sum / double(seeds);
        const glm::dvec3 sigma = glm::sqrt(glm::max(glm::dvec3(0.0), sum2 / double(seeds) - mean * mean) / double(seeds));
        for (int c = 0; c < 3; ++c) CHECK(std::abs(mean[c] - exact[c]) <= 5 * sigma[c] + 1e-5 * exact[c] + 1e-12);
        noisy += sigma.x > 0.0 ? 1 : 0;
        checked += exact.x > 0.0 ? 1 : 0;
    }
    // Hits that both lights reach vary with the choice (their colours differ), and there
    // are many of them.
    CHECK(checked > 30);
    CHECK(noisy > 10);
}

TEST_CASE("a hit is shaded with surface_at's position, normals and albedo", "[reference][batched][surface]") {
    // The integrator shades hits from its own packed copy of each triangle; the radiance
    // must be bitwise what surface_at's surface gives. A sphere with interpolated vertex
    // normals under a directional light: a hit on the lit side is unshadowed (the sphere is
    // convex), so its radiance is rho / pi * E_perp max(0, -n . d) with surface_at's n.
    test::owned_scene s;
    s.name = "sphere";
    const auto m = hand_built::add_material(s, glm::vec3(0.7f, 0.5f, 0.3f));
    hand_built::add_icosphere(s, {0.2, -0.1, 0.3}, 1.0, 2, m);
    const bounce::directional_light sun{glm::normalize(glm::vec3(0.3f, -1.f, 0.2f)), glm::vec3(2.f, 1.5f, 1.f)};
    s.lights.push_back(sun);
    const accel bvh(s);
    const reference_integrator ri(bvh, s);
    pcg32 rng(91);
    std::size_t lit = 0;
    for (int k = 0; k < 500; ++k) {
        ray r;
        r.origin = glm::vec3(float(6 * rng.next_double() - 3), 3.f, float(6 * rng.next_double() - 3));
        r.direction = glm::normalize(glm::vec3(0.2f, -0.1f, 0.3f) - r.origin +
                                     glm::vec3(float(rng.next_double() - 0.5), 0.f, float(rng.next_double() - 0.5)));
        const hit h = bvh.intersect(r);
        if (!h.found()) continue;
        const surface sf = surface_at(s, r, h);
        const glm::vec3 c = directional_light_irradiance<float, glm::vec3>(sf.normal, sun.direction, sun.irradiance);
        const glm::vec3 expected(glm::dvec3(sf.albedo) * (1.0 / std::numbers::pi) * glm::dvec3(c));
        float d = 0.f;
        CHECK(same_bits(ri.incoming_radiance(r, 1, &d), expected));
        CHECK(d == h.t * glm::length(r.direction));
        lit += c.x > 0.f ? 1 : 0;
    }
    CHECK(lit > 100);
}
