#pragma once
/// \file rsm_textures.hpp
/// A reflective shadow map (Dachsbacher and Stamminger 2005) as GL textures: what
/// gl::rsm_renderer writes and gl::indirect_renderer reads, and its copy on the CPU.

#include <bounce/gl/objects.hpp>
#include <bounce/image.hpp>
#include <bounce/indirect/vpl_sampling.hpp>

#include <cstddef>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace bounce::gl {

/// A reflective shadow map as the caller's textures (all RGBA32F, one size, GL row order):
/// world position (xyz), unit normal (xyz) and reflected flux (rgb, W per channel; 0
/// where the map sees nothing), with the matrix that maps world positions to the map's
/// clip space (bounce::rsm_view's convention). gl::rsm_renderer writes these.
struct rsm_textures {
    texture_ref position, normal, flux;
    glm::mat4 light_view_projection{1.f};

    std::size_t width() const noexcept { return flux.width; }
    std::size_t height() const noexcept { return flux.height; }
    /// Throws parameter_error naming `name` unless the three are set, RGBA32F and of one
    /// non-zero size.
    void validate(const char* name = "rsm") const;
};

/// Reads an RSM's textures into images (row 0 at the top) that a bounce::rsm_view can
/// borrow: the CPU's copy of a map the GPU rendered (VPL selection reads it).
struct rsm_images {
    image<glm::vec3> position, normal, flux;
    glm::mat4 light_view_projection{1.f};

    rsm_images() = default;
    /// Throws parameter_error on bad textures.
    explicit rsm_images(const rsm_textures& t);
    rsm_view view() const { return {position.view(), normal.view(), flux.view(), light_view_projection}; }
};

}  // namespace bounce::gl
