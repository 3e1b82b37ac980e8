#pragma once
// Brute-force ray casting against every triangle, in double: the exact answer the item
// buffers are measured against (O(triangles) per query; for hand-built scenes only).
#include "radiosity_scenes.hpp"

#include <bounce/cpu/radiosity_item_buffer.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>

#include <limits>
#include <optional>

namespace bounce::radiosity_test {

// Distance along the unit direction d from o to triangle (a, b, c), either side
// (Moller and Trumbore 1997); none when missed.
inline std::optional<double> ray_triangle(glm::dvec3 o, glm::dvec3 d, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-300) return std::nullopt;
    const double inv = 1.0 / det;
    const glm::dvec3 s = o - a;
    const double u = glm::dot(s, p) * inv;
    if (u < 0 || u > 1) return std::nullopt;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(d, q) * inv;
    if (v < 0 || u + v > 1) return std::nullopt;
    const double t = glm::dot(e2, q) * inv;
    if (t <= 0) return std::nullopt;
    return t;
}

// The nearest chart along a ray, leaving out chart `skip` and hits nearer than `t_min`.
inline std::pair<std::uint32_t, double> nearest_chart(const owned_scene& s, const lightmap_atlas& atlas, glm::dvec3 o,
                                                      glm::dvec3 d, std::uint32_t skip, double t_min = 0) {
    std::pair<std::uint32_t, double> best{lightmap_atlas::none, std::numeric_limits<double>::infinity()};
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        const std::uint32_t c = atlas.chart_of_triangle[t];
        if (c == lightmap_atlas::none || c == skip) continue;
        const auto& tri = s.triangles[t];
        const auto hit = ray_triangle(o, d, glm::dvec3(s.positions[tri.x]), glm::dvec3(s.positions[tri.y]),
                                      glm::dvec3(s.positions[tri.z]));
        if (hit && *hit > t_min && *hit < best.second) best = {c, *hit};
    }
    return best;
}

// Exact visibility (models cpu::shot_visibility): the segment from the shooter to the point
// crosses no triangle of another chart than the point's and the shooter's, short of the
// point by more than 1e-6 of its distance.
struct ray_cast_visibility {
    const owned_scene* scene;
    const lightmap_atlas* atlas;
    cpu::shot_frame shot{};

    void begin_shot(const cpu::shot_frame& s) { shot = s; }
    float visible(const glm::vec3& position, std::uint32_t own) const {
        const glm::dvec3 p(position);
        glm::dvec3 o(shot.position), d;
        double dist;
        if (shot.parallel) {
            d = glm::normalize(glm::dvec3(shot.axis));
            o = p - d * 1e3;
            dist = 1e3;
        } else {
            d = p - o;
            dist = glm::length(d);
            d /= dist;
        }
        return segment_clear(o, d, dist, shot.chart, own);
    }
    // From any point (grouped shooters): the same test with `origin` on chart `origin_chart`.
    float visible_from(const glm::vec3& origin, std::uint32_t origin_chart, const glm::vec3& position,
                       std::uint32_t own) const {
        const glm::dvec3 o(origin);
        glm::dvec3 d = glm::dvec3(position) - o;
        const double dist = glm::length(d);
        return dist > 0 ? segment_clear(o, d / dist, dist, origin_chart, own) : 1.f;
    }
    float segment_clear(const glm::dvec3& o, const glm::dvec3& d, double dist, std::uint32_t from, std::uint32_t own) const {
        for (std::size_t t = 0; t < scene->triangles.size(); ++t) {
            const std::uint32_t c = atlas->chart_of_triangle[t];
            if (c == lightmap_atlas::none || c == own || c == from) continue;
            const auto& tri = scene->triangles[t];
            const auto hit = ray_triangle(o, d, glm::dvec3(scene->positions[tri.x]), glm::dvec3(scene->positions[tri.y]),
                                          glm::dvec3(scene->positions[tri.z]));
            if (hit && *hit < dist * (1 - 1e-6)) return 0.f;
        }
        return 1.f;
    }
};

}  // namespace bounce::radiosity_test
