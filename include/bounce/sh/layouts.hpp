#pragma once
/// \file sh/layouts.hpp
/// Converters between bounce's SH layout (sh/basis.hpp: index l (l + 1) + m, real SH with
/// the Condon-Shortley phase, RGB as one vector per coefficient) and layouts other engines
/// use:
/// - *no phase*: the same index order and normalization without (-1)^m, so
///   Y_1-1 = +0.4886 y, Y_11 = +0.4886 x, Y_2-1 = +1.0925 y z, Y_21 = +1.0925 x z: the
///   convention of three.js's SphericalHarmonics3 and of Ivanic and Ruedenberg's rotation
///   paper. bounce's own layout is that of Sloan's papers and DirectXMath's XMSHEvalDirection.
/// - *channel-major* (planar): all coefficients of red, then green, then blue, as float
///   arrays uploaded to uniform blocks or textures are often laid out.

#include <bounce/sh/basis.hpp>

#include <array>
#include <cstddef>

#include <glm/vec3.hpp>

namespace bounce::inline sh {

/// The coefficients of the same function in the no-phase convention: coefficient (l, m)
/// times (-1)^m. Applying it twice gives the input back.
template <int L, class C>
sh_coefficients<L, C> sh_without_condon_shortley_phase(const sh_coefficients<L, C>& c) {
    sh_coefficients<L, C> out = c;
    for (int l = 1; l < L; ++l)
        for (int m = -l; m <= l; ++m)
            if (m % 2 != 0) out[sh_index(l, m)] = -c[sh_index(l, m)];
    return out;
}

/// bounce's coefficients from no-phase ones (the same sign flip).
template <int L, class C>
sh_coefficients<L, C> sh_with_condon_shortley_phase(const sh_coefficients<L, C>& no_phase) {
    return sh_without_condon_shortley_phase<L, C>(no_phase);
}

/// `sh_without_condon_shortley_phase` with L and C deduced from `c`.
template <class C, std::size_t N>
    requires(sh_bands_of(N) > 0)
std::array<C, N> sh_without_condon_shortley_phase(const std::array<C, N>& c) {
    return sh_without_condon_shortley_phase<sh_bands_of(N), C>(c);
}

/// `sh_with_condon_shortley_phase` with L and C deduced from `no_phase`.
template <class C, std::size_t N>
    requires(sh_bands_of(N) > 0)
std::array<C, N> sh_with_condon_shortley_phase(const std::array<C, N>& no_phase) {
    return sh_with_condon_shortley_phase<sh_bands_of(N), C>(no_phase);
}

/// Channel-major copy of RGB coefficients: element [channel * L^2 + i].
template <int L, class T, glm::qualifier Q>
std::array<T, 3 * sh_count(L)> sh_to_channel_major(const sh_coefficients<L, glm::vec<3, T, Q>>& c) {
    std::array<T, 3 * sh_count(L)> out{};
    for (std::size_t i = 0; i < sh_count(L); ++i)
        for (int k = 0; k < 3; ++k) out[std::size_t(k) * sh_count(L) + i] = c[i][k];
    return out;
}

/// `sh_to_channel_major` with L deduced from `c`.
template <class T, glm::qualifier Q, std::size_t N>
    requires(sh_bands_of(N) > 0)
std::array<T, 3 * N> sh_to_channel_major(const std::array<glm::vec<3, T, Q>, N>& c) {
    return sh_to_channel_major<sh_bands_of(N), T, Q>(c);
}

/// RGB coefficients from a channel-major array (`sh_to_channel_major`'s inverse).
template <int L, class T>
sh_coefficients<L, glm::vec<3, T>> sh_from_channel_major(const std::array<T, 3 * sh_count(L)>& planar) {
    sh_coefficients<L, glm::vec<3, T>> out{};
    for (std::size_t i = 0; i < sh_count(L); ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = planar[std::size_t(k) * sh_count(L) + i];
    return out;
}

/// `sh_from_channel_major` with L deduced from `planar` (3 L^2 values).
template <class T, std::size_t N>
    requires(N % 3 == 0 && sh_bands_of(N / 3) > 0)
std::array<glm::vec<3, T>, N / 3> sh_from_channel_major(const std::array<T, N>& planar) {
    return sh_from_channel_major<sh_bands_of(N / 3), T>(planar);
}

}  // namespace bounce::sh
