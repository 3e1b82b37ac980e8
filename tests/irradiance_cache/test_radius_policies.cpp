// Where a record's radius comes from and how it is kept consistent over many frames:
// neighbour clamping of the whole cache (cpu::irradiance_cache::clamp_to_neighbours), the
// occlusion Hessian of a hemisphere (add_translation_hessian) and the Hessian radius policy.
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/sampling.hpp>
#include <bounce/cache/weighting.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <limits>
#include <random>
#include <vector>

using namespace bounce;

namespace {

// Records scattered in a unit box, some clustered, radii over three decades.
std::vector<irradiance_record> random_records(std::size_t count, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    std::vector<irradiance_record> recs(count);
    for (auto& r : recs) {
        r.position = u(rng) < 0.3f ? glm::vec3(0.5f) + 0.01f * glm::vec3(u(rng), u(rng), u(rng))
                                   : glm::vec3(u(rng), u(rng), u(rng));
        r.radius = std::pow(10.f, -3.f * u(rng));
    }
    return recs;
}

// A hemisphere of M x N cells whose every hit lies at distance r(i) with radiance L(i).
template <class Radiance, class Distance>
hemisphere_samples hemisphere_of(std::uint32_t m, std::uint32_t n, Radiance radiance, Distance distance) {
    hemisphere_samples s;
    s.rings = m;
    s.wedges = n;
    std::vector<glm::vec2> u(std::size_t(m) * n, glm::vec2(0.5f));
    s.direction = stratified_cosine_directions(m, n, u);
    for (std::size_t i = 0; i < s.direction.size(); ++i) {
        s.radiance.push_back(radiance(s.direction[i]));
        s.distance.push_back(distance(s.direction[i]));
    }
    return s;
}

// The built-in box and a cache with neighbour clamping, rendered camera after camera.
struct box_walk {
    static cpu::irradiance_cache_options options() {
        cpu::irradiance_cache_options o;
        o.splat.a = 0.3f;
        o.neighbour_clamp = true;
        return o;
    }
    io::scene scene = io::cornell_box();
    embree::accel bvh{scene};
    embree::reference_integrator integrator{bvh, scene, {}};
    embree::record_sampler sampler{integrator, embree::hemisphere_grid_for(64), radius_limits{}};
    cpu::irradiance_cache<ward_smooth_weight> cache{scene.bounds().first, scene.bounds().second, options()};

    cpu::cache_frame_stats render(const camera& cam, std::uint32_t size) {
        auto g = embree::ray_cast_gbuffer(bvh, scene, cam, size, size);
        image<glm::vec3> indirect(size, size);
        return cache.render(g.view(), cam, sampler, indirect.view());
    }
};

}  // namespace

TEST_CASE("clamping the whole cache makes its radius field 1-Lipschitz and only ever shrinks radii",
          "[irradiance_cache][neighbour_clamp]") {
    const auto original = random_records(600, 3);
    cpu::irradiance_cache_options o;
    o.neighbour_clamp = true;
    cpu::irradiance_cache<ward_weight> cache(glm::vec3(0.f), glm::vec3(1.f), o);
    cache.assign(original);
    const std::size_t shrunk = cache.clamp_to_neighbours();
    const auto& recs = cache.records();
    REQUIRE(recs.size() == original.size());
    std::size_t changed = 0;
    for (std::size_t i = 0; i < recs.size(); ++i) {
        // Exactly the minimum over every original radius plus distance (the linear loop).
        CHECK(recs[i].radius == neighbour_clamped_radius(original[i], original));
        CHECK(recs[i].radius <= original[i].radius);
        changed += recs[i].radius < original[i].radius;
    }
    CHECK(shrunk == changed);
    CHECK(shrunk > 0);
    // R_i <= R_j + |p_i - p_j| for every pair, up to the rounding of two float sums: each side
    // is a float sum of at most three terms, each within 2^-23 relative of the exact one.
    float worst = 0.f;
    for (const auto& a : recs)
        for (const auto& b : recs) {
            const float bound = b.radius + glm::length(a.position - b.position);
            worst = std::max(worst, (a.radius - bound) / bound);
        }
    CHECK(worst <= 4 * std::numeric_limits<float>::epsilon());
    // Nothing new since: the next call changes nothing.
    CHECK(cache.clamp_to_neighbours() == 0);
}

