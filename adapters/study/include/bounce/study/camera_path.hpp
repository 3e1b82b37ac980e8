#pragma once
/// \file camera_path.hpp
/// The camera path of the progressive (multi-frame) runs: cpu::walkthrough and the studies
/// render one frame per camera of it.

#include <bounce/camera.hpp>
#include <bounce/embree/accel.hpp>

#include <cstddef>

#include <glm/vec3.hpp>

namespace bounce::study {

/// From `start`, a walk forward along the view axis (a tenth of the way to the target, and
/// never more than half the way to the first surface on the axis) while the view pans from
/// -10 to +10 degrees about the up axis, so the eye stays in the open space it starts in.
/// (An orbit about the target swung Sponza's eye through the colonnade, where frames saw
/// one column from centimetres away.)
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
