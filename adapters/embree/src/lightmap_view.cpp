// A camera's view of a lightmap (see lightmap_view.hpp).
#include <bounce/embree/lightmap_view.hpp>

#include <bounce/errors.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bounce::embree {

image<glm::vec3> lightmap_view(const accel& bvh, const scene_view& scene, const lightmap_atlas& atlas,
                               image_view<const glm::vec3> lightmap, int level, const bounce::camera& cam,
                               std::size_t width, std::size_t height) {
    return lightmap_view(bvh, scene, atlas, lightmap, lightmap, level, cam, width, height);
}

image<glm::vec3> lightmap_view(const accel& bvh, const scene_view& scene, const lightmap_atlas& atlas,
                               image_view<const glm::vec3> front, image_view<const glm::vec3> back, int level,
                               const bounce::camera& cam, std::size_t width, std::size_t height) {
    require_match(bvh, scene);
    cam.validate();
    require(width > 0 && height > 0, "width/height", "must be positive");
    require(atlas.chart_of_triangle.size() == scene.triangles.size(), "atlas",
            "was not built from this scene (triangle counts differ)");
    require(level >= 0 && level <= 8, "level", "must lie in [0, 8]");
    const std::size_t f = std::size_t(1) << level;
    for (const auto& lightmap : {front, back})
        require(lightmap.width() == std::size_t(atlas.width) * f && lightmap.height() == std::size_t(atlas.height) * f,
                "lightmap", "must be the atlas's size times 2^level");
    image<glm::vec3> out(width, height, glm::vec3(0.f));
    const float scale = float(f);
    const float inv_pi = float(1.0 / std::numbers::pi);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, height), [&](const tbb::blocked_range<std::size_t>& rows) {
        std::vector<ray> rays(width);
        std::vector<hit> hits(width);
        for (std::size_t y = rows.begin(); y != rows.end(); ++y) {
            for (std::size_t x = 0; x < width; ++x) {
                rays[x].origin = cam.position;
                rays[x].direction = cam.direction(float(x) + 0.5f, float(y) + 0.5f, width, height);
                rays[x].tnear = cam.near_plane;
                rays[x].tfar = cam.far_plane;
            }
            bvh.intersect(rays, hits, /*coherent=*/true);
            for (std::size_t x = 0; x < width; ++x) {
                if (!hits[x].found()) continue;
                const std::uint32_t chart = atlas.chart_of_triangle[hits[x].triangle];
                if (chart == lightmap_atlas::none) continue;
                const glm::vec3 p = rays[x].origin + hits[x].t * rays[x].direction;
                // The side seen: the hit triangle's own (a chart that follows a curved surface
                // tilts its triangles up to its cone from the chart's normal).
                const glm::uvec3 tri = scene.triangles[hits[x].triangle];
                const glm::vec3 ng = glm::cross(scene.positions[tri.y] - scene.positions[tri.x],
                                                scene.positions[tri.z] - scene.positions[tri.x]);
                const bool sees_back = glm::dot(ng, rays[x].direction) > 0.f;
                const image_view<const glm::vec3>& lightmap = sees_back ? back : front;
                // Texel (i, j) spans [i, i+1]: its centre is at i + 1/2.
                const glm::vec2 uv = atlas.atlas_coords(chart, p) * scale - 0.5f;
                const float fx = std::floor(uv.x), fy = std::floor(uv.y);
                const float tx = uv.x - fx, ty = uv.y - fy;
                const auto at = [&](float i, float j) {
                    const auto xi = std::size_t(std::clamp(i, 0.f, float(lightmap.width() - 1)));
                    const auto yj = std::size_t(std::clamp(j, 0.f, float(lightmap.height() - 1)));
                    return lightmap(xi, yj);
                };
                const glm::vec3 b = (1.f - ty) * ((1.f - tx) * at(fx, fy) + tx * at(fx + 1.f, fy)) +
                                    ty * ((1.f - tx) * at(fx, fy + 1.f) + tx * at(fx + 1.f, fy + 1.f));
                out(x, y) = b * inv_pi;
            }
        }
    });
    return out;
}

}  // namespace bounce::embree
