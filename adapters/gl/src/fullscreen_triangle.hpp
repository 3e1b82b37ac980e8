#pragma once
// The vertex shader of the full-screen triangle that every full-screen pass of this adapter
// draws (glDrawArrays(GL_TRIANGLES, 0, 3), no vertex buffer): corners (-1, -1), (3, -1) and
// (-1, 3) in clip space from gl_VertexID, so one triangle covers the viewport.

namespace bounce::gl::detail {

inline constexpr const char* fullscreen_vertex = R"(#version 450 core
void main() {
    vec2 corner = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1));
    gl_Position = vec4(corner - 1.0, 0.0, 1.0);
}
)";

}  // namespace bounce::gl::detail
