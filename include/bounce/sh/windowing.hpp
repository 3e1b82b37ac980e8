#pragma once
/// \file sh/windowing.hpp
/// Windows against ringing: truncating a function's SH expansion at band L - 1 multiplies
/// it by a step in frequency, which rings (Gibbs) and gives negative lobes opposite a bright
/// light; scaling band l by a window h_l that falls smoothly to zero trades sharpness for
/// less ringing (Sloan, "Stupid Spherical Harmonics Tricks", GDC 2008, section "Windowing").
/// Each window is a function of l / w for a width w (typical: w = L, so band L - 1 keeps
/// a little weight and every band past the set would get none).
///   Hann:    h_l = (1 + cos(pi l / w)) / 2   for l < w, 0 beyond
///   Lanczos: h_l = sin(pi l / w) / (pi l / w) (h_0 = 1), for l < w, 0 beyond
/// What a window costs is reported by `sh_window_cost`: the fraction of the energy
/// (int f^2 dw) and of the peak value it keeps. `sh_nonnegative_window_width` finds the
/// widest window of a family that leaves no negative value: for a directional light's
/// irradiance that is w ~ 2 for both families (bands 0 and 1 only, a quarter of the energy
/// gone) at every order, since any weight on band 2 and above with band 1 intact dips below
/// zero somewhere (docs/sh-and-irradiance-volumes.md has the table).

#include <bounce/errors.hpp>
#include <bounce/sh/basis.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <numbers>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::inline sh {

/// Hann window of width `width` (> 0; typical: L) for bands 0 .. L - 1.
template <int L>
std::array<double, std::size_t(L)> hann_window(double width) {
    require(width > 0 && std::isfinite(width), "width", "window width must be positive");
    std::array<double, std::size_t(L)> h{};
    for (int l = 0; l < L; ++l) h[std::size_t(l)] = l < width ? 0.5 * (1 + std::cos(std::numbers::pi * l / width)) : 0.0;
    return h;
}

/// Lanczos (sigma-factor, sinc) window of width `width` (> 0; typical: L) for bands
/// 0 .. L - 1.
template <int L>
std::array<double, std::size_t(L)> lanczos_window(double width) {
    require(width > 0 && std::isfinite(width), "width", "window width must be positive");
    std::array<double, std::size_t(L)> h{};
    h[0] = 1;
    for (int l = 1; l < L; ++l) {
        const double x = std::numbers::pi * l / width;
        h[std::size_t(l)] = l < width ? std::sin(x) / x : 0.0;
    }
    return h;
}

/// The windows of this file, by name.
enum class sh_window_family { hann, lanczos };

/// The window of `family` with width `width` for bands 0 .. L - 1.
template <int L>
std::array<double, std::size_t(L)> sh_window(sh_window_family family, double width) {
    return family == sh_window_family::hann ? hann_window<L>(width) : lanczos_window<L>(width);
}

/// `c` with band l scaled by `window[l]`.
template <int L, class C>
sh_coefficients<L, C> sh_apply_window(const sh_coefficients<L, C>& c, const std::array<double, std::size_t(L)>& window) {
    sh_coefficients<L, C> w = c;
    for (std::size_t i = 0; i < sh_count(L); ++i) w[i] = c[i] * window[std::size_t(sh_band(i))];
    return w;
}

/// `sh_apply_window` with the band count deduced from the window (and checked against the
/// coefficients at compile time): `sh_apply_window(radiance, hann_window<3>(w))`.
template <class C, std::size_t N, std::size_t B>
    requires(N == sh_count(int(B)))
std::array<C, N> sh_apply_window(const std::array<C, N>& c, const std::array<double, B>& window) {
    return sh_apply_window<int(B), C>(c, window);
}

/// What a window costs one function (one channel).
struct window_cost {
    double energy_kept = 1;  ///< int f_windowed^2 dw / int f^2 dw (Parseval: sums of squares)
    double peak_kept = 1;    ///< max f_windowed / max f over the probe directions
    double min_before = 0;   ///< smallest value of f over the probe directions (negative: a lobe)
    double min_after = 0;    ///< the same after windowing
};

/// Unit directions of the spherical Fibonacci set of `count` points (Swinbank and Purser
/// 2006), near-uniform on the sphere; point j has z = 1 - (2 j + 1) / count.
inline glm::dvec3 spherical_fibonacci_direction(std::size_t j, std::size_t count) {
    const double golden = (1 + std::sqrt(5.0)) / 2;
    const double z = 1 - (2 * double(j) + 1) / double(count);
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = 2 * std::numbers::pi * (double(j) / golden - std::floor(double(j) / golden));
    return {r * std::cos(phi), r * std::sin(phi), z};
}

