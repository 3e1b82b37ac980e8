// Camera rays through pixel centres into a G-buffer (issue 2: CPU G-buffer by ray casting).
#include <bounce/embree/ray_cast_gbuffer.hpp>

#include <limits>
#include <vector>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bounce::embree {

void ray_cast_gbuffer(const accel& bvh, const scene_view& scene, const bounce::camera& cam, gbuffer_view<float> out) {
    require_match(bvh, scene);
    cam.validate();
    const std::size_t w = out.depth.width(), h = out.depth.height();
    require(w > 0 && h > 0, "out", "the G-buffer is empty");
    auto same = [&](std::size_t vw, std::size_t vh) { return vw == w && vh == h; };
    require(same(out.position.width(), out.position.height()) && same(out.normal.width(), out.normal.height()) &&
                same(out.albedo.width(), out.albedo.height()),
            "out", "position, normal, albedo and depth views differ in size");

    const glm::vec3 forward = cam.forward();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, h), [&](const tbb::blocked_range<std::size_t>& rows) {
        std::vector<ray> rays(w);
        std::vector<hit> hits(w);
        for (std::size_t y = rows.begin(); y != rows.end(); ++y) {
            for (std::size_t x = 0; x < w; ++x) {
                ray& r = rays[x];
                r.origin = cam.position;
                // camera.hpp: the direction's component along forward is 1, so t is the
                // depth and [near, far] clips exactly as the raster projection does.
                r.direction = cam.direction(float(x) + 0.5f, float(y) + 0.5f, w, h);
                r.tnear = cam.near_plane;
                r.tfar = cam.far_plane;
            }
            bvh.intersect(rays, hits, /*coherent=*/true);
            for (std::size_t x = 0; x < w; ++x) {
                if (!hits[x].found()) {
                    out.position(x, y) = glm::vec3(0.f);
                    out.normal(x, y) = glm::vec3(0.f);
                    out.albedo(x, y) = glm::vec3(0.f);
                    out.depth(x, y) = std::numeric_limits<float>::infinity();
                    continue;
                }
                const surface s = surface_at(scene, rays[x], hits[x]);
                out.position(x, y) = s.position;
                out.normal(x, y) = s.normal;
                out.albedo(x, y) = s.albedo;
                out.depth(x, y) = glm::dot(s.position - cam.position, forward);
            }
        }
    });
}

gbuffer<float> ray_cast_gbuffer(const accel& bvh, const scene_view& scene, const bounce::camera& cam, std::size_t width,
                                std::size_t height) {
    require(width > 0 && height > 0, "width/height", "the G-buffer size must be positive");
    gbuffer<float> g(width, height);
    ray_cast_gbuffer(bvh, scene, cam, g.view());
    return g;
}

void snap_to_ray_hits(const accel& bvh, const scene_view& scene, const bounce::camera& cam, gbuffer_view<float> g) {
    gbuffer<float> ray = ray_cast_gbuffer(bvh, scene, cam, g.width(), g.height());
    const auto [lo, hi] = scene.bounds();
    const float scene_size = glm::length(hi - lo);
    const gbuffer_view<float> rv = ray.view();
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x)
            if (same_surface(g, rv, x, y, scene_size)) {
                g.position(x, y) = rv.position(x, y);
                g.normal(x, y) = rv.normal(x, y);
                g.depth(x, y) = rv.depth(x, y);
            }
}

}  // namespace bounce::embree
