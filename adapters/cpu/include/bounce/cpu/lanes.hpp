#pragma once
/// \file lanes.hpp
/// Four floats computed at once: a scalar type and a vector type that satisfy the kernel
/// contract of concepts.hpp, so a kernel of include/bounce/ runs on four pixels per
/// instruction with no second copy of its math (the third instantiation, beside plain
/// numbers and GLSL expressions).
///
/// Every lane computes exactly what the scalar float instantiation computes: the same
/// IEEE operations (+ - * / and sqrt are correctly rounded in both) in the same order as
/// GLM's (dot is (x + y) + z, cross and clamp as GLM writes them). Fused multiply-add is
/// the one exception: on a target with FMA (-march=haswell and later) GCC's default
/// -ffp-contract=fast fuses a*b+c differently in scalar and vector code, and lanes then
/// differ from the scalar kernel in the last ulp or two (226 of 18,067 checks of
/// tests/cpu/test_lanes.cpp with -march=native). Build with -ffp-contract=off where bitwise
/// agreement matters; the default x86-64 target has no FMA, and there the CPU splat is
/// bitwise the scalar kernel, as tests/cpu/test_lanes.cpp checks lane by lane (with GCC 12
/// and Clang 14).
///
/// Built on the GCC/Clang vector extensions, which compile to SSE on x86-64 and to NEON on
/// AArch64 (and to scalar code elsewhere).

#include <bounce/concepts.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace bounce::cpu::lanes {

using f32v = float __attribute__((vector_size(16)));
using i32v = std::int32_t __attribute__((vector_size(16)));

/// A lane-wise comparison result: all bits set where it holds.
struct mask4 {
    i32v bits;
    friend mask4 operator&&(mask4 a, mask4 b) noexcept { return {a.bits & b.bits}; }
    friend mask4 operator||(mask4 a, mask4 b) noexcept { return {a.bits | b.bits}; }
    friend mask4 operator!(mask4 a) noexcept { return {~a.bits}; }
    bool any() const noexcept { return (bits[0] | bits[1] | bits[2] | bits[3]) != 0; }
    bool operator[](int i) const noexcept { return bits[i] != 0; }
};

/// Four floats.
struct f32x4 {
    f32v v;

    f32x4() noexcept : v{0.f, 0.f, 0.f, 0.f} {}
    f32x4(f32v x) noexcept : v(x) {}
    /// Broadcast; a double rounds to float as `T(x)` does in the scalar kernel.
    template <class A>
        requires std::is_arithmetic_v<A>
    explicit f32x4(A x) noexcept : v{float(x), float(x), float(x), float(x)} {}
    f32x4(float a, float b, float c, float d) noexcept : v{a, b, c, d} {}

    /// Four consecutive floats (any alignment).
    static f32x4 load(const float* p) noexcept {
        f32v x;
        std::memcpy(&x, p, sizeof x);
        return {x};
    }

    /// Stores the four floats at `p` (any alignment).
    void store(float* p) const noexcept { std::memcpy(p, &v, sizeof v); }

    float operator[](int i) const noexcept { return v[i]; }

    friend f32x4 operator+(f32x4 a, f32x4 b) noexcept { return {a.v + b.v}; }
    friend f32x4 operator-(f32x4 a, f32x4 b) noexcept { return {a.v - b.v}; }
    friend f32x4 operator*(f32x4 a, f32x4 b) noexcept { return {a.v * b.v}; }
    friend f32x4 operator/(f32x4 a, f32x4 b) noexcept { return {a.v / b.v}; }
    friend f32x4 operator-(f32x4 a) noexcept { return {-a.v}; }
    friend mask4 operator<(f32x4 a, f32x4 b) noexcept { return {a.v < b.v}; }
    friend mask4 operator>(f32x4 a, f32x4 b) noexcept { return {a.v > b.v}; }
    friend mask4 operator<=(f32x4 a, f32x4 b) noexcept { return {a.v <= b.v}; }
    friend mask4 operator>=(f32x4 a, f32x4 b) noexcept { return {a.v >= b.v}; }
};

/// The 4x4 transpose: lane i of the result holds (a[i], b[i], c[i], d[i]).
inline std::array<f32x4, 4> transpose(f32x4 a, f32x4 b, f32x4 c, f32x4 d) noexcept {
#if defined(__SSE__)
    __m128 r0 = a.v, r1 = b.v, r2 = c.v, r3 = d.v;
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    return {f32x4{r0}, f32x4{r1}, f32x4{r2}, f32x4{r3}};
#else
    return {f32x4(a[0], b[0], c[0], d[0]), f32x4(a[1], b[1], c[1], d[1]), f32x4(a[2], b[2], c[2], d[2]),
            f32x4(a[3], b[3], c[3], d[3])};
#endif
}

/// `a` where `m` holds, else `b`.
inline f32x4 select(mask4 m, f32x4 a, f32x4 b) noexcept {
    i32v ai, bi;
    std::memcpy(&ai, &a.v, sizeof ai);
    std::memcpy(&bi, &b.v, sizeof bi);
    const i32v r = (ai & m.bits) | (bi & ~m.bits);
    f32v out;
    std::memcpy(&out, &r, sizeof out);
    return {out};
}

