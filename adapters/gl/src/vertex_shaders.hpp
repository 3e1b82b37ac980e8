#pragma once
// The vertex shaders that several passes of this adapter share, so that each is written once:
// plumbing only (no math of the core's kernels).

namespace bounce::gl::detail {

/// The full-screen triangle every full-screen pass draws (glDrawArrays(GL_TRIANGLES, 0, 3),
/// no vertex buffer): corners (-1, -1), (3, -1) and (-1, 3) in clip space from gl_VertexID,
/// so one triangle covers the viewport.
inline constexpr const char* fullscreen_vertex = R"(#version 450 core
void main() {
    vec2 corner = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1));
    gl_Position = vec4(corner - 1.0, 0.0, 1.0);
}
)";

/// A scene mesh seen through one camera: world position (attribute 0) and vertex normal
/// (attribute 1) passed on as world_position and world_normal, the position transformed by
/// the mat4 at uniform location 0 (world to clip space). The raster G-buffer and the
/// reflective shadow maps draw with it.
inline constexpr const char* mesh_vertex = R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 0) uniform mat4 view_projection;
out vec3 world_position;
out vec3 world_normal;
void main() {
    world_position = position;
    world_normal = normal;
    gl_Position = view_projection * vec4(position, 1.0);
}
)";

/// mesh_vertex's outputs as the fragment shader after it declares them.
inline constexpr const char* mesh_varyings = "in vec3 world_position;\nin vec3 world_normal;\n";

}  // namespace bounce::gl::detail
