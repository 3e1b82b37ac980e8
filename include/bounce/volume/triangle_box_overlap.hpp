#pragma once
/// \file volume/triangle_box_overlap.hpp
/// Exact triangle / axis-aligned box overlap by the separating axis theorem
/// (Akenine-Moller, "Fast 3D Triangle-Box Overlap Testing", journal of graphics tools 6(1),
/// 2001): a triangle and a box are disjoint iff their projections onto one of 13 axes are
/// disjoint: the box's 3 face normals, the triangle's normal, and the 9 cross products of
/// the triangle's edges with the box's axes. Closed sets: touching counts as overlap.
/// Degenerate triangles (a segment or a point) are handled by the same test: an axis that
/// is a zero vector separates nothing, and the remaining axes are exactly the separating
/// axes of a segment (box normals and edge x box axes) or a point (box normals).
/// Irradiance volumes use it to find the cells that hold geometry.

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>

namespace bounce::inline volume {

/// Whether the triangle (v0, v1, v2) and the closed box with centre `centre` and half
/// extents `half` (all >= 0) share a point. Computed in double; coordinates are relative to
/// the box centre, so the decision is exact whenever the products involved are (e.g. small
/// integer or dyadic coordinates), and otherwise wrong only within rounding of a touch.
inline bool triangle_box_overlap(const glm::dvec3& centre, const glm::dvec3& half, const glm::dvec3& a,
                                 const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 v[3] = {a - centre, b - centre, c - centre};
    // Box face normals: the triangle's bounding box against the box.
    for (int k = 0; k < 3; ++k) {
        const double lo = std::min({v[0][k], v[1][k], v[2][k]}), hi = std::max({v[0][k], v[1][k], v[2][k]});
        if (lo > half[k] || hi < -half[k]) return false;
    }
    const glm::dvec3 e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
    // The 9 axes e_i x u_k (u_k the box's k-th axis).
    for (const auto& edge : e) {
        for (int k = 0; k < 3; ++k) {
            glm::dvec3 axis(0.0);
            // e x u_k
            const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
            axis[k1] = edge[k2];
            axis[k2] = -edge[k1];
            const double p0 = glm::dot(axis, v[0]), p1 = glm::dot(axis, v[1]), p2 = glm::dot(axis, v[2]);
            const double r = half[k1] * std::abs(axis[k1]) + half[k2] * std::abs(axis[k2]);
            if (std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r) return false;
        }
    }
    // The triangle's plane n . x = n . v0 against the box.
    const glm::dvec3 n = glm::dvec3(e[0].y * e[1].z - e[0].z * e[1].y, e[0].z * e[1].x - e[0].x * e[1].z,
                                    e[0].x * e[1].y - e[0].y * e[1].x);
    const double d = n.x * v[0].x + n.y * v[0].y + n.z * v[0].z;
    const double r = half.x * std::abs(n.x) + half.y * std::abs(n.y) + half.z * std::abs(n.z);
    return std::abs(d) <= r;
}

}  // namespace bounce::volume