TEST_CASE("without neighbour clamping the cache's radii are left as measured", "[irradiance_cache][neighbour_clamp]") {
    const auto original = random_records(50, 4);
    cpu::irradiance_cache<ward_weight> cache(glm::vec3(0.f), glm::vec3(1.f), {});
    cache.assign(original);
    CHECK(cache.clamp_to_neighbours() == 0);
    for (std::size_t i = 0; i < original.size(); ++i) CHECK(cache.records()[i].radius == original[i].radius);
}

TEST_CASE("a frame from a second camera starts by clamping the first camera's records to the ones made since",
          "[irradiance_cache][neighbour_clamp]") {
    box_walk box;
    const io::scene& scene = box.scene;
    auto& cache = box.cache;
    camera second = scene.camera;
    second.position += 0.3f * (second.look_at - second.position);
    std::size_t reclamped_total = 0;
    for (const camera& cam : {scene.camera, second, scene.camera}) {
        reclamped_total += box.render(cam, 32).reclamped;
    }
    // The second camera's records shrank some of the first's, and the third frame's start
    // some of the second's; one more clamp (as the next frame would start) settles the
    // records the third frame added, and then every pair obeys it.
    CHECK(reclamped_total > 0);
    cache.clamp_to_neighbours();
    const std::vector<irradiance_record>& recs = cache.records();
    float worst = 0.f;
    for (const auto& a : recs)
        for (const auto& b : recs) {
            const float bound = b.radius + glm::length(a.position - b.position);
            worst = std::max(worst, (a.radius - bound) / bound);
        }
    CHECK(worst <= 4 * std::numeric_limits<float>::epsilon());
}

TEST_CASE("clamping only what changed since the last clamp equals clamping the whole cache, frame after frame",
          "[irradiance_cache][neighbour_clamp]") {
    // Each frame adds records from another camera; before each clamp the expected radii are
    // the whole pass over a copy of the cache (the linear loop, every record against every
    // other with the radii before the pass). Old records must shrink to new ones (a clamp of
    // the new records alone would leave them), and the records the previous clamp shrank
    // must act on the rest.
    box_walk box;
    const io::scene& scene = box.scene;
    auto& cache = box.cache;
    std::size_t old_shrunk = 0, frames = 0;
    for (const float step : {0.f, 0.3f, -0.2f, 0.45f, 0.1f}) {
        camera cam = scene.camera;
        cam.position += step * (cam.look_at - cam.position);
        cam.look_at.x += 0.5f * step;
        const std::size_t before = cache.records().size();
        box.render(cam, 40);
        const std::vector<irradiance_record> snapshot = cache.records();
        if (snapshot.size() == before) continue;
        ++frames;
        const std::size_t shrunk = cache.clamp_to_neighbours();
        const std::vector<irradiance_record>& recs = cache.records();
        REQUIRE(recs.size() == snapshot.size());
        std::size_t mismatched = 0, changed = 0;
        for (std::size_t i = 0; i < recs.size(); ++i) {
            const float expected = neighbour_clamped_radius(snapshot[i], snapshot);
            mismatched += recs[i].radius != expected;
            changed += expected < snapshot[i].radius;
            old_shrunk += i < before && expected < snapshot[i].radius;
        }
        CHECK(mismatched == 0);
        CHECK(shrunk == changed);
    }
    CHECK(frames >= 4);
    CHECK(old_shrunk > 0);
}

