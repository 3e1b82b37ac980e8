// docs/embedding.md, the irradiance volume: probes baked by Embree rays, looked up for the
// points of a moving object. Components: cpu, embree.
#include "room.hpp"

#include <bounce/cpu/irradiance_volume.hpp>
#include <bounce/embree/probe_baker.hpp>

int main() {
    const room r;
    const bounce::scene_view scene = r.view();
    // [recipe]
    using namespace bounce;
    const embree::accel bvh(scene);
    const embree::reference_integrator light(bvh, scene);      // direct light at the probes' hits
    const embree::probe_baker baker(light, bvh, scene);        // 512 rays per probe
    const auto [lo, hi] = scene.bounds();
    const irradiance_volume volume = irradiance_volume::build(scene, lo, hi, {.min_depth = 2, .max_depth = 2}, baker);
    const std::vector<glm::vec3> points{{0.5f, 1.f, 0.f}, {1.f, 0.5f, 1.f}}, normals{{0, 1, 0}, {-1, 0, 0}};
    std::vector<glm::vec3> e(points.size());
    cpu::light_points(volume, points, normals, e, {});  // indirect irradiance, W/m^2
    // light_points(..., output_quantity::radiance, albedo): rho/pi E with one albedo per point
    // [/recipe]
    return report("volume: indirect irradiance at the first point", double(e[0].x + e[1].x));
}
