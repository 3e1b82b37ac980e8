// docs/embedding.md, RSM / SII on the CPU: reflective shadow maps cast by Embree, gathered over
// a ray-cast G-buffer, light stopped at the partition by occlusion rays. Components: cpu, embree.
#include "room.hpp"

#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/embree/occlusion_rays.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/rsm_ray_cast.hpp>

int main() {
    const room r;
    const bounce::scene_view scene = r.view();
    const bounce::camera& cam = r.camera;
    // [recipe]
    using namespace bounce;
    const embree::accel bvh(scene);
    embree::rsm_ray_caster caster(bvh, scene);  // or rsm_views of your own maps (indirect/rsm.hpp)
    caster.render();                            // six maps for a point light, one per spot
    gbuffer<float> g = embree::ray_cast_gbuffer(bvh, scene, cam, 64, 48);
    const embree::occlusion_rays rays(bvh);     // so that light stops at walls and partitions
    indirect_options o;                         // gather or SII, interleaving
    o.visibility = indirect_visibility::rays;   // none: as published, light leaks through walls
    cpu::indirect_renderer renderer(o, &rays);
    image<glm::vec3> e(64, 48);
    renderer.render(g.view(), cam, caster.views(), e.view());  // indirect irradiance, W/m^2
    // [/recipe]
    return report("rsm: sum of indirect irradiance", total(e));
}
