// docs/embedding.md, irradiance splatting on the GPU: the cache's records splatted by GL over
// G-buffer textures, measured by GL hemisphere planes. Components: gl, cpu.
#include "room.hpp"

#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/gl/context.hpp>
#include <bounce/gl/irradiance_splatter.hpp>
#include <bounce/gl/raster_record_sampler.hpp>

int main() {
    const room r;
    const bounce::scene_view scene = r.view();
    const bounce::camera& cam = r.camera;
    // [recipe]
    using namespace bounce;
    gl::context context;                      // or your own current GL 4.5 context
    const gl::scene_mesh mesh(scene);         // or your own geometry through draw callbacks
    gl::gbuffer_pass gbuffer;                 // or your own textures: gl::gbuffer_textures{texture_ref::of(id), ...}
    gbuffer.render(mesh, cam, 64, 48);
    const gl::direct_light direct(scene, mesh);       // shadow-mapped direct light shades the planes
    gl::hemisphere_raster raster(scene, mesh, direct);
    gl::raster_record_sampler sampler(raster, radius_limits{});
    const auto [lo, hi] = scene.bounds();
    cpu::irradiance_cache<ward_smooth_weight> cache(lo, hi);  // keep it across frames
    gl::irradiance_splatter splatter;                          // weighting ward_smooth, as the cache's
    splatter.render(gl::textures_of(gbuffer), cam, cache.records(),
                    [&](auto g, auto splat) { cache.scan(g, cam, sampler, splat); });
    // splatter.indirect(): RGBA32F texture of indirect irradiance, W/m^2 (output_quantity::radiance
    // as render's last argument: rho/pi E, which splatter.compose(direct radiance) adds to yours)
    image<glm::vec3> e(64, 48);
    splatter.read_indirect(e.view());
    // [/recipe]
    return report("splatter: sum of indirect irradiance", total(e));
}
