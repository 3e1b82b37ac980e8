#pragma once
/// \file sh/lights.hpp
/// SH coefficients of the radiance of analytic lights, in closed form: a distant
/// directional light, a cone of uniform radiance (a disc or a sphere seen from a point, a
/// sun with its angular size) and a uniform sky over a hemisphere. Convention:
/// sh/basis.hpp. Units: radiance in W/(m^2 sr), irradiance in W/m^2; `C` is double (one
/// channel) or glm::dvec3 (RGB).
///
/// Every light here is symmetric about an axis a, so its coefficients are those of a zonal
/// function z_l rotated onto a: c_lm = sqrt(4 pi / (2l + 1)) z_l Y_lm(a) (Sloan 2008,
/// "Stupid SH Tricks", rotating zonal harmonics).

#include <bounce/errors.hpp>
#include <bounce/sh/basis.hpp>

#include <cmath>
#include <cstddef>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::detail {

inline glm::dvec3 unit_axis(const glm::dvec3& a, const char* name) {
    const double len = glm::length(a);
    require(len > 0 && std::isfinite(len), name, "axis must be a finite, non-zero vector");
    return a / len;
}

/// int_t^1 P_l(x) dx for l = 0 .. L - 1: 1 - t for l = 0 and, from
/// (2l + 1) P_l = d/dx (P_(l+1) - P_(l-1)) and P_l(1) = 1, (P_(l-1)(t) - P_(l+1)(t)) / (2l + 1).
template <int L>
std::array<double, std::size_t(L)> legendre_tail_integrals(double t) {
    std::array<double, std::size_t(L) + 1> p{};
    p[0] = 1;
    if (L >= 1) p[1] = t;
    for (int k = 2; k <= L; ++k)
        p[std::size_t(k)] = (double(2 * k - 1) * t * p[std::size_t(k - 1)] - double(k - 1) * p[std::size_t(k - 2)]) / k;
    std::array<double, std::size_t(L)> integral{};
    integral[0] = 1 - t;
    for (int l = 1; l < L; ++l)
        integral[std::size_t(l)] = (p[std::size_t(l - 1)] - p[std::size_t(l + 1)]) / double(2 * l + 1);
    return integral;
}

}  // namespace bounce::detail

namespace bounce::inline sh {

/// A distant light delivering `irradiance` (W/m^2) to a surface facing it, seen in the unit
/// direction `to_light` (from the receiver towards the light): radiance
/// irradiance * delta(w - to_light), so c_i = irradiance Y_i(to_light). Its truncation
/// rings (sh/windowing.hpp); its irradiance at order 2 is off by at most 3/32 of the peak
/// (docs/sh-and-irradiance-volumes.md).
template <int L, class C>
sh_coefficients<L, C> sh_project_directional_light(const glm::dvec3& to_light, const C& irradiance) {
    const auto y = sh_basis<L, double, glm::dvec3>(detail::unit_axis(to_light, "to_light"));
    sh_coefficients<L, C> c{};
    for (std::size_t i = 0; i < sh_count(L); ++i) c[i] = irradiance * y[i];
    return c;
}

/// Uniform radiance `radiance` (W/(m^2 sr)) inside the cone of directions within the
/// half-angle alpha of `axis` (cos alpha = `cos_half_angle`, in [-1, 1]; 1 is empty,
/// -1 the whole sphere), zero outside:
///   c_lm = 2 pi radiance (int_(cos alpha)^1 P_l) Y_lm(axis).
/// Its irradiance on a surface facing the axis is pi radiance sin^2 alpha.
template <int L, class C>
sh_coefficients<L, C> sh_project_cone_light(const glm::dvec3& axis, double cos_half_angle, const C& radiance) {
    require(cos_half_angle >= -1 && cos_half_angle <= 1, "cos_half_angle", "must lie in [-1, 1]");
    const auto y = sh_basis<L, double, glm::dvec3>(detail::unit_axis(axis, "axis"));
    const auto tail = detail::legendre_tail_integrals<L>(cos_half_angle);
    sh_coefficients<L, C> c{};
    for (int l = 0; l < L; ++l)
        for (int m = -l; m <= l; ++m) {
            const std::size_t i = sh_index(l, m);
            c[i] = radiance * (2 * std::numbers::pi * tail[std::size_t(l)] * y[i]);
        }
    return c;
}

/// A Lambertian disc of radius `radius` and radiance `radiance` whose centre lies at
/// `distance` along `to_centre`, facing the receiver: from the receiver it fills the cone
/// of cos alpha = distance / sqrt(distance^2 + radius^2) (units: any length, the same for
/// both; typical: a 0.5 m lamp 2 m away). A sphere of radius r at distance d (centre)
/// fills the cone of sin alpha = r / d instead: use sh_project_cone_light.
template <int L, class C>
sh_coefficients<L, C> sh_project_disc_light(const glm::dvec3& to_centre, double distance, double radius,
                                            const C& radiance) {
    require(distance > 0 && std::isfinite(distance), "distance", "must be positive and finite");
    require(radius > 0 && std::isfinite(radius), "radius", "must be positive and finite");
    return sh_project_cone_light<L, C>(to_centre, distance / std::sqrt(distance * distance + radius * radius), radiance);
}

/// A uniform sky: radiance `radiance` over the hemisphere around `up`, none below. The
/// irradiance it gives a surface whose normal is theta from `up` is
/// pi radiance (1 + cos theta) / 2, a function of bands 0 and 1 only, so SH irradiance of
/// any order >= 1 is exact for it.
template <int L, class C>
sh_coefficients<L, C> sh_project_uniform_sky(const glm::dvec3& up, const C& radiance) {
    return sh_project_cone_light<L, C>(up, 0.0, radiance);
}

/// Radiance `radiance` from every direction: c_00 = radiance sqrt(4 pi), the rest 0. Its
/// irradiance is pi radiance for every normal.
template <int L, class C>
sh_coefficients<L, C> sh_project_constant(const C& radiance) {
    sh_coefficients<L, C> c{};
    c[0] = radiance * std::sqrt(4 * std::numbers::pi);
    return c;
}

}  // namespace bounce::sh
