#pragma once
/// \file irradiance_volume.hpp
/// Irradiance-volume lookups on the GPU (Oat 2006): the flattened octree and probes
/// (irradiance_volume::flatten, std430) in storage buffers, and a compute pass that lights
/// points with the same kernels as the CPU (volume/kernels.hpp, printed as GLSL
/// by glsl::emit). The pass's own GLSL is plumbing only: buffer reads, the descent loop,
/// the traversal stack and the loops over corners. With the probes' distance moments
/// (volume/probe_visibility.hpp) the trilinear lookup tests each corner's visibility with
/// the kernels of volume/visibility_kernels.hpp (DDGI), as cpu::light_points does.

#include <bounce/gl/objects.hpp>
#include <bounce/output.hpp>
#include <bounce/volume/probe_octree.hpp>
#include <bounce/volume/probe_visibility.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::gl {

/// A volume's nodes, probes and probe owners in three storage buffers, and optionally its
/// probes' distance moments in a fourth (created in the current context; destroy before it).
class irradiance_volume_buffers {
public:
    /// Uploads `volume` and, when not null, `visibility` (one map per probe of `volume`).
    /// Throws gl_error when a buffer exceeds GL_MAX_SHADER_STORAGE_BLOCK_SIZE,
    /// parameter_error naming "visibility" for moments of another volume.
    explicit irradiance_volume_buffers(const irradiance_volume& volume, const probe_visibility* visibility = nullptr);

    const buffer& nodes() const noexcept { return nodes_; }    ///< irradiance_volume_gpu_node[]
    const buffer& probes() const noexcept { return probes_; }  ///< irradiance_volume_gpu_probe[]
    const buffer& owners() const noexcept { return owners_; }  ///< uint[]: probe_owners()
    float reference_reach() const noexcept { return reference_reach_; }
    const buffer& moments() const noexcept { return moments_; }  ///< float[]: probe_visibility::moments()
    /// vec4[]: each probe's actual position (probe_visibility::position), with the moments.
    const buffer& positions() const noexcept { return positions_; }
    /// The moments' map resolution N; 0 when none were uploaded.
    std::uint32_t visibility_resolution() const noexcept { return visibility_resolution_; }

private:
    buffer nodes_, probes_, owners_, moments_, positions_;
    float reference_reach_;
    std::uint32_t visibility_resolution_ = 0;
};

/// Which interpolation the GPU lookup runs.
enum class volume_interpolation { trilinear, weighted };

/// The compute pass that lights points from irradiance_volume_buffers.
class irradiance_volume_lookup {
public:
    /// Compiles the pass (current context). Throws shader_error when it does not compile.
    irradiance_volume_lookup();

    /// The compute shader's source: the emitted kernels and the plumbing around them.
    static std::string shader_source();

    /// Irradiance (W/m^2, RGB) at each point with its unit normal, as
    /// irradiance_volume::trilinear or ::weighted compute it, or as `quantity` radiance
    /// rho/pi * E with `albedo` (one per point; output.hpp), as cpu::light_points gives it.
    /// Restores the program and the storage-buffer bindings 0..4 it uses. Throws
    /// parameter_error on mismatched sizes (naming "albedo" for radiance without one per
    /// point) or a `how` the CPU lookup refuses, gl_error on a GL failure.
    std::vector<glm::vec3> light_points(const irradiance_volume_buffers& volume, std::span<const glm::vec3> points,
                                        std::span<const glm::vec3> normals, volume_interpolation interpolation,
                                        const weighted_lookup& how = {},
                                        output_quantity quantity = output_quantity::irradiance,
                                        std::span<const glm::vec3> albedo = {}) const;

    /// The trilinear lookup with each corner probe's visibility tested from the point (its
    /// view direction towards `eye`), as cpu::light_points with a probe_visibility computes
    /// it; `how.mode = none` is the plain trilinear lookup. Throws parameter_error naming
    /// "visibility" when `volume` holds no moments and the test is asked, and as above.
    std::vector<glm::vec3> light_points(const irradiance_volume_buffers& volume, std::span<const glm::vec3> points,
                                        std::span<const glm::vec3> normals, glm::vec3 eye, const visibility_lookup& how,
                                        output_quantity quantity = output_quantity::irradiance,
                                        std::span<const glm::vec3> albedo = {}) const;

private:
    struct dispatch;
    std::vector<glm::vec3> run(const irradiance_volume_buffers& volume, std::span<const glm::vec3> points,
                               std::span<const glm::vec3> normals, const dispatch& d, output_quantity quantity,
                               std::span<const glm::vec3> albedo) const;

    program program_;
};

}  // namespace bounce::gl
