// docs/embedding.md, progressive radiosity on the CPU: a lightmap of indirect irradiance for
// the renderer's own raster pass, and embree::lightmap_view to look at the solution.
// Components: cpu, embree.
#include "room.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/embree/lightmap_view.hpp>

int main() {
    const room r;
    const bounce::scene_view scene = r.view();
    const bounce::camera& cam = r.camera;
    // [recipe]
    using namespace bounce;
    const lightmap_atlas atlas = build_lightmap_atlas(scene, {.elements = 2000});
    cpu::progressive_radiosity solver(scene, atlas, cpu::item_buffer_visibility(scene, atlas, {}));
    solver.solve(0.1);                          // until 10% of the power is left unshot
    const image<glm::vec3> lightmap = solver.lightmap();  // indirect irradiance, W/m^2, per texel
    const std::vector<glm::vec2> uv = atlas.corner_uvs(scene);  // 3 per triangle, for your vertex buffer
    // Direct light counted once: your own light pass plus lightmap * albedo / pi. Or the whole
    // solution (B = pi * radiance) seen by a camera, ray cast:
    const embree::accel bvh(scene);
    const image<glm::vec3> view = embree::lightmap_view(bvh, scene, atlas, solver.radiosity_lightmap().view(), 0, cam, 64, 48);
    // [/recipe]
    const bool corners = uv.size() == 3 * scene.triangles.size();
    return report("radiosity: the lightmap's indirect irradiance times the view's radiance",
                  corners ? total(lightmap) * total(view) : 0.0);
}
