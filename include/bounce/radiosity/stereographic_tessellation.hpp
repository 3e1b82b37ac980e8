#pragma once
/// \file radiosity/stereographic_tessellation.hpp
/// The geometry that prepares triangles for an item buffer in the stereographic projection
/// (Coombe and Harris 2005, section 39.2.1), shared by cpu::item_buffer_visibility and
/// gl::progressive_radiosity so that both draw the same pieces, bit for bit:
///  - clip_polygon: a convex polygon clipped to a half-space, each cut edge's intersection
///    computed from its endpoints in a canonical order (a shared edge clips alike from both of
///    its triangles);
///  - tessellate_stereographic: the sagitta rule. The projection bends straight edges into
///    arcs (Figure 39-5), so a triangle is split in four at its edges' midpoints, recursively,
///    until the sagitta of each edge (distance, in pixels, between the projected midpoint of an
///    edge and the midpoint of its projected chord) is at most the tolerance, or the depth cap
///    is reached (halving an edge quarters its sagitta);
///  - clip_and_tessellate_stereographic: a triangle in the shooter's frame clipped just above
///    the shooter's plane (z >= z_min), fanned, and each fan triangle tessellated;
///  - item_buffer_triangles: the triangles every item buffer draws (those with a chart) with
///    the world planes its lookups test, for the stereographic buffer, the hemicube and a
///    directional light's buffer alike.
/// Pure geometry on GLM floats: no threads, no I/O.

#include <bounce/radiosity/kernels.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/scene_view.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce::inline radiosity {

/// Whether b comes before a in the canonical (lexicographic x, y, z) order of points.
inline bool canonical_swap(glm::vec3 a, glm::vec3 b) noexcept {
    return b.x < a.x || (b.x == a.x && (b.y < a.y || (b.y == a.y && b.z < a.z)));
}

/// A convex polygon of points in some 3D frame, clipped in place to dot(p, plane) >= offset.
/// Intersection points are computed from the edge's endpoints in a canonical order, so the
/// same edge clipped from its two triangles gives the same point bit for bit.
inline void clip_polygon(std::vector<glm::vec3>& poly, glm::vec3 plane, float offset, std::vector<glm::vec3>& scratch) {
    scratch.clear();
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i) {
        const glm::vec3 a = poly[i], b = poly[(i + 1) % n];
        const float da = glm::dot(a, plane) - offset, db = glm::dot(b, plane) - offset;
        if (da >= 0.f) scratch.push_back(a);
        if ((da >= 0.f) != (db >= 0.f)) {
            const bool swap = canonical_swap(a, b);
            const glm::vec3 p = swap ? b : a, q = swap ? a : b;
            const float dp = swap ? db : da, dq = swap ? da : db;
            scratch.push_back(p + (q - p) * (dp / (dp - dq)));
        }
    }
    poly.swap(scratch);
}

/// The point t of the way from a to b, with a and b taken in a canonical order so that a
/// shared edge gives the same points from both of its triangles.
inline glm::vec3 canonical_lerp(glm::vec3 a, glm::vec3 b, float t) noexcept {
    if (t == 0.f) return a;  // the endpoints exactly, which a + (b - a) 1 need not give
    if (t == 1.f) return b;
    return canonical_swap(a, b) ? b + (a - b) * (1.f - t) : a + (b - a) * t;
}

/// How finely tessellate_stereographic splits.
struct stereographic_tessellation {
    float resolution = 256.f;  ///< item buffer side, pixels
    float tolerance_px = 0.25f;  ///< largest sagitta of an edge, pixels
    int max_depth = 10;        ///< cap on the halvings of one triangle's edges (4^depth pieces at most)
};

/// Calls emit(points, pixels) for each piece of the triangle (a, b, c) (shooter frame, z > 0)
/// that the sagitta rule leaves (see the file comment), depth first, children in the order
/// (a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca); `points` are the piece's corners in
/// the shooter's frame, `pixels` their projections (stereographic_item_coords times the
/// resolution).
template <class Emit>
void tessellate_stereographic(glm::vec3 a, glm::vec3 b, glm::vec3 c, const stereographic_tessellation& how,
                              const Emit& emit, int depth = 0) {
    const auto pixel = [&](glm::vec3 l) {
        return stereographic_item_coords<float, glm::vec3, glm::vec2>(l) * how.resolution;
    };
    const glm::vec2 pa = pixel(a), pb = pixel(b), pc = pixel(c);
    const glm::vec3 ab = canonical_lerp(a, b, 0.5f), bc = canonical_lerp(b, c, 0.5f), ca = canonical_lerp(c, a, 0.5f);
    const float s = std::max({glm::length(pixel(ab) - 0.5f * (pa + pb)), glm::length(pixel(bc) - 0.5f * (pb + pc)),
                              glm::length(pixel(ca) - 0.5f * (pc + pa))});
    if (!(s > how.tolerance_px) || depth >= how.max_depth) {
        emit(std::array<glm::vec3, 3>{a, b, c}, std::array<glm::vec2, 3>{pa, pb, pc});
        return;
    }
    tessellate_stereographic(a, ab, ca, how, emit, depth + 1);
    tessellate_stereographic(ab, b, bc, how, emit, depth + 1);
    tessellate_stereographic(ca, bc, c, how, emit, depth + 1);
    tessellate_stereographic(ab, bc, ca, how, emit, depth + 1);
}

/// The triangle `local` (shooter frame) clipped to z >= z_min (just above the shooter's
/// plane: a surface through the shooter's centre sees it edge-on and neither occludes nor is
/// seen), fanned from its first corner, each fan triangle given to tessellate_stereographic.
/// Nothing is emitted for a triangle wholly below z_min. `poly` and `scratch` are the caller's
/// buffers, reused between calls.
template <class Emit>
void clip_and_tessellate_stereographic(const std::array<glm::vec3, 3>& local, float z_min,
                                       const stereographic_tessellation& how, std::vector<glm::vec3>& poly,
                                       std::vector<glm::vec3>& scratch, const Emit& emit) {
    if (local[0].z < z_min && local[1].z < z_min && local[2].z < z_min) return;
    poly.assign(local.begin(), local.end());
    clip_polygon(poly, glm::vec3(0, 0, 1), z_min, scratch);
    for (std::size_t f = 1; f + 1 < poly.size(); ++f) tessellate_stereographic(poly[0], poly[f], poly[f + 1], how, emit);
}

/// The scene's triangles that have a chart in `atlas`, in scene order: their corners, chart,
/// and world plane (unit normal n, n . corner), the plane computed in double from the corners.
struct item_triangles {
    std::vector<std::array<glm::vec3, 3>> corners;
    std::vector<std::uint32_t> chart;
    std::vector<glm::vec4> world_plane;
};
inline item_triangles item_buffer_triangles(const scene_view& scene, const lightmap_atlas& atlas) {
    item_triangles out;
    for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
        if (atlas.chart_of_triangle[t] == lightmap_atlas::none) continue;
        const auto& tri = scene.triangles[t];
        out.corners.push_back({scene.positions[tri.x], scene.positions[tri.y], scene.positions[tri.z]});
        out.chart.push_back(atlas.chart_of_triangle[t]);
        const glm::dvec3 a(out.corners.back()[0]), b(out.corners.back()[1]), c(out.corners.back()[2]);
        const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
        out.world_plane.emplace_back(glm::vec3(n), float(glm::dot(n, a)));
    }
    return out;
}

}  // namespace bounce::radiosity
