// Adaptive rays per record (bounce/cache/adaptive_hemisphere.hpp, embree::record_sampler with
// adaptive_rays): the variance estimator against the spread of the estimate over seeds, the
// stopping rule on easy and hard hemispheres, the adaptive estimate's mean against the exact
// irradiance, and refusal of bad settings.
#include <bounce/cache/adaptive_hemisphere.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/sampling.hpp>

#include "../embree/hand_built_scenes.hpp"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

using namespace bounce;

namespace {

constexpr double pi = std::numbers::pi;

// Mean, variance and the standard error of that variance (from the fourth central moment)
// of a series of values.
struct moments {
    double mean = 0, variance = 0, variance_se = 0, mean_se = 0;
};
moments moments_of(const std::vector<double>& x) {
    moments m;
    const double n = double(x.size());
    for (double v : x) m.mean += v;
    m.mean /= n;
    double m2 = 0, m4 = 0;
    for (double v : x) {
        const double d = (v - m.mean) * (v - m.mean);
        m2 += d;
        m4 += d * d;
    }
    m2 /= n;
    m4 /= n;
    m.variance = m2 * n / (n - 1);
    m.variance_se = std::sqrt(std::max(0.0, m4 - m2 * m2) / n);
    m.mean_se = std::sqrt(m.variance / n);
    return m;
}

// |a - b| within z standard errors of their difference.
bool agree(double a, double a_se, double b, double b_se, double z = 4.0) {
    return std::abs(a - b) <= z * std::sqrt(a_se * a_se + b_se * b_se);
}

// A radiance field with a hard edge and a smooth part: 1 + w.z, plus 10 where w.x > 0.3.
glm::vec3 edge_field(const glm::vec3& w) {
    const float y = 1.f + w.z + (w.x > 0.3f ? 10.f : 0.f);
    return glm::vec3(y);  // grey: luminance == each channel
}

// The black square under a uniform sky of tests/embree: E = L (pi - Lambert(square)), exact.
struct sky_and_square {
    test::owned_scene scene;
    glm::vec3 sky{0.8f, 1.f, 1.2f};
    float height = 0.5f, half = 0.4f;
    glm::vec2 centre{0.1f, -0.2f};
    sky_and_square() {
        scene.name = "sky and square";
        const auto floor = hand_built::add_material(scene, glm::vec3(0.5f));
        hand_built::add_square_z(scene, 0.f, 10.f, true, floor);
        const auto black = hand_built::add_material(scene, glm::vec3(0.f));
        hand_built::add_square_z(scene, height, half, false, black, centre);
    }
    embree::reference_settings settings() const {
        embree::reference_settings s;
        s.environment = sky;
        return s;
    }
    // At the ray origin p + epsilon n (the integrator starts its rays there): with the
    // square half a unit above, the offset moves E by a few tenths of a percent.
    double exact_luminance(glm::vec3 p, float epsilon) const {
        const glm::dvec2 c(centre);
        const std::vector<glm::dvec3> corners{{c.x - half, c.y - half, height},
                                              {c.x + half, c.y - half, height},
                                              {c.x + half, c.y + half, height},
                                              {c.x - half, c.y + half, height}};
        const double blocked = hand_built::lambert_polygon(glm::dvec3(p) + glm::dvec3(0, 0, epsilon), {0, 0, 1}, corners);
        return rec709_luminance<double, glm::dvec3>(glm::dvec3(sky)) * (pi - blocked);
    }
};

double luminance(const glm::vec3& c) { return rec709_luminance<double, glm::dvec3>(glm::dvec3(c)); }

}  // namespace

