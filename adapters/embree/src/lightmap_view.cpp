// A camera's view of a lightmap (see lightmap_view.hpp).
#include <bounce/embree/lightmap_view.hpp>

#include <bounce/embree/reference.hpp>
#include <bounce/errors.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bounce::embree {

namespace {

void check_atlas(const accel& bvh, const scene_view& scene, const lightmap_atlas& atlas) {
    require_match(bvh, scene);
    require(atlas.chart_of_triangle.size() == scene.triangles.size(), "atlas",
            "was not built from this scene (triangle counts differ)");
}

// The level and both lightmaps' sizes; returns 2^level, the texels per atlas texel side.
std::size_t check_lightmaps(const lightmap_atlas& atlas, image_view<const glm::vec3> front,
                            image_view<const glm::vec3> back, int level) {
    require(level >= 0 && level <= 8, "level", "must lie in [0, 8]");
    const std::size_t f = std::size_t(1) << level;
    for (const auto& lightmap : {front, back})
        require(lightmap.width() == std::size_t(atlas.width) * f && lightmap.height() == std::size_t(atlas.height) * f,
                "lightmap", "must be the atlas's size times 2^level");
    return f;
}

// Runs f(y) for every row, rows in parallel.
template <class F>
void for_rows(std::size_t height, F&& f) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, height), [&](const tbb::blocked_range<std::size_t>& rows) {
        for (std::size_t y = rows.begin(); y != rows.end(); ++y) f(y);
    });
}

}  // namespace

std::vector<lightmap_hit> lightmap_hits(const accel& bvh, const scene_view& scene, const lightmap_atlas& atlas,
                                        const bounce::camera& cam, std::size_t width, std::size_t height) {
    check_atlas(bvh, scene, atlas);
    cam.validate();
    require(width > 0 && height > 0, "width/height", "must be positive");
    std::vector<lightmap_hit> out(width * height);
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
                lightmap_hit& h = out[y * width + x];
                h.triangle = hits[x].triangle;
                h.position = rays[x].origin + hits[x].t * rays[x].direction;
                const glm::uvec3 tri = scene.triangles[h.triangle];
                const glm::vec3 ng = glm::cross(scene.positions[tri.y] - scene.positions[tri.x],
                                                scene.positions[tri.z] - scene.positions[tri.x]);
                h.back = glm::dot(ng, rays[x].direction) > 0.f;
                const float len = glm::length(ng);
                if (len > 0.f) h.normal = (h.back ? -ng : ng) / len;
                h.chart = atlas.chart_of_triangle[h.triangle];
                if (h.chart != lightmap_atlas::none) h.uv = atlas.atlas_coords(h.chart, h.position);
            }
        }
    });
    return out;
}

image<glm::vec3> lightmap_view(const std::vector<lightmap_hit>& hits, std::size_t width, std::size_t height,
                               const lightmap_atlas& atlas, image_view<const glm::vec3> front,
                               image_view<const glm::vec3> back, int level) {
    require(hits.size() == width * height, "hits", "must hold width x height pixels");
    const std::size_t f = check_lightmaps(atlas, front, back, level);
    image<glm::vec3> out(width, height, glm::vec3(0.f));
    const float scale = float(f);
    const float inv_pi = float(1.0 / std::numbers::pi);
    for_rows(height, [&](std::size_t y) {
        for (std::size_t x = 0; x < width; ++x) {
            const lightmap_hit& h = hits[y * width + x];
            if (h.chart == lightmap_atlas::none) continue;
            const image_view<const glm::vec3>& lightmap = h.back ? back : front;
            // Texel (i, j) spans [i, i+1]: its centre is at i + 1/2.
            const glm::vec2 uv = h.uv * scale - 0.5f;
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
    });
    return out;
}

image<glm::vec3> lightmap_view(const accel& bvh, const scene_view& scene, const lightmap_atlas& atlas,
                               image_view<const glm::vec3> lightmap, int level, const bounce::camera& cam,
                               std::size_t width, std::size_t height) {
    return lightmap_view(bvh, scene, atlas, lightmap, lightmap, level, cam, width, height);
}

image<glm::vec3> lightmap_view(const accel& bvh, const scene_view& scene, const lightmap_atlas& atlas,
                               image_view<const glm::vec3> front, image_view<const glm::vec3> back, int level,
                               const bounce::camera& cam, std::size_t width, std::size_t height) {
    check_atlas(bvh, scene, atlas);
    check_lightmaps(atlas, front, back, level);  // before any ray
    return lightmap_view(lightmap_hits(bvh, scene, atlas, cam, width, height), width, height, atlas, front, back, level);
}

image<glm::vec3> direct_light_view(const accel& bvh, const scene_view& scene, const std::vector<lightmap_hit>& hits,
                                   std::size_t width, std::size_t height, std::uint32_t area_samples,
                                   std::uint64_t seed) {
    require(hits.size() == width * height, "hits", "must hold width x height pixels");
    require(area_samples > 0, "area_samples", "must be positive");
    reference_settings settings;
    settings.area_samples = area_samples;
    const reference_integrator direct(bvh, scene, settings);
    const double inv_pi = 1.0 / std::numbers::pi;
    image<glm::vec3> out(width, height, glm::vec3(0.f));
    for_rows(height, [&](std::size_t y) {
        for (std::size_t x = 0; x < width; ++x) {
            const lightmap_hit& h = hits[y * width + x];
            if (h.triangle == no_triangle || !(glm::dot(h.normal, h.normal) > 0.f)) continue;
            const material& m = scene.materials[scene.material_of[h.triangle]];
            const glm::dvec3 e(direct.direct_irradiance(h.position, h.normal, derive_seed(seed, 7, y * width + x)));
            out(x, y) = glm::vec3(glm::dvec3(m.albedo) * inv_pi * e);
        }
    });
    return out;
}

image<glm::vec3> lightmap_direct_view(const accel& bvh, const scene_view& scene, const lightmap_atlas& atlas,
                                      image_view<const glm::vec3> front_rest, image_view<const glm::vec3> back_rest,
                                      int level, const bounce::camera& cam, std::size_t width, std::size_t height) {
    const std::vector<lightmap_hit> hits = lightmap_hits(bvh, scene, atlas, cam, width, height);
    image<glm::vec3> out = lightmap_view(hits, width, height, atlas, front_rest, back_rest, level);
    scene_view lights_only = scene;
    lights_only.use_emission = false;  // what emissive surfaces shot is in the lightmap
    const image<glm::vec3> direct = direct_light_view(bvh, lights_only, hits, width, height);
    for (std::size_t y = 0; y < height; ++y)
        for (std::size_t x = 0; x < width; ++x) out(x, y) += direct(x, y);
    return out;
}

}  // namespace bounce::embree
