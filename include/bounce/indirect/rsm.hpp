#pragma once
/// \file indirect/rsm.hpp
/// Reflective shadow maps (Dachsbacher and Stamminger 2005, "Reflective Shadow Maps", I3D)
/// as kernels: the flux a map texel reflects, the irradiance a texel (a "pixel light")
/// gives a receiver, the region of space where that irradiance can matter (the splat volume
/// of Dachsbacher and Stamminger 2006, "Splatting Indirect Illumination", I3D), and the
/// disc pattern of the RSM gather.
///
/// Radiometric convention (docs/rsm-sii-interleaved.md, section 1). A texel stores the flux
/// Phi_p (W per channel) its surface patch reflects, as a Lambertian emitter of radiance
/// L = Phi_p / (pi A_p). The irradiance it gives a receiver at distance d is then
///   E_p(x, n) = Phi_p / pi * cos theta_p cos theta / d^2
///            = Phi_p / pi * max(0, n_p.(x - x_p)) max(0, n.(x_p - x)) / |x - x_p|^4,
/// the published formula (DS05 Eq. 1) with the 1/pi it leaves out: DS05's Phi_p is what
/// bounce calls Phi_p / pi (the patch's intensity along its normal, W/sr). With bounce's
/// convention the sum of E_p over every texel of a fine map converges to the one-bounce
/// irradiance of the unoccluded scene (tested on a closed form in tests/rsm).
///
/// Units: positions and distances in scene units (metres by convention), flux in W,
/// irradiance in W/m^2, intensity in W/sr, solid angles in sr. RGB quantities are vectors of
/// the position type, one value per channel.

#include <bounce/concepts.hpp>
#include <bounce/direct_light.hpp>
#include <bounce/rectangle_solid_angle.hpp>
#include <bounce/vocabulary.hpp>

#include <numbers>
#include <tuple>

