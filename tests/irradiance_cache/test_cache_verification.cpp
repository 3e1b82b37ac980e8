// Error the records cannot see (issue 28, third session): the verification pass after the
// scan (cache/verification.hpp, cpu::irradiance_cache's options().verify with set_probe) on
// the strip plane of strip_plane.hpp (the probes on every other pixel, as the cache asks).
#include "strip_plane.hpp"

#include <bounce/cache/verification.hpp>
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/cache/weighting.hpp>
#include <bounce/image.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <random>
#include <span>
#include <vector>

using namespace bounce;
using namespace bounce::strip_test;

namespace {

struct strip_result {
    double strip_error = 0, rest_error = 0;  // mean |cache - truth| over the strip's pixels and the others'
    cpu::cache_frame_stats stats;
    std::size_t records = 0;
};

strip_result render_strip(std::uint32_t rounds) {
    plane_view v;
    cpu::irradiance_cache<ward_smooth_weight> cache(glm::vec3(-1.f), glm::vec3(1.f), strip_options(rounds));
    cache.set_probe(noisy_probe);
    strip_sampler sampler;
    image<glm::vec3> out(size, size);
    strip_result r;
    r.stats = cache.render(v.g.view(), v.cam, sampler, out.view());
    r.records = cache.records().size();
    const strip_errors e = errors_of(v.g, out);
    REQUIRE(e.strip_pixels == 128);  // two columns of pixels
    r.strip_error = e.strip;
    r.rest_error = e.rest;
    return r;
}

}  // namespace

TEST_CASE("the scan covers a strip no record sampled with its surroundings' irradiance; the verification finds it",
          "[irradiance_cache][verification]") {
    const strip_result scan = render_strip(0);
    // Without verification most of the strip shows the plane's 1 instead of 0.4.
    CHECK(scan.strip_error > 0.3);
    CHECK(scan.stats.verify_tiles == 0);
    const strip_result verified = render_strip(2);
    CHECK(verified.stats.verify_disagreed > 0);
    CHECK(verified.stats.verify_shrunk > 0);
    CHECK(verified.records > scan.records);
    CHECK(verified.strip_error < 0.25 * scan.strip_error);
    CHECK(verified.strip_error < 0.08);
    // Away from the strip the image stays right (the records shrunk to the strip's are the
    // plane's own irradiance).
    CHECK(verified.rest_error < 0.02);
}

TEST_CASE("the verification leaves a cache that agrees with its probes alone", "[irradiance_cache][verification]") {
    plane_view v;
    cpu::irradiance_cache_options o;
    o.splat.a = 0.4f;
    o.verify.rounds = 2;
    cpu::irradiance_cache<ward_smooth_weight> cache(glm::vec3(-1.f), glm::vec3(1.f), o);
    // A flat field: the probes' noise alone, within their variance.
    cache.set_probe([](glm::vec3, glm::vec3, std::size_t pixel) {
        std::mt19937 rng(std::uint32_t(pixel) + 1u);
        std::normal_distribution<float> z(0.f, 0.1f);
        return probe_estimate{glm::vec3(1.f + z(rng)), 0.01f, 8};
    });
    auto flat = [](std::span<const glm::vec3> points, std::span<const glm::vec3> normals, std::span<const double>,
                   std::span<std::optional<irradiance_record>> out) {
        for (std::size_t k = 0; k < points.size(); ++k) {
            irradiance_record r;
            r.position = points[k];
            r.normal = normals[k];
            r.irradiance = glm::vec3(1.f);
            r.radius = 0.5f;
            out[k] = r;
        }
    };
    image<glm::vec3> out(64, 64);
    const cpu::cache_frame_stats s = cache.render(v.g.view(), v.cam, flat, out.view());
    CHECK(s.verify_tiles == 256 + 289);  // 16 x 16 tiles, then 17 x 17 shifted by half a tile
    CHECK(s.verify_disagreed == 0);
    CHECK(s.verify_shrunk == 0);
}

TEST_CASE("a tile's test pools its pixels' residuals and variances", "[irradiance_cache][verification]") {
    verification_options o;
    o.k = 3.f;
    o.tolerance = 0.1f;
    // Cache 1 everywhere (weight 2, sum 2 * 1), grey albedo pi: the splat holds E.
    const glm::vec4 sum(2.f, 2.f, 2.f, 2.f);
    const glm::vec3 albedo(std::numbers::pi_v<float>);
    tile_residuals low, noisy;
    for (int i = 0; i < 16; ++i) {
        low.add(residual_at(sum, albedo, {glm::vec3(0.7f), 0.01f, 0}));    // 30% low, standard error 0.1 each
        noisy.add(residual_at(sum, albedo, {glm::vec3(0.7f), 1.0f, 0}));   // 30% low, standard error 1 each
    }
    CHECK(low.pixels == 16);
    CHECK(low.residual == Approx(-16 * 0.3).epsilon(1e-5));
    CHECK(low.variance == Approx(16 * 0.01).epsilon(1e-5));
    CHECK(low.disagrees(o, 1.0));         // mean -0.3 against a standard error of 0.025
    CHECK_FALSE(noisy.disagrees(o, 1.0));  // against 0.25: within 3 of them
    // The tolerance is the frame's: the same 30% in a tile at a tenth of the frame's mean
    // luminance (0.03 of the frame's scale) is not a disagreement.
    CHECK_FALSE(low.disagrees(o, 10.0));
    // The floor: a probe that reports no spread still has (Y / 2)^2 / rays.
    const pixel_residual floored = residual_at(sum, albedo, {glm::vec3(1.f), 0.f, 4});
    CHECK(floored.variance == Approx(0.25 / 4));
    // Unknown variance, or no weight: left out.
    CHECK_FALSE(residual_at(sum, albedo, {glm::vec3(1.f), -1.f, 8}).valid);
    CHECK_FALSE(residual_at(glm::vec4(0.f), albedo, {glm::vec3(1.f), 0.1f, 8}).valid);
    // Below the tolerance: a 5% bias, however certain, is not a disagreement.
    tile_residuals slight;
    for (int i = 0; i < 16; ++i) slight.add(residual_at(sum, albedo, {glm::vec3(0.95f), 1e-8f, 0}));
    CHECK_FALSE(slight.disagrees(o, 1.0));
}