TEST_CASE("bad adaptive settings are refused, naming the setting", "[adaptive_rays][errors]") {
    auto refuses = [](adaptive_rays a, const char* name) {
        a.enabled = true;
        CHECK_THROWS_AS(a.validate(), parameter_error);
        CHECK_THROWS_WITH(a.validate(), Catch::Contains(name));
    };
    adaptive_rays a;
    a.min_rays = 1024;
    a.max_rays = 512;
    refuses(a, "max_rays");
    a = {};
    a.min_rays = 2;
    refuses(a, "min_rays");
    for (double t : {0.0, -0.1, std::nan(""), std::numeric_limits<double>::infinity()}) {
        a = {};
        a.target = t;
        refuses(a, "target");
    }
    a = {};
    a.irradiance_floor = -1;
    refuses(a, "irradiance_floor");
    a.irradiance_floor = std::nan("");
    refuses(a, "irradiance_floor");
    CHECK_THROWS_WITH(adaptive_grid(3), Catch::Contains("rays"));
    CHECK_THROWS_WITH(adaptive_hemisphere(4, 7), Catch::Contains("wedges"));
    adaptive_hemisphere h(2, 4);
    CHECK_THROWS_WITH(h.variance(), Catch::Contains("cell"));  // empty cells have no estimate
    CHECK_THROWS_WITH(h.add(0, {0.5f, 0.5f}, {0, 0, 1}, glm::vec3(std::nanf("")), 1.f), Catch::Contains("radiance"));
    CHECK_THROWS_WITH(h.add(0, {0.5f, 0.5f}, {0, 0, 1}, glm::vec3(1.f), 0.f), Catch::Contains("distance"));
    for (int k = 0; k < 3; ++k) h.add(1, {0.5f, 0.5f}, {0, 0, 1}, glm::vec3(1.f), 1.f);
    CHECK_THROWS_WITH(h.refinement_jitters(1, [] { return 0.5f; }), Catch::Contains("power of two"));

    // The sampler checks them too.
    const sky_and_square s;
    const embree::accel bvh(s.scene);
    const embree::reference_integrator integrator(bvh, s.scene, s.settings());
    a = {};
    a.enabled = true;
    a.target = -1;
    CHECK_THROWS_WITH(embree::record_sampler(integrator, a, radius_limits{}), Catch::Contains("target"));
}

TEST_CASE("the first round's grid pairs up in phi", "[adaptive_rays]") {
    for (std::uint32_t rays : {4u, 16u, 100u, 256u, 512u, 1000u, 4096u}) {
        const adaptive_grid_size g = adaptive_grid(rays);
        CHECK(g.wedges % 2 == 0);
        CHECK(g.rings >= 1);
        // About `rays` strata: within one ring of wedges rounded to an even number.
        CHECK(std::abs(double(g.count()) - double(rays)) <= double(g.rings) + 2);
    }
    // jitter_of inverts direction_in inside every cell (to float rounding of the direction).
    const adaptive_grid_size g = adaptive_grid(256);
    const adaptive_hemisphere h(g.rings, g.wedges);
    pcg32 rng(5);
    for (std::size_t c = 0; c < h.cells(); ++c) {
        const glm::vec2 u(rng.next_float(), rng.next_float());
        const glm::vec2 back = h.jitter_of(c, h.direction_in(c, u));
        CHECK(std::abs(back.x - u.x) < 1e-4f * float(g.wedges));
        CHECK(std::abs(back.y - u.y) < 1e-4f * float(g.rings));
    }
}

TEST_CASE("the fine grid for the gradients keeps the cell-mean irradiance", "[adaptive_rays]") {
    // Cells with one, two and four samples (split once, twice) side by side: every sample's
    // value covers its sub-stratum's share of the 2M x 2N grid.
    const adaptive_grid_size g = adaptive_grid(64);
    adaptive_hemisphere h(g.rings, g.wedges);
    pcg32 rng(9);
    auto next = [&] { return rng.next_float(); };
    auto add = [&](std::size_t c, glm::vec2 u) {
        const glm::vec3 w = h.direction_in(c, u);
        h.add(c, u, w, edge_field(w), 1.f + w.x * w.x);
    };
    for (std::size_t c = 0; c < h.cells(); ++c) add(c, {next(), next()});
    for (std::size_t c = 0; c < h.cells(); c += 3)
        for (const glm::vec2 u : h.refinement_jitters(c, next)) add(c, u);
    for (std::size_t c = 0; c < h.cells(); c += 6)
        for (const glm::vec2 u : h.refinement_jitters(c, next)) add(c, u);
    const hemisphere_samples fine = h.fine_samples();
    REQUIRE(fine.rings == 2 * g.rings);
    REQUIRE(fine.wedges == 2 * g.wedges);
    const hemisphere_estimate e = estimate_hemisphere(fine);
    CHECK(e.irradiance.x == Approx(h.irradiance().x).epsilon(1e-6));
    CHECK(rec709_luminance<double, glm::dvec3>(e.irradiance) == Approx(h.luminance_irradiance()).epsilon(1e-6));
    // Cell 1 (one sample): four equal quadrants. Cell 3 (split once, in phi): equal within
    // each phi half, different across. Cell 0 (split twice): a sample of its own in each.
    const std::size_t W = fine.wedges;
    CHECK(fine.radiance[2] == fine.radiance[3]);
    CHECK(fine.radiance[2] == fine.radiance[W + 2]);
    CHECK(fine.radiance[2] == fine.radiance[W + 3]);
    CHECK(fine.radiance[6] == fine.radiance[W + 6]);
    CHECK(fine.radiance[7] == fine.radiance[W + 7]);
    CHECK(fine.radiance[6] != fine.radiance[7]);
    CHECK(fine.radiance[0] != fine.radiance[1]);
    CHECK(fine.radiance[0] != fine.radiance[W]);
    CHECK(fine.radiance[1] != fine.radiance[W + 1]);
}

