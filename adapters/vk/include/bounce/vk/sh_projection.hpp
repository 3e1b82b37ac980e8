#pragma once
/// \file sh_projection.hpp
/// `vk::sh_projector`: SH projection of RGB cube maps as Vulkan 1.2 compute on the caller's
/// device, queue and buffers, the quadrature of sh/projection.hpp's sh_project_cube_map
/// (each texel's value times Y_i at its centre times its exact solid angle) with the
/// one-source kernels emitted as GLSL: sh_basis (sh/basis.hpp) and the texel solid angle
/// (rectangle_solid_angle_triangles, rectangle_solid_angle.hpp), compiled to SPIR-V at build
/// time for L = 2, 3 and 4 bands.
///
/// Buffers (std430):
/// - texels: packed RGB floats (12 bytes a texel, as an array of glm::vec3), map after map,
///   each six faces in OpenGL's order (+x -x +y -y +z -z), each face size x size texels, row 0
///   first (sh/projection.hpp's orientation): texel (map m, face f, x, y) at float
///   3 (((m 6 + f) size + y) size + x);
/// - coefficients: one vec4 per coefficient (rgb; a = 0), L^2 per map, map after map.
/// One workgroup of 256 invocations projects one map: each sums a strided share of the
/// texels in float, then the workgroup adds the shares in a tree.

#include <bounce/vk/compute.hpp>
#include <bounce/vk/device.hpp>

#include <cstddef>
#include <memory>

namespace bounce::vk {

class sh_projector {
public:
    /// Projects onto `bands` bands (2, 3 or 4: 4, 9 or 16 coefficients). Throws
    /// parameter_error naming "bands" for another count, vulkan_error on a failed call.
    sh_projector(const device_ref& device, int bands);
    ~sh_projector();

    int bands() const noexcept { return bands_; }
    /// Coefficients per map (bands^2).
    std::size_t coefficients() const noexcept { return std::size_t(bands_ * bands_); }

    /// Projects maps [first_map, first_map + maps) of size x size faces from `texels` into
    /// their coefficients in `coefficients` (at the same map index). Throws parameter_error
    /// naming "size" or "maps" when they are 0 or too large for 32-bit indices.
    void record_project(VkCommandBuffer cmd, buffer_range texels, buffer_range coefficients, std::size_t size,
                        std::size_t first_map, std::size_t maps) const;
    void project(buffer_range texels, buffer_range coefficients, std::size_t size, std::size_t first_map, std::size_t maps);

private:
    int bands_;
    submitter submit_;
    std::unique_ptr<compute_pipeline> pipeline_;
};

}  // namespace bounce::vk
