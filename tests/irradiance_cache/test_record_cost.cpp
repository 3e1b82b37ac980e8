// A record's own work made cheap without changing a bit of it (issue 19, "cheaper records";
// docs/irradiance-splatting.md, "Record cost against Embree"):
//  - estimate_hemisphere from a grid's precomputed trigonometry (hemisphere_strata) against
//    the straightforward estimate that evaluates every ring's and wedge's sines, cosines and
//    arcsines per cell (the code before the tables, kept here as the reference), bit for bit,
//    on random hemispheres of many grid sizes and both translation-gradient formulas;
//  - embree::record_sampler (per-thread buffers, cached strata, batched adaptive rounds)
//    against the same records computed the plain way from the integrator's public calls,
//    bit for bit, serially and on every core;
//  - bad input still refused, naming the parameter.
#include <bounce/cache/adaptive_hemisphere.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/cache/gradients.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <vector>

using namespace bounce;

namespace {

// estimate_hemisphere as it was before hemisphere_strata: every boundary's trigonometry
// evaluated where it is used, per cell. The reference the tables must reproduce exactly.
hemisphere_estimate straightforward_estimate(const hemisphere_samples& s, translation_gradient_kind kind) {
    s.validate();
    const std::uint32_t M = s.rings, N = s.wedges;
    const double pi = std::numbers::pi, dphi = 2 * pi / N;
    auto L = [&](std::uint32_t j, std::uint32_t k) { return glm::dvec3(s.radiance[j * N + k]); };
    auto r = [&](std::uint32_t j, std::uint32_t k) { return double(s.distance[j * N + k]); };
    auto sin_lo = [&](std::uint32_t j) { return std::sqrt(double(j) / M); };
    auto cos_lo = [&](std::uint32_t j) { return std::sqrt(1.0 - double(j) / M); };
    auto theta_lo = [&](std::uint32_t j) { return std::asin(sin_lo(j)); };

    hemisphere_estimate e;
    double inverse_distance_sum = 0;
    for (std::uint32_t j = 0; j < M; ++j) {
        const double t0 = theta_lo(j), t1 = theta_lo(j + 1);
        const double sin2_integral = (t1 - t0) / 2 - (sin_lo(j + 1) * cos_lo(j + 1) - sin_lo(j) * cos_lo(j)) / 2;
        for (std::uint32_t k = 0; k < N; ++k) {
            const glm::dvec3 Ljk = L(j, k);
            e.irradiance += Ljk * (pi / (double(M) * N));
            const double p0 = dphi * k, p1 = dphi * (k + 1);
            const glm::dvec3 v_integral(std::cos(p1) - std::cos(p0), std::sin(p1) - std::sin(p0), 0);
            for (int c = 0; c < 3; ++c) e.rotation[c] += v_integral * (sin2_integral * Ljk[c]);
            inverse_distance_sum += 1.0 / r(j, k);
        }
    }
    if (inverse_distance_sum > 0) e.harmonic_mean_distance = double(M) * N / inverse_distance_sum;
    for (std::uint32_t k = 0; k < N; ++k) {
        const double phi_lo = dphi * k, phi_c = dphi * (k + 0.5);
        const glm::dvec3 u_c(std::cos(phi_c), std::sin(phi_c), 0);
        const glm::dvec3 v_lo(-std::sin(phi_lo), std::cos(phi_lo), 0);
        const std::uint32_t km = (k + N - 1) % N;
        for (std::uint32_t j = 1; j < M; ++j) {
            const double sl = sin_lo(j), cl = cos_lo(j);
            const double rate = sl * cl * cl / std::min(r(j, k), r(j - 1, k));
            const double azimuth = kind == translation_gradient_kind::krivanek_2005 ? 2 * std::sin(dphi / 2) : dphi;
            const glm::dvec3 dL = L(j, k) - L(j - 1, k);
            for (int c = 0; c < 3; ++c) e.translation[c] += u_c * (azimuth * rate * dL[c]);
        }
        for (std::uint32_t j = 0; j < M; ++j) {
            const double rmin = std::min(r(j, k), r(j, km));
            double rate;
            if (kind == translation_gradient_kind::krivanek_2005) {
                rate = (sin_lo(j + 1) - sin_lo(j)) / rmin;
            } else {
                const auto& d = s.direction[j * N + k];
                const double sin_t = std::max(std::sqrt(double(d.x) * d.x + double(d.y) * d.y), 1e-12);
                rate = (cos_lo(j) - cos_lo(j + 1)) / (sin_t * rmin);
            }
            const glm::dvec3 dL = L(j, k) - L(j, km);
            for (int c = 0; c < 3; ++c) e.translation[c] += v_lo * (rate * dL[c]);
        }
    }
    add_translation_hessian(s, e);
    return e;
}

bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }
bool same_bits(const glm::dvec3& a, const glm::dvec3& b) {
    return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}
