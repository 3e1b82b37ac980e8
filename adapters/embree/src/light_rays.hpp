#pragma once
// What direct light at a point asks of each light, for the integrators of this adapter
// (reference.cpp, rsm_unoccluded_reference.cpp): the shadow ray that tests the unshadowed
// irradiance of bounce/direct_light.hpp's light_irradiance.

#include <bounce/embree/accel.hpp>
#include <bounce/light.hpp>

#include <algorithm>

#include <glm/geometric.hpp>

namespace bounce::embree::detail {

/// The segment from `origin` to the point `q`, stopped short of q by `epsilon` (world
/// units) so that the surface at q itself (a light's own position, an emitter's triangle)
/// does not block it. Unnormalized direction: t runs over [0, 1 - epsilon / |q - origin|].
inline ray shadow_ray_to(glm::vec3 origin, glm::vec3 q, float epsilon) {
    ray r;
    r.origin = origin;
    r.direction = q - origin;
    const float d = glm::length(r.direction);
    r.tfar = std::max(0.f, 1.f - epsilon / std::max(d, epsilon));
    return r;
}

/// The shadow ray from `origin` towards light `l`: against a directional light's direction
/// without end, else to its position (shadow_ray_to).
inline ray shadow_ray_towards(const packed_light& l, glm::vec3 origin, float epsilon) {
    if (l.kind() != light_kind::directional) return shadow_ray_to(origin, l.position(), epsilon);
    ray r;
    r.origin = origin;
    r.direction = -l.direction();
    return r;
}

}  // namespace bounce::embree::detail
