#include <bounce/embree/near_field_rays.hpp>

#include <bounce/errors.hpp>

#include <cmath>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>

namespace bounce::embree {

near_field_rays::near_field_rays(const accel& bvh, const scene_view& scene)
    : integrator_(bvh, scene), unoccluded_(bvh, scene) {}

void near_field_rays::radiance(std::span<const bounce::indirect::near_field_ray> rays, std::span<glm::vec3> radiance,
                               std::span<float> distance2) const {
    require(radiance.size() == rays.size() && distance2.size() == rays.size(), "radiance",
            "radiance and distance2 must have one entry per ray");
    thread_local std::vector<ray> traced;
    thread_local std::vector<std::uint64_t> seeds;
    thread_local std::vector<float> distance;
    traced.resize(rays.size());
    seeds.resize(rays.size());
    distance.resize(rays.size());
    const float eps = integrator_.ray_epsilon();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const auto& r = rays[i];
        traced[i] = {r.receiver + eps * r.normal, r.direction, 0.f, r.length};
        seeds[i] = r.seed;
    }
    integrator_.incoming_radiance(traced, seeds, radiance, distance);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (!std::isfinite(distance[i])) {
            radiance[i] = glm::vec3(0.f);
            distance2[i] = std::numeric_limits<float>::infinity();
            continue;
        }
        const glm::vec3 v = traced[i].origin + traced[i].direction * distance[i] - rays[i].receiver;
        distance2[i] = glm::dot(v, v);
    }
}

void near_field_rays::crossings(std::span<const bounce::indirect::near_field_ray> rays,
                                std::vector<bounce::indirect::near_field_crossing>& out) const {
    out.clear();
    const float eps = unoccluded_.ray_epsilon();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const auto& r = rays[i];
        const ray traced{r.receiver + eps * r.normal, r.direction, 0.f, r.length};
        unoccluded_.for_each_sender(traced, [&](float t, const glm::dvec3& l) {
            const glm::vec3 v = traced.origin + traced.direction * t - r.receiver;
            out.push_back({std::uint32_t(i), glm::dot(v, v), glm::vec3(l)});
        });
    }
}

}  // namespace bounce::embree