bool same_bits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }
bool same_bits(const glm::vec3& a, const glm::vec3& b) {
    return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}

// Every field of two estimates, bit for bit; `with_hessian` false: b's Hessian and mean
// distance are the defaults instead.
void check_same(const hemisphere_estimate& a, const hemisphere_estimate& b, bool with_hessian = true) {
    CHECK(same_bits(a.irradiance, b.irradiance));
    CHECK(same_bits(a.harmonic_mean_distance, b.harmonic_mean_distance));
    for (int c = 0; c < 3; ++c) {
        CHECK(same_bits(a.rotation[c], b.rotation[c]));
        CHECK(same_bits(a.translation[c], b.translation[c]));
        for (int x = 0; x < 2; ++x) {
            const glm::dvec2 expected = with_hessian ? a.hessian[c][x] : glm::dvec2(0.0);
            CHECK(same_bits(glm::dvec3(expected, 0.0), glm::dvec3(b.hessian[c][x], 0.0)));
        }
    }
    CHECK(same_bits(with_hessian ? a.mean_distance : std::numeric_limits<double>::infinity(), b.mean_distance));
}

// A random hemisphere: jittered directions, radiance mostly in [0, 3) with dark cells and a
// few bright ones, hit distances over four decades, a fifth of the rays escaping.
hemisphere_samples random_hemisphere(std::uint32_t m, std::uint32_t n, std::uint64_t seed) {
    pcg32 rng(seed);
    hemisphere_samples s;
    s.rings = m;
    s.wedges = n;
    std::vector<glm::vec2> u(s.size());
    for (auto& x : u) x = {rng.next_float(), rng.next_float()};
    s.direction = stratified_cosine_directions(m, n, u);
    s.radiance.resize(s.size());
    s.distance.resize(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        const float kind = rng.next_float();
        const glm::vec3 base(rng.next_float(), rng.next_float(), rng.next_float());
        s.radiance[i] = kind < 0.1f ? glm::vec3(0.f) : kind > 0.95f ? 40.f * base : 3.f * base;
        const float far = rng.next_float();
        s.distance[i] = far < 0.2f ? std::numeric_limits<float>::infinity() : std::pow(10.f, 4.f * rng.next_float() - 3.f);
    }
    return s;
}

// The plain record of embree::record_sampler at (p, n) with a fixed grid: the integrator's
// hemisphere with the sampler's stream (its documented key: the bits of p and n, under its
// seed 7 and stage 0x1c), turned into the local frame, distances floored at the ray offset,
// the straightforward estimate, make_record.
irradiance_record plain_record(const embree::reference_integrator& integrator, embree::hemisphere_grid grid,
                               const radius_limits& limits, glm::vec3 p, glm::vec3 n, double footprint) {
    const std::uint64_t key = hash_floats({p.x, p.y, p.z, n.x, n.y, n.z});
    const embree::hemisphere_samples h = integrator.sample_hemisphere(p, n, grid, embree::derive_seed(7, 0x1c, key));
    hemisphere_samples local;
    local.rings = grid.m;
    local.wedges = grid.n;
    for (std::size_t i = 0; i < h.direction.size(); ++i) {
        const glm::vec3 d = h.direction[i];
        local.direction.push_back({glm::dot(d, h.tangent), glm::dot(d, h.bitangent), glm::dot(d, h.normal)});
        local.distance.push_back(std::max(h.distance[i], integrator.ray_epsilon()));
    }
    local.radiance = h.radiance;
    return make_record(p, h.normal, h.tangent, h.bitangent,
                       straightforward_estimate(local, translation_gradient_kind::krivanek_2005), limits, footprint);
}

