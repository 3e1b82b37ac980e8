#include <bounce/embree/plane_sampler.hpp>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace bounce::embree {

void sample_planes(const reference_integrator& ref, const plane_camera& camera, std::span<const glm::vec3> points,
                   std::span<const glm::vec3> normals, const plane_consumer& consume) {
    camera.validate();
    require(normals.size() == points.size(), "normals", "must have one entry per point");
    require(bool(consume), "consume", "must be a callable");
    struct buffers {
        image<glm::vec3> radiance;
        image<float> distance;
    };
    const std::uint32_t N = camera.resolution;
    tbb::enumerable_thread_specific<buffers> local([N] { return buffers{image<glm::vec3>(N, N), image<float>(N, N)}; });
    tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t k) {
        buffers& b = local.local();
        sample_plane(ref, camera, points[k], normals[k], b.radiance.view(), b.distance.view());
        consume(k, plane_view{b.radiance.view(), b.distance.view()});
    });
}

}  // namespace bounce::embree
