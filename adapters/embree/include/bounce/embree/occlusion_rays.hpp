#pragma once
/// \file occlusion_rays.hpp
/// The exact visibility of the RSM / SII family (indirect/visibility.hpp) on the CPU: an
/// Embree occlusion ray for each receiver-sender segment a frame sums, so that
/// cpu::indirect_renderer with indirect_visibility::rays lets no light through walls.
///
///     const bounce::embree::accel bvh(scene);
///     const bounce::embree::occlusion_rays rays(bvh);
///     bounce::cpu::indirect_renderer renderer(options /* visibility = rays */, &rays);

#include <bounce/embree/accel.hpp>
#include <bounce/indirect/visibility.hpp>

#include <cstdint>
#include <span>

namespace bounce::embree {

/// occlusion_query by Embree occlusion rays on one accel (shared, not copied: copies of an
/// accel share its BVH). Safe to call from any number of threads.
class occlusion_rays final : public bounce::indirect::occlusion_query {
public:
    /// Rays on `bvh`, each end of a segment moved `offset` off its surface (segment_end);
    /// offset 0 takes bvh.ray_epsilon(), 1e-4 of the scene's size. Throws parameter_error
    /// for a negative or non-finite offset.
    explicit occlusion_rays(const accel& bvh, float offset = 0.f);

    /// blocked[i] = 1 where the scene's triangles cross segment i between its moved ends
    /// (one stream query, rtcOccluded1M). Sizes must match (parameter_error).
    void occluded(std::span<const visibility_segment> segments, std::span<std::uint8_t> blocked) const override;

    float offset() const noexcept { return offset_; }

private:
    accel bvh_;
    float offset_;
};

}  // namespace bounce::embree
