#pragma once
/// \file sh/basis.hpp
/// The real spherical-harmonics basis Y_lm at a unit direction, as a kernel: polynomial in
/// (x, y, z), no trigonometry, loops with compile-time bounds. Every `sh_*.hpp` header uses
/// the convention stated here, once:
///
/// - A *band* l is the 2l + 1 functions Y_l,-l .. Y_l,l of degree l.
/// - The template parameter `L` of every SH function counts *bands*: bands 0 .. L - 1,
///   L^2 coefficients. The *order* of such a set is its highest band, L - 1: "order 2" is
///   L = 3, 9 coefficients, the set irradiance needs (Ramamoorthi and Hanrahan 2001).
/// - Coefficient index l (l + 1) + m for -l <= m <= l (`sh_index`): band-major, m rising.
/// - Normalization and phase (Sloan, "Stupid Spherical Harmonics Tricks", GDC 2008, and
///   "Efficient Spherical Harmonic Evaluation", JCGT 2013):
///     Y_l0  = K_l0 P_l^0(z),
///     Y_lm  = sqrt(2) K_lm cos(m phi) P_l^m(z),   m > 0,
///     Y_l-m = sqrt(2) K_lm sin(m phi) P_l^m(z),   m > 0,
///     K_lm  = sqrt((2l + 1) / (4 pi) (l - m)! / (l + m)!),
///   with the Condon-Shortley phase (-1)^m included in P_l^m, so Y_1-1 = -0.4886 y,
///   Y_10 = 0.4886 z, Y_11 = -0.4886 x. The basis is orthonormal on the unit sphere, so a
///   function's coefficients are c_lm = int f Y_lm dw and int f^2 dw = sum c_lm^2 (Parseval).
/// - Every function that takes coefficients also deduces L from them (`sh_evaluate(c, d)`,
///   `sh_apply_window(c, hann_window<3>(w))`, `sh_irradiance(radiance, n)`); L is spelled
///   only where nothing carries it (a projection's result, a window's length).
/// - z is the polar axis, phi is measured from +x towards +y. sh/layouts.hpp converts to
///   the layouts other engines use (no phase, channel-major).

#include <bounce/concepts.hpp>
#include <bounce/vocabulary.hpp>

#include <array>
#include <cstddef>
#include <numbers>
#include <type_traits>
#include <utility>

namespace bounce::detail {

/// sqrt for constant expressions: Newton's iteration from above, which decreases
/// monotonically to within one ulp of the root and stops when it no longer decreases.
constexpr double constexpr_sqrt(double x) noexcept {
    if (!(x > 0)) return 0;
    double r = x > 1 ? x : 1;
    for (;;) {
        const double next = 0.5 * (r + x / r);
        if (!(next < r)) return r;
        r = next;
    }
}

/// Coefficients of the normalized associated-Legendre recurrence: with
/// Q_l^m = s_m K_lm P_l^m(z) / sin^m(theta) (s_0 = 1, s_m = sqrt 2),
///   Q_m^m     = s_m K_mm (-1)^m (2m - 1)!!                        (qmm)
///   Q_m+1^m   = sqrt(2m + 3) z Q_m^m
///   Q_l^m     = a_lm z Q_l-1^m - b_lm Q_l-2^m,
///   a_lm = sqrt((4l^2 - 1) / (l^2 - m^2)),
///   b_lm = sqrt((2l + 1) ((l - 1)^2 - m^2) / ((2l - 3) (l^2 - m^2))).
/// Folding K_lm into the recurrence keeps every Q of order one (the unnormalized
/// (2m - 1)!! overflows float near m = 17).
template <int L>
struct sh_recurrence {
    std::array<double, std::size_t(L)> qmm{};
    std::array<std::array<double, std::size_t(L)>, std::size_t(L)> a{}, b{};  // [l][m]
};

template <int L>
constexpr sh_recurrence<L> make_sh_recurrence() noexcept {
    sh_recurrence<L> r;
    // K_mm^2 (2m - 1)!!^2 = (2m + 1) / (4 pi) prod_{k=1..m} (2k - 1) / (2k).
    double ratio = 1;
    for (int m = 0; m < L; ++m) {
        if (m > 0) ratio *= double(2 * m - 1) / double(2 * m);
        const double q = constexpr_sqrt((2 * m + 1) / (4 * std::numbers::pi) * ratio * (m > 0 ? 2.0 : 1.0));
        r.qmm[std::size_t(m)] = m % 2 ? -q : q;
        for (int l = m + 1; l < L; ++l) {
            const double l2 = double(l) * l, m2 = double(m) * m;
            r.a[std::size_t(l)][std::size_t(m)] = constexpr_sqrt((4 * l2 - 1) / (l2 - m2));
            if (l >= m + 2)
                r.b[std::size_t(l)][std::size_t(m)] =
                    constexpr_sqrt((2 * l + 1) * (double(l - 1) * (l - 1) - m2) / ((2 * l - 3) * (l2 - m2)));
        }
    }
    return r;
}

template <int L>
inline constexpr sh_recurrence<L> sh_recurrence_v = make_sh_recurrence<L>();

/// The scalar of a vector type (double for glm::dvec3, glsl::f32 for glsl::vec3): what the
/// SH functions that deduce their arguments pass as `T`.
template <class V>
using vector_scalar_t = std::remove_cvref_t<decltype(std::declval<const V&>().x)>;

}  // namespace bounce::detail

