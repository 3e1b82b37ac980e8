// docs/embedding.md, RSM / SII on the GPU: maps rasterized by GL, gathered over G-buffer
// textures into a texture. Components: gl.
#include "room.hpp"

#include <bounce/gl/context.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/indirect_renderer.hpp>
#include <bounce/gl/rsm_renderer.hpp>

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
    // [/recipe]
    image<glm::vec3> pixels(64, 48);
    gl::read_texture(e, pixels.view());
    return report("rsm gl: sum of indirect irradiance", total(pixels));
}
