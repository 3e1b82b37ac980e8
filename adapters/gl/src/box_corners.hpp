#pragma once
// The corners of an axis-aligned box, as the light maps fit their projections to the scene
// bounds (direct_light's shadow maps, rsm_renderer's maps).
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>

namespace bounce::gl::detail {

/// Corner `c` (0..7, one bit per axis) of the box [lo, hi].
inline glm::vec3 box_corner(const glm::vec3& lo, const glm::vec3& hi, int c) {
    return {(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z};
}

/// The distance from `p` to the farthest corner of the box [lo, hi].
inline float farthest_corner_distance(const glm::vec3& p, const glm::vec3& lo, const glm::vec3& hi) {
    float d = 0.f;
    for (int c = 0; c < 8; ++c) d = std::max(d, glm::length(box_corner(lo, hi, c) - p));
    return d;
}

}  // namespace bounce::gl::detail
