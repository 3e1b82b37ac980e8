#pragma once
// Where the view's black pixels come from (issue 30, "no holes"): for each pixel black where
// the reference is lit (report.hpp's black_pixels), the triangle and chart the view's ray
// meets, the side it sees, the element the lookup's nearest texel reads, and whether that
// element's point is buried (its hemisphere on the seen side closed within a texel's side or
// 1/1000 of the scene's diagonal, the smaller) or seen
// from the pixel's own surface point. Written as CSV by --holes-out.

#include <bounce/embree/accel.hpp>
#include <bounce/errors.hpp>
#include <bounce/camera.hpp>
#include <bounce/luminance.hpp>
#include <bounce/image.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/scene_view.hpp>

#include "report.hpp"

#include <fmt/core.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <vector>

namespace bounce::examples {

// Fraction of 64 directions over the hemisphere of `n` from `p` that meet a surface within `reach`.
inline float closed_fraction(const embree::accel& bvh, const glm::vec3& p, const glm::vec3& n, float reach) {
    const glm::vec3 t = glm::normalize(std::abs(n.x) > 0.5f ? glm::cross(n, glm::vec3(0, 1, 0)) : glm::cross(n, glm::vec3(1, 0, 0)));
    const glm::vec3 b = glm::cross(n, t);
    constexpr int count = 64;
    int closed = 0;
    for (int k = 0; k < count; ++k) {  // a Fibonacci spiral over the hemisphere
        const float z = 1.f - (float(k) + 0.5f) / float(count);
        const float r = std::sqrt(1.f - z * z), phi = float(k) * 2.39996323f;
        embree::ray ray;
        ray.origin = p + n * bvh.ray_epsilon();
        ray.direction = r * std::cos(phi) * t + r * std::sin(phi) * b + z * n;
        ray.tfar = reach;
        closed += bvh.occluded(ray) ? 1 : 0;
    }
    return float(closed) / float(count);
}

// Writes one CSV row per black pixel of `view` (mask and thresholds as black_pixels) to `file`.
inline void write_holes(const std::filesystem::path& file, const embree::accel& bvh,
                        const lightmap_atlas& atlas, const image<glm::vec3>& front, const image<glm::vec3>& back,
                        const bounce::camera& cam, const image<glm::vec3>& view, const image<glm::vec3>& reference,
                        const image<float>& mask, int level) {
    const auto lum = [](const glm::vec3& c) { return rec709_luminance<float, glm::vec3>(c); };
    const double mean = reference_mean(reference, mask);
    std::FILE* f = std::fopen(file.string().c_str(), "w");
    if (!f) throw parameter_error("--holes-out", "cannot write " + file.string());
    fmt::print(f, "x,y,triangle,chart,chart_w,chart_h,chart_triangles,sees_back,element,texel_own,"
                  "b_seen,b_other,albedo,closed_seen,closed_other,seen_from_pixel,distance\n");
    for (std::size_t y = 0; y < view.height(); ++y)
        for (std::size_t x = 0; x < view.width(); ++x) {
            if (!black_pixel(view, reference, mask, mean, x, y)) continue;
            embree::ray r;
            r.origin = cam.position;
            r.direction = cam.direction(float(x) + 0.5f, float(y) + 0.5f, view.width(), view.height());
            r.tnear = cam.near_plane;
            r.tfar = cam.far_plane;
            const embree::hit h = bvh.intersect(r);
            if (!h.found()) continue;
            const std::uint32_t c = atlas.chart_of_triangle[h.triangle];
            if (c == lightmap_atlas::none) {
                fmt::print(f, "{},{},{},none\n", x, y, h.triangle);
                continue;
            }
            const lightmap_chart& ch = atlas.charts[c];
            const glm::vec3 p = r.origin + h.t * r.direction;
            const bool sees_back = glm::dot(ch.normal, r.direction) > 0.f;
            const glm::vec2 uv = atlas.atlas_coords(c, p);
            const auto tx = std::uint32_t(std::clamp(uv.x, 0.f, float(atlas.width - 1)));
            const auto ty = std::uint32_t(std::clamp(uv.y, 0.f, float(atlas.height - 1)));
            const std::int32_t e = atlas.element_at(tx, ty);
            if (e < 0) {
                fmt::print(f, "{},{},{},{},{},{},{},{},-1\n", x, y, h.triangle, c, ch.width, ch.height, ch.triangle_count, sees_back);
                continue;
            }
            const auto el = std::size_t(e);
            const bool own = atlas.texel[el] == glm::uvec2(tx, ty);
            const glm::vec3 side = sees_back ? -atlas.normal[el] : atlas.normal[el];
            const float texel = std::sqrt(glm::length(ch.axis_u) * glm::length(ch.axis_v));  // a texel's side
            const float reach = std::min(texel, 1e-3f * bvh.diagonal());  // buried: closed within this
            const glm::vec3 q = atlas.position[el];
            embree::ray s;  // from the pixel's point (off its surface) to the element's point
            s.origin = p - r.direction * bvh.ray_epsilon() * 4.f;
            s.direction = q + side * bvh.ray_epsilon() - s.origin;
            const float d = glm::length(s.direction);
            s.direction /= std::max(d, 1e-12f);
            s.tfar = d;
            const auto& seen = sees_back ? back : front;
            const auto& other = sees_back ? front : back;
            const glm::uvec2 et = atlas.texel[el] * (1u << unsigned(level));  // its first fine texel
            fmt::print(f, "{},{},{},{},{},{},{},{},{},{},{:.4g},{:.4g},{:.3g},{:.3f},{:.3f},{},{:.4g}\n", x, y, h.triangle, c,
                       ch.width, ch.height, ch.triangle_count, sees_back, e, own, lum(seen(et.x, et.y)),
                       lum(other(et.x, et.y)), lum(atlas.albedo[el]), closed_fraction(bvh, q, side, reach),
                       closed_fraction(bvh, q, -side, reach), !bvh.occluded(s), d / texel);
        }
    std::fclose(f);
}

}  // namespace bounce::examples
