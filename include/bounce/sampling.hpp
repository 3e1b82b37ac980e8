#pragma once
/// \file sampling.hpp
/// Sampling helpers every technique uses: hemisphere maps, 2D point sets with fixed
/// seeds, and an orthonormal basis that is stable for every unit normal.
///
/// The maps are kernels (select instead of branches), so the GL adapter can print them.

#include <bounce/errors.hpp>
#include <bounce/vocabulary.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <initializer_list>
#include <numbers>
#include <vector>

namespace bounce {

/// Tangent frame {t, b} completing a unit normal n to a right-handed orthonormal basis
/// (t x b = n). Duff et al., "Building an Orthonormal Basis, Revisited" (JCGT 2017):
/// no division by a vanishing quantity for any n, including n = (0, 0, -1).
template <real T, vec3_of<T> V>
std::array<V, 2> orthonormal_basis(const V& n) {
    const T sign = select(n.z >= T(0), T(1), T(-1));
    const T a = T(-1) / (sign + n.z);
    const T b = n.x * n.y * a;
    return {V(T(1) + sign * n.x * n.x * a, sign * b, -sign * n.x),
            V(b, sign + n.y * n.y * a, -n.y)};
}

/// Shirley-Chiu concentric map from the unit square to the unit disc (area preserving).
/// Written branch-free: the wedge is chosen with select.
template <real T, vec2_of<T> V2>
V2 concentric_disc(const V2& u) {
    const T pi = T(std::numbers::pi);
    const T ox = T(2) * u.x - T(1), oy = T(2) * u.y - T(1);
    const auto first = abs(ox) > abs(oy);
    // Guard the origin: both branches divide by one of the offsets.
    const T safe_x = select(abs(ox) > T(0), ox, T(1)), safe_y = select(abs(oy) > T(0), oy, T(1));
    const T r = select(first, ox, oy);
    const T theta = select(first, (pi / T(4)) * (oy / safe_x), (pi / T(2)) - (pi / T(4)) * (ox / safe_y));
    return V2(r * cos(theta), r * sin(theta));
}

/// Cosine-weighted direction on the hemisphere around +z from u in [0,1)^2;
/// pdf = cos(theta) / pi. Malley's method over the concentric map.
template <real T, vec3_of<T> V, vec2_of<T> V2>
V cosine_hemisphere(const V2& u) {
    const V2 d = concentric_disc<T, V2>(u);
    return V(d.x, d.y, sqrt(max(T(0), T(1) - d.x * d.x - d.y * d.y)));
}

/// Uniform direction on the hemisphere around +z; pdf = 1 / (2 pi).
template <real T, vec3_of<T> V, vec2_of<T> V2>
V uniform_hemisphere(const V2& u) {
    const T z = u.x, r = sqrt(max(T(0), T(1) - z * z)), phi = T(2 * std::numbers::pi) * u.y;
    return V(r * cos(phi), r * sin(phi), z);
}

/// Direction of sample (j, k) of an M x N stratified cosine-weighted hemisphere around +z
/// (Ward & Heckbert 1992, "Irradiance Gradients", section 3): theta_j = asin(sqrt((j + u) / M)),
/// phi_k = 2 pi (k + v) / N, with jitter (u, v) in [0,1)^2. Each of the M N cells carries
/// the same cosine-weighted solid angle, so E ~ pi / (M N) * sum of the sampled radiances.
/// `j`, `k`, `m`, `n` are passed as reals so that the kernel also instantiates for GLSL.
template <real T, vec3_of<T> V>
V stratified_cosine_direction(T j, T k, T m, T n, T u, T v) {
    const T sin2 = (j + u) / m;
    const T sin_theta = sqrt(sin2), cos_theta = sqrt(max(T(0), T(1) - sin2));
    const T phi = T(2 * std::numbers::pi) * (k + v) / n;
    return V(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

/// Barycentric weights (b1, b2) of a uniformly distributed point on a triangle from u in
/// [0,1)^2 (the square-root map, Shirley 1990; pbrt 4th ed. section A.5.4): the point is
/// (1 - b1 - b2) v0 + b1 v1 + b2 v2. The map is area preserving up to a constant, so
/// strata in u stay strata of equal area on the triangle.
template <real T, vec2_of<T> V2>
V2 uniform_triangle(const V2& u) {
    const T s = sqrt(u.x);
    return V2(s * (T(1) - u.y), s * u.y);
}

/// Local direction d (around +z) to world space around the unit normal n.
template <real T, vec3_of<T> V>
V to_world(const V& d, const V& n) {
    const auto tb = orthonormal_basis<T, V>(n);
    return tb[0] * d.x + tb[1] * d.y + n * d.z;
}

/// SplitMix64's step (Steele, Lea and Flood 2014): a bijective mix of 64 bits, for
/// deriving seeds and keys (not a generator by itself).
constexpr std::uint64_t splitmix64(std::uint64_t x) noexcept {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

/// 64 bits from the bit patterns of `values`, one splitmix64 step each: different inputs
/// (-0 and +0 included) get unrelated keys, the same inputs always the same key.
inline std::uint64_t hash_floats(std::initializer_list<float> values) noexcept {
    std::uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (const float f : values) h = splitmix64(h ^ std::bit_cast<std::uint32_t>(f));
    return h;
}

/// PCG32 (O'Neill 2014): a small, fast generator with the same stream on every platform,
/// which std::uniform_real_distribution does not promise.
class pcg32 {
public:
    explicit constexpr pcg32(std::uint64_t seed = 0x853c49e6748fea9bULL, std::uint64_t stream = 0xda3e39cb94b95bdbULL) noexcept
        : inc_((stream << 1u) | 1u) {
        next_u32();
        state_ += seed;
        next_u32();
    }
    constexpr std::uint32_t next_u32() noexcept {
        const std::uint64_t old = state_;
        state_ = old * 6364136223846793005ULL + inc_;
        const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
        const auto rot = static_cast<std::uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
    }
    /// Uniform float in [0, 1): 24 random bits, so 1 is never returned.
    constexpr float next_float() noexcept { return float(next_u32() >> 8) * 0x1p-24f; }
    /// Uniform double in [0, 1) from 53 random bits.
    constexpr double next_double() noexcept {
        const std::uint64_t hi = next_u32() >> 5, lo = next_u32() >> 6;
        return double(hi * 67108864ULL + lo) * 0x1p-53;
    }

private:
    std::uint64_t state_ = 0, inc_;
};

/// Radical inverse of i in the given prime base (van der Corput), in [0, 1).
/// The digits are reversed into an integer and divided once, so the result is exact
/// (correctly rounded) wherever the reversed integer fits a double's 53 bits.
constexpr double radical_inverse(std::uint64_t i, std::uint32_t base) noexcept {
    double reversed = 0.0, denominator = 1.0;
    while (i > 0) {
        reversed = reversed * base + double(i % base);
        denominator *= base;
        i /= base;
    }
    return reversed / denominator;
}

/// Point i of the 2D Halton sequence (bases 2 and 3), optionally rotated toroidally by
/// `shift` (Cranley-Patterson) so that different seeds give decorrelated sets.
inline glm::dvec2 halton2(std::uint64_t i, glm::dvec2 shift = {0, 0}) noexcept {
    glm::dvec2 p(radical_inverse(i, 2) + shift.x, radical_inverse(i, 3) + shift.y);
    p -= glm::floor(p);
    return p;
}

/// `nx * ny` jittered points in [0,1)^2, one per cell of an nx x ny grid, row by row,
/// from a fixed seed. Stratification bounds the variance of smooth integrands by O(N^-2)
/// in 2D against O(N^-1) for independent points.
inline std::vector<glm::vec2> stratified2(std::uint32_t nx, std::uint32_t ny, std::uint64_t seed) {
    require(nx > 0 && ny > 0, "nx/ny", "stratum counts must be positive");
    pcg32 rng(seed);
    std::vector<glm::vec2> pts;
    pts.reserve(std::size_t(nx) * ny);
    for (std::uint32_t j = 0; j < ny; ++j)
        for (std::uint32_t i = 0; i < nx; ++i) {
            // Computed in double so a point never rounds up onto the next cell's edge.
            const double x = (i + rng.next_double()) / nx, y = (j + rng.next_double()) / ny;
            pts.emplace_back(float(std::min(x, 0x1.fffffep-1)), float(std::min(y, 0x1.fffffep-1)));
        }
    return pts;
}

}  // namespace bounce
