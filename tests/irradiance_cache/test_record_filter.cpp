// The neighbour filter (cache/record_filter.hpp): a record's variance from its own rays,
// the shrinkage toward its neighbours' prediction, and what the cache's index hands it.
#include <bounce/cache/record_filter.hpp>
#include <bounce/cache/weighting.hpp>
#include <bounce/cpu/neighbour_index.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/scene.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

using namespace bounce;

namespace {

irradiance_record record_with(float e, float variance) {
    irradiance_record r;
    r.irradiance = glm::vec3(e);
    r.variance = variance;
    return r;
}

// n neighbours' prediction of luminance `e` each, weight w_j = j + 1, variance s2 each.
neighbour_prediction prediction_of(const std::vector<double>& e, double s2) {
    neighbour_prediction p;
    for (std::size_t j = 0; j < e.size(); ++j) p.add(double(j + 1), glm::dvec3(e[j]), s2);
    return p;
}

}  // namespace

TEST_CASE("stratified variance: second differences match the spread of E over seeds", "[record_filter]") {
    // Each cell's radiance uniform in [0, 2 L(cell)), L smooth in phi: E's true variance is
    // known in closed form.
    const std::uint32_t m = 6, n = 10;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    const double cell = std::numbers::pi / double(m * n);
    double true_var = 0;
    for (std::uint32_t i = 0; i < m * n; ++i) {
        const double l = 1.0 + 0.3 * std::sin(2.0 * std::numbers::pi * double(i % n) / double(n)) + 0.1 * double(i / n);
        true_var += cell * cell * (4.0 * l * l / 12.0);
    }
    double sum_est = 0, sum_e = 0, sum_e2 = 0;
    const int trials = 4000;
    std::vector<glm::vec3> radiance(m * n);
    for (int t = 0; t < trials; ++t) {
        double e = 0;
        for (std::uint32_t i = 0; i < m * n; ++i) {
            const double l = 1.0 + 0.3 * std::sin(2.0 * std::numbers::pi * double(i % n) / double(n)) + 0.1 * double(i / n);
            radiance[i] = glm::vec3(float(2.0 * l) * u(rng));
            e += cell * double(radiance[i].x);  // grey: luminance = the channel
        }
        sum_est += stratified_luminance_variance(radiance, m, n);
        sum_e += e;
        sum_e2 += e * e;
    }
    const double spread = sum_e2 / trials - (sum_e / trials) * (sum_e / trials);
    CHECK(spread == Approx(true_var).epsilon(0.1));
    // The means' smooth change in phi hardly counts (a percent or two here).
    CHECK(sum_est / trials == Approx(true_var).epsilon(0.05));
    CHECK(std::isnan(stratified_luminance_variance(std::vector<glm::vec3>(2 * m), m, 2)));
    CHECK(std::isnan(stratified_luminance_variance(radiance, m, n + 1)));
    CHECK(stratified_luminance_variance(std::vector<glm::vec3>(m * n, glm::vec3(2.f)), m, n) == 0.0);
}

TEST_CASE("filter: a record beyond k standard errors of its neighbours is left unchanged", "[record_filter]") {
    for (const bool soft : {false, true}) {
        // Record 1.0 +- 0.1, prediction 1.5 +- 0.1: D = 0.5 = 3.5 sigma of the difference.
        irradiance_record rec = record_with(1.f, 0.01f);
        const irradiance_record before = rec;
        const filter_outcome f = shrink_to_prediction(rec, prediction_of({1.5, 1.5, 1.5, 1.5}, 0.04), 3.0, soft);
        CHECK(f.what == filter_outcome::refused);
        CHECK(rec.irradiance == before.irradiance);
        CHECK(rec.variance == before.variance);
        // At k = 4 it merges, moving toward the prediction by lambda D.
        const filter_outcome g = shrink_to_prediction(rec, prediction_of({1.5, 1.5, 1.5, 1.5}, 0.04), 4.0, soft);
        CHECK(g.what == filter_outcome::merged);
        CHECK(rec.irradiance.x > 1.f);
        CHECK(rec.irradiance.x < 1.5f);
        CHECK(rec.variance < before.variance);
        if (soft)  // the bias estimate bounds the move by s^2 / |D|
            CHECK(rec.irradiance.x - 1.f <= 0.01f / 0.5f + 1e-6f);
        else  // lambda = s^2 / (s^2 + s^2^), s^2^ = 0.04 * sum w^2 / (sum w)^2 = 0.04 * 30 / 100
            CHECK(rec.irradiance.x == Approx(1.0 + 0.5 * 0.01 / (0.01 + 0.012)));
    }
}