TEST_CASE("the occlusion Hessian vanishes under uniform radiance however near the geometry is",
          "[irradiance_gradients][hessian]") {
    // A closed box of uniform radiance: E = pi L wherever the point moves, so its Hessian is 0.
    const auto s = hemisphere_of(16, 50, [](glm::vec3) { return glm::vec3(2.f, 1.f, 0.5f); },
                                 [](glm::vec3 d) { return 0.1f + 0.5f * std::abs(d.x); });
    const hemisphere_estimate e = estimate_hemisphere(s);
    for (int c = 0; c < 3; ++c) {
        // Each cell's term is (L - E/pi) with E/pi equal to L up to the double sum's rounding.
        const double scale = e.irradiance[c] / (0.1 * 0.1) * 15;
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) CHECK(std::abs(e.hessian[c][i][j]) <= 1e-12 * scale);
    }
    // So the radius is unbounded but for that rounding: over 10^4 times the nearest hit.
    CHECK(hessian_radius(e.irradiance, e.hessian, 0.2) > 1e3);
}

TEST_CASE("the occlusion Hessian is symmetric and scales as one over distance squared",
          "[irradiance_gradients][hessian]") {
    // A dark block on one side (x > 0.3) under a bright sky: the point sees an occluder.
    auto radiance = [](glm::vec3 d) { return d.x > 0.3f ? glm::vec3(0.f) : glm::vec3(1.f); };
    const auto near = estimate_hemisphere(hemisphere_of(16, 50, radiance, [](glm::vec3 d) {
        return d.x > 0.3f ? 1.f : std::numeric_limits<float>::infinity();
    }));
    const auto far = estimate_hemisphere(hemisphere_of(16, 50, radiance, [](glm::vec3 d) {
        return d.x > 0.3f ? 4.f : std::numeric_limits<float>::infinity();
    }));
    const double h = near.hessian[0][0][0];
    CHECK(h != 0.0);
    CHECK(near.hessian[0][0][1] == near.hessian[0][1][0]);
    // Distances 4x: every term 16x smaller (the float distances are exact powers of two).
    CHECK(far.hessian[0][0][0] == Approx(h / 16).epsilon(1e-12));
    // So the Hessian radius grows 4x (R ~ 1 / sqrt(lambda)).
    const double r_near = hessian_radius(near.irradiance, near.hessian, 0.2),
                 r_far = hessian_radius(far.irradiance, far.hessian, 0.2);
    CHECK(r_far == Approx(4 * r_near).epsilon(1e-9));
}

TEST_CASE("the Hessian radius puts the second-order error a at the zone's edge", "[irradiance_record][hessian]") {
    // Channel 0: eigenvalues 3 and -5 (largest magnitude 5); E = 2. 1/2 * 5 * (a R)^2 = a * 2.
    std::array<glm::dmat2, 3> h{glm::dmat2(0.0), glm::dmat2(0.0), glm::dmat2(0.0)};
    const double c = std::cos(0.4), s = std::sin(0.4);
    const glm::dmat2 rot(c, s, -s, c);
    h[0] = rot * glm::dmat2(3.0, 0.0, 0.0, -5.0) * glm::transpose(rot);
    const double a = 0.15;
    const double r = hessian_radius(glm::dvec3(2.0, 0.0, 1.0), h, a);
    CHECK(0.5 * 5 * (a * r) * (a * r) == Approx(a * 2));
    // Through make_record with the policy: the radius before the limits is that one.
    hemisphere_estimate est;
    est.irradiance = glm::dvec3(2.0, 1.0, 1.0);
    est.hessian = h;
    est.harmonic_mean_distance = 0.01;
    radius_limits lim;
    lim.gradient_limit = false;
    lim.policy = radius_policy::hessian;
    lim.hessian_a = float(a);
    const auto rec = make_record(glm::vec3(0.f), glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), est, lim, 0.0);
    CHECK(rec.radius == Approx(r).epsilon(1e-6));
    lim.policy = radius_policy::split_sphere;
    CHECK(make_record(glm::vec3(0.f), glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), est, lim, 0.0).radius ==
          Approx(0.01f));
    lim.policy = radius_policy::hessian;
    lim.hessian_a = 0.f;
    CHECK_THROWS_WITH(make_record(glm::vec3(0.f), glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), est, lim, 0.0),
                      Catch::Contains("hessian_a"));
}

