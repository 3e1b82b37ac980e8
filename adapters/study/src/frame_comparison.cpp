// Masks of comparable pixels and the progressive runs' camera path.
#include <bounce/study/frame_comparison.hpp>

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

namespace bounce::study {

image<float> coverage_mask(const gbuffer_view<float>& g) {
    image<float> m(g.width(), g.height(), 0.f);
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x) m(x, y) = std::isfinite(g.depth(x, y)) ? 1.f : 0.f;
    return m;
}

image<float> comparable_mask(const gbuffer_view<float>& g, const gbuffer_view<float>& reference_g, float scene_size) {
    require(g.width() == reference_g.width() && g.height() == reference_g.height(), "reference_g",
            "size differs from the frame's G-buffer");
    image<float> m = coverage_mask(g);
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x)
            if (m(x, y) > 0.f && !same_surface(g, reference_g, x, y, scene_size)) m(x, y) = 0.f;
    return m;
}

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
