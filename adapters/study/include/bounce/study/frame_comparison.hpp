#pragma once
/// \file frame_comparison.hpp
/// What a study needs to compare a technique's frames with reference images: the pixels
/// where the comparison means something, and the camera path of multi-frame runs.

#include <bounce/camera.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>

#include <cstddef>

namespace bounce::study {

/// 1 where `g` sees geometry, 0 elsewhere.
image<float> coverage_mask(const gbuffer_view<float>& g);

/// The pixels where a frame's G-buffer (a raster one, say) sees the same surface as the
/// ray-cast G-buffer `reference_g` the reference was computed on (same_surface with
/// `scene_size`): elsewhere (a few silhouette pixels) the two images show different surfaces
/// and their difference is not the technique's error.
image<float> comparable_mask(const gbuffer_view<float>& g, const gbuffer_view<float>& reference_g, float scene_size);

/// The progressive runs' camera path: from `start`, a walk forward along the view axis (a
/// tenth of the way to the target, and never more than half the way to the first surface on
/// the axis) while the view pans from -10 to +10 degrees about the up axis, so the eye stays
/// in the open space it starts in. (An orbit about the target swung Sponza's eye through
/// the colonnade, where frames saw one column from centimetres away.)
class camera_path {
public:
    camera_path(const embree::accel& bvh, const camera& start, std::size_t frames);
    /// The camera of frame f in [0, frames).
    camera at(std::size_t f) const;
    std::size_t frames() const noexcept { return frames_; }

private:
    camera base_;
    glm::vec3 forward_;
    float walk_;  // world units the eye moves over the whole path
    std::size_t frames_;
};

}  // namespace bounce::study