TEST_CASE("without gradients the Hessian radius puts the first- plus second-order error a at the zone's edge",
          "[irradiance_record][hessian]") {
    // Eigenvalues 3 and -5 (largest magnitude 5), E = 2, |grad E| = 1 on channel 0.
    std::array<glm::dmat2, 3> h{glm::dmat2(0.0), glm::dmat2(0.0), glm::dmat2(0.0)};
    h[0] = glm::dmat2(3.0, 0.0, 0.0, -5.0);
    const std::array<glm::dvec3, 3> g{glm::dvec3(0.6, 0.8, 0.0), glm::dvec3(0.0), glm::dvec3(0.0)};
    const glm::dvec3 e(2.0, 0.0, 0.0);
    const double a = 0.2;
    const double d = a * hessian_radius(e, h, a, &g);
    CHECK(1.0 * d + 0.5 * 5 * d * d == Approx(a * 2).epsilon(1e-12));
    // No curvature: the first-order bound alone, d = a E / |grad E|.
    const std::array<glm::dmat2, 3> flat{glm::dmat2(0.0), glm::dmat2(0.0), glm::dmat2(0.0)};
    CHECK(a * hessian_radius(e, flat, a, &g) == Approx(a * 2 / 1.0).epsilon(1e-12));
    // No gradient: the same as the radius for a cache that extrapolates with gradients.
    const std::array<glm::dvec3, 3> none{};
    CHECK(hessian_radius(e, h, a, &none) == Approx(hessian_radius(e, h, a)).epsilon(1e-12));
    // The first-order term only ever shrinks the zone.
    CHECK(hessian_radius(e, h, a, &g) < hessian_radius(e, h, a));
}

TEST_CASE("with a length the Hessian radius spends the error of a over a disc of that radius on its zone",
          "[irradiance_record][hessian]") {
    // Relative curvature lambda / E = 5 / 2 on channel 0 (channels 1, 2 dark: skipped).
    std::array<glm::dmat2, 3> h{glm::dmat2(0.0), glm::dmat2(0.0), glm::dmat2(0.0)};
    h[0] = glm::dmat2(-5.0, 0.0, 0.0, 1.0);
    const glm::dvec3 e(2.0, 0.0, 0.0);
    const double a = 0.15, ell = 3.0, lambda_rel = 2.5;
    const double d = a * hessian_radius(e, h, a, nullptr, ell);
    // The zone's integrated second-order relative error, int_0^d int_0^2pi 1/2 lambda_rel r^2 r dphi dr
    // = pi lambda_rel d^4 / 4, equals a spread over a disc of radius ell.
    CHECK(std::numbers::pi * lambda_rel * std::pow(d, 4) / 4 == Approx(a * std::numbers::pi * ell * ell).epsilon(1e-12));
    // The same integral by the midpoint rule in r (the integrand r^3 is smooth; error ~ 1/n^2).
    double integral = 0;
    const int n = 2000;
    for (int i = 0; i < n; ++i) {
        const double r = (i + 0.5) * d / n;
        integral += 2 * std::numbers::pi * 0.5 * lambda_rel * r * r * r * (d / n);
    }
    CHECK(integral == Approx(a * std::numbers::pi * ell * ell).epsilon(1e-5));
    // The zone is the geometric mean of sqrt(2) ell and the pointwise zone sqrt(2 a / lambda_rel).
    const double pointwise = a * hessian_radius(e, h, a);
    CHECK(pointwise == Approx(std::sqrt(2 * a / lambda_rel)).epsilon(1e-12));
    CHECK(d == Approx(std::sqrt(std::sqrt(2.0) * ell * pointwise)).epsilon(1e-12));
    // Fourth root: 16 times the curvature halves the zone (the pointwise zone would shrink 4x).
    std::array<glm::dmat2, 3> h16 = h;
    h16[0] = 16.0 * h[0];
    CHECK(a * hessian_radius(e, h16, a, nullptr, ell) == Approx(d / 2).epsilon(1e-12));
    // No curvature anywhere: the zone is the length itself (not unbounded).
    const std::array<glm::dmat2, 3> flat{glm::dmat2(0.0), glm::dmat2(0.0), glm::dmat2(0.0)};
    CHECK(a * hessian_radius(e, flat, a, nullptr, ell) == Approx(ell));
    CHECK(std::isinf(hessian_radius(e, flat, a)));
}

