#pragma once
/// \file radiosity_object_visibility.hpp
/// The visibility of one moved object alone, before and after a rigid move, for the exact
/// differential re-bake (cpu::rebake_move with an object visibility; radiosity/rebake.hpp):
/// the whole scene's rays (radiosity_visibility: the same origins, ends and offsets, the
/// whole scene's ray_epsilon) through a BVH of the object's triangles only, at their place
/// before and after the move. Between two unmoved elements the whole scene blocks a ray when
/// the static triangles or the object do, each triangle tested alone (Embree's per-triangle
/// test depends on the ray and the triangle only), so a pair whose ray the object blocks in
/// both places or in neither sees the same visibility before and after the move.

#include <bounce/embree/radiosity_visibility.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <span>

namespace bounce::embree {

/// The object's visibility where it was (`before`) and where it is (`after`).
struct radiosity_object_visibility {
    radiosity_visibility before, after;
};

/// The triangles `moved` (indices into both scenes) of `before_scene` and `after_scene` (the
/// scene before and after the move), each alone in a BVH on `whole_before`'s device, cast
/// with the options and ray offsets of `whole_before` and `whole_after` (the solver's
/// visibilities of the two scenes); `chart_of_triangle` as theirs (per scene triangle).
/// Throws parameter_error ("moved_triangles": empty or out of range; "chart_of_triangle",
/// "after_scene": sizes that differ) and embree_error when Embree fails.
radiosity_object_visibility object_visibility(const scene_view& before_scene, const radiosity_visibility& whole_before,
                                              const scene_view& after_scene, const radiosity_visibility& whole_after,
                                              std::span<const std::uint32_t> moved,
                                              std::span<const std::uint32_t> chart_of_triangle);

}  // namespace bounce::embree
