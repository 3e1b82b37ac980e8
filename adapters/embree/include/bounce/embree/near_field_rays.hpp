#pragma once
/// \file near_field_rays.hpp
/// The rays of the RSM gather's clamp compensation (indirect/clamp_compensation.hpp) on the
/// CPU: each ray's first surface and the light it sends back, shaded exactly as the occluded
/// one-bounce reference shades its hemisphere hits (reference_integrator::incoming_radiance:
/// Kd / pi times the direct irradiance with shadow rays), so that the gather plus its
/// compensation converges to that reference. Without visibility (crossings) every surface
/// within the ray's length counts, shaded exactly as the unoccluded one-bounce reference
/// shades its senders (unoccluded_reference::for_each_sender), so that the gather without
/// visibility plus its compensation converges to that reference.
///
///     const bounce::embree::accel bvh(scene);
///     const bounce::embree::occlusion_rays rays(bvh);
///     const bounce::embree::near_field_rays near(bvh, scene.view());
///     bounce::cpu::indirect_renderer renderer(options /* gather, rays, clamp_compensation_rays */,
///                                             &rays, nullptr, &near);

#include <bounce/embree/accel.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/embree/rsm_unoccluded_reference.hpp>
#include <bounce/indirect/clamp_compensation.hpp>
#include <bounce/scene_view.hpp>

#include <span>
#include <vector>

namespace bounce::embree {

/// near_field_query by Embree rays on one accel and its scene (both must outlive it). Safe
/// to call from any number of threads.
class near_field_rays final : public bounce::indirect::near_field_query {
public:
    /// Throws parameter_error as reference_integrator does (lights, a scene not matching `bvh`).
    near_field_rays(const accel& bvh, const scene_view& scene);

    /// Each ray starts at receiver + ray_epsilon() normal (as the reference's hemisphere rays
    /// do) and ends at its length; radiance and squared distance from the receiver of its
    /// first hit, (0, +infinity) where it meets nothing. Sizes must match (parameter_error).
    void radiance(std::span<const bounce::indirect::near_field_ray> rays, std::span<glm::vec3> radiance,
                  std::span<float> distance2) const override;
    /// Each ray from the same origin as radiance's: every surface it crosses before its length
    /// (unoccluded_reference's senders, default settings), with its squared distance from the
    /// receiver.
    void crossings(std::span<const bounce::indirect::near_field_ray> rays,
                   std::vector<bounce::indirect::near_field_crossing>& out) const override;

private:
    reference_integrator integrator_;
    unoccluded_reference unoccluded_;
};

}  // namespace bounce::embree
