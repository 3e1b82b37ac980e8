#pragma once
// What direct light at a point asks of each light, for the integrators of this adapter
// (reference.cpp, rsm_unoccluded_reference.cpp): its unshadowed irradiance (the kernels of
// bounce/direct_light.hpp) and the shadow ray that tests it.

#include <bounce/direct_light.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/light.hpp>

#include <algorithm>

#include <glm/geometric.hpp>

namespace bounce::embree::detail {

/// Irradiance (W/m^2, RGB) at `p` with unit normal `n` from the point, spot or directional
/// light `l`, without visibility.
inline glm::vec3 unshadowed_irradiance(const packed_light& l, glm::vec3 p, glm::vec3 n) {
    switch (l.kind()) {
    case light_kind::point: return point_light_irradiance<float, glm::vec3>(p, n, l.position(), l.intensity());
    case light_kind::spot:
        return spot_light_irradiance<float, glm::vec3>(p, n, l.position(), l.direction(), l.intensity(), l.cos_cone(),
                                                        l.cosine_falloff());
    default: return directional_light_irradiance<float, glm::vec3>(n, l.direction(), l.intensity());
    }
}

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