TEST_CASE("filter: on a constant field the variance drops by the predicted factor", "[record_filter]") {
    // Truth 2.0 everywhere; the record's noise s^2 = 0.04, eight neighbours' 0.02 each.
    std::mt19937 rng(11);
    std::normal_distribution<double> noise(0.0, 1.0);
    const double s2 = 0.04, s2_nb = 0.02;
    for (const bool soft : {false, true}) {
        double sum = 0, sum2 = 0, predicted = 0, raw2 = 0;
        const int trials = 20000;
        for (int t = 0; t < trials; ++t) {
            std::vector<double> nb(8);
            for (double& e : nb) e = 2.0 + std::sqrt(s2_nb) * noise(rng);
            const double e = 2.0 + std::sqrt(s2) * noise(rng);
            irradiance_record rec = record_with(float(e), float(s2));
            const neighbour_prediction p = prediction_of(nb, s2_nb);
            if (t == 0) predicted = s2 * p.variance() / (s2 + p.variance());
            const filter_outcome f = shrink_to_prediction(rec, p, 1e9, soft);
            REQUIRE(f.what == filter_outcome::merged);
            const double x = rec.irradiance.x;
            sum += x;
            sum2 += (x - 2.0) * (x - 2.0);
            raw2 += (e - 2.0) * (e - 2.0);
        }
        CHECK(sum / trials == Approx(2.0).margin(0.005));  // no bias on a constant field
        const double measured = sum2 / trials;
        CHECK(raw2 / trials == Approx(s2).epsilon(0.05));
        if (!soft) {
            CHECK(measured == Approx(predicted).epsilon(0.05));
        } else {
            // The bias estimate spends a part of the reduction where the noise alone makes D large.
            CHECK(measured > predicted);
            CHECK(measured < 0.6 * s2);
        }
    }
}

TEST_CASE("filter: unknown, zero and NaN variances and empty predictions leave records alone", "[record_filter]") {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (const float v : {0.f, nan, std::numeric_limits<float>::infinity(), -1.f}) {
        irradiance_record rec = record_with(1.f, v);
        CHECK(shrink_to_prediction(rec, prediction_of({1.1}, 0.01), 3.0).what == filter_outcome::unknown);
        CHECK(rec.irradiance == glm::vec3(1.f));
    }
    irradiance_record rec = record_with(1.f, 0.01f);
    CHECK(shrink_to_prediction(rec, neighbour_prediction{}, 3.0).what == filter_outcome::unknown);
    CHECK(shrink_to_prediction(rec, prediction_of({1.1}, 0.01), 0.0).what == filter_outcome::unknown);
    CHECK(rec.irradiance == glm::vec3(1.f));
    // Neighbours whose variance is unknown (0, NaN) or whose values are not finite are left out.
    neighbour_prediction p;
    p.add(1.0, glm::dvec3(5.0), 0.0);
    p.add(1.0, glm::dvec3(5.0), double(nan));
    p.add(1.0, glm::dvec3(double(nan)), 0.01);
    p.add(0.0, glm::dvec3(5.0), 0.01);
    CHECK(p.empty());
    p.add(2.0, glm::dvec3(1.2), 0.01);
    CHECK(p.irradiance().x == Approx(1.2));
    CHECK(p.variance() == Approx(0.01));
    CHECK(shrink_to_prediction(rec, p, 3.0).what == filter_outcome::merged);
    CHECK(rec.irradiance.x == Approx(1.1));  // equal variances: the mean
    CHECK(std::isfinite(rec.variance));
}