TEST_CASE("the variance estimator matches the spread of the estimate over seeds (a hard edge)", "[adaptive_rays][variance]") {
    // Means and variances of the field over each cell's quadrants by a 64 x 64 midpoint rule
    // per quadrant. An edge crosses about 64 sqrt(2) of a quadrant's 4096 sub-cells, each
    // misjudged by at most half its area, so a quadrant's bright fraction f is within 1.1%
    // and its variance 100 f (1 - f) within about 1.1 of up to 25; allow 3% of the predicted
    // sums (edge quadrants are a minority, and the errors have either sign) for the rule.
    const adaptive_grid_size g = adaptive_grid(256);
    adaptive_hemisphere layout(g.rings, g.wedges);
    const std::size_t cells = layout.cells();
    // Quadrant (x half hx, y half hy) at index 2 hx + hy: the first split halves phi (u.x),
    // the second theta (u.y), as refinement_jitters does.
    std::vector<std::array<double, 4>> mu(cells), var(cells);
    constexpr int q = 64;
    for (std::size_t c = 0; c < cells; ++c)
        for (int quadrant = 0; quadrant < 4; ++quadrant) {
            const float x0 = 0.5f * float(quadrant / 2), y0 = 0.5f * float(quadrant % 2);
            double s = 0, s2 = 0;
            for (int a = 0; a < q; ++a)
                for (int b = 0; b < q; ++b) {
                    const glm::vec2 u(x0 + 0.5f * (float(a) + 0.5f) / q, y0 + 0.5f * (float(b) + 0.5f) / q);
                    const double y = edge_field(layout.direction_in(c, u)).x;
                    s += y;
                    s2 += y * y;
                }
            mu[c][quadrant] = s / (q * q);
            var[c][quadrant] = s2 / (q * q) - mu[c][quadrant] * mu[c][quadrant];
        }
    auto cell_mean = [&](std::size_t c) { return 0.25 * (mu[c][0] + mu[c][1] + mu[c][2] + mu[c][3]); };
    auto cell_var = [&](std::size_t c) {  // variance of one uniform sample over the whole cell
        double m2 = 0;
        for (int k = 0; k < 4; ++k) m2 += 0.25 * (var[c][k] + mu[c][k] * mu[c][k]);
        return m2 - cell_mean(c) * cell_mean(c);
    };
    const double w2 = layout.cell_weight() * layout.cell_weight();
    // One sample per cell: Var = w^2 sum sigma_c^2; the estimator's expectation adds the
    // squared differences of paired cells' means.
    double true_var_1 = 0, expected_1 = 0;
    for (std::size_t c = 0; c < cells; ++c) true_var_1 += w2 * cell_var(c);
    for (std::size_t p = 0; p < cells / 2; ++p) {
        const double d = cell_mean(2 * p) - cell_mean(2 * p + 1);
        expected_1 += w2 * (cell_var(2 * p) + cell_var(2 * p + 1) + d * d);
    }
    // Four per cell, one per quadrant: Var = w^2 / 16 sum of quadrant variances; the last
    // split is in theta, so siblings are the quadrants (hx, 0) and (hx, 1).
    double true_var_4 = 0, expected_4 = 0;
    for (std::size_t c = 0; c < cells; ++c)
        for (int hx = 0; hx < 2; ++hx) {
            const double a = var[c][2 * hx], b = var[c][2 * hx + 1], d = mu[c][2 * hx] - mu[c][2 * hx + 1];
            true_var_4 += w2 / 16 * (a + b);
            expected_4 += w2 / 16 * (a + b + d * d);
        }
    REQUIRE(true_var_1 > 0);

    for (std::uint32_t per_cell : {1u, 4u}) {
        const int seeds = 4000;
        std::vector<double> estimate(seeds), variance(seeds);
        for (int s = 0; s < seeds; ++s) {
            pcg32 rng(1000 + std::uint64_t(s));
            auto next = [&] { return rng.next_float(); };
            adaptive_hemisphere h(g.rings, g.wedges);
            auto add = [&](std::size_t c, glm::vec2 u) {
                const glm::vec3 w = h.direction_in(c, u);
                h.add(c, u, w, edge_field(w), std::numeric_limits<float>::infinity());
            };
            for (std::size_t c = 0; c < cells; ++c) add(c, {next(), next()});
            for (std::uint32_t n = 1; n < per_cell; n *= 2)
                for (std::size_t c = 0; c < cells; ++c)
                    for (const glm::vec2 u : h.refinement_jitters(c, next)) add(c, u);
            estimate[s] = h.luminance_irradiance();
            variance[s] = h.variance();
        }
        const moments e = moments_of(estimate), v = moments_of(variance);
        const double true_var = per_cell == 1 ? true_var_1 : true_var_4;
        const double expected = per_cell == 1 ? expected_1 : expected_4;
        INFO("per cell " << per_cell << ": Var over seeds " << e.variance << " +- " << e.variance_se << ", predicted "
                         << true_var << ", mean estimated variance " << v.mean << " +- " << v.mean_se
                         << ", its predicted expectation " << expected);
        // The spread over seeds is the stratified variance, the estimator's mean its expectation.
        CHECK(agree(e.variance, e.variance_se, true_var, 0.03 * true_var));
        CHECK(agree(v.mean, v.mean_se, expected, 0.03 * expected));
        // Never below the truth (conservative), up to the noise of both means.
        CHECK(v.mean >= e.variance - 4 * std::sqrt(v.mean_se * v.mean_se + e.variance_se * e.variance_se));
        // Splitting the strata beats four times the samples' 1/4 (the edge's share shrinks).
        if (per_cell == 4) CHECK(e.variance < true_var_1 / 4);
        // The mean is the exact integral: pi/(MN) sum of cell means.
        double exact = 0;
        for (std::size_t c = 0; c < cells; ++c) exact += layout.cell_weight() * cell_mean(c);
        CHECK(agree(e.mean, e.mean_se, exact, 1e-3 * exact));
    }
}