TEST_CASE("the occlusion Hessian turns with the hemisphere", "[irradiance_gradients][hessian]") {
    // With N divisible by 4 and centred jitter, turning the radiance and distances by 90
    // degrees about the normal moves every cell onto another: H' = Q H Q^T exactly but for
    // the rounding of the cells' float directions.
    auto radiance = [](glm::vec3 d) { return glm::vec3(1.f + 3.f * std::max(0.f, d.x - 0.2f * d.y), 0.5f, 2.f * d.z); };
    auto distance = [](glm::vec3 d) { return d.y > 0.4f ? std::numeric_limits<float>::infinity() : 0.5f + d.x * d.x + 0.3f * d.y; };
    auto turned = [](glm::vec3 d) { return glm::vec3(d.y, -d.x, d.z); };  // Q^T d for Q a +90 degree turn
    const auto e0 = estimate_hemisphere(hemisphere_of(12, 40, radiance, distance));
    const auto e1 = estimate_hemisphere(hemisphere_of(12, 40, [&](glm::vec3 d) { return radiance(turned(d)); },
                                                      [&](glm::vec3 d) { return distance(turned(d)); }));
    const glm::dmat2 q(0.0, 1.0, -1.0, 0.0);  // columns: (0, 1), (-1, 0)
    for (int c = 0; c < 3; ++c) {
        const glm::dmat2 expected = q * e0.hessian[c] * glm::transpose(q);
        const double scale = largest_abs_eigenvalue(e0.hessian[c]);
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) CHECK(std::abs(e1.hessian[c][i][j] - expected[i][j]) <= 1e-5 * scale);
        CHECK(e1.hessian[c][0][1] == e1.hessian[c][1][0]);
        CHECK(largest_abs_eigenvalue(e1.hessian[c]) == Approx(scale).epsilon(1e-5));
    }
    CHECK(e1.mean_distance == Approx(e0.mean_distance).epsilon(1e-6));
}

TEST_CASE("the mean hit distance averages the cells that hit", "[irradiance_gradients][hessian]") {
    auto distance = [](glm::vec3 d) { return d.x > 0.5f ? std::numeric_limits<float>::infinity() : 1.f + d.z; };
    const auto s = hemisphere_of(8, 25, [](glm::vec3) { return glm::vec3(1.f); }, distance);
    double sum = 0;
    int hits = 0;
    for (float r : s.distance)
        if (std::isfinite(r)) sum += r, ++hits;
    REQUIRE(hits > 0);
    REQUIRE(hits < int(s.size()));
    CHECK(estimate_hemisphere(s).mean_distance == Approx(sum / hits).epsilon(1e-12));
    // Nothing hit: no length.
    const auto sky = hemisphere_of(8, 25, [](glm::vec3) { return glm::vec3(1.f); },
                                   [](glm::vec3) { return std::numeric_limits<float>::infinity(); });
    CHECK(std::isinf(estimate_hemisphere(sky).mean_distance));
}

