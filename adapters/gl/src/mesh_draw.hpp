#pragma once
// A scene_mesh as the passes that rasterize it (gbuffer_pass, the built-in drawer of
// rsm_renderer) draw it: its per-triangle albedo in storage buffer mesh_albedo_binding, as
// their fragment shaders declare it, and one indexed draw. Plumbing only.
#include <bounce/gl/gbuffer_pass.hpp>

#include <epoxy/gl.h>

#include <string>

namespace bounce::gl::detail {

/// The storage-buffer binding of scene_mesh::albedo_per_triangle() while a mesh is drawn.
inline constexpr GLuint mesh_albedo_binding = 0;

/// The fragment shaders' declaration of that buffer: Kd of the drawn triangle t in kd[t].rgb.
inline std::string mesh_albedo_block() {
    return "layout(std430, binding = " + std::to_string(mesh_albedo_binding) +
           ") readonly buffer bounce_albedo { vec4 kd[]; };\n";
}

/// Binds the mesh's albedo and vertex array and draws all its triangles with the current
/// program (nothing for an empty mesh). The caller saves and restores the state it changes.
inline void draw_mesh(const scene_mesh& mesh) {
    if (mesh.triangle_count() == 0) return;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, mesh_albedo_binding, mesh.albedo_per_triangle().id());
    glBindVertexArray(mesh.vertices().id());
    glDrawElements(GL_TRIANGLES, GLsizei(3 * mesh.triangle_count()), GL_UNSIGNED_INT, nullptr);
}

}  // namespace bounce::gl::detail