// The plain adaptive record: the sampler's rounds as they were written first, each new ray
// shaded alone by the single-ray incoming_radiance (the sampler batches them).
std::pair<irradiance_record, std::uint32_t> plain_adaptive_record(const embree::reference_integrator& integrator,
                                                                  const adaptive_rays& a, const radius_limits& limits,
                                                                  glm::vec3 p, glm::vec3 n) {
    const adaptive_grid_size g = adaptive_grid(a.min_rays);
    const std::uint64_t key = hash_floats({p.x, p.y, p.z, n.x, n.y, n.z});
    const embree::hemisphere_samples h =
        integrator.sample_hemisphere(p, n, {g.rings, g.wedges}, embree::derive_seed(7, 0x1c, key));
    adaptive_hemisphere ah(g.rings, g.wedges);
    const float eps = integrator.ray_epsilon();
    for (std::size_t i = 0; i < h.direction.size(); ++i) {
        const glm::vec3 d = h.direction[i];
        const glm::vec3 l(glm::dot(d, h.tangent), glm::dot(d, h.bitangent), glm::dot(d, h.normal));
        ah.add(i, ah.jitter_of(i, l), l, h.radiance[i], std::max(h.distance[i], eps));
    }
    const std::uint64_t cap = std::max<std::uint64_t>(a.max_rays, g.count());
    std::uint64_t used = g.count();
    for (std::uint64_t round = 1; used < cap && round <= 16; ++round) {
        const double allowed = a.target * std::max(ah.luminance_irradiance(), a.irradiance_floor);
        if (!(ah.variance() > allowed * allowed)) break;
        const std::uint64_t budget = std::min(cap - used, used);
        const std::vector<std::uint32_t> extra = ah.plan(budget, allowed * allowed, std::min(budget, used / 8));
        if (extra.empty()) break;
        const std::uint64_t stream = embree::derive_seed(7, 0x1d, key ^ (round * 0x9e3779b97f4a7c15ULL));
        pcg32 rng(stream);
        struct fresh {
            std::size_t cell;
            glm::vec2 u;
            glm::vec3 local;
        };
        std::vector<fresh> rays;
        for (std::size_t c = 0; c < extra.size(); ++c) {
            if (extra[c] == 0) continue;
            for (const glm::vec2 u : ah.refinement_jitters(c, [&] { return rng.next_float(); }))
                rays.push_back({c, u, ah.direction_in(c, u)});
        }
        for (std::size_t i = 0; i < rays.size(); ++i) {
            embree::ray r;
            r.origin = h.origin + eps * h.normal;
            const glm::vec3 l = rays[i].local;
            r.direction = glm::normalize(l.x * h.tangent + l.y * h.bitangent + l.z * h.normal);
            float distance = 0;
            const glm::vec3 radiance = integrator.incoming_radiance(r, embree::derive_seed(stream, 0x2e, i), &distance);
            ah.add(rays[i].cell, rays[i].u, l, radiance, std::max(distance, eps));
        }
        used += rays.size();
    }
    const hemisphere_estimate est = straightforward_estimate(ah.fine_samples(), translation_gradient_kind::krivanek_2005);
    return {make_record(p, h.normal, h.tangent, h.bitangent, est, limits, 0.0), std::uint32_t(used)};
}

void check_same(const irradiance_record& a, const irradiance_record& b) {
    CHECK(same_bits(a.position, b.position));
    CHECK(same_bits(a.normal, b.normal));
    CHECK(same_bits(a.irradiance, b.irradiance));
    for (int c = 0; c < 3; ++c) {
        CHECK(same_bits(a.rotation[c], b.rotation[c]));
        CHECK(same_bits(a.translation[c], b.translation[c]));
    }
    CHECK(same_bits(a.radius, b.radius));
}

// Points inside the Cornell box on its floor, back wall, ceiling near the light, a side
// wall's corner and the short block's top, with their normals: near and far geometry, lit
// and shadowed cells, a corner where hits land within the ray offset.
struct cornell_points {
    std::vector<glm::vec3> p, n;
    explicit cornell_points(const io::scene& scene) {
        const auto [lo, hi] = scene.bounds();
        const glm::vec3 size = hi - lo;
        auto at = [&](float x, float y, float z) { return lo + glm::vec3(x, y, z) * size; };
        auto add = [&](glm::vec3 point, glm::vec3 normal) {
            p.push_back(point);
            n.push_back(normal);
        };
        add(at(0.5f, 1e-3f, 0.5f), {0, 1, 0});
        add(at(0.1f, 1e-3f, 0.9f), {0, 1, 0});
        add(at(0.02f, 1e-3f, 0.02f), {0, 1, 0});
        add(at(0.5f, 0.5f, 1.f - 1e-3f), {0, 0, -1});
        add(at(0.5f, 1.f - 1e-3f, 0.4f), {0, -1, 0});
        add(at(1e-3f, 0.3f, 0.3f), {1, 0, 0});
        add(at(0.3f, 0.2f, 0.3f), glm::normalize(glm::vec3(0.3f, 1.f, -0.2f)));
    }
};

}  // namespace

