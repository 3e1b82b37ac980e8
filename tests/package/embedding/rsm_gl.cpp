// docs/embedding.md, RSM / SII on the GPU: maps rasterized by GL, gathered over G-buffer
// textures into a texture. Components: gl.
#include "room.hpp"

#include <bounce/gl/context.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/indirect_renderer.hpp>
#include <bounce/gl/rsm_renderer.hpp>

#include <glm/geometric.hpp>

int main() {
    const room r;
    const bounce::scene_view scene = r.view();
    const bounce::camera& cam = r.camera;
    // [recipe]
    using namespace bounce;
    gl::context context;                         // or your own current GL 4.5 context
    const gl::scene_mesh mesh(scene);            // or rsm_renderer(scene, your rsm_drawer)
    gl::gbuffer_pass gbuffer;                    // or your own G-buffer textures
    gbuffer.render(mesh, cam, 64, 48);
    gl::rsm_renderer maps(scene, mesh);
    maps.render();                               // the scene's lights; maps() are the textures
    gl::indirect_renderer renderer;              // the options and answers of cpu::indirect_renderer
    const gl::texture e(gl::texel_format::rgba32f, 64, 48);
    renderer.render(gl::textures_of(gbuffer), cam, maps.maps(), e);  // indirect irradiance, W/m^2
    // render(..., e, output_quantity::radiance): rho/pi E with the G-buffer's albedo, in e
    // [/recipe]
    image<glm::vec3> pixels(64, 48), radiance(64, 48);
    gl::read_texture(e, pixels.view());
    const gl::texture l(gl::texel_format::rgba32f, 64, 48);
    renderer.render(gl::textures_of(gbuffer), cam, maps.maps(), l, output_quantity::radiance);
    gl::read_texture(l, radiance.view());
    // The radiance is the irradiance times the G-buffer's albedo over pi.
    const auto g = gbuffer.read();  // the G-buffer pass's albedo, row 0 at the top as read_texture
    for (std::size_t y = 0; y < 48; ++y)
        for (std::size_t x = 0; x < 64; ++x) {
            const glm::vec3 expected = lambertian_radiance<float, glm::vec3>(g.albedo(x, y), pixels(x, y));
            if (glm::length(radiance(x, y) - expected) > 1e-5f * (1.f + glm::length(expected))) return 1;
        }
    return report("rsm gl: sum of indirect irradiance", total(pixels));
}
