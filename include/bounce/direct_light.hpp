#pragma once
/// \file direct_light.hpp
/// Direct-light kernels: the irradiance a point, spot, directional or area light delivers
/// to a surface point, without visibility (the caller multiplies by its shadow test:
/// a shadow ray, a shadow map lookup).
///
/// These are the only definitions of the light models of scene.json (docs/scenes.md); the
/// reference integrator instantiates them with float/GLM and the GL passes print them as
/// GLSL. Units: radiant intensity I in W/sr, radiance L in W/(m^2 sr), irradiance E in
/// W/m^2, distances in scene units (metres by convention). RGB quantities are vectors of
/// the same type as positions (one value per channel).
///
/// Every surface here is one-sided: light arriving from behind the unit normal `n`
/// contributes nothing (the clamped cosine of the irradiance integral, E = int L cos dw).

#include <bounce/concepts.hpp>
#include <bounce/light.hpp>
#include <bounce/vocabulary.hpp>

#include <numbers>

namespace bounce {

/// Irradiance (W/m^2) at `p` with unit normal `n` from an isotropic point light at
/// `light_position` of intensity `intensity` (W/sr per channel): the inverse-square cosine
/// law E = I max(0, cos theta) / d^2. A point at the light itself receives 0 (the limit
/// is undefined; 0 keeps the result finite).
template <real T, vec3_of<T> V>
V point_light_irradiance(const V& p, const V& n, const V& light_position, const V& intensity) {
    const V d = light_position - p;
    const T d2 = dot(d, d);
    const auto lit = d2 > T(0);
    const T safe_d2 = select(lit, d2, T(1));
    // cos theta / d^2 = dot(n, d) / d^3.
    const T cos_over_d2 = max(T(0), dot(n, d)) * inversesqrt(safe_d2) / safe_d2;
    return intensity * select(lit, cos_over_d2, T(0));
}

/// Angular profile of a spot light: the factor in [0, 1] multiplying its on-axis intensity
/// in a direction at cosine `cos_axis` from its axis. Dark beyond the cone (cos_axis below
/// `cos_cone`, the cosine of the half-angle `cone_deg`); inside it, 1 for falloff "none"
/// (`cosine_falloff` = 0) or cos_axis for falloff "cosine" (`cosine_falloff` = 1).
/// Values of `cosine_falloff` between 0 and 1 blend the two linearly.
template <real T>
T spot_profile(T cos_axis, T cos_cone, T cosine_falloff) {
    const T inside = select(cos_axis >= cos_cone, T(1), T(0));
    return inside * mix(T(1), max(T(0), cos_axis), cosine_falloff);
}

/// Irradiance (W/m^2) at `p` with unit normal `n` from a spot light at `light_position`
/// whose unit `axis` is the direction it points, with on-axis intensity `intensity` (W/sr),
/// cone half-angle cosine `cos_cone` (typical: cos(45 deg)) and falloff selector
/// `cosine_falloff` (0: none, 1: cosine; see spot_profile): E = I profile(cos_axis) cos theta / d^2.
template <real T, vec3_of<T> V>
V spot_light_irradiance(const V& p, const V& n, const V& light_position, const V& axis, const V& intensity,
                        T cos_cone, T cosine_falloff) {
    const V d = light_position - p;
    const T d2 = dot(d, d);
    const auto lit = d2 > T(0);
    const T safe_d2 = select(lit, d2, T(1));
    const T inv_d = inversesqrt(safe_d2);
    // The emission direction is from the light towards p, i.e. -d / |d|.
    const T cos_axis = -dot(axis, d) * inv_d;
    const T cos_over_d2 = max(T(0), dot(n, d)) * inv_d / safe_d2;
    return intensity * select(lit, spot_profile<T>(cos_axis, cos_cone, cosine_falloff) * cos_over_d2, T(0));
}

/// Irradiance (W/m^2) at a surface with unit normal `n` from a distant light travelling
/// along the unit vector `direction`, delivering `irradiance` (W/m^2) to a surface facing
/// it: E = E_perp max(0, -n . direction).
template <real T, vec3_of<T> V>
V directional_light_irradiance(const V& n, const V& direction, const V& irradiance) {
    return irradiance * max(T(0), -dot(n, direction));
}

/// Irradiance (W/m^2) at `p` with unit normal `n` from a light of model `kind`, given the
/// fields of its packed form (light.hpp): the kernel above that `kind` names. `kind` is a
/// plain value, so with the GLSL expression types the choice is made while printing
/// (a shader per light model, or one per light); `position` is unused for a directional
/// light, `cos_cone` and `cosine_falloff` for all but a spot.
template <real T, vec3_of<T> V>
V light_irradiance(light_kind kind, const V& p, const V& n, const V& position, const V& direction, const V& intensity,
                   T cos_cone, T cosine_falloff) {
    switch (kind) {
    case light_kind::point: return point_light_irradiance<T, V>(p, n, position, intensity);
    case light_kind::spot:
        return spot_light_irradiance<T, V>(p, n, position, direction, intensity, cos_cone, cosine_falloff);
    default: return directional_light_irradiance<T, V>(n, direction, intensity);
    }
}

/// Irradiance (W/m^2, RGB) at `p` with unit normal `n` from the point, spot or directional
/// light `l`, without visibility: the form the CPU loops call.
inline glm::vec3 light_irradiance(const packed_light& l, glm::vec3 p, glm::vec3 n) {
    return light_irradiance<float, glm::vec3>(l.kind(), p, n, l.position(), l.direction(), l.intensity(), l.cos_cone(),
                                              l.cosine_falloff());
}

/// One area-sampled term of the irradiance at `p` (unit normal `n`) from a Lambertian
/// emitter: the point `q` on it with unit normal `nq` (the side that emits) and radiance
/// `radiance` (W/(m^2 sr)), drawn with area density pdf_A, enters as
/// L cos theta cos theta_q / d^2 / pdf_A (the area form of E = int L cos dw, e.g. pbrt
/// 4th ed. Eq. 4.9). Pass `inv_pdf_area` = 1 / pdf_A (m^2; the emitters' total area for
/// uniform area sampling). Averaging N such terms estimates E without bias; coincident
/// points give 0.
template <real T, vec3_of<T> V>
V area_light_irradiance_sample(const V& p, const V& n, const V& q, const V& nq, const V& radiance, T inv_pdf_area) {
    const V d = q - p;
    const T d2 = dot(d, d);
    const auto apart = d2 > T(0);
    const T safe_d2 = select(apart, d2, T(1));
    // cos theta cos theta_q / d^2 = dot(n, d) dot(nq, -d) / d^4.
    const T geometry = max(T(0), dot(n, d)) * max(T(0), -dot(nq, d)) / (safe_d2 * safe_d2);
    return radiance * (select(apart, geometry, T(0)) * inv_pdf_area);
}

/// Outgoing radiance (W/(m^2 sr)) of a Lambertian surface of diffuse reflectance `albedo`
/// (rho_d per channel, in [0, 1]) under irradiance `irradiance` (W/m^2): L = rho_d E / pi.
template <real T, vec3_of<T> V>
V lambertian_radiance(const V& albedo, const V& irradiance) {
    return albedo * irradiance * T(1.0 / std::numbers::pi);
}

}  // namespace bounce