TEST_CASE("filter: a neighbour's share is the cache's weight and extrapolation", "[record_filter]") {
    irradiance_record nb;
    nb.position = {0.f, 0.f, 0.f};
    nb.irradiance = glm::vec3(1.f);
    nb.translation = {glm::vec3(1.f, 0.f, 0.f), glm::vec3(1.f, 0.f, 0.f), glm::vec3(1.f, 0.f, 0.f)};
    nb.radius = 1.f;
    nb.variance = 0.01f;
    irradiance_record rec;
    rec.position = {0.2f, 0.f, 0.f};
    neighbour_prediction with, without, outside;
    add_neighbour<ward_smooth_weight>(with, rec, nb, 0.4, true, 1.0);
    add_neighbour<ward_smooth_weight>(without, rec, nb, 0.4, false, 1.0);
    CHECK(with.irradiance().x == Approx(1.2));
    CHECK(without.irradiance().x == Approx(1.0));
    CHECK(with.weight == Approx(1.0 / 0.2 - 1.0 / 0.4));
    rec.position = {0.5f, 0.f, 0.f};  // beyond the zone a R = 0.4
    add_neighbour<ward_smooth_weight>(outside, rec, nb, 0.4, true, 1.0);
    CHECK(outside.empty());
}

TEST_CASE("neighbour_index: for_each_covering finds exactly the records whose zones hold the point",
          "[record_filter]") {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    std::vector<irradiance_record> recs(3000);
    for (auto& r : recs) {
        r.position = glm::vec3(u(rng), u(rng), u(rng)) * 1.2f - 0.1f;  // some outside the box
        r.radius = std::pow(10.f, -2.5f * u(rng));
    }
    cpu::neighbour_index index(glm::vec3(0.f), glm::vec3(1.f));
    index.sync(recs);
    for (int q = 0; q < 200; ++q) {
        const glm::vec3 p(u(rng), u(rng), u(rng));
        for (const float scale : {0.4f, 0.8f}) {
            std::vector<std::size_t> found, brute;
            index.for_each_covering(p, scale, [&](std::size_t j) { found.push_back(j); });
            for (std::size_t j = 0; j < recs.size(); ++j)
                if (double(glm::length(p - recs[j].position)) < double(scale) * double(recs[j].radius)) brute.push_back(j);
            std::sort(found.begin(), found.end());
            REQUIRE(found == brute);
        }
    }
}

TEST_CASE("embree records carry their variance: it matches the spread of E over nearby seeds", "[record_filter]") {
    const io::scene scene = io::cornell_box();
    const embree::accel bvh(scene);
    const embree::reference_integrator integrator(bvh, scene, {});
    const embree::record_sampler sampler(integrator, embree::hemisphere_grid{8, 25}, radius_limits{});
    // The point the camera sees in the image's centre (the back wall); each nudge by 1e-6
    // along the wall gets another stream (records are keyed by the point).
    auto g = embree::ray_cast_gbuffer(bvh, scene, scene.camera, 9, 9);
    const glm::vec3 p0 = g.view().position(4, 4), n0 = g.view().normal(4, 4);
    double sum = 0, sum2 = 0, est = 0;
    const int trials = 300;
    int n = 0;
    for (int t = 0; t < trials; ++t) {
        const glm::vec3 p = p0 + glm::vec3(1e-6f * float(t), 0.f, 0.f);
        const auto rec = sampler(p, n0, 0.01);
        if (!rec) continue;
        const double y = rec709_luminance<double, glm::dvec3>(glm::dvec3(rec->irradiance));
        sum += y;
        sum2 += y * y;
        est += rec->variance;
        ++n;
    }
    REQUIRE(n > trials * 9 / 10);
    INFO("mean E " << sum / n << ", mean variance estimate " << est / n);
    const double spread = sum2 / n - (sum / n) * (sum / n);
    REQUIRE(spread > 0.0);
    // From above where the strata's means jump (the walls' edges), within a factor 2.
    CHECK(est / n >= 0.8 * spread);
    CHECK(est / n <= 2.0 * spread);
}
