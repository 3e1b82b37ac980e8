// What ic_splatting --ray-rates compares: a record's hemisphere rays traced alone
// (reference_integrator::trace_hemisphere, embree::record_sampler::trace_only) must be the
// very rays sample_hemisphere shades, or the two rates would time different work.
#include <bounce/embree/accel.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/scene.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace bounce;

TEST_CASE("tracing a record's rays alone hits exactly where the shaded samples found a surface", "[embree][ray_rates]") {
    const io::scene scene = io::cornell_box();
    const embree::accel bvh(scene);
    const embree::reference_integrator integrator(bvh, scene, {});
    // Points on the floor and the back wall (the camera looks along +z), one near the box's
    // open front (rays escape there).
    const auto [lo, hi] = scene.bounds();
    const glm::vec3 mid = 0.5f * (lo + hi), size = hi - lo;
    const std::vector<glm::vec3> points{{mid.x, lo.y + 1e-3f * size.y, mid.z},
                                        {lo.x + 0.2f * size.x, lo.y + 1e-3f * size.y, lo.z + 0.02f * size.z},
                                        {mid.x, mid.y, hi.z - 1e-3f * size.z}};
    const std::vector<glm::vec3> normals{{0.f, 1.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, 0.f, -1.f}};
    const embree::hemisphere_grid grid = embree::hemisphere_grid_for(256);
    std::size_t total_hits = 0, total_rays = 0;
    for (std::size_t k = 0; k < points.size(); ++k) {
        const auto shaded = integrator.sample_hemisphere(points[k], normals[k], grid, 17 + k);
        std::size_t finite = 0;
        for (float d : shaded.distance) finite += std::isfinite(d) ? 1 : 0;
        CHECK(integrator.trace_hemisphere(points[k], normals[k], grid, 17 + k) == finite);
        total_hits += finite;
        total_rays += shaded.distance.size();
    }
    // The open front lets some rays escape and the walls stop the rest: both cases occur.
    CHECK(total_hits > 0);
    CHECK(total_hits < total_rays);
    const embree::record_sampler sampler(integrator, grid, radius_limits{});
    CHECK(sampler.trace_only(points, normals) == points.size() * grid.count());
    CHECK_THROWS_WITH(integrator.trace_hemisphere(points[0], glm::vec3(0.f, 2.f, 0.f), grid, 1), Catch::Contains("n"));
}
