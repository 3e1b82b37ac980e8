#pragma once
/// \file cell_overlap.hpp
/// The exact overlap of a triangle with the cells of a grid (lightmap_atlas.hpp's texels,
/// subdivision.hpp's leaves), and the cells whose point lies on a triangle: an element's point
/// is the centroid of its overlap, which for a texel that a non-convex set of triangles covers
/// (a floor's border around a column's base) may lie off them.

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

namespace bounce::detail {

/// Area and area-weighted centroid sum of the triangle (a, b, c) clipped to the unit square
/// [0, 1]^2 (Sutherland-Hodgman against its four sides), in the square's coordinates.
inline void clipped_triangle_moments(const std::array<glm::dvec2, 3>& tri, double& area, glm::dvec2& moment) {
    std::array<glm::dvec2, 9> poly{}, next{};
    int n = 3;
    for (int i = 0; i < 3; ++i) poly[std::size_t(i)] = tri[std::size_t(i)];
    // Keep the side where coordinate `axis` * sign >= bound.
    const auto clip = [&](int axis, double sign, double bound) {
        int m = 0;
        for (int i = 0; i < n; ++i) {
            const glm::dvec2 a = poly[std::size_t(i)], b = poly[std::size_t((i + 1) % n)];
            const double da = sign * a[axis] - bound, db = sign * b[axis] - bound;
            if (da >= 0) next[std::size_t(m++)] = a;
            if ((da >= 0) != (db >= 0)) next[std::size_t(m++)] = a + (b - a) * (da / (da - db));
        }
        n = m;
        poly = next;
    };
    clip(0, 1, 0);
    clip(0, -1, -1);
    clip(1, 1, 0);
    clip(1, -1, -1);
    area = 0;
    moment = glm::dvec2(0);
    for (int i = 0; i + 2 < n; ++i) {
        // Fan from vertex 0; signed areas, the triangle's orientation fixed below.
        const glm::dvec2 a = poly[0], b = poly[std::size_t(i + 1)], c = poly[std::size_t(i + 2)];
        const double s = 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
        area += s;
        moment += s * (a + b + c) / 3.0;
    }
    if (area < 0) {
        area = -area;
        moment = -moment;
    }
}

/// Calls add(cell, area, moment) for each cell of a width x height grid that triangle `q`
/// overlaps (grid coordinates: cell (i, j), index j * width + i, is [i, i + 1] x [j, j + 1]),
/// with the exact overlap's area and first moment, in grid coordinates.
template <class Add>
void for_each_cell_overlap(const std::array<glm::dvec2, 3>& q, std::uint32_t width, std::uint32_t height, Add&& add) {
    const glm::dvec2 mn = glm::min(q[0], glm::min(q[1], q[2])), mx = glm::max(q[0], glm::max(q[1], q[2]));
    const int i0 = std::max(0, int(std::floor(mn.x))), i1 = std::min(int(width) - 1, int(std::floor(mx.x)));
    const int j0 = std::max(0, int(std::floor(mn.y))), j1 = std::min(int(height) - 1, int(std::floor(mx.y)));
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
            std::array<glm::dvec2, 3> local;
            for (int m = 0; m < 3; ++m) local[std::size_t(m)] = q[std::size_t(m)] - glm::dvec2(i, j);
            double a;
            glm::dvec2 mom;
            clipped_triangle_moments(local, a, mom);
            if (a <= 0) continue;
            add(std::size_t(j) * width + std::size_t(i), a, mom + a * glm::dvec2(i, j));
        }
}

/// Whether point p lies on triangle q (its edges included, within 1e-9 of each edge's length).
inline bool point_on_triangle(const std::array<glm::dvec2, 3>& q, glm::dvec2 p) {
    const auto cross = [](glm::dvec2 a, glm::dvec2 b, glm::dvec2 x) { return (b.x - a.x) * (x.y - a.y) - (b.y - a.y) * (x.x - a.x); };
    const double twice_area = cross(q[0], q[1], q[2]);
    if (twice_area == 0) return false;
    // On the inner side of each edge (the triangle's orientation), or within 1e-9 of it.
    bool on = true;
    for (std::size_t k = 0; k < 3; ++k) {
        const glm::dvec2 a = q[k], b = q[(k + 1) % 3];
        on = on && cross(a, b, p) * (twice_area > 0 ? 1 : -1) >= -1e-9 * glm::length(b - a);
    }
    return on;
}

/// Calls on(cell) for each cell of a width x height grid (as for_each_cell_overlap) whose
/// point[cell] lies on triangle `q` (point_on_triangle).
template <class On>
void for_each_point_on_triangle(const std::array<glm::dvec2, 3>& q, std::uint32_t width, std::uint32_t height,
                                std::span<const glm::dvec2> point, On&& on) {
    const glm::dvec2 mn = glm::min(q[0], glm::min(q[1], q[2])), mx = glm::max(q[0], glm::max(q[1], q[2]));
    const int i0 = std::max(0, int(std::floor(mn.x))), i1 = std::min(int(width) - 1, int(std::floor(mx.x)));
    const int j0 = std::max(0, int(std::floor(mn.y))), j1 = std::min(int(height) - 1, int(std::floor(mx.y)));
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
            const std::size_t cell = std::size_t(j) * width + std::size_t(i);
            if (point_on_triangle(q, point[cell])) on(cell);
        }
}

/// Sets inside[cell] for each cell of a width x height grid (as for_each_cell_overlap) whose
/// point[cell] lies on triangle `q` (its edges included, within 1e-9 of a cell).
inline void mark_points_on_triangle(const std::array<glm::dvec2, 3>& q, std::uint32_t width, std::uint32_t height,
                                    std::span<const glm::dvec2> point, std::span<std::uint8_t> inside) {
    for_each_point_on_triangle(q, width, height, point, [&](std::size_t cell) { inside[cell] = 1; });
}

/// The point of triangle `tri` (3D corners) whose projection is p, given the triangle's
/// projection q (any 2D coordinates, p in the same): barycentric coordinates in q, clamped
/// onto the triangle, applied to the corners.
inline glm::dvec3 lift_to_triangle(const std::array<glm::dvec2, 3>& q, const std::array<glm::dvec3, 3>& tri, glm::dvec2 p) {
    const glm::dvec2 e1 = q[1] - q[0], e2 = q[2] - q[0], d = p - q[0];
    const double det = e1.x * e2.y - e1.y * e2.x;
    if (det == 0) return (tri[0] + tri[1] + tri[2]) / 3.0;
    double b1 = (d.x * e2.y - d.y * e2.x) / det, b2 = (e1.x * d.y - e1.y * d.x) / det;
    b1 = std::clamp(b1, 0.0, 1.0);
    b2 = std::clamp(b2, 0.0, 1.0);
    if (b1 + b2 > 1) {
        const double s = b1 + b2;
        b1 /= s;
        b2 /= s;
    }
    return tri[0] + (tri[1] - tri[0]) * b1 + (tri[2] - tri[0]) * b2;
}

}  // namespace bounce::detail