TEST_CASE("on a hand-built scene the estimated variance matches the spread over seeds", "[adaptive_rays][variance][embree]") {
    // The black square under the sky: radiance L outside it, 0 on it, so every stratum the
    // square's edge crosses has variance L^2 f (1 - f). With one ray per cell or four (each
    // cell split in four) the collapsed-strata estimator is never below the spread.
    const sky_and_square s;
    const embree::accel bvh(s.scene);
    const embree::reference_integrator integrator(bvh, s.scene, s.settings());
    const glm::vec3 p(0.05f, -0.1f, 0.f), n(0, 0, 1);
    const adaptive_grid_size g = adaptive_grid(256);
    const int seeds = 600;
    for (std::uint32_t per_cell : {1u, 4u}) {
        std::vector<double> estimate(seeds), variance(seeds);
        for (int k = 0; k < seeds; ++k) {
            const auto hs = integrator.sample_hemisphere(p, n, {g.rings, g.wedges}, 9000 + std::uint64_t(k));
            adaptive_hemisphere h(g.rings, g.wedges);
            for (std::size_t i = 0; i < hs.direction.size(); ++i) {
                const glm::vec3 d = hs.direction[i];
                const glm::vec3 l(glm::dot(d, hs.tangent), glm::dot(d, hs.bitangent), d.z);
                h.add(i, h.jitter_of(i, l), l, hs.radiance[i], hs.distance[i]);
            }
            pcg32 rng(77 + std::uint64_t(k));
            embree::ray r;
            r.origin = p + integrator.ray_epsilon() * n;
            for (std::uint32_t count = 1; count < per_cell; count *= 2)
                for (std::size_t c = 0; c < h.cells(); ++c)
                    for (const glm::vec2 u : h.refinement_jitters(c, [&] { return rng.next_float(); })) {
                        const glm::vec3 l = h.direction_in(c, u);
                        r.direction = glm::normalize(l.x * hs.tangent + l.y * hs.bitangent + l.z * n);
                        float dist = 0;
                        const glm::vec3 L = integrator.incoming_radiance(r, 5, &dist);
                        h.add(c, u, l, L, std::max(dist, integrator.ray_epsilon()));
                    }
            estimate[k] = h.luminance_irradiance();
            variance[k] = h.variance();
        }
        const moments e = moments_of(estimate), v = moments_of(variance);
        INFO("per cell " << per_cell << ": Var over seeds " << e.variance << " +- " << e.variance_se
                         << ", mean estimated variance " << v.mean << " +- " << v.mean_se);
        REQUIRE(e.variance > 0);
        // The mean over seeds is the exact irradiance (stratified sampling is unbiased).
        CHECK(agree(e.mean, e.mean_se, s.exact_luminance(p, integrator.ray_epsilon()), 0));
        CHECK(v.mean >= e.variance - 4 * std::sqrt(v.mean_se * v.mean_se + e.variance_se * e.variance_se));
        // Conservative, but informative: paired strata's means differ only where the edge
        // crosses one of them (measured: 1.2x the spread with one ray per cell, 3x with four,
        // where more of the pairs straddle the edge).
        CHECK(v.mean <= 4 * e.variance);
    }
}

