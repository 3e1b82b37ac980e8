#pragma once
/// \file rsm_textures.hpp
/// A reflective shadow map (Dachsbacher and Stamminger 2005) as GL textures: what
/// gl::rsm_renderer writes and gl::indirect_renderer reads, its copy on the CPU
/// (rsm_images), and the way back: maps made on the CPU (embree::rsm_ray_caster's, or a
/// renderer's own rsm_view) uploaded as such textures (rsm_upload), so the GL gather and
/// splatting passes run on them.

#include <bounce/gl/objects.hpp>
#include <bounce/image.hpp>
#include <bounce/indirect/vpl_sampling.hpp>

#include <cstddef>
#include <span>
#include <vector>

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

/// Reflective shadow maps made on the CPU (bounce::rsm_view: embree::rsm_ray_caster's
/// views(), rsm_images, or a renderer's own buffers) uploaded as RGBA32F textures of
/// rsm_renderer's layout (rgb the view's value, a = 0; rows flipped into GL order), so
/// gl::indirect_renderer gathers and splats from them as from rendered maps. Maps of any
/// size, each its own (a texture is reallocated only when its map's size changes). A
/// context must be current; the textures live as long as this object.
class rsm_upload {
public:
    rsm_upload() = default;
    /// Uploads `maps`.
    explicit rsm_upload(std::span<const rsm_view> maps) { upload(maps); }
    /// Replaces the contents with `maps`. Throws parameter_error naming "maps[i]" (and
    /// nothing is uploaded) when a map is empty or its views differ in size, a position,
    /// normal or flux is not finite, a flux is negative, or the matrix is not finite.
    void upload(std::span<const rsm_view> maps);
    /// The uploaded maps, in the order given (light_view_projection copied from each view).
    std::span<const rsm_textures> textures() const noexcept { return refs_; }

private:
    struct owned {
        texture position, normal, flux;
    };
    std::vector<owned> owned_;
    std::vector<rsm_textures> refs_;
};

}  // namespace bounce::gl
