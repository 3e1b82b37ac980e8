#pragma once
/// \file shadow_mapping.hpp
/// Shadow-map lookups as kernels (Williams 1978; percentage-closer filtering, Reeves et al.
/// 1987): where a surface point looks up a shadow map, how far it is moved off its surface
/// to avoid self-shadowing (normal offset), and the 16 taps of the 4x4 PCF kernel.
///
/// A raster backend renders the depth of the scene from the light and compares, per tap,
/// the point's depth `ref` with the stored depth (hardware comparison: lit when
/// ref <= stored). 2D maps (perspective for spot lights, orthographic for distant ones)
/// store window depth; cube maps for point lights store radial distance. Everything a shader computes around those comparisons is here, so the
/// GLSL of a direct-light pass is only plumbing (matrix transforms, texture fetches,
/// derivatives). The matrices are OpenGL's: clip = projection * view * p, window depth =
/// clip.z / clip.w * 0.5 + 0.5 in [0, 1].

#include <bounce/vocabulary.hpp>

#include <array>
#include <utility>

namespace bounce {

/// Number of PCF taps: a 4x4 grid.
inline constexpr int pcf_tap_count = 16;

/// Offset of PCF tap `i` (0..15) in texels along the map's u (`axis` 0) or v (`axis` 1):
/// -1.5, -0.5, 0.5, 1.5, a grid centred on the lookup point.
constexpr double pcf_tap_offset(int i, int axis) noexcept {
    return double(axis == 0 ? i % 4 : i / 4) - 1.5;
}

/// The major-axis distance max(|d.x|, |d.y|, |d.z|): the view depth of direction `d` in the
/// cube-map face it falls in (each face is a 90-degree perspective view along one axis).
template <real T, vec3_of<T> V>
T cube_major_axis(const V& d) {
    return max(max(abs(d.x), abs(d.y)), abs(d.z));
}

/// Depth a radial (distance) shadow map stores for the point `p` seen from a point light at
/// `light_position`: |p - light| / far, the same for every face of a cube map, so depth
/// comparisons and bilinear filtering agree across face seams (per-face window depths do
/// not). `inv_far` = 1 / the largest distance the map holds.
template <real T, vec3_of<T> V>
T radial_shadow_depth(const V& p, const V& light_position, T inv_far) {
    return length(p - light_position) * inv_far;
}

/// Slope-scaled depth bias for a depth the shader writes itself (where glPolygonOffset does
/// not apply): `depth` pushed away from the light by `slope_bias` times its largest
/// screen-space derivative (`ddx`, `ddy`: its change per shadow-map texel) plus
/// `constant_bias` steps of 2^-23 `depth` (about two float ulps each). Typical slope_bias
/// 2-4: the reach of the PCF footprint in texels.
template <real T>
T slope_biased_depth(T depth, T ddx, T ddy, T slope_bias, T constant_bias) {
    return depth + slope_bias * max(abs(ddx), abs(ddy)) + constant_bias * T(1.0 / 8388608.0) * depth;
}

/// World size of one texel of a square perspective shadow map at `p`: the map looks along
/// the unit `axis` from `light_position` with tan(fov / 2) = `tan_half_fov`, and has
/// 1 / `inv_resolution` texels per side; a texel spans 2 depth tan(fov/2) / resolution.
template <real T, vec3_of<T> V>
T perspective_shadow_texel(const V& p, const V& light_position, const V& axis, T tan_half_fov, T inv_resolution) {
    return T(2) * abs(dot(p - light_position, axis)) * tan_half_fov * inv_resolution;
}

/// World size of one texel of a cube shadow map centred at `light_position` at `p`: the
/// face p falls in spans 2 x its major-axis distance over the resolution.
template <real T, vec3_of<T> V>
T cube_shadow_texel(const V& p, const V& light_position, T inv_resolution) {
    return T(2) * cube_major_axis<T, V>(p - light_position) * inv_resolution;
}

/// Normal-offset shadow lookup (Holbert 2011, "Normal offset shadows"): the point is moved
/// along its unit normal `n` by `offset_texels` texels of world size `texel` before it is
/// projected into the shadow map, so that a lit surface does not compare against its own
/// rasterized depth (acne) where the slope-scaled depth bias alone is not enough (grazing
/// light). Typical offset_texels: 1-2.
template <real T, vec3_of<T> V>
V normal_offset_point(const V& p, const V& n, T texel, T offset_texels) {
    return p + n * (texel * offset_texels);
}

/// The 16 PCF lookups (u, v, ref) into a 2D shadow map (perspective or orthographic) for a
/// point whose light clip-space position is (`clip`, `clip_w`): the projected point
/// uv = clip.xy / w * 1/2 + 1/2 shifted by each tap's offset in texels of a map with
/// 1 / `inv_resolution` texels per side, and its window depth ref = clip.z / w * 1/2 + 1/2.
template <real T, vec3_of<T> V>
std::array<V, pcf_tap_count> shadow_map_taps(const V& clip, T clip_w, T inv_resolution) {
    const T inv_w = T(1) / clip_w;
    const T u = clip.x * inv_w * T(0.5) + T(0.5), v = clip.y * inv_w * T(0.5) + T(0.5);
    const T ref = clip.z * inv_w * T(0.5) + T(0.5);
    std::array<V, pcf_tap_count> taps;
    for (int i = 0; i < pcf_tap_count; ++i)
        taps[std::size_t(i)] = V(u + T(pcf_tap_offset(i, 0)) * inv_resolution, v + T(pcf_tap_offset(i, 1)) * inv_resolution, ref);
    return taps;
}

/// The 16 PCF lookups into a radial cube shadow map (radial_shadow_depth) for the direction
/// `d` = p - light (not necessarily unit): d shifted by each tap's offset in texels along
/// the two axes of the face d falls in (a face at major-axis distance |d|_max spans
/// 2 |d|_max over the resolution, so a step is one face texel, as in a 2D map), and for each
/// tap its own reference depth |tap| / far (a tap may land on a neighbouring face; radial
/// depths compare alike on every face). `inv_far` = 1 / the map's far distance.
/// Returns {directions, reference depths}.
template <real T, vec3_of<T> V>
std::pair<std::array<V, pcf_tap_count>, std::array<T, pcf_tap_count>> cube_shadow_taps(const V& d, T inv_far,
                                                                                        T inv_resolution) {
    const T ax = abs(d.x), ay = abs(d.y), az = abs(d.z);
    const auto major_x = ax >= ay && ax >= az;
    const auto major_y = !major_x && ay >= az;
    const V ex(T(1), T(0), T(0)), ey(T(0), T(1), T(0)), ez(T(0), T(0), T(1));
    const V s_axis = select(major_x, ey, select(major_y, ez, ex));
    const V t_axis = select(major_x, ez, select(major_y, ex, ey));
    const T texel = T(2) * cube_major_axis<T, V>(d) * inv_resolution;
    std::pair<std::array<V, pcf_tap_count>, std::array<T, pcf_tap_count>> taps;
    for (int i = 0; i < pcf_tap_count; ++i) {
        const V t = d + (s_axis * T(pcf_tap_offset(i, 0)) + t_axis * T(pcf_tap_offset(i, 1))) * texel;
        taps.first[std::size_t(i)] = t;
        taps.second[std::size_t(i)] = length(t) * inv_far;
    }
    return taps;
}

/// Percentage-closer filtering: the fraction of the 16 taps that passed their depth
/// comparison (each `tests[i]` in [0, 1], 1 = lit), the visibility that scales a light's
/// unshadowed irradiance.
template <real T>
T pcf_visibility(const std::array<T, pcf_tap_count>& tests) {
    T sum = tests[0];
    for (int i = 1; i < pcf_tap_count; ++i) sum = sum + tests[std::size_t(i)];
    return sum * T(1.0 / pcf_tap_count);
}

}  // namespace bounce