TEST_CASE("estimate_hemisphere from precomputed strata is bitwise the per-cell trigonometry", "[record_cost]") {
    // Grids: the smallest ones, odd and even wedge counts, the 1,024-ray grid (18 x 57),
    // 16 x 50, and fine adaptive grids (2M x 2N, 2M x 4N).
    const std::vector<std::pair<std::uint32_t, std::uint32_t>> grids{{1, 1},  {1, 2},   {2, 3},   {3, 7},  {5, 16},
                                                                     {9, 28}, {16, 50}, {18, 57}, {18, 56}, {36, 112}};
    std::uint64_t seed = 1;
    for (const auto& [m, n] : grids) {
        const hemisphere_strata strata(m, n);
        CHECK(strata.rings == m);
        CHECK(strata.wedges == n);
        CHECK(strata.ring_terms.size() == m);
        CHECK(strata.wedge_terms.size() == n);
        for (int trial = 0; trial < 3; ++trial) {
            const hemisphere_samples s = random_hemisphere(m, n, ++seed);
            for (const auto kind : {translation_gradient_kind::krivanek_2005, translation_gradient_kind::ward_heckbert_1992}) {
                INFO("grid " << m << " x " << n << ", trial " << trial << ", kind " << int(kind));
                const hemisphere_estimate expected = straightforward_estimate(s, kind);
                check_same(expected, estimate_hemisphere(s, kind));
                check_same(expected, estimate_hemisphere(s, strata, kind));
                check_same(expected, estimate_hemisphere(s, strata, kind, false), false);
            }
        }
    }
}

TEST_CASE("the comparison of estimates can fail: the reference has non-zero gradients and a Hessian", "[record_cost]") {
    // Guards the test above against comparing zeros with zeros.
    const hemisphere_samples s = random_hemisphere(18, 57, 99);
    const hemisphere_estimate e = straightforward_estimate(s, translation_gradient_kind::krivanek_2005);
    for (int c = 0; c < 3; ++c) {
        CHECK(glm::length(e.rotation[c]) > 0);
        CHECK(glm::length(e.translation[c]) > 0);
        CHECK(std::abs(e.hessian[c][0][0]) > 0);
    }
    CHECK(std::isfinite(e.harmonic_mean_distance));
    CHECK(std::isfinite(e.mean_distance));
    hemisphere_samples t = s;
    t.radiance[200].y = std::nextafter(t.radiance[200].y, 100.f);  // one ulp of one sample
    const hemisphere_estimate f = estimate_hemisphere(t, hemisphere_strata(18, 57));
    CHECK_FALSE(same_bits(e.irradiance, f.irradiance));
}

TEST_CASE("bad hemispheres and strata are refused, naming the parameter", "[record_cost][errors]") {
    const hemisphere_samples good = random_hemisphere(4, 9, 5);
    const hemisphere_strata strata(4, 9);
    CHECK_THROWS_AS(hemisphere_strata(0, 9), parameter_error);
    CHECK_THROWS_WITH(hemisphere_strata(4, 0), Catch::Contains("rings/wedges"));
    CHECK_THROWS_WITH(estimate_hemisphere(good, hemisphere_strata(9, 4)), Catch::Contains("strata"));
    CHECK_THROWS_WITH(estimate_hemisphere(good, hemisphere_strata(4, 10)), Catch::Contains("strata"));
    auto broken = [&](auto change) {
        hemisphere_samples s = good;
        change(s);
        return s;
    };
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<hemisphere_samples> bad_radiance{broken([&](hemisphere_samples& s) { s.radiance[7].x = nan; }),
                                                       broken([&](hemisphere_samples& s) { s.radiance[35].z = inf; }),
                                                       broken([&](hemisphere_samples& s) { s.radiance[0].y = -inf; })};
    for (const auto& s : bad_radiance) {
        CHECK_THROWS_AS(estimate_hemisphere(s, strata), parameter_error);
        CHECK_THROWS_WITH(estimate_hemisphere(s, strata), Catch::Contains("radiance"));
        CHECK_THROWS_WITH(estimate_hemisphere(s), Catch::Contains("radiance"));
    }
    const std::vector<hemisphere_samples> bad_distance{broken([&](hemisphere_samples& s) { s.distance[3] = 0.f; }),
                                                       broken([&](hemisphere_samples& s) { s.distance[20] = -1.f; }),
                                                       broken([&](hemisphere_samples& s) { s.distance[35] = nan; })};
    for (const auto& s : bad_distance) CHECK_THROWS_WITH(estimate_hemisphere(s, strata, {}, false), Catch::Contains("distance"));
    const hemisphere_samples short_one = broken([](hemisphere_samples& s) { s.distance.pop_back(); });
    CHECK_THROWS_WITH(estimate_hemisphere(short_one, strata), Catch::Contains("samples"));
}