TEST_CASE("adaptive records stop at the first round where nothing varies and go to max on a hard case",
          "[adaptive_rays][embree]") {
    const sky_and_square s;
    const embree::accel bvh(s.scene);
    const embree::reference_integrator integrator(bvh, s.scene, s.settings());
    adaptive_rays a;
    a.enabled = true;
    a.min_rays = 256;
    a.max_rays = 2048;
    a.target = 0.01;
    radius_limits limits;
    limits.max_world = 10.f;  // a record that sees nothing gets this radius, not infinity
    const embree::record_sampler sampler(integrator, a, limits);
    const std::uint32_t first = sampler.grid().count();
    CHECK(first == adaptive_grid(256).count());

    // Above everything every ray sees the uniform sky: zero variance, one round.
    std::uint32_t rays = 0;
    const auto open = sampler.measure({8.f, 8.f, 1.f}, {0, 0, 1}, 0.0, &rays);
    REQUIRE(open);
    CHECK(rays == first);
    CHECK(luminance(open->irradiance) == Approx(pi * luminance(s.sky)).epsilon(1e-5));

    // Under the square's edge with a target no record can meet: every ray up to max_rays.
    a.target = 1e-7;
    const embree::record_sampler strict(integrator, a, radius_limits{});
    const auto hard = strict.measure({0.4f, -0.1f, 0.f}, {0, 0, 1}, 0.0, &rays);
    REQUIRE(hard);
    // Pairs are doubled whole, so the last round may leave less than one doubling unspent.
    CHECK(rays <= a.max_rays);
    CHECK(rays > a.max_rays - a.max_rays / 8);

    // In between, the edge costs more rays than the open sky but (at a 1% target) fewer than max.
    const auto mid = sampler.measure({0.4f, -0.1f, 0.f}, {0, 0, 1}, 0.0, &rays);
    REQUIRE(mid);
    CHECK(rays > first);
    CHECK(rays < a.max_rays);

    // A record is a pure function of its point: the same rays and the same record again.
    std::uint32_t again = 0;
    const auto mid2 = sampler.measure({0.4f, -0.1f, 0.f}, {0, 0, 1}, 0.0, &again);
    CHECK(again == rays);
    CHECK(mid2->irradiance == mid->irradiance);
    CHECK(mid2->translation == mid->translation);
    CHECK(mid2->radius == mid->radius);

    const auto tally = sampler.rays_cast();
    CHECK(tally.records == 3);
    CHECK(tally.rays == std::uint64_t(first) + 2 * rays);
    CHECK(tally.fewest == first);
    CHECK(tally.most == rays);
    CHECK(tally.mean() == Approx(double(tally.rays) / 3));
    sampler.reset_rays_cast();
    CHECK(sampler.rays_cast().records == 0);

    // The scale for an irradiance floor: above everything it is the sky's pi L, exactly;
    // under the square it is less. Not counted as records.
    const std::vector<glm::vec3> up{{8.f, 8.f, 1.f}, {-8.f, 5.f, 1.f}}, under{{0.1f, -0.2f, 0.f}}, normals{{0, 0, 1}, {0, 0, 1}};
    CHECK(sampler.mean_irradiance(up, normals) == Approx(pi * luminance(s.sky)).epsilon(1e-5));
    CHECK(sampler.mean_irradiance(under, std::span(normals).first(1)) < 0.7 * pi * luminance(s.sky));
    CHECK(sampler.mean_irradiance({}, {}) == 0.0);
    CHECK(sampler.rays_cast().records == 0);
    CHECK_THROWS_WITH(sampler.mean_irradiance(up, std::span(normals).first(1)), Catch::Contains("normals"));
}