namespace bounce::inline sh {

/// Index of Y_lm in the array `sh_basis` returns: l (l + 1) + m, for -l <= m <= l.
constexpr std::size_t sh_index(int l, int m) noexcept { return std::size_t(l * (l + 1) + m); }

/// Number of coefficients of bands 0 .. bands - 1: bands^2.
constexpr std::size_t sh_count(int bands) noexcept { return std::size_t(bands) * std::size_t(bands); }

/// The band count L of `count` coefficients (count = L^2), or 0 when `count` is not the
/// size of whole bands. What lets an SH function deduce L from a coefficient array.
constexpr int sh_bands_of(std::size_t count) noexcept {
    int l = 0;
    while (sh_count(l + 1) <= count) ++l;
    return sh_count(l) == count ? l : 0;
}

/// The band l of coefficient index i (the l with l^2 <= i < (l + 1)^2).
constexpr int sh_band(std::size_t i) noexcept {
    int l = 0;
    while (sh_count(l + 1) <= i) ++l;
    return l;
}

/// Coefficients of bands 0 .. L - 1, index `sh_index(l, m)`; `C` is a number (one channel)
/// or a vector (RGB: glm::vec3, glm::dvec3, glsl::vec3).
template <int L, class C>
using sh_coefficients = std::array<C, sh_count(L)>;

/// Real spherical harmonics Y_lm(d) for the bands l < L (L*L values, index
/// `sh_index(l, m)`) at the unit direction `d`; see the file comment for the convention.
/// cos(m phi) sin^m(theta) and sin(m phi) sin^m(theta) are the real and imaginary parts of
/// (x + i y)^m, built by complex multiplication; the z-dependence by the normalized
/// Legendre recurrence (Sloan 2013, section 3). Typical L: 3 (irradiance), up to 32.
template <int L, real T, vec3_of<T> V>
std::array<T, std::size_t(L) * std::size_t(L)> sh_basis(const V& d) {
    static_assert(L >= 1 && L <= 32, "sh_basis: bands 1..32");
    constexpr const auto& k = detail::sh_recurrence_v<L>;
    std::array<T, std::size_t(L) * std::size_t(L)> y;
    T c = d.x, s = d.y;  // (x + i y)^m for m = 1
    for (int m = 0; m < L; ++m) {
        const auto mi = std::size_t(m);
        T q_prev2 = T(0), q_prev = T(0);
        for (int l = m; l < L; ++l) {
            const auto li = std::size_t(l);
            T q = T(k.qmm[mi]);
            if (l == m + 1) q = T(k.a[li][mi] * k.qmm[mi]) * d.z;
            else if (l > m + 1) q = T(k.a[li][mi]) * d.z * q_prev - T(k.b[li][mi]) * q_prev2;
            if (m == 0) {
                y[sh_index(l, 0)] = q;
            } else {
                y[sh_index(l, m)] = q * c;
                y[sh_index(l, -m)] = q * s;
            }
            q_prev2 = q_prev;
            q_prev = q;
        }
        if (m >= 1 && m + 1 < L) {
            const T c_next = d.x * c - d.y * s;
            s = d.x * s + d.y * c;
            c = c_next;
        }
    }
    return y;
}

/// The function with coefficients `c` at the unit direction `d`: sum_i c_i Y_i(d).
/// `C` is the coefficient type (T for one channel, V for RGB).
template <int L, real T, vec3_of<T> V, class C>
C sh_evaluate(const std::array<C, sh_count(L)>& c, const V& d) {
    const auto y = sh_basis<L, T, V>(d);
    C sum = c[0] * y[0];
    for (std::size_t i = 1; i < sh_count(L); ++i) sum = sum + c[i] * y[i];
    return sum;
}

/// `sh_evaluate` with L, T and C deduced from the arguments: `sh_evaluate(c, d)`. Every SH
/// function that takes coefficients has such a form (the coefficient type first, so that a
/// call spelling `<L, ...>` never reaches it); the spelled form is the kernel GLSL prints.
template <class C, std::size_t N, class V>
    requires(sh_bands_of(N) > 0)
C sh_evaluate(const std::array<C, N>& c, const V& d) {
    return sh_evaluate<sh_bands_of(N), detail::vector_scalar_t<V>, V, C>(c, d);
}

}  // namespace bounce::sh
