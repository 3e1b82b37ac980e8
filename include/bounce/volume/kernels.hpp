#pragma once
/// \file volume/kernels.hpp
/// The per-point math of an irradiance-volume lookup (Oat, "Irradiance Volumes for
/// Real-time Rendering", ShaderX5 section 6.1, 2006), written once as kernels: the CPU
/// lookup (volume/probe_octree.hpp) instantiates them with float and glm::vec3, the GL
/// adapter prints them as GLSL (gl/irradiance_volume.hpp). What is left outside them is
/// plumbing: reading nodes and probes from buffers and the loops over them.
///
/// Probes hold the SH coefficients (bands 0..2, RGB) of the incoming radiance at a point
/// and, optionally, their translational gradients (sh/gradients.hpp).

#include <bounce/concepts.hpp>
#include <bounce/sh/gradients.hpp>
#include <bounce/sh/irradiance.hpp>
#include <bounce/vocabulary.hpp>

#include <array>
#include <cstddef>
#include <utility>

namespace bounce::inline volume {

/// SH bands of an irradiance-volume probe: 3 (order 2, 9 coefficients per channel), all
/// that irradiance needs (Ramamoorthi and Hanrahan 2001).
inline constexpr int irradiance_volume_bands = 3;
/// Coefficients per channel of a probe.
inline constexpr std::size_t irradiance_volume_coefficients = sh_count(irradiance_volume_bands);

/// The child of the octree cell [lo, lo + size] holding `p`: 0..7 with bit 0 set for
/// p.x >= centre.x, bit 1 for y, bit 2 for z, centre = lo + size / 2 (a point on a
/// splitting plane belongs to the upper child; size / 2 is exact, so every backend finds
/// the same centre). Returned as a number so that the same kernel runs in GLSL, where the
/// caller converts it to an index.
template <real T, vec3_of<T> V>
T octree_octant(const V& p, const V& lo, const V& size) {
    const V centre = lo + size * T(0.5);
    return select(p.x >= centre.x, T(1), T(0)) + select(p.y >= centre.y, T(2), T(0)) +
           select(p.z >= centre.z, T(4), T(0));
}

/// `p` clamped into the box [lo, lo + size] (lookups outside a volume use its boundary).
template <real T, vec3_of<T> V>
V volume_clamp(const V& p, const V& lo, const V& size) {
    return clamp(p, lo, lo + size);
}

/// 1 when the box [lo, lo + size] grown on every side by `support` times its half
/// diagonal holds p, else 0: whether a weighted lookup at p must descend into an octree
/// node (no probe of a leaf inside it reaches farther than that).
template <real T, vec3_of<T> V>
T octree_node_reaches(const V& p, const V& lo, const V& size, const T& support) {
    const T grow = support * T(0.5) * length(size);
    const V a = lo - V(grow), b = lo + size + V(grow);
    return select(p.x >= a.x && p.y >= a.y && p.z >= a.z && p.x <= b.x && p.y <= b.y && p.z <= b.z, T(1), T(0));
}

/// Trilinear weights of the 8 corners of the box [lo, lo + size] at `p` (clamped into the
/// box), corner k at lo + size * (k & 1, (k >> 1) & 1, (k >> 2) & 1). They sum to 1 and
/// reproduce any linear function of position exactly.
template <real T, vec3_of<T> V>
std::array<T, 8> trilinear_weights(const V& p, const V& lo, const V& size) {
    const V t = clamp((p - lo) / size, T(0), T(1));
    const T x[2] = {T(1) - t.x, t.x}, y[2] = {T(1) - t.y, t.y}, z[2] = {T(1) - t.z, t.z};
    std::array<T, 8> w{x[0], x[0], x[0], x[0], x[0], x[0], x[0], x[0]};
    for (int k = 0; k < 8; ++k) w[std::size_t(k)] = x[k & 1] * y[(k >> 1) & 1] * z[(k >> 2) & 1];
    return w;
}

/// Irradiance (W/m^2, RGB) at a surface with unit normal `n` at offset `d` from a probe
/// with radiance coefficients `c` and gradients (`gx`, `gy`, `gz`): Oat's first-order
/// extrapolation I'_i = I_i + grad I_i . d (sh_extrapolate), then the clamped-cosine
/// convolution (sh_irradiance). With d = 0 it is the probe's own irradiance.
template <int L, real T, vec3_of<T> V>
V probe_irradiance(const std::array<V, sh_count(L)>& c, const std::array<V, sh_count(L)>& gx,
                   const std::array<V, sh_count(L)>& gy, const std::array<V, sh_count(L)>& gz, const V& d, const V& n) {
    return sh_irradiance<L, T, V>(sh_extrapolate<L, T, V, V>(c, gx, gy, gz, d), n);
}

/// One probe's term of the distance-weighted average (Oat 2006, "Interpolating between
/// probes": w_j ~ (1 / |p - s_j|)^b), in Franke and Nielson's compactly supported form
/// ("Smooth interpolation of large sets of scattered data", IJNME 15, 1980):
///   w = ((R - d)_+ / (R d))^b = (1/d - 1/R)_+^b,   d = |p - s|,  R = `reach`,
/// which is Oat's (1/d)^b near the probe and falls continuously to 0 at d = R, so the
/// average is continuous wherever the caller adds every probe with d < R (a probe then
/// enters and leaves it with weight 0: nothing pops). `reach` = 0 marks a probe inside
/// geometry (no weight). Computed as ((1 - t)_+ / max(t, min_distance))^b (ref / R)^b with
/// t = d / R: `ref` (world units, e.g. the smallest reach of the volume) only keeps the
/// numbers in float range and cancels in the average; `min_distance` (typical 1e-4) caps
/// the weight at the probe, where the average is then the probe's value. The probe's
/// irradiance at p is extrapolated by its gradients scaled by `gradient_scale` (1: on,
/// 0: off). Returns the new (sum of w E, sum of w).
template <int L, real T, vec3_of<T> V>
std::pair<V, T> weighted_probe_accumulate(const V& sum, const T& weight_sum, const V& p, const V& n, const V& s,
                                          const T& reach, const T& ref, const T& b, const T& min_distance,
                                          const T& gradient_scale, const std::array<V, sh_count(L)>& c,
                                          const std::array<V, sh_count(L)>& gx, const std::array<V, sh_count(L)>& gy,
                                          const std::array<V, sh_count(L)>& gz) {
    const V d = p - s;
    const T r = max(reach, T(1e-30));
    const T t = length(d) / r;
    const T w = select(reach > T(0), pow(max(T(1) - t, T(0)) / max(t, min_distance), b) * pow(ref / r, b), T(0));
    const V e = probe_irradiance<L, T, V>(c, gx, gy, gz, d * gradient_scale, n);
    return {sum + e * w, weight_sum + w};
}

/// One corner's term of a trilinear lookup: weight times valid, added with the probe's own
/// irradiance (no extrapolation). Returns the new (sum of w E, sum of w).
template <int L, real T, vec3_of<T> V>
std::pair<V, T> trilinear_probe_accumulate(const V& sum, const T& weight_sum, const V& n, const T& weight,
                                           const T& valid, const std::array<V, sh_count(L)>& c) {
    const T w = weight * valid;
    return {sum + sh_irradiance<L, T, V>(c, n) * w, weight_sum + w};
}

/// One term of a computed hanging corner (volume/hanging_corners.hpp): acc + weight * c per
/// coefficient. The lookup sums a corner's terms (stored probes and their weights: the
/// coarser leaf's interpolation) from zero, then weighs the sum as a corner
/// (trilinear_probe_accumulate); irradiance is linear in the coefficients, so this equals
/// a stored probe holding that interpolation.
template <int L, real T, vec3_of<T> V>
std::array<V, sh_count(L)> probe_combination_add(const std::array<V, sh_count(L)>& acc, const T& weight,
                                                 const std::array<V, sh_count(L)>& c) {
    std::array<V, sh_count(L)> out = acc;
    for (std::size_t i = 0; i < sh_count(L); ++i) out[i] = acc[i] + c[i] * weight;
    return out;
}

/// The average sum / weight_sum, and 0 where no probe contributed (weight_sum = 0).
template <real T, vec3_of<T> V>
V probe_average(const V& sum, const T& weight_sum) {
    return sum * select(weight_sum > T(0), T(1) / max(weight_sum, T(1e-30)), T(0));
}

}  // namespace bounce::volume
