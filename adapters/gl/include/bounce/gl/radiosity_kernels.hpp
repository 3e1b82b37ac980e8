#pragma once
/// \file radiosity_kernels.hpp
/// The per-texel decisions of the GL progressive radiosity passes (gl::progressive_radiosity),
/// written once in the kernel vocabulary and emitted as GLSL: the depth an item-buffer pixel
/// stores, the item-buffer lookup rule for concave corners, and the near-field test of a
/// block shooter. They restate, for the GPU, the rules cpu::item_buffer_visibility and
/// cpu::progressive_radiosity apply (docs/radiosity.md, sections 3 and 4), with the same
/// constants, so that both backends answer alike; tests/gl_radiosity checks that they do.
/// (They belong beside radiosity.hpp in the core once the CPU adapter calls them too.)

#include <bounce/concepts.hpp>
#include <bounce/vocabulary.hpp>

namespace bounce::gl {

/// Depth (scene units) an item-buffer pixel stores for a surface: the distance from the
/// shooter along the pixel centre's unit direction `w` (shooter frame) to the surface's
/// plane n . x = d (shooter frame, d >= 0), exact at the pixel centre; where the plane is seen
/// edge-on (n . w <= 1e-6) the radial distance `interpolated` across the drawn piece instead.
/// The same rule as cpu::item_buffer_visibility's stereographic raster.
template <real T, vec3_of<T> V>
T item_plane_depth(const V& plane_normal, T plane_offset, const V& w, T interpolated) {
    const T nw = dot(plane_normal, w);
    const auto facing = nw > T(1e-6);
    return select(facing, plane_offset / select(facing, nw, T(1)), interpolated);
}

/// Whether an element is seen through its item-buffer pixel (1) or hidden (0): the pixel
/// shows the element's own chart or nothing (`shown_chart` < 0), or the surface it shows,
/// taken as its plane n . x = d (shooter frame, unit n, d >= 0: `plane_normal`,
/// `plane_offset`) and met along the element's own ray from the shooter, lies beyond the
/// element less a slack of 1e-4 of the distance plus 1e-6 of the scene's `diagonal`; where
/// that plane is seen edge-on from the element's direction, the pixel's stored depth
/// `shown_depth` is compared instead. The id test alone (Coombe and Harris 2005, Listing 39-3)
/// darkens a row of elements along every concave corner, where the pixel's centre falls on the
/// neighbouring wall at the same depth; this is cpu::item_buffer_visibility's rule
/// (docs/radiosity.md section 3). `element`: the element's position in the shooter's frame.
template <real T, vec3_of<T> V>
T item_buffer_sees(const V& element, T element_chart, T shown_chart, const V& plane_normal, T plane_offset,
                   T shown_depth, T diagonal) {
    const T dist = length(element);
    const T nw = dot(plane_normal, element) / dist;
    const T slack = T(1e-4) * dist + T(1e-6) * diagonal;
    const auto edge_on = nw <= T(1e-6);
    const T met = plane_offset / select(edge_on, T(1), nw);
    const auto beyond = (edge_on && shown_depth >= dist - slack) || (!edge_on && met >= dist - slack);
    const auto own = shown_chart == element_chart || shown_chart < T(0);
    return select(own || beyond, T(1), T(0));
}

/// item_buffer_sees for a directional light's orthographic buffer (rays along the unit
/// `direction` the light travels): the element at world position `element` is seen when its
/// pixel shows its chart or nothing, or when the shown surface's plane (world: unit
/// `plane_normal`, n . x = `plane_offset`) is met downstream of the element along the light
/// (less 1e-6 of the scene's `diagonal`); for a plane parallel to the light, when the
/// pixel's stored depth along the light `shown_depth` is not upstream of the element's.
/// cpu::item_buffer_visibility's rule for parallel shots.
template <real T, vec3_of<T> V>
T parallel_item_sees(const V& element, T element_chart, T shown_chart, const V& plane_normal, T plane_offset,
                     T shown_depth, const V& direction, T diagonal) {
    const T nd = dot(plane_normal, direction);
    const auto parallel = abs(nd) <= T(1e-6);
    const T s = (plane_offset - dot(plane_normal, element)) / select(parallel, T(1), nd);
    const T slack = T(1e-6) * diagonal;
    const auto beyond = (parallel && shown_depth >= dot(element, direction) - slack) || (!parallel && s >= -slack);
    const auto own = shown_chart == element_chart || shown_chart < T(0);
    return select(own || beyond, T(1), T(0));
}

/// Whether a receiver at `receiver` sees a node of a block shooter's quadtree (centre
/// `node_position`, area `node_area`) as its children rather than as one disc: it lies within
/// sqrt(`near2`) node sides of the node (cpu::progressive_radiosity's near field, a
/// substructuring refinement of Cohen et al. 1986; near2 = near_field^2).
template <real T, vec3_of<T> V>
T near_field_opens(const V& receiver, const V& node_position, T node_area, T near2) {
    const V r = node_position - receiver;
    return select(dot(r, r) < near2 * node_area, T(1), T(0));
}

}  // namespace bounce::gl