TEST_CASE("adaptive records are unbiased: their mean over seeds is the exact irradiance", "[adaptive_rays][embree]") {
    // Points under and beside the square's edges, where refinement is decided record by
    // record. The tolerance is four standard errors of the mean over seeds.
    const sky_and_square s;
    const embree::accel bvh(s.scene);
    const embree::reference_integrator integrator(bvh, s.scene, s.settings());
    adaptive_rays a;
    a.enabled = true;
    a.min_rays = 64;
    a.max_rays = 1024;
    a.target = 0.004;
    const int seeds = 300;
    for (const glm::vec3 p : {glm::vec3(0.4f, -0.1f, 0.f), glm::vec3(0.6f, 0.3f, 0.f), glm::vec3(0.1f, -0.2f, 0.f)}) {
        std::vector<double> e(seeds), fixed(seeds);
        std::uint64_t rays = 0;
        for (int k = 0; k < seeds; ++k) {
            const embree::record_sampler adaptive(integrator, a, radius_limits{}, translation_gradient_kind::krivanek_2005,
                                                  100 + std::uint64_t(k));
            std::uint32_t r = 0;
            e[k] = luminance(adaptive.measure(p, {0, 0, 1}, 0.0, &r)->irradiance);
            rays += r;
            // The same point from a fixed grid of about the adaptive records' mean rays.
            const embree::record_sampler plain(integrator, embree::hemisphere_grid_for(256), radius_limits{},
                                               translation_gradient_kind::krivanek_2005, 100 + std::uint64_t(k));
            fixed[k] = luminance(plain(p, {0, 0, 1}, 0.0)->irradiance);
        }
        const moments m = moments_of(e), f = moments_of(fixed);
        const double exact = s.exact_luminance(p, integrator.ray_epsilon());
        INFO("point " << p.x << ", " << p.y << ": adaptive " << m.mean << " +- " << m.mean_se << " (mean rays "
                      << double(rays) / seeds << "), fixed " << f.mean << " +- " << f.mean_se << ", exact " << exact);
        CHECK(agree(m.mean, m.mean_se, exact, 0));
        CHECK(agree(f.mean, f.mean_se, exact, 0));
        CHECK(agree(m.mean, m.mean_se, f.mean, f.mean_se));
    }
}

TEST_CASE("adaptive rays off: the sampler casts the fixed grid of max_rays, record for record", "[adaptive_rays][embree]") {
    const sky_and_square s;
    const embree::accel bvh(s.scene);
    const embree::reference_integrator integrator(bvh, s.scene, s.settings());
    adaptive_rays off;
    off.max_rays = 512;
    const embree::record_sampler a(integrator, off, radius_limits{});
    const embree::record_sampler b(integrator, embree::hemisphere_grid_for(512), radius_limits{});
    CHECK(a.grid().count() == b.grid().count());
    for (const glm::vec3 p : {glm::vec3(0.4f, -0.1f, 0.f), glm::vec3(2.f, 1.f, 0.f)}) {
        const auto ra = a(p, {0, 0, 1}, 0.0), rb = b(p, {0, 0, 1}, 0.0);
        REQUIRE(ra);
        REQUIRE(rb);
        CHECK(ra->irradiance == rb->irradiance);
        CHECK(ra->rotation == rb->rotation);
        CHECK(ra->translation == rb->translation);
        CHECK(ra->radius == rb->radius);
    }
    CHECK(a.rays_cast().rays == 2 * std::uint64_t(a.grid().count()));
    CHECK(b.rays_cast().records == 2);
}
