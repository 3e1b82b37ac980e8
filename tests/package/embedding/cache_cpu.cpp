// docs/embedding.md, the irradiance cache on the CPU: records measured by Embree rays, splatted
// over a ray-cast G-buffer. Components: cpu, embree.
#include "room.hpp"

#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/embree/irradiance_probe.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/record_sampler.hpp>

#include <functional>

int main() {
    const room r;
    const bounce::scene_view scene = r.view();
    const bounce::camera& cam = r.camera;
    // [recipe]
    using namespace bounce;
    const embree::accel bvh(scene);                                   // copies the geometry
    const embree::reference_integrator shading(bvh, scene);           // shades the rays' hits
    const embree::record_sampler sampler(shading, embree::hemisphere_grid_for(256), radius_limits{});
    const auto [lo, hi] = scene.bounds();
    cpu::irradiance_cache_options options;
    options.verify.rounds = 2;                                        // check the image against 8-ray probes
    cpu::irradiance_cache<ward_smooth_weight> cache(lo, hi, options); // keep it across frames
    const embree::irradiance_probe probe(shading, 8);                 // the verification's probe
    cache.set_probe(std::cref(probe));                                // must outlive the cache's frames
    gbuffer<float> g = embree::ray_cast_gbuffer(bvh, scene, cam, 64, 48);  // or your own G-buffer
    image<glm::vec3> e(64, 48);
    cache.render(g.view(), cam, sampler, e.view());                   // indirect irradiance, W/m^2
    // cache.render(..., output_quantity::radiance): rho/pi E with g's albedo, W/(m^2 sr)
    // [/recipe]
    return report("cache: sum of indirect irradiance", total(e));
}
