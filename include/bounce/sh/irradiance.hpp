#pragma once
/// \file sh/irradiance.hpp
/// Irradiance from SH radiance by the closed-form clamped-cosine convolution
/// (Ramamoorthi and Hanrahan, "An Efficient Representation for Irradiance Environment
/// Maps", SIGGRAPH 2001, section 3): the irradiance at a surface with unit normal n,
///   E(n) = int L(w) max(0, n . w) dw = sum_lm A_l L_lm Y_lm(n),
/// where A_l (their "A-hat") depends on the band only, for every band:
///   A_0 = pi,   A_1 = 2 pi / 3,   A_l = 0 for odd l > 1,
///   A_l = 2 pi (-1)^(l/2 - 1) / ((l + 2)(l - 1)) * l! / (2^l ((l/2)!)^2)   for even l >= 2.
/// Convention: sh/basis.hpp (L counts bands; order 2 is L = 3). Units: radiance in
/// W/(m^2 sr) gives irradiance in W/m^2; irradiance / pi is the radiance a white
/// Lambertian surface reflects, the quantity most shaders want.

#include <bounce/sh/basis.hpp>

#include <array>
#include <cstddef>
#include <numbers>

namespace bounce::inline sh {

/// A_l of the file comment: the factor band l of a radiance function is multiplied by when
/// it is convolved with the clamped cosine max(0, cos theta). The even-band factorial ratio
/// l! / (2^l ((l/2)!)^2) = C(l, l/2) / 2^l is built as prod_{k=1..l/2} (2k - 1) / (2k), which
/// neither overflows nor loses precision at high l.
constexpr double clamped_cosine_band_factor(int l) noexcept {
    constexpr double pi = std::numbers::pi;
    if (l == 0) return pi;
    if (l == 1) return 2 * pi / 3;
    if (l % 2 != 0) return 0;
    double ratio = 1;
    for (int k = 1; k <= l / 2; ++k) ratio *= double(2 * k - 1) / double(2 * k);
    const double sign = (l / 2 - 1) % 2 == 0 ? 1.0 : -1.0;
    return 2 * pi * sign / (double(l + 2) * double(l - 1)) * ratio;
}

/// A_0 .. A_(L-1).
template <int L>
constexpr std::array<double, std::size_t(L)> clamped_cosine_band_factors() noexcept {
    std::array<double, std::size_t(L)> a{};
    for (int l = 0; l < L; ++l) a[std::size_t(l)] = clamped_cosine_band_factor(l);
    return a;
}

/// The SH coefficients of the irradiance E(n) from those of the radiance: E_lm = A_l L_lm.
/// Evaluating the result with `sh_evaluate` gives `sh_irradiance`; storing it saves the
/// multiplications per shaded point.
template <int L, class C>
sh_coefficients<L, C> sh_convolve_clamped_cosine(const sh_coefficients<L, C>& radiance) {
    constexpr auto a = clamped_cosine_band_factors<L>();
    sh_coefficients<L, C> e = radiance;
    for (std::size_t i = 0; i < sh_count(L); ++i) e[i] = radiance[i] * a[std::size_t(sh_band(i))];
    return e;
}

/// `sh_convolve_clamped_cosine` with L and C deduced: `sh_convolve_clamped_cosine(radiance)`.
template <class C, std::size_t N>
    requires(sh_bands_of(N) > 0)
std::array<C, N> sh_convolve_clamped_cosine(const std::array<C, N>& radiance) {
    return sh_convolve_clamped_cosine<sh_bands_of(N), C>(radiance);
}

/// Irradiance (W/m^2 per channel) at a surface with unit normal `n` under the radiance
/// whose SH coefficients are `radiance` (W/(m^2 sr)): sum_lm A_l L_lm Y_lm(n)
/// (Ramamoorthi and Hanrahan 2001). Bands with A_l = 0 (odd l > 1) cost nothing: the test
/// is on a compile-time constant. A kernel: `sh_irradiance<3, glsl::f32, glsl::vec3>` prints
/// `vec3 sh_irradiance(vec3 radiance[9], vec3 n)`.
template <int L, real T, vec3_of<T> V>
V sh_irradiance(const std::array<V, sh_count(L)>& radiance, const V& n) {
    constexpr auto a = clamped_cosine_band_factors<L>();
    const auto y = sh_basis<L, T, V>(n);
    V sum = radiance[0] * (T(a[0]) * y[0]);
    for (int l = 1; l < L; ++l) {
        if (a[std::size_t(l)] == 0) continue;
        for (int m = -l; m <= l; ++m) {
            const std::size_t i = sh_index(l, m);
            sum = sum + radiance[i] * (T(a[std::size_t(l)]) * y[i]);
        }
    }
    return sum;
}

/// `sh_irradiance` with L and T deduced from the arguments: `sh_irradiance(radiance, n)`.
template <class V, std::size_t N>
    requires(sh_bands_of(N) > 0)
V sh_irradiance(const std::array<V, N>& radiance, const V& n) {
    return sh_irradiance<sh_bands_of(N), detail::vector_scalar_t<V>, V>(radiance, n);
}

/// Irradiance / pi (W/(m^2 sr)): the radiance a white Lambertian surface with unit normal
/// `n` reflects under `radiance`; multiply by the albedo for the diffuse colour. The 1/pi
/// is folded into the band factors, so this is exactly as cheap as `sh_irradiance`.
template <int L, real T, vec3_of<T> V>
V sh_irradiance_over_pi(const std::array<V, sh_count(L)>& radiance, const V& n) {
    constexpr auto a = clamped_cosine_band_factors<L>();
    constexpr double inv_pi = 1 / std::numbers::pi;
    const auto y = sh_basis<L, T, V>(n);
    V sum = radiance[0] * (T(a[0] * inv_pi) * y[0]);
    for (int l = 1; l < L; ++l) {
        if (a[std::size_t(l)] == 0) continue;
        for (int m = -l; m <= l; ++m) {
            const std::size_t i = sh_index(l, m);
            sum = sum + radiance[i] * (T(a[std::size_t(l)] * inv_pi) * y[i]);
        }
    }
    return sum;
}

/// `sh_irradiance_over_pi` with L and T deduced: `sh_irradiance_over_pi(radiance, n)`.
template <class V, std::size_t N>
    requires(sh_bands_of(N) > 0)
V sh_irradiance_over_pi(const std::array<V, N>& radiance, const V& n) {
    return sh_irradiance_over_pi<sh_bands_of(N), detail::vector_scalar_t<V>, V>(radiance, n);
}

}  // namespace bounce::sh
