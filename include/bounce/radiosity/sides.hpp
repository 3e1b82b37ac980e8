#pragma once
/// \file radiosity/sides.hpp
/// Two-sided elements (issue 30): published scenes are modelled for renderers whose diffuse
/// surfaces are two-sided (the reference integrator's convention, surface.hpp's
/// facing_normal), so a radiosity solver that lets only the counter-clockwise side receive
/// and shoot leaves walls wound the other way black. cpu::progressive_radiosity keeps a
/// radiosity per side of every element (radiosity_options::two_sided, docs/radiosity.md
/// section 4); this is what it needs from the scene beyond the atlas.

#include <bounce/concepts.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/scene_view.hpp>
#include <bounce/vocabulary.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>

namespace bounce::inline radiosity {

/// The side of a two-sided receiver at `receiver` (its front's unit normal `receiver_normal`)
/// that a source at `source` lights: 1 (its back) when the source lies behind its plane and
/// `two_sided` is 1, else 0 (its front; element_form_factor's clamped cosine then gives 0 for
/// a source behind a one-sided receiver). Both solvers ask it per node of a shot, the GL
/// solver as emitted GLSL.
template <real T, vec3_of<T> V>
T receiving_side(const V& receiver, const V& receiver_normal, const V& source, T two_sided) {
    return select(two_sided > T(0.5) && dot(receiver_normal, source - receiver) < T(0), T(1), T(0));
}

/// The unit normal of side `side` (0 the front, 1 the back) of an element whose front's is `normal`.
template <real T, vec3_of<T> V>
V side_normal(const V& normal, T side) {
    return select(side > T(0.5), -normal, normal);
}

/// Per chart of `atlas` (built from `scene`), 1 when its emission leaves from its back: the
/// side the reference integrator emits from is a triangle's winding normal turned to its
/// vertex normals' side when the scene has normals (embree::multi_bounce_reference), so a
/// chart emits from its back when its triangles' vertex normals, summed, point behind it.
/// What a two-sided solver needs to emit on the reference's side.
inline std::vector<std::uint8_t> emission_sides(const scene_view& scene, const lightmap_atlas& atlas) {
    std::vector<std::uint8_t> back(atlas.charts.size(), 0);
    if (scene.normals.empty()) return back;
    for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
        const lightmap_chart& ch = atlas.charts[c];
        double facing = 0;
        for (std::uint32_t k = 0; k < ch.triangle_count; ++k) {
            const glm::uvec3 t = scene.triangles[atlas.chart_triangles[ch.first_triangle + k]];
            facing += double(glm::dot(scene.normals[t.x] + scene.normals[t.y] + scene.normals[t.z], ch.normal));
        }
        back[c] = facing < 0 ? 1 : 0;
    }
    return back;
}

}  // namespace bounce::radiosity
