#pragma once
/// \file volume/visibility_kernels.hpp
/// The per-point math of visibility-aware probes (DDGI: Majercik et al., "Dynamic Diffuse
/// Global Illumination with Ray-Traced Irradiance Fields", JCGT 8(2) 2019; the self-shadow
/// bias of Majercik et al., "Scaling Probe-Based Real-Time Dynamic Global Illumination for
/// Production", JCGT 10(2) 2021), written once as kernels: the CPU lookup
/// (volume/probe_visibility.hpp) instantiates them with float and glm::vec3, the GL lookup
/// prints them as GLSL (gl/irradiance_volume.hpp).
///
/// Each probe keeps, over directions, the mean and the mean square of the distance to the
/// first hit in a small octahedral map (Cigolle et al., "A Survey of Efficient
/// Representations for Independent Unit Vectors", JCGT 3(2) 2014). A lookup weighs each
/// of the 8 corner probes of the cell by a Chebyshev test of the shading point's distance
/// from the probe against those moments (a surface between them makes the point farther
/// than the mean), by the angle between the direction to the probe and the surface normal,
/// and by its trilinear weight, and renormalizes.

#include <bounce/concepts.hpp>
#include <bounce/vocabulary.hpp>

#include <array>
#include <utility>

namespace bounce::inline volume {

/// Octahedral coordinates (u, v) in [-1, 1]^2 of the unit direction `d` (Cigolle et al.
/// 2014): the upper hemisphere (z >= 0) maps to the diamond |u| + |v| <= 1, the lower one
/// is folded over its edges into the corners; +z is (0, 0), -z the four corners (+-1, +-1)
/// (returned as (1, 1) when x = y = 0). A zero vector gives (0, 0).
template <real T, vec3_of<T> V>
std::pair<T, T> octahedral_encode(const V& d) {
    const T l1 = max(abs(d.x) + abs(d.y) + abs(d.z), T(1e-30));
    const T px = d.x / l1, py = d.y / l1;
    const T sx = select(px >= T(0), T(1), T(-1)), sy = select(py >= T(0), T(1), T(-1));
    const auto lower = d.z < T(0);
    return {select(lower, (T(1) - abs(py)) * sx, px), select(lower, (T(1) - abs(px)) * sy, py)};
}

/// The unit direction of octahedral coordinates (u, v) in [-1, 1]^2 (octahedral_encode's
/// inverse).
template <real T, vec3_of<T> V>
V octahedral_decode(const T& u, const T& v) {
    const T z = T(1) - abs(u) - abs(v);
    const T sx = select(u >= T(0), T(1), T(-1)), sy = select(v >= T(0), T(1), T(-1));
    const auto lower = z < T(0);
    return normalize(V(select(lower, (T(1) - abs(v)) * sx, u), select(lower, (T(1) - abs(u)) * sy, v), z));
}

/// Where a bilinear read of an N x N octahedral map at (u, v) falls: {x0, y0, fx, fy},
/// texel (x0, y0) and its +x, +y neighbours blended with fractions (fx, fy); texel (i, j)
/// has its centre at u = 2 (i + 0.5) / N - 1. x0 and y0 lie in -1 .. N - 1: the read wraps
/// through octahedral_texel_index.
template <real T>
std::array<T, 4> octahedral_bilinear(const T& u, const T& v, const T& n) {
    const T x = (u * T(0.5) + T(0.5)) * n - T(0.5), y = (v * T(0.5) + T(0.5)) * n - T(0.5);
    const T x0 = floor(x), y0 = floor(y);
    return {x0, y0, x - x0, y - y0};
}

/// The index y * N + x of texel (x, y) of an N x N octahedral map, x and y in -1 .. N,
/// with a texel beyond an edge read from its mirror image inside (the map's edges meet
/// their own reversal on the sphere: column -1, row j is column 0, row N - 1 - j; a corner
/// beyond both edges is the opposite corner). Returned as a number, as octree_octant.
template <real T>
T octahedral_texel_index(const T& x, const T& y, const T& n) {
    const T last = n - T(1);
    const auto off_x = x < T(0) || x > last;
    const T x1 = select(off_x, clamp(x, T(0), last), x), y1 = select(off_x, last - y, y);
    const auto off_y = y1 < T(0) || y1 > last;
    const T x2 = select(off_y, last - x1, x1), y2 = select(off_y, clamp(y1, T(0), last), y1);
    return y2 * n + x2;
}

/// The bilinear blend of four texels' moments (mean, mean square) at fractions (fx, fy):
/// texels (x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1) in that order.
template <real T>
std::pair<T, T> bilinear_moments(const std::array<T, 4>& mean, const std::array<T, 4>& mean_square, const T& fx,
                                 const T& fy) {
    const T m = mix(mix(mean[0], mean[1], fx), mix(mean[2], mean[3], fx), fy);
    const T m2 = mix(mix(mean_square[0], mean_square[1], fx), mix(mean_square[2], mean_square[3], fx), fy);
    return {m, m2};
}

/// Chebyshev's one-sided bound on the chance that a point at `distance` from the probe
/// is seen from it, given the mean and mean square of the first-hit distance in its
/// direction (Majercik et al. 2019, after variance shadow maps): 1 when distance <= mean,
/// else (var / (var + (distance - mean)^2))^3 with var = |mean^2 - mean_square| (cubed, as
/// the paper's code, to darken faster behind a surface). In [0, 1]; finite at distance 0.
template <real T>
T chebyshev_visibility(const T& distance, const T& mean, const T& mean_square) {
    const T variance = abs(mean * mean - mean_square);
    const T e = max(distance - mean, T(0));
    const T p = variance / max(variance + e * e, T(1e-30));
    return select(distance > mean, p * p * p, T(1));
}

/// The self-shadow bias of Majercik et al. 2021 (section 4.1): the point the visibility
/// test uses, p moved along its unit normal `n` and its unit direction to the viewer `view`
/// by (0.2 n + 0.8 view) * 0.75 * spacing * bias, `spacing` the probe spacing (the cell's
/// shortest edge), `bias` the self-shadow bias (typical 0.3). The point stays on the
/// viewer's side of its surface, so that the surface itself does not shadow it.
template <real T, vec3_of<T> V>
V self_shadow_biased(const V& p, const V& n, const V& view, const T& spacing, const T& bias) {
    return p + (n * T(0.2) + view * T(0.8)) * (T(0.75) * spacing * bias);
}

/// The unit direction from p to the eye, or n where they coincide (no view direction).
template <real T, vec3_of<T> V>
V view_direction(const V& p, const V& n, const V& eye) {
    const V d = eye - p;
    const T r = length(d);
    return select(r > T(0), d / max(r, T(1e-30)), n);
}

/// The probe spacing of a cell with edges `size`: its shortest edge.
template <real T, vec3_of<T> V>
T cell_spacing(const V& size) {
    return min(min(size.x, size.y), size.z);
}

/// The direction the visibility test reads a probe at `s` in: from the probe to the biased
/// point, unit (a zero vector where they coincide), and its length.
template <real T, vec3_of<T> V>
std::pair<V, T> probe_to_point(const V& s, const V& biased) {
    const V d = biased - s;
    const T r = length(d);
    return {d / max(r, T(1e-30)), r};
}

/// A corner probe's weight in a visibility-aware trilinear lookup (Majercik et al. 2019,
/// their code's constants): the "wrap shading" ((dot(dir to probe, n) + 1) / 2)^2 + 0.2 of
/// the normal n at p, times max(0.05, chebyshev_visibility) of the biased point at
/// `distance` against the probe's moments (mean, mean_square) in that direction, kept
/// above 1e-6 and crushed below 0.2 (w^3 / 0.2^2, so that barely visible probes fade
/// fast), times the trilinear weight. Finite when p is at the probe.
template <real T, vec3_of<T> V>
T visibility_probe_weight(const V& p, const V& n, const V& s, const T& distance, const T& mean, const T& mean_square,
                          const T& trilinear) {
    const V to_probe = s - p;
    const T wrap = (dot(to_probe / max(length(to_probe), T(1e-30)), n) + T(1)) * T(0.5);
    const T visible = max(T(0.05), chebyshev_visibility(distance, mean, mean_square));
    const T w = max((wrap * wrap + T(0.2)) * visible, T(1e-6));
    const T crush = T(0.2);
    return select(w < crush, w * w * w / (crush * crush), w) * trilinear;
}

}  // namespace bounce::volume
