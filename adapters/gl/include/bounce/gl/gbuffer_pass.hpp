#pragma once
/// \file gbuffer_pass.hpp
/// A scene's triangles uploaded once, and the raster G-buffer pass that renders them for a
/// camera into float textures and reads them back into a `bounce::gbuffer_view`.
///
/// The raster G-buffer agrees pixel by pixel with a ray-cast one: pixel centres and row
/// order are those of camera.hpp (row 0 at the top), the normal and the depth come from the
/// kernels of surface.hpp (`facing_normal`, `view_depth`), emitted to GLSL.

#include <bounce/camera.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/scene_view.hpp>

#include <cstddef>
#include <optional>
#include <string>

namespace bounce::gl {

/// The geometry of a scene_view in GL buffers: positions and normals (one vertex array,
/// attributes 0 and 1), triangle indices, and per-triangle diffuse reflectance (Kd of the
/// triangle's material) as a storage buffer of vec4 indexed by gl_PrimitiveID.
class scene_mesh {
public:
    /// Uploads `s` (a copy: the viewed arrays need not outlive the mesh). A view without
    /// vertex normals is drawn with each triangle's plane normal. Throws parameter_error
    /// naming the span at fault as scene_view::validate_mesh does.
    explicit scene_mesh(const scene_view& s);

    std::size_t triangle_count() const noexcept { return triangles_; }
    /// The vertex array: attribute 0 = position (vec3), 1 = normal (vec3), with the
    /// index buffer attached; draw with glDrawElements(GL_TRIANGLES, 3 * triangle_count(),
    /// GL_UNSIGNED_INT, 0).
    const vertex_array& vertices() const noexcept { return vao_; }
    /// Kd per triangle as vec4 (w = 0), for `layout(std430) buffer { vec4 kd[]; }`.
    const buffer& albedo_per_triangle() const noexcept { return albedo_; }

private:
    vertex_array vao_;
    std::optional<buffer> positions_, normals_, indices_;
    buffer albedo_;
    std::size_t triangles_ = 0;
};

/// Renders a scene_mesh into three RGBA32F textures:
/// - `position_depth`: world-space position (xyz) and depth along camera.forward() (w);
///   background (0, 0, 0, +infinity);
/// - `normal`: unit shading normal facing the camera (xyz), w = 0; background 0;
/// - `albedo`: Kd of the triangle (rgb), w = 1 where covered; background 0.
/// Textures are in GL row order (row 0 at the bottom); `read` flips them. Geometry outside
/// [camera.near_plane, camera.far_plane] is clipped, as in any raster pass; no face is
/// culled. Works in the context current on the calling thread and restores the state it
/// changes (framebuffers, viewport, program, vertex array, storage binding 0, depth and
/// blend state, masks, polygon mode, clip control, pixel-pack state).
class gbuffer_pass {
public:
    /// Compiles the program (a context must be current).
    gbuffer_pass();

    /// Draws `mesh` seen by `cam` into width x height textures (reallocated when the size
    /// changes). Throws parameter_error for a zero size or an invalid camera.
    void render(const scene_mesh& mesh, const camera& cam, std::size_t width, std::size_t height);
    /// Copies the last rendering into `out`, which must have the rendered size, with row 0
    /// at the top. Throws parameter_error on a size mismatch or before any render.
    void read(gbuffer_view<float> out) const;
    /// The last rendering as an owning G-buffer.
    gbuffer<float> read() const;

    std::size_t width() const noexcept { return width_; }
    std::size_t height() const noexcept { return height_; }
    /// The textures of the last rendering (throw parameter_error before any render).
    const texture& position_depth() const;
    const texture& normal() const;
    const texture& albedo() const;
    /// The shaders' sources (the fragment shader includes the emitted kernels).
    const std::string& vertex_source() const noexcept { return vertex_source_; }
    const std::string& fragment_source() const noexcept { return fragment_source_; }

private:
    struct targets {
        texture position_depth, normal, albedo, depth;
        framebuffer fbo;
    };
    std::string vertex_source_, fragment_source_;
    program program_;
    std::optional<targets> targets_;
    std::size_t width_ = 0, height_ = 0;
};

}  // namespace bounce::gl