inline f32x4 sqrt(f32x4 x) noexcept {
#if defined(__SSE__)
    return {_mm_sqrt_ps(x.v)};
#else
    return {x[0] >= 0.f ? std::sqrt(x[0]) : NAN, x[1] >= 0.f ? std::sqrt(x[1]) : NAN,
            x[2] >= 0.f ? std::sqrt(x[2]) : NAN, x[3] >= 0.f ? std::sqrt(x[3]) : NAN};
#endif
}
// The scalar vocabulary's semantics (vocabulary.hpp): min(a, b) = b < a ? b : a.
inline f32x4 min(f32x4 a, f32x4 b) noexcept { return select(b < a, b, a); }
inline f32x4 max(f32x4 a, f32x4 b) noexcept { return select(a < b, b, a); }
inline f32x4 clamp(f32x4 x, f32x4 lo, f32x4 hi) noexcept { return min(max(x, lo), hi); }
inline f32x4 abs(f32x4 x) noexcept { return select(x < f32x4(0.f), -x, x); }

/// Three components of four lanes each (a structure of arrays).
struct vec3x4 {
    f32x4 x, y, z;

    vec3x4() noexcept = default;
    vec3x4(f32x4 a, f32x4 b, f32x4 c) noexcept : x(a), y(b), z(c) {}
    /// Four vectors, one per lane.
    template <class V3>
    static vec3x4 gather(const V3& a, const V3& b, const V3& c, const V3& d) noexcept {
        return {{a.x, b.x, c.x, d.x}, {a.y, b.y, c.y, d.y}, {a.z, b.z, c.z, d.z}};
    }
    /// Four consecutive vectors of three packed floats (a G-buffer row: x0 y0 z0 x1 ...),
    /// one per lane: three unaligned loads and seven shuffles instead of twelve scalar loads.
    /// The lanes hold the same floats `gather` would give them.
    static vec3x4 load_packed(const float* p) noexcept {
        const f32v a = f32x4::load(p).v, b = f32x4::load(p + 4).v, c = f32x4::load(p + 8).v;
        // a = x0 y0 z0 x1, b = y1 z1 x2 y2, c = z2 x3 y3 z3
#if defined(__SSE__)
        const __m128 bc_x = _mm_shuffle_ps(b, c, _MM_SHUFFLE(0, 1, 0, 2));  // x2 . x3 .
        const __m128 ab_y = _mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 0, 0, 1));  // y0 . y1 .
        const __m128 bc_y = _mm_shuffle_ps(b, c, _MM_SHUFFLE(0, 2, 0, 3));  // y2 . y3 .
        const __m128 ab_z = _mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 1, 0, 2));  // z0 . z1 .
        const f32v x = _mm_shuffle_ps(a, bc_x, _MM_SHUFFLE(2, 0, 3, 0));
        const f32v y = _mm_shuffle_ps(ab_y, bc_y, _MM_SHUFFLE(2, 0, 2, 0));
        const f32v z = _mm_shuffle_ps(ab_z, c, _MM_SHUFFLE(3, 0, 2, 0));
#else
        const f32v x{a[0], a[3], b[2], c[1]}, y{a[1], b[0], b[3], c[2]}, z{a[2], b[1], c[0], c[3]};
#endif
        return {{x}, {y}, {z}};
    }
    /// One vector in every lane.
    template <class V3>
    static vec3x4 broadcast(const V3& a) noexcept {
        return {f32x4(float(a.x)), f32x4(float(a.y)), f32x4(float(a.z))};
    }

    friend vec3x4 operator+(const vec3x4& a, const vec3x4& b) noexcept { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
    friend vec3x4 operator-(const vec3x4& a, const vec3x4& b) noexcept { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
    friend vec3x4 operator*(const vec3x4& a, const vec3x4& b) noexcept { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
    friend vec3x4 operator*(const vec3x4& a, f32x4 s) noexcept { return {a.x * s, a.y * s, a.z * s}; }
    friend vec3x4 operator*(f32x4 s, const vec3x4& a) noexcept { return {s * a.x, s * a.y, s * a.z}; }
    friend vec3x4 operator/(const vec3x4& a, f32x4 s) noexcept { return {a.x / s, a.y / s, a.z / s}; }
    friend vec3x4 operator-(const vec3x4& a) noexcept { return {-a.x, -a.y, -a.z}; }
};

// GLM's order of operations (glm/detail/func_geometric.inl).
inline f32x4 dot(const vec3x4& a, const vec3x4& b) noexcept {
    const vec3x4 t = a * b;
    return t.x + t.y + t.z;
}
inline vec3x4 cross(const vec3x4& a, const vec3x4& b) noexcept {
    return {a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y};
}
inline f32x4 length(const vec3x4& a) noexcept { return sqrt(dot(a, a)); }
inline vec3x4 normalize(const vec3x4& a) noexcept { return a * (f32x4(1.f) / sqrt(dot(a, a))); }
inline vec3x4 clamp(const vec3x4& v, const vec3x4& lo, const vec3x4& hi) noexcept {
    return {clamp(v.x, lo.x, hi.x), clamp(v.y, lo.y, hi.y), clamp(v.z, lo.z, hi.z)};
}
inline vec3x4 select(mask4 m, const vec3x4& a, const vec3x4& b) noexcept {
    return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}

static_assert(real<f32x4>);
static_assert(vec3_of<vec3x4, f32x4>);

}  // namespace bounce::cpu::lanes
