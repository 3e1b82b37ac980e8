#pragma once
/// \file sh/gradients.hpp
/// Translational gradients of SH probes and extrapolation with them (Oat, "Irradiance
/// Volumes for Real-time Rendering", ShaderX5 6.1, section "Irradiance Gradients", after
/// Annen et al. 2004): each coefficient's gradient is estimated by central differences of
/// six extra probes at p +- h x, p +- h y, p +- h z, and a probe at p serves a nearby point
/// p + d through the first-order extrapolation I'_i = I_i + grad I_i . d.
///
/// The probes themselves come from a callable, so any renderer can feed this: a GL pass
/// that renders and projects a cube map, an Embree ray caster, an analytic environment.

#include <bounce/errors.hpp>
#include <bounce/sh/basis.hpp>

#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <type_traits>

#include <glm/vec3.hpp>

namespace bounce::detail {
/// The band count and coefficient type of an SH coefficient array (bands = 0 for anything else).
template <class A>
struct sh_array_shape {
    static constexpr int bands = 0;
};
template <class C, std::size_t N>
struct sh_array_shape<std::array<C, N>> {
    using coefficient = C;
    static constexpr int bands = sh_bands_of(N);
};
template <class F>
using probe_result_t = std::remove_cvref_t<std::invoke_result_t<F&, const glm::dvec3&>>;
}  // namespace bounce::detail

namespace bounce::inline sh {

/// d c_i / dx, d c_i / dy, d c_i / dz of every coefficient (units: the coefficients' per
/// scene unit).
template <int L, class C>
struct sh_gradient {
    sh_coefficients<L, C> x{}, y{}, z{};
};

/// Central-difference gradient of the probe at `position`:
///   grad_k c_i = (c_i(p + h e_k) - c_i(p - h e_k)) / (2 h),   h = `step`.
/// `probe_at(glm::dvec3 position)` returns the SH coefficients (sh_coefficients<L, C>) of
/// the probe at a position; it is called six times, in the order +x -x +y -y +z -z.
/// The step trades two errors: the difference quotient is off by h^2 / 6 times the third
/// derivative (lighting that changes over a distance s gives a relative error about
/// (h / s)^2 / 6), and an error e in each probe (Monte Carlo noise, cube-map aliasing)
/// becomes e / h in the gradient. Typical step: a tenth of the probe spacing, and always
/// less than the distance to the nearest surface (a displaced probe must not cross a wall:
/// its gradient would describe the other side). Scene units. Throws parameter_error when
/// `step` is not positive and finite.
template <int L, class C, class ProbeAt>
    requires std::invocable<ProbeAt&, const glm::dvec3&> &&
             std::convertible_to<std::invoke_result_t<ProbeAt&, const glm::dvec3&>, sh_coefficients<L, C>>
sh_gradient<L, C> sh_translational_gradient(ProbeAt&& probe_at, const glm::dvec3& position, double step) {
    require(step > 0 && std::isfinite(step), "step", "central-difference step must be positive and finite");
    require(std::isfinite(position.x) && std::isfinite(position.y) && std::isfinite(position.z), "position",
            "probe position must be finite");
    sh_gradient<L, C> g;
    sh_coefficients<L, C>* axes[3] = {&g.x, &g.y, &g.z};
    for (int k = 0; k < 3; ++k) {
        glm::dvec3 offset(0.0);
        offset[k] = step;
        const sh_coefficients<L, C> plus = probe_at(position + offset);
        const sh_coefficients<L, C> minus = probe_at(position - offset);
        for (std::size_t i = 0; i < sh_count(L); ++i) (*axes[k])[i] = (plus[i] - minus[i]) * (1 / (2 * step));
    }
    return g;
}

/// `sh_translational_gradient` with L and C deduced from what `probe_at` returns (an
/// std::array of whole bands): `sh_translational_gradient(probe_at, position, step)`.
template <class ProbeAt>
    requires std::invocable<ProbeAt&, const glm::dvec3&> && (detail::sh_array_shape<detail::probe_result_t<ProbeAt>>::bands > 0)
auto sh_translational_gradient(ProbeAt&& probe_at, const glm::dvec3& position, double step) {
    using shape = detail::sh_array_shape<detail::probe_result_t<ProbeAt>>;
    return sh_translational_gradient<shape::bands, typename shape::coefficient>(probe_at, position, step);
}

/// Oat's extrapolation I'_i = I_i + grad I_i . d of the probe `c` with gradient
/// (`gx`, `gy`, `gz`) to the point at offset `d` from it (scene units, not unit length).
/// A kernel: `C` is the coefficient type (T or V); on the GPU each probe is 4 L^2 values.
template <int L, real T, vec3_of<T> V, class C>
std::array<C, sh_count(L)> sh_extrapolate(const std::array<C, sh_count(L)>& c, const std::array<C, sh_count(L)>& gx,
                                          const std::array<C, sh_count(L)>& gy, const std::array<C, sh_count(L)>& gz,
                                          const V& d) {
    std::array<C, sh_count(L)> out = c;
    for (std::size_t i = 0; i < sh_count(L); ++i) out[i] = c[i] + gx[i] * d.x + gy[i] * d.y + gz[i] * d.z;
    return out;
}

/// The kernel `sh_extrapolate` with L, T and C deduced: `sh_extrapolate(c, gx, gy, gz, d)`.
template <class C, std::size_t N, class V>
    requires(sh_bands_of(N) > 0)
std::array<C, N> sh_extrapolate(const std::array<C, N>& c, const std::array<C, N>& gx, const std::array<C, N>& gy,
                                const std::array<C, N>& gz, const V& d) {
    return sh_extrapolate<sh_bands_of(N), detail::vector_scalar_t<V>, V, C>(c, gx, gy, gz, d);
}

/// `sh_extrapolate` with a gradient from `sh_translational_gradient`, in double precision
/// (`C` is double or glm::dvec3: GLM does not multiply a float vector by a double). L and C
/// are deduced from the gradient: `sh_extrapolate(c, g, d)`.
template <int L, class C>
sh_coefficients<L, C> sh_extrapolate(const sh_coefficients<L, C>& c, const sh_gradient<L, C>& g, const glm::dvec3& d) {
    return sh_extrapolate<L, double, glm::dvec3, C>(c, g.x, g.y, g.z, d);
}

}  // namespace bounce::sh