/// The cost of `window` to the function with coefficients `c`: energy exactly, peak and
/// minima over `probes` spherical Fibonacci directions (typical: 16384, a spacing of
/// sqrt(4 pi / 16384) = 1.6 degrees; a peak between probes is missed by at most the
/// function's variation over that spacing). Throws parameter_error when probes = 0 or the
/// function is zero.
template <int L>
window_cost sh_window_cost(const sh_coefficients<L, double>& c, const std::array<double, std::size_t(L)>& window,
                           std::size_t probes = 16384) {
    require(probes > 0, "probes", "need at least one probe direction");
    double energy = 0, kept = 0;
    for (std::size_t i = 0; i < sh_count(L); ++i) {
        const double h = window[std::size_t(sh_band(i))];
        energy += c[i] * c[i];
        kept += h * h * c[i] * c[i];
    }
    require(energy > 0, "c", "the function is zero");
    const auto w = sh_apply_window<L, double>(c, window);
    double peak = -INFINITY, peak_w = -INFINITY, lo = INFINITY, lo_w = INFINITY;
    for (std::size_t j = 0; j < probes; ++j) {
        const glm::dvec3 d = spherical_fibonacci_direction(j, probes);
        const double f = sh_evaluate<L, double, glm::dvec3>(c, d), fw = sh_evaluate<L, double, glm::dvec3>(w, d);
        peak = std::max(peak, f);
        peak_w = std::max(peak_w, fw);
        lo = std::min(lo, f);
        lo_w = std::min(lo_w, fw);
    }
    return {kept / energy, peak_w / peak, lo, lo_w};
}

/// `sh_window_cost` with the band count deduced from the window: `sh_window_cost(c, h)`.
template <class C, std::size_t N, std::size_t B>
    requires std::same_as<C, double> && (N == sh_count(int(B)))
window_cost sh_window_cost(const std::array<C, N>& c, const std::array<double, B>& window, std::size_t probes = 16384) {
    return sh_window_cost<int(B)>(c, window, probes);
}

/// The widest width w <= `max_width` (typical: L), on a grid of step `resolution`
/// (typical: 1/64), for which the window of `family` leaves no negative value of the
/// function `c` on `probes` spherical Fibonacci directions (typical: 4096). The scan runs
/// downwards from `max_width` because the smallest value is not monotonic in w; it ends by
/// w = 1 at the latest, where only band 0 is left. Between probes the function can dip
/// below zero by at most 1/2 max|f''| (probe spacing)^2. Throws parameter_error naming "c"
/// when c_00 < 0 (no window can help), or when the arguments are out of range.
template <int L>
double sh_nonnegative_window_width(const sh_coefficients<L, double>& c, sh_window_family family, double max_width,
                                   std::size_t probes = 4096, double resolution = 1.0 / 64) {
    require(c[0] >= 0, "c", "the function's mean is negative: no window makes it non-negative");
    require(max_width > 0 && std::isfinite(max_width), "max_width", "must be positive");
    require(resolution > 0 && resolution < max_width, "resolution", "must be positive and below max_width");
    require(probes > 0, "probes", "need at least one probe direction");
    std::vector<std::array<double, sh_count(L)>> basis(probes);
    for (std::size_t j = 0; j < probes; ++j) basis[j] = sh_basis<L, double, glm::dvec3>(spherical_fibonacci_direction(j, probes));
    for (double w = max_width; w > 0; w -= resolution) {
        const auto h = sh_window<L>(family, w);
        const auto cw = sh_apply_window<L, double>(c, h);
        bool nonnegative = true;
        for (std::size_t j = 0; j < probes && nonnegative; ++j) {
            double f = 0;
            for (std::size_t i = 0; i < sh_count(L); ++i) f += cw[i] * basis[j][i];
            nonnegative = f >= 0;
        }
        if (nonnegative) return w;
    }
    return resolution;
}

/// `sh_nonnegative_window_width` with the band count deduced from `c`.
template <class C, std::size_t N>
    requires std::same_as<C, double> && (sh_bands_of(N) > 0)
double sh_nonnegative_window_width(const std::array<C, N>& c, sh_window_family family, double max_width,
                                   std::size_t probes = 4096, double resolution = 1.0 / 64) {
    return sh_nonnegative_window_width<sh_bands_of(N)>(c, family, max_width, probes, resolution);
}

}  // namespace bounce::sh
