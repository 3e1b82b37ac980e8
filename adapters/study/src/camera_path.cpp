// The progressive runs' camera path: a short walk forward while the view pans.
#include <bounce/study/camera_path.hpp>

#include <algorithm>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

namespace bounce::study {

camera_path::camera_path(const embree::accel& bvh, const camera& start, std::size_t frames)
    : base_(start), forward_(start.forward()), frames_(frames) {
    const embree::hit first = bvh.intersect({base_.position, forward_});  // t = inf on a miss
    walk_ = std::min(0.1f * glm::length(base_.look_at - base_.position), 0.5f * first.t);
}

camera camera_path::at(std::size_t f) const {
    const float t = float(f) / float(std::max<std::size_t>(1, frames_ - 1));
    camera cam = base_;
    cam.position = base_.position + t * walk_ * forward_;
    const glm::quat pan = glm::angleAxis(glm::radians(20.f) * (t - 0.5f), glm::normalize(base_.up));
    cam.look_at = cam.position + pan * (base_.look_at - cam.position);
    return cam;
}

}  // namespace bounce::study
