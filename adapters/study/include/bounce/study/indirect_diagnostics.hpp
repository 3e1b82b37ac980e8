#pragma once
/// \file indirect_diagnostics.hpp
/// Diagnostics of indirect visibility's error (issue 29; rsm_visibility_study,
/// docs/rsm-sii-interleaved.md section 15): occlusion queries that differ from the library's
/// only in how a segment's ends are set, a scene shaded with per-face normals, a reference
/// blurred by a frame's own tent, the sub-buffers that tent reaches, and raw float32 dumps for
/// per-pixel analysis.

#include <bounce/embree/accel.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/indirect/options.hpp>
#include <bounce/indirect/visibility.hpp>
#include <bounce/io/scene.hpp>

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include <glm/vec3.hpp>

namespace bounce::study {

/// The occlusion queries rsm_visibility_study --occlusion compares: "rays" answers as
/// embree::occlusion_rays (each end moved off its surface along the given, shading, normal);
/// "geometric" moves each end along its triangle's geometric normal instead (found by a probe
/// ray back along the shading normal); "shortened" keeps the receiver's end and stops the ray
/// 2 epsilon before the sender itself, whatever the sender's normal says. Each counts where
/// blocked segments meet their first surface: within 3, 30 or 300 epsilon of the receiver's
/// end, of the sender's, or further from both (summary()). Throws parameter_error
/// ("--occlusion") for another mode. `scene` must outlive it.
class diagnostic_occlusion final : public occlusion_query {
public:
    diagnostic_occlusion(const embree::accel& bvh, const io::scene& scene, std::string mode);
    void occluded(std::span<const visibility_segment> segments, std::span<std::uint8_t> blocked) const override;
    /// "MODE: N segments; blocked within 3/30/300/more eps of the receiver a b c d, of the sender ...".
    std::string summary() const;

private:
    glm::vec3 geometric_normal(const glm::vec3& p, const glm::vec3& n) const;
    embree::accel bvh_;
    const io::scene& scene_;
    std::string mode_;
    float eps_;
    mutable std::array<std::array<std::atomic<std::uint64_t>, 4>, 2> counts_{};
    mutable std::atomic<std::uint64_t> total_{0};
};

/// `s` with every triangle's corners its own vertices carrying the triangle's geometric normal
/// (the per-face normals an OBJ without `vn` stands for, instead of the loader's smoothed
/// ones), on the side the smoothed normals gave; named NAME-flat.
io::scene flat_shaded(const io::scene& s);

/// The reference radiance `radiance` (rho / pi E, 0 where rho is 0) turned into irradiance,
/// blurred by the frame's own geometry-aware tent (options.pattern, options.discontinuity) and
/// back to radiance: what the blurred frame averages to over the VPLs' draws.
image<glm::vec3> blurred_reference(const gbuffer_view<float>& g, image_view<const glm::vec3> radiance,
                                   const indirect_options& options);

/// How many of the pattern's sub-buffers the blur of geometry alone reaches at each pixel
/// (cpu::reached_sub_buffers), in every channel.
image<glm::vec3> reached_sub_buffers_image(const gbuffer_view<float>& g, const indirect_options& options);

/// `img` as raw float32 (width x height x 3, row-major) at `file`, its folder created. Throws
/// parameter_error naming `parameter` when it cannot be written.
void write_raw_f32(const std::filesystem::path& file, image_view<const glm::vec3> img, const std::string& parameter);

}  // namespace bounce::study
