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
#include <bounce/weighting.hpp>

#include <catch2/catch.hpp>

#include <cmath>
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
    const io::scene scene = io::cornell_box();
    const embree::accel bvh(scene);
    const embree::reference_integrator integrator(bvh, scene, {});
    const embree::record_sampler sampler(integrator, embree::hemisphere_grid_for(64), radius_limits{});
    cpu::irradiance_cache_options o;
    o.splat.a = 0.3f;
    o.neighbour_clamp = true;
    const auto [lo, hi] = scene.bounds();
    cpu::irradiance_cache<ward_smooth_weight> cache(lo, hi, o);
    camera second = scene.camera;
    second.position += 0.3f * (second.look_at - second.position);
    std::size_t reclamped_total = 0;
    for (const camera& cam : {scene.camera, second, scene.camera}) {
        auto g = embree::ray_cast_gbuffer(bvh, scene, cam, 32, 32);
        image<glm::vec3> indirect(32, 32);
        reclamped_total += cache.render(g.view(), cam, sampler, indirect.view()).reclamped;
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