TEST_CASE("the Hessian policy's radius on hard hemispheres", "[irradiance_record][hessian]") {
    radius_limits lim;
    lim.policy = radius_policy::hessian;
    lim.hessian_a = 0.2f;
    const glm::vec3 p(0.f), n(0, 0, 1), t(1, 0, 0), b(0, 1, 0);
    SECTION("zero irradiance: a black enclosure gets the zone of its own size, not an unbounded one") {
        const auto s = hemisphere_of(8, 25, [](glm::vec3) { return glm::vec3(0.f); }, [](glm::vec3) { return 2.f; });
        const auto est = estimate_hemisphere(s);
        const auto rec = make_record(p, n, t, b, est, lim, 0.0);
        CHECK(rec.radius * lim.hessian_a == Approx(2.f));
    }
    SECTION("a hit at distance ~epsilon at a grazing direction: finite, and shrinking as the fourth root") {
        // A bright sky with one dark speck of geometry in the outermost ring (theta ~ 80 degrees).
        auto make = [&](float r_near) {
            auto s = hemisphere_of(16, 50, [](glm::vec3) { return glm::vec3(1.f); },
                                   [](glm::vec3) { return std::numeric_limits<float>::infinity(); });
            const std::size_t i = 15 * 50 + 7;
            REQUIRE(s.direction[i].z < 0.2f);
            s.radiance[i] = glm::vec3(0.f);
            s.distance[i] = r_near;
            return estimate_hemisphere(s);
        };
        const auto e1 = make(1e-6f), e2 = make(16e-6f);
        for (const auto* e : {&e1, &e2}) {
            const float r = make_record(p, n, t, b, *e, lim, 0.0).radius;
            CHECK(std::isfinite(r));
            CHECK(r > 0.f);
        }
        // The speck is the only hit, so the length is its distance and the zone
        // sqrt(sqrt(2) ell d_pointwise) with d_pointwise ~ r: 16x the distance, 16x the zone.
        const double r1 = hessian_radius(e1.irradiance, e1.hessian, 0.2, nullptr, e1.mean_distance);
        const double r2 = hessian_radius(e2.irradiance, e2.hessian, 0.2, nullptr, e2.mean_distance);
        CHECK(r2 / r1 == Approx(16.0).epsilon(1e-4));
    }
    SECTION("the gradient limit bounds the zone, not R, when the cache extrapolates with gradients") {
        hemisphere_estimate est;
        est.irradiance = glm::dvec3(2.0);
        est.translation = {glm::dvec3(4.0, 0, 0), glm::dvec3(4.0, 0, 0), glm::dvec3(4.0, 0, 0)};  // E / |g| = 0.5
        est.hessian = {glm::dmat2(1e-6), glm::dmat2(1e-6), glm::dmat2(1e-6)};  // nearly flat: a large Hessian radius
        est.harmonic_mean_distance = 10.0;
        CHECK(make_record(p, n, t, b, est, lim, 0.0).radius * lim.hessian_a == Approx(0.5f));
        lim.gradient_limit = false;
        CHECK(make_record(p, n, t, b, est, lim, 0.0).radius * lim.hessian_a > 100.f);
        // Without gradients the first-order term is in the error model itself: g d <= a E.
        lim.hessian_gradients = false;
        CHECK(make_record(p, n, t, b, est, lim, 0.0).radius * lim.hessian_a <= Approx(lim.hessian_a * 0.5f));
        // The split sphere keeps R <= E / |g|.
        lim.policy = radius_policy::split_sphere;
        lim.gradient_limit = true;
        CHECK(make_record(p, n, t, b, est, lim, 0.0).radius == Approx(0.5f));
    }
}