TEST_CASE("record_sampler's records are bitwise the plain records, on one thread and on many", "[record_cost][embree]") {
    const io::scene scene = io::cornell_box();
    const embree::accel bvh(scene);
    const embree::reference_integrator integrator(bvh, scene, {});
    const cornell_points pts(scene);
    const embree::hemisphere_grid grid = embree::hemisphere_grid_for(1024);
    radius_limits split;
    split.min_pixels = 1.f;
    split.max_pixels = 40.f;
    radius_limits hessian = split;
    hessian.policy = radius_policy::hessian;
    for (const radius_limits& limits : {split, hessian}) {
        INFO("policy " << int(limits.policy));
        const embree::record_sampler sampler(integrator, grid, limits);
        std::vector<irradiance_record> expected;
        for (std::size_t k = 0; k < pts.p.size(); ++k)
            expected.push_back(plain_record(integrator, grid, limits, pts.p[k], pts.n[k], 0.004));
        // Serially, twice over (the second pass reuses the first's buffers), and on every core.
        for (int pass = 0; pass < 2; ++pass)
            for (std::size_t k = 0; k < pts.p.size(); ++k) {
                const auto rec = sampler(pts.p[k], pts.n[k], 0.004);
                REQUIRE(rec);
                check_same(expected[k], *rec);
            }
        std::vector<glm::vec3> p, n;
        for (int copy = 0; copy < 16; ++copy) {
            p.insert(p.end(), pts.p.begin(), pts.p.end());
            n.insert(n.end(), pts.n.begin(), pts.n.end());
        }
        const std::vector<double> footprints(p.size(), 0.004);
        std::vector<std::optional<irradiance_record>> out(p.size());
        sampler(p, n, footprints, out);
        for (std::size_t k = 0; k < p.size(); ++k) {
            REQUIRE(out[k]);
            check_same(expected[k % pts.p.size()], *out[k]);
        }
    }
}

TEST_CASE("adaptive records with batched rounds are bitwise the single-ray rounds", "[record_cost][adaptive_rays][embree]") {
    const io::scene scene = io::cornell_box();
    const embree::accel bvh(scene);
    const embree::reference_integrator integrator(bvh, scene, {});
    const cornell_points pts(scene);
    adaptive_rays a;
    a.enabled = true;
    a.min_rays = 128;
    a.max_rays = 2048;
    a.target = 0.01;  // refines most points for several rounds
    const embree::record_sampler sampler(integrator, a, radius_limits{});
    std::uint32_t most = 0;
    std::vector<irradiance_record> expected;
    for (std::size_t k = 0; k < pts.p.size(); ++k) {
        const auto [rec, rays] = plain_adaptive_record(integrator, a, radius_limits{}, pts.p[k], pts.n[k]);
        std::uint32_t cast = 0;
        const auto got = sampler.measure(pts.p[k], pts.n[k], 0.0, &cast);
        REQUIRE(got);
        CHECK(cast == rays);
        check_same(rec, *got);
        expected.push_back(rec);
        most = std::max(most, rays);
    }
    CHECK(most > 2 * adaptive_grid(a.min_rays).count());  // later rounds were exercised
    // On every core: the per-thread buffers and strata of different fine grids interleave.
    std::vector<glm::vec3> p, n;
    for (int copy = 0; copy < 8; ++copy) {
        p.insert(p.end(), pts.p.begin(), pts.p.end());
        n.insert(n.end(), pts.n.begin(), pts.n.end());
    }
    const std::vector<double> footprints(p.size(), 0.0);
    std::vector<std::optional<irradiance_record>> out(p.size());
    sampler(p, n, footprints, out);
    for (std::size_t k = 0; k < p.size(); ++k) {
        REQUIRE(out[k]);
        check_same(expected[k % pts.p.size()], *out[k]);
    }
}
