// The verification pass's Embree probe (embree/irradiance_probe.hpp): a few rays per point,
// the variance it reports against the spread of its estimates over seeds, and no bias against
// the reference integrator's many-ray irradiance.
#include <bounce/embree/accel.hpp>
#include <bounce/embree/irradiance_probe.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/luminance.hpp>

#include <catch2/catch.hpp>

#include <cmath>

using namespace bounce;

TEST_CASE("the probe's variance is its estimates' spread over pixels' seeds, from above, and its mean is unbiased",
          "[irradiance_cache][verification]") {
    const io::scene scene = io::cornell_box();
    const embree::accel bvh(scene);
    const embree::reference_integrator integrator(bvh, scene, {});
    const embree::irradiance_probe probe(integrator, 8);
    CHECK(probe.grid().count() == 8);
    auto g = embree::ray_cast_gbuffer(bvh, scene, scene.camera, 9, 9);
    // The back wall at the image's centre; each `pixel` index seeds another stream.
    const glm::vec3 p = g.view().position(4, 4), n = g.view().normal(4, 4);
    const int trials = 2000;
    double sum = 0, sum2 = 0, reported = 0;
    for (int t = 0; t < trials; ++t) {
        const probe_estimate e = probe(p, n, std::size_t(t));
        REQUIRE(e.rays == 8);
        REQUIRE(e.variance >= 0.f);
        const double y = rec709_luminance<float>(e.irradiance);
        sum += y;
        sum2 += y * y;
        reported += e.variance;
    }
    const double mean = sum / trials, spread = sum2 / trials - mean * mean;
    const double truth = rec709_luminance<float>(integrator.indirect_irradiance(p, n, 65536, 3));
    INFO("mean " << mean << " against " << truth << "; spread " << spread << ", reported " << reported / trials);
    // The mean within 4 standard errors of the many-ray estimate.
    CHECK(std::abs(mean - truth) < 4.0 * std::sqrt(spread / trials) + 0.01 * truth);
    // The strata only lower the true variance: the independent-ray estimate is from above,
    // but not wildly (1.45 times over this wall; at most 2).
    CHECK(reported / trials >= 0.9 * spread);
    CHECK(reported / trials <= 2.0 * spread);
}
