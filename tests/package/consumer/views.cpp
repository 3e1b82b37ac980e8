// A renderer that owns its mesh: two triangles of its own arrays behind a bounce::scene_view,
// G-buffers from the installed GL (raster) and Embree (ray cast) adapters, which must agree
// on the depth at the centre. Links neither OpenImageIO nor tinyobjloader (the package test
// checks the link line). Exits non-zero when something is wrong.
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/gl/context.hpp>
#include <bounce/gl/gbuffer_pass.hpp>

#include <epoxy/gl.h>  // the renderer's own GL calls: libepoxy comes with bounce::gl

#ifndef BOUNCE_WITH_GL
#error "the installed bounce::gl defines BOUNCE_WITH_GL for what links it"
#endif

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

int main() {
    // A 2 x 2 square at z = 0 facing +z, its own material, no lights needed for a G-buffer.
    const std::vector<glm::vec3> positions{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    const std::vector<glm::uvec3> triangles{{0, 1, 2}, {0, 2, 3}};
    const std::vector<std::uint32_t> material_of{0, 0};
    const std::vector<bounce::material> materials{{glm::vec3(0.5f, 0.25f, 0.125f), glm::vec3(0.f)}};
    bounce::scene_view view;
    view.positions = positions;
    view.triangles = triangles;
    view.material_of = material_of;
    view.materials = materials;

    bounce::camera cam;
    cam.position = {0.f, 0.f, 3.f};
    cam.look_at = {0.f, 0.f, 0.f};
    const std::size_t w = 8, h = 8;

    const bounce::embree::accel bvh(view);
    const auto traced = bounce::embree::ray_cast_gbuffer(bvh, view, cam, w, h);

    bounce::gl::context context;
    const bounce::gl::scene_mesh mesh(view);
    bounce::gl::gbuffer_pass pass;
    pass.render(mesh, cam, w, h);
    const auto raster = pass.read();
    // A GL call of the renderer's own, through the loader bounce::gl passes on.
    const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    if (!version) return 1;
    std::printf("GL %s\n", version);

    const float dt = traced.depth(w / 2, h / 2), dr = raster.depth(w / 2, h / 2);
    const glm::vec3 albedo = raster.albedo(w / 2, h / 2);
    std::printf("depth at the centre: ray cast %g, raster %g; albedo %g %g %g\n", double(dt), double(dr),
                double(albedo.x), double(albedo.y), double(albedo.z));
    const bool ok = std::abs(dt - 3.f) < 1e-4f && std::abs(dr - dt) < 1e-4f && albedo == materials[0].albedo;
    return ok ? 0 : 1;
}