TEST_CASE("world limits from the scene's size and the record's mean hit distance", "[irradiance_record][world]") {
    const glm::dvec3 e(1.0);
    const std::array<glm::dvec3, 3> flat{};
    SECTION("scene_radius_limits: size over the resolution, capped by the ratio and the size") {
        const radius_limits lim = scene_radius_limits({}, glm::vec3(-1.f, 0.f, 0.f), glm::vec3(3.f, 1.f, 2.f), 64.f, 8.f);
        CHECK(lim.min_world == Approx(4.f / 64.f));  // the largest extent, 4, over 64
        CHECK(lim.max_world == Approx(8.f * 4.f / 64.f));
        CHECK(scene_radius_limits({}, glm::vec3(0.f), glm::vec3(1.f), 2.f, 64.f).max_world == Approx(1.f));  // at most the size
        const radius_limits none = scene_radius_limits({}, glm::vec3(0.f), glm::vec3(1.f), 0.f);
        CHECK(none.min_world == 0.f);
        CHECK(std::isinf(none.max_world));
        CHECK_THROWS(scene_radius_limits({}, glm::vec3(0.f), glm::vec3(1.f), -1.f));
        CHECK_THROWS(scene_radius_limits({}, glm::vec3(0.f), glm::vec3(1.f), 8.f, 0.5f));
        // The clamp follows: a corner's R = 0.001 rises to the floor, an open sky's to the cap.
        CHECK(limit_radius(0.001, e, flat, lim, 0.0) == Approx(lim.min_world));
        CHECK(limit_radius(std::numeric_limits<double>::infinity(), e, flat, lim, 0.0) == Approx(lim.max_world));
    }
    SECTION("the mean-distance floor: a corner's harmonic mean against the room's mean distance") {
        radius_limits lim;
        lim.min_mean_distance = 1.f / 32.f;
        CHECK(limit_radius(0.01, e, flat, lim, 0.0, 4.0) == Approx(4.0 / 32.0));  // raised to 1/32 of 4
        CHECK(limit_radius(0.5, e, flat, lim, 0.0, 4.0) == Approx(0.5));          // above the floor: unchanged
        CHECK(limit_radius(0.01, e, flat, lim, 0.0) == Approx(0.01));             // no length: no floor
        // The pixel guard still applies after it, and the floor scales with the scene.
        lim.min_pixels = 2.f;
        CHECK(limit_radius(0.01, e, flat, lim, 0.1, 4.0) == Approx(0.2));
        lim.min_pixels = 0.f;
        CHECK(limit_radius(0.01 * 1000, e, flat, lim, 0.0, 4.0 * 1000) == Approx(1000 * limit_radius(0.01, e, flat, lim, 0.0, 4.0)));
    }
    SECTION("make_record floors the split sphere with the estimate's mean distance") {
        // A point 1 above the floor of a box of size 100: the floor's hits are near, the walls far.
        const auto s = hemisphere_of(8, 25, [](glm::vec3) { return glm::vec3(1.f); },
                                     [](glm::vec3 d) { return d.z > 0.9f ? 0.001f : 50.f; });
        const hemisphere_strata strata(8, 25);
        const auto est = estimate_hemisphere(s, strata, translation_gradient_kind::krivanek_2005, true);
        radius_limits lim;
        lim.gradient_limit = false;
        const float plain = make_record(glm::vec3(0.f), glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), est, lim, 0.0).radius;
        lim.min_mean_distance = 1.f / 16.f;
        const float floored = make_record(glm::vec3(0.f), glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), est, lim, 0.0).radius;
        CHECK(plain < est.mean_distance / 16.0);
        CHECK(floored == Approx(est.mean_distance / 16.0));
    }
}

TEST_CASE("the Hessian zone capped by the split sphere's radius", "[irradiance_record][hessian]") {
    radius_limits lim;
    lim.policy = radius_policy::hessian;
    lim.hessian_a = 0.25f;
    lim.gradient_limit = false;
    hemisphere_estimate est;
    est.irradiance = glm::dvec3(2.0);
    est.hessian = {glm::dmat2(1e-6), glm::dmat2(1e-6), glm::dmat2(1e-6)};  // nearly flat light
    est.harmonic_mean_distance = 0.1;  // near geometry
    est.mean_distance = 5.0;
    const glm::vec3 p(0.f), n(0, 0, 1), t(1, 0, 0), b(0, 1, 0);
    const float free = make_record(p, n, t, b, est, lim, 0.0).radius;
    CHECK(free * lim.hessian_a > 1.f);  // the Hessian alone: a zone of the room's size
    lim.hessian_zone_cap = 1.f;
    CHECK(make_record(p, n, t, b, est, lim, 0.0).radius * lim.hessian_a == Approx(0.1f));  // the zone at R_split
    lim.hessian_zone_cap = 2.f;
    CHECK(make_record(p, n, t, b, est, lim, 0.0).radius * lim.hessian_a == Approx(0.2f));
    // Where the light curves, the Hessian's own zone is the smaller and the cap does nothing.
    est.hessian = {glm::dmat2(1e6), glm::dmat2(1e6), glm::dmat2(1e6)};
    const float curved = make_record(p, n, t, b, est, lim, 0.0).radius;
    lim.hessian_zone_cap = std::numeric_limits<float>::infinity();
    CHECK(make_record(p, n, t, b, est, lim, 0.0).radius == curved);
    CHECK(curved * lim.hessian_a < 0.2f);
}
