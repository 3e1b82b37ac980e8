#pragma once
/// \file cache/plane_pixel.hpp
/// Kernels of one pixel of the hemisphere plane camera (Gautron 2008, section 8.4;
/// cache/plane_camera.hpp states the plane's conventions): its edges, its centre direction, the
/// hit distance it stores, and its terms of a record's irradiance, gradients and harmonic
/// mean distance. Instantiated on the CPU (cpu::estimate_plane) and emitted as GLSL (the
/// GL adapter's reduction), so both sums add the same terms.

#include <bounce/concepts.hpp>
#include <bounce/vocabulary.hpp>

#include <array>
#include <tuple>

namespace bounce::inline cache {

/// Left, bottom, right, top edges (x0, y0, x1, y1) of pixel (i, j) of an n x n plane of
/// half-extent a = tan(aperture / 2), on the plane z = 1 (see cache/plane_camera.hpp: column i
/// along +x, row j from the top). i, j, n are passed as reals so that GLSL can call it.
template <real T>
std::array<T, 4> plane_pixel_bounds(T i, T j, T n, T a) {
    const T step = T(2) * a / n;
    return {step * i - a, a - step * (j + T(1)), step * (i + T(1)) - a, a - step * j};
}

/// Unit local direction (z along the record's normal) through the centre of pixel (i, j)
/// of an n x n plane of half-extent a.
template <real T, vec3_of<T> V>
V plane_pixel_direction(T i, T j, T n, T a) {
    const T step = T(2) * a / n;
    return normalize(V(step * (i + T(0.5)) - a, a - step * (j + T(0.5)), T(1)));
}

/// Hit distance a plane pixel stores: |p - eye| from the record's (offset) position `eye` to
/// the surface point `p` (world units), the r of the translation gradient's walls and of
/// the harmonic mean distance. At least 1e-30: a surface through the eye (a record in a
/// corner) can round to distance 0 in float, and distances must stay positive.
template <real T, vec3_of<T> V>
T plane_hit_distance(const V& p, const V& eye) {
    return max(length(p - eye), T(1e-30));
}

/// The contributions of one plane pixel to a record; summed over the plane they give
/// irradiance, gradients and harmonic mean distance (cpu::estimate_plane shows the sums).
/// Weights, from a plane_weights table:
///  - `w`: the cosine-weighted solid angle (sr) the pixel's radiance stands for;
///  - `wd`: the same for its hit distance (differs from w only for fall-off stretching,
///    whose band carries attenuated radiance but the border pixel's full distance);
///  - `rot`: int (n x omega) d omega over what the pixel stands for (x, y; sr);
///  - `left`, `up`: translation weights of its walls with the pixels to its left (i - 1)
///    and above (j - 1), tangent-plane vectors (sr-like, per unit of 1 / distance);
///  - `edge`: translation weight of the wall between a border pixel and its own band, for
///    the radiance step (band - border) = -L * edge-scale; 0 inside the plane.
/// Samples: the pixel's radiance L and hit distance r (+infinity for an escaped ray), and
/// those of its left and upper neighbours (any value where the wall weight is 0).
/// Outputs: w L, rot.x L, rot.y L, translation along x and along y, wd / r, wd.
/// A wall moves with the nearer of its two surfaces (Ward and Heckbert 1992; Krivanek et
/// al. 2005), so a radiance step is divided by the smaller distance; escaped rays give 0.
template <real T, vec3_of<T> V, vec2_of<T> V2>
std::tuple<V, V, V, V, V, T, T> plane_pixel_terms(T w, T wd, V2 rot, V2 left, V2 up, V2 edge, V L, V L_left, V L_up,
                                                  T r, T r_left, T r_up) {
    const T far = T(3.0e38);  // beyond any hit distance: an escaped ray (float max ~3.4e38)
    const T near_left = min(r, r_left), near_up = min(r, r_up);
    const T inv_left = select(near_left < far, T(1) / max(near_left, T(1e-30)), T(0));
    const T inv_up = select(near_up < far, T(1) / max(near_up, T(1e-30)), T(0));
    const T inv_r = select(r < far, T(1) / max(r, T(1e-30)), T(0));
    const V d_left = (L - L_left) * inv_left, d_up = (L - L_up) * inv_up, d_self = L * inv_r;
    return {L * w,
            L * rot.x,
            L * rot.y,
            d_left * left.x + d_up * up.x + d_self * edge.x,
            d_left * left.y + d_up * up.y + d_self * edge.y,
            wd * inv_r,
            wd};
}

}  // namespace bounce::cache
