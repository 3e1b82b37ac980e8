#pragma once
// Where the view's black pixels come from (issue 30, "no holes"): for each pixel black where
// the reference is lit (report.hpp's black_pixels), the triangle and chart the view's ray
// meets, the side it sees, the element the lookup's nearest texel reads, and whether that
// element's point is buried (its hemisphere on the seen side closed within a texel's side or
// 1/1000 of the scene's diagonal, the smaller) or seen
// from the pixel's own surface point; and one bounce gathered there from the solved lightmaps
// (gathered_b: rho times the irradiance the element's hemisphere sees in them; open_share: its
// rays that leave the scene), so that an element the shots missed (gathered_b well above its
// own B) tells itself apart from one that sees nothing lit. Written as CSV by --holes-out.

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
#include <utility>
#include <vector>

namespace bounce::examples {

// Fraction of 64 directions over the hemisphere of `n` from `p` that meet a surface within `reach`.
// Two unit tangents (t, b) across the unit normal `n`.
inline std::pair<glm::vec3, glm::vec3> tangents(const glm::vec3& n) {
    const glm::vec3 t = glm::normalize(std::abs(n.x) > 0.5f ? glm::cross(n, glm::vec3(0, 1, 0)) : glm::cross(n, glm::vec3(1, 0, 0)));
    return {t, glm::cross(n, t)};
}

inline float closed_fraction(const embree::accel& bvh, const glm::vec3& p, const glm::vec3& n, float reach) {
    const auto [t, b] = tangents(n);
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

// One bounce gathered from the solved lightmaps at the element's point `q` on the side `n`: the
// mean luminance of B (front or back image, by the side each ray meets) over 256
// cosine-distributed rays, which is the irradiance there; and the share of rays leaving the
// scene. Where it is large and the element's own B small, the shots missed the element.
struct gathered_light {
    float irradiance = 0, open = 0;
};
inline gathered_light gather_from_lightmaps(const embree::accel& bvh, const lightmap_atlas& atlas, const image<glm::vec3>& front,
                                            const image<glm::vec3>& back, int level, const glm::vec3& q, const glm::vec3& n) {
    const auto [t, b] = tangents(n);
    constexpr int count = 256;
    double sum = 0;
    int open = 0;
    for (int k = 0; k < count; ++k) {  // cosine-distributed: a Fibonacci spiral over the disc, lifted
        const float r2 = (float(k) + 0.5f) / float(count), r = std::sqrt(r2), phi = float(k) * 2.39996323f;
        embree::ray ray;
        ray.origin = q + n * bvh.ray_epsilon() * 4.f;
        ray.direction = r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(1.f - r2) * n;
        const embree::hit h = bvh.intersect(ray);
        if (!h.found()) {
            ++open;
            continue;
        }
        const std::uint32_t c = atlas.chart_of_triangle[h.triangle];
        if (c == lightmap_atlas::none) continue;
        const glm::vec2 uv = atlas.atlas_coords(c, ray.origin + h.t * ray.direction);
        const auto tx = std::uint32_t(std::clamp(uv.x, 0.f, float(atlas.width - 1)));
        const auto ty = std::uint32_t(std::clamp(uv.y, 0.f, float(atlas.height - 1)));
        const std::int32_t e = atlas.element_at(tx, ty);
        if (e < 0) continue;
        const glm::uvec2 et = atlas.texel[std::size_t(e)] * (1u << unsigned(level));
        const bool hit_back = glm::dot(atlas.charts[c].normal, ray.direction) > 0.f;
        sum += rec709_luminance<float, glm::vec3>((hit_back ? back : front)(et.x, et.y));
    }
    return {float(sum / count), float(open) / float(count)};
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
                  "b_seen,b_other,albedo,closed_seen,closed_other,seen_from_pixel,distance,gathered_b,open_share,px,py,pz,ex,ey,ez,nx,ny,nz\n");
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
            const gathered_light g = gather_from_lightmaps(bvh, atlas, front, back, level, q, side);
            fmt::print(f, "{},{},{},{},{},{},{},{},{},{},{:.4g},{:.4g},{:.3g},{:.3f},{:.3f},{},{:.4g},{:.4g},{:.3f},", x, y,
                       h.triangle, c, ch.width, ch.height, ch.triangle_count, sees_back, e, own, lum(seen(et.x, et.y)),
                       lum(other(et.x, et.y)), lum(atlas.albedo[el]), closed_fraction(bvh, q, side, reach),
                       closed_fraction(bvh, q, -side, reach), !bvh.occluded(s), d / texel,
                       lum(atlas.albedo[el]) * g.irradiance, g.open);
            fmt::print(f, "{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.3f},{:.3f},{:.3f}\n", p.x, p.y, p.z, q.x, q.y, q.z, side.x,
                       side.y, side.z);
        }
    std::fclose(f);
}

}  // namespace bounce::examples
