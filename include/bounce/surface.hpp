#pragma once
/// \file surface.hpp
/// What a G-buffer stores about the first visible surface, as kernels, so that a raster
/// G-buffer (GL) and a ray-cast one (Embree) compute the same numbers the same way.

#include <bounce/concepts.hpp>
#include <bounce/vocabulary.hpp>

namespace bounce {

/// The unit shading normal seen from the eye: `normalize(n)`, negated when the eye lies
/// behind it (dot(n, eye - p) < 0), so that two-sided surfaces light from the visible side.
/// n: interpolated (not necessarily unit) vertex normal; p: surface point; eye: camera
/// position (world units).
template <real T, vec3_of<T> V>
V facing_normal(const V& n, const V& p, const V& eye) {
    const V u = normalize(n);
    return u * select(dot(u, eye - p) < T(0), T(-1), T(1));
}

/// Depth of the surface point p as camera.hpp defines it: the distance from the eye along
/// the unit view axis `forward` (view-space -z), not the distance to the eye.
template <real T, vec3_of<T> V>
T view_depth(const V& p, const V& eye, const V& forward) {
    return dot(p - eye, forward);
}

}  // namespace bounce
