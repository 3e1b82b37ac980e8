#include <bounce/embree/occlusion_rays.hpp>

#include <bounce/errors.hpp>

#include <cmath>
#include <vector>

namespace bounce::embree {

occlusion_rays::occlusion_rays(const accel& bvh, float offset)
    : bvh_(bvh), offset_(offset == 0.f ? bvh.ray_epsilon() : offset) {
    require(std::isfinite(offset) && offset >= 0.f, "offset", "must be finite and >= 0");
}

void occlusion_rays::occluded(std::span<const visibility_segment> segments, std::span<std::uint8_t> blocked) const {
    require(blocked.size() == segments.size(), "blocked", "size differs from the segments'");
    thread_local std::vector<ray> rays;
    rays.resize(segments.size());
    for (std::size_t i = 0; i < segments.size(); ++i) {
        const visibility_segment& s = segments[i];
        const glm::vec3 from = segment_end(s.receiver, s.receiver_normal, s.sender, offset_);
        const glm::vec3 to = segment_end(s.sender, s.sender_normal, s.receiver, offset_);
        rays[i].origin = from;
        rays[i].direction = to - from;
        rays[i].tnear = 0.f;
        rays[i].tfar = 1.f;
    }
    bvh_.occluded(rays, blocked);
}

}  // namespace bounce::embree