namespace bounce::inline indirect {

// ---- what a texel reflects --------------------------------------------------------------

// The exact solid angle of a perspective texel (the rectangle [x0, x1] x [y0, y1] of the
// image plane at unit distance, tangent units: a texel of a square map with tan(fov/2) = t
// and R texels per side spans 2t/R) is rectangle_solid_angle (rectangle_solid_angle.hpp);
// the six faces of a cube map sum to 4 pi (tested in tests/rsm).

/// Solid angle (sr) of a small texel of size dx x dy centred at (x, y) on the image plane at
/// unit distance (tangent units): the midpoint rule dw = dx dy / (1 + x^2 + y^2)^(3/2).
/// Its relative error is below 1.3 t^2 for texels of side t inside a 90-degree face (the
/// integrand's second derivatives are at most 3 in size and it is at least 3^(-3/2)), while
/// rectangle_solid_angle, evaluated in float, loses about 2.4e-7 / dw relatively to the
/// cancellation of its four O(1) terms: use this one in float for maps finer than about
/// 100 texels per side (t < 0.02), the exact one in double or for coarse maps.
template <real T>
T perspective_texel_solid_angle_midpoint(T x, T y, T dx, T dy) {
    const T r2 = T(1) + x * x + y * y;
    return dx * dy * inversesqrt(r2) / r2;
}

/// Reflected flux (W) of the texel that sees the surface point `p` (unit normal `n`,
/// diffuse reflectance `albedo`) through the solid angle `solid_angle` (sr) of a point
/// light at `light_position` of intensity `intensity` (W/sr): the light sends I dw through
/// the texel whatever the surface's slope (the patch it hits grows as 1/cos), and the
/// surface reflects the fraction rho_d: Phi = rho_d I dw. A surface seen from behind
/// (one-sided, as in direct_light.hpp) reflects nothing.
template <real T, vec3_of<T> V>
V point_light_texel_flux(const V& albedo, const V& p, const V& n, const V& light_position, const V& intensity,
                         T solid_angle) {
    const T facing = select(dot(n, light_position - p) > T(0), T(1), T(0));
    return albedo * intensity * (solid_angle * facing);
}

/// As point_light_texel_flux for a spot light pointing along the unit `axis`, with cone
/// cosine `cos_cone` and falloff selector `cosine_falloff` (direct_light.hpp's spot_profile):
/// Phi = rho_d I profile(cos_axis) dw, with cos_axis taken towards `p`.
template <real T, vec3_of<T> V>
V spot_light_texel_flux(const V& albedo, const V& p, const V& n, const V& light_position, const V& axis,
                        const V& intensity, T cos_cone, T cosine_falloff, T solid_angle) {
    const V d = p - light_position;
    const T d2 = dot(d, d);
    const T cos_axis = dot(axis, d) * inversesqrt(select(d2 > T(0), d2, T(1)));
    const T profile = spot_profile<T>(cos_axis, cos_cone, cosine_falloff);
    const T facing = select(dot(n, d) < T(0), T(1), T(0));
    return albedo * intensity * (solid_angle * profile * facing);
}

/// Reflected flux (W) of a texel of an orthographic map looking along the unit `direction`
/// of a distant light delivering `irradiance` (W/m^2 on a surface facing it): the texel's
/// cross-section `texel_area` (m^2, measured across the light) passes E a, and the
/// surface reflects rho_d of it: Phi = rho_d E a. Zero for a surface facing away.
template <real T, vec3_of<T> V>
V directional_light_texel_flux(const V& albedo, const V& n, const V& direction, const V& irradiance, T texel_area) {
    const T facing = select(dot(n, direction) < T(0), T(1), T(0));
    return albedo * irradiance * (texel_area * facing);
}

// ---- what a texel gives a receiver ------------------------------------------------------

/// Squared distance below which a sender and a receiver count as coincident (m^2): 1e-30
/// keeps 1/d in float's normal range (FLT_MIN = 1.2e-38), so the cosines, computed with
/// 1/d, are finite, and the result is 0 (the limit does not exist).
inline constexpr double coincident_distance2 = 1e-30;

/// Irradiance (W/m^2) at `x` (unit normal `n`) from the pixel light at `xp` (unit normal
/// `np`) reflecting `flux` (W): E = Phi / pi cos theta_p cos theta / d^2 (DS05 Eq. 1 with
/// the 1/pi of a Lambertian emitter; see the file comment).
///
/// Two remedies for the 1/d^2 singularity where a sender and a receiver share a boundary
/// (two walls meeting; DS05 section 4), each with its bias (docs, section 2):
///  - `offset` (m, >= 0; typical: half a texel's footprint): the sender is moved to
///    xp - offset np, DS05's remedy. E stays below Phi / (pi offset^2) on the sender's own
///    side; a receiver at distance d gains or loses O(offset / d) relatively.
///  - `min_distance2` (m^2, >= 0; typical: (texel footprint)^2): d^2 is clamped below at
///    that value, which caps E at Phi / (pi min_distance2) and removes (only) energy that
///    arrives from closer than sqrt(min_distance2).
/// Both 0 gives the plain formula. Coincident points (d^2 <= coincident_distance2) get 0,
/// never NaN or infinity in float32; so do grazing (cos = 0) and back-facing pairs.
template <real T, vec3_of<T> V>
V pixel_light_irradiance(const V& x, const V& n, const V& xp, const V& np, const V& flux, T offset, T min_distance2) {
    const V v = x - (xp - np * offset);
    const T d2 = dot(v, v);
    const auto apart = d2 > T(coincident_distance2);
    const T safe_d2 = select(apart, d2, T(1));
    const T inv_d = inversesqrt(safe_d2);
    const T cos_p = max(T(0), dot(np, v) * inv_d);
    const T cos_r = max(T(0), -dot(n, v) * inv_d);
    const T g = cos_p * cos_r / max(safe_d2, min_distance2) * T(1.0 / std::numbers::pi);
    return flux * select(apart, g, T(0));
}

/// Where a pixel light can matter: since cos theta <= 1 at the receiver,
/// E_p <= Phi / pi cos theta_p / d^2, which falls below `cutoff` (W/m^2) outside the lobe
/// d <= R sqrt(cos theta_p), R = sqrt(Phi / (pi cutoff)). The lobe is enclosed by the sphere
/// centred t R along np from the (offset) sender with radius s R, where t = 27^(-1/4) =
/// 0.4387 and s = sqrt(2 / sqrt 27) = 0.6204 minimize the largest distance
/// R^2 (u - 2 t u^(3/2) + t^2), u = cos theta_p in [0, 1] (docs, section 3). The sphere holds
/// 0.24 of the volume of the ball of radius R, so a splat of it shades a quarter of the
/// pixels a sphere around the sender would.
/// `flux_max`: the largest channel of the flux (W); `cutoff` > 0. Outside the sphere the
/// light gives less than `cutoff` per channel, which is the energy a splat cuts off.
/// Returns {centre, radius}; the radius is widened by 1e-4 relatively for rounding.
template <real T, vec3_of<T> V>
std::tuple<V, T> pixel_light_bounding_sphere(const V& xp, const V& np, T flux_max, T cutoff, T offset) {
    const T reach = sqrt(max(flux_max, T(0)) / (T(std::numbers::pi) * cutoff));
    const T t = T(0.43869133765083085);  // 27^(-1/4)
    const T s = T(0.62040323);           // sqrt(2 / sqrt(27)) = 0.620403..., rounded up
    return {xp - np * offset + np * (t * reach), s * reach * T(1.0001)};
}

// ---- the RSM gather ---------------------------------------------------------------------

/// One sample of the RSM gather's disc pattern (DS05 section 3.2): the offset
/// (r_max xi1 sin 2 pi xi2, r_max xi1 cos 2 pi xi2) in map coordinates (u, v in [0, 1]) and
/// its weight. Offsets with uniform xi1 crowd the centre: their density per unit area is
/// 1 / (2 pi r_max^2 xi1), so the weight that makes the sum of weight x (texel's E_p) an
/// unbiased estimate of the sum over every texel of the disc is
///   w = 2 pi r_max^2 xi1 * texel_count / sample_count
/// (texel_count = the map's width x height; one texel has area 1 / texel_count in map
/// coordinates). DS05 weights by xi1^2, which over-weights the rim by 3/2 xi1 (docs,
/// section 4): bounce keeps the unbiased xi1.
/// xi1, xi2 in [0, 1); r_max in (0, 1] (typical: 0.1-0.3 of the map; 1 or more reaches
/// every texel from every centre); sample_count typical 400. Returns (du, dv, w).
template <real T, vec3_of<T> V>
V rsm_disc_sample(T xi1, T xi2, T r_max, T texel_count, T sample_count) {
    const T angle = T(2.0 * std::numbers::pi) * xi2;
    const T r = r_max * xi1;
    return V(r * sin(angle), r * cos(angle),
             T(2.0 * std::numbers::pi) * r_max * r_max * xi1 * texel_count / sample_count);
}

/// Centre (u, v in [0, 1], row 0 at the top) of a receiver's gather disc in a map, from the
/// receiver's clip-space position (clip_x, clip_y, clip_w) under the map's view-projection:
/// its projection clamped into the map, or the map's centre when the receiver is behind the
/// projection centre (clip_w <= 0, e.g. a point light's cube face behind it). The disc's
/// estimate is unbiased for the texels it covers whatever its centre, so with r_max >= sqrt 2
/// every texel stays reachable; DS05 centres on the receiver's own texel because near texels
/// matter most and the samples crowd the centre.
template <real T, vec2_of<T> V2>
V2 rsm_disc_centre(T clip_x, T clip_y, T clip_w) {
    const auto front = clip_w > T(0);
    const T inv_w = T(1) / select(front, clip_w, T(1));
    const T u = clamp(clip_x * inv_w * T(0.5) + T(0.5), T(0), T(1));
    const T v = clamp(T(0.5) - clip_y * inv_w * T(0.5), T(0), T(1));
    return V2(select(front, u, T(0.5)), select(front, v, T(0.5)));
}

/// DS05's published weighting of the same offsets, for comparison: w proportional to xi1^2,
/// scaled by 3 so that its expectation is the unbiased weight's (E[3 xi1^2] = 2 E[xi1] = 1):
///   w = 3 pi r_max^2 xi1^2 * texel_count / sample_count.
/// It estimates the sum of f (3/2)(rho / r_max) over the disc instead of the sum of f, i.e.
/// it over-weights texels far from the centre (docs, section 4); a constant f is estimated
/// without bias, which is why the error is easy to miss. Returns (du, dv, w).
template <real T, vec3_of<T> V>
V rsm_disc_sample_xi1_squared(T xi1, T xi2, T r_max, T texel_count, T sample_count) {
    const T angle = T(2.0 * std::numbers::pi) * xi2;
    const T r = r_max * xi1;
    return V(r * sin(angle), r * cos(angle),
             T(3.0 * std::numbers::pi) * r_max * r_max * xi1 * xi1 * texel_count / sample_count);
}

}  // namespace bounce::indirect
