#pragma once
/// \file plane_sampler.hpp
/// The ray-cast counterpart of gl::hemisphere_raster: one hemisphere plane (bounce/
/// cache/plane_camera.hpp) filled by casting its pixel rays through Embree, each hit shaded by the
/// reference integrator, so a plane estimator's error can be told from rasterization's.

#include <bounce/embree/reference.hpp>
#include <bounce/cache/plane_camera.hpp>

#include <algorithm>
#include <cstddef>
#include <functional>
#include <span>
#include <utility>

#include <glm/vec3.hpp>

namespace bounce::embree {

/// Fills `radiance` and `distance` (resolution x resolution) with the plane of `camera` at
/// the record (p, n), in the camera's frame (plane_camera::frame), rays leaving
/// p + ray_epsilon n.
/// Distances are floored at 1e-30: an origin lying on another surface (a record in a
/// corner) can hit it at t = 0, and plane distances must be positive, as
/// plane_hit_distance keeps them in the raster sampler.
inline void sample_plane(const reference_integrator& ref, const plane_camera& camera, glm::vec3 p, glm::vec3 n,
                         image_view<glm::vec3> radiance, image_view<float> distance) {
    const auto tb = camera.frame(p, n);
    const glm::vec3 origin = p + ref.ray_epsilon() * n;
    bounce::sample_plane(
        camera,
        [&](const glm::dvec3& d) {
            ray r;
            r.origin = origin;
            r.direction = glm::normalize(tb[0] * float(d.x) + tb[1] * float(d.y) + n * float(d.z));
            float hit = 0;
            const glm::vec3 L = ref.incoming_radiance(r, 0, &hit);
            return std::pair{L, std::max(hit, 1e-30f)};
        },
        radiance, distance);
}

/// Called with a record's index in the batch and its plane (valid during the call only).
using plane_consumer = std::function<void(std::size_t record, plane_view plane)>;

/// The planes of records (points[k], normals[k]), cast in parallel (TBB, one plane buffer
/// per thread): sample_plane for each, then `consume(k, plane)` on the thread that cast
/// it, so `consume` must be safe to call concurrently for different k (summing each into
/// its own slot, or into per-thread accumulators). The ray-cast counterpart of
/// gl::hemisphere_raster::read_planes, without its batches: memory is one plane per thread.
/// Throws parameter_error when the spans' sizes differ or the camera is invalid; an
/// exception from `consume` propagates (after the other threads stop).
void sample_planes(const reference_integrator& ref, const plane_camera& camera, std::span<const glm::vec3> points,
                   std::span<const glm::vec3> normals, const plane_consumer& consume);

}  // namespace bounce::embree
