#pragma once
/// \file sh_projection.hpp
/// SH projection of many RGB cube maps of one size at once (a probe bake's worth): the
/// direction set of a size x size cube map is the same for every probe, so Y_j(texel) times
/// the texel's exact solid angle is tabulated once (sh/projection.hpp of the core defines
/// the layout and the quadrature), and projecting a map is a matrix product.
///
/// What is tabulated, and how the product is laid out (docs/sh-and-irradiance-volumes.md
/// has the measurements):
/// - One face's table serves all six: face f looks along R_f (u, -v, 1) with R_f a signed
///   permutation, each band of SH is closed under it, so a face's coefficients are its
///   moments against the +z face's table times a fixed orthogonal matrix per face (computed
///   once by exact quadrature). Rows y and size - 1 - y differ only in the sign of the local
///   y, under which Y_lm is even (m >= 0) or odd (m < 0): only the top half is tabulated,
///   and each pair of texels is multiplied once, by its sum for even coefficients and its
///   difference for odd ones. The table is 4 ceil(size / 2) size L^2 bytes (74 KB for
///   L = 3, size 64: it stays in L2) and a texel costs 13.5 multiply-adds for L = 3.
/// - A block of rows (and of their mirror rows) is first split into r, g and b planes in a
///   streaming pass, with software prefetch 4 KB ahead, and then multiplied from L1 with
///   the accumulators of a whole parity group in registers (AVX-512: 18 + 9 accumulators of
///   16 lanes; AVX2: 9 of 8 lanes, three coefficients a pass). Splitting in registers in the
///   same pass as the products measured 1.7x slower from memory.
/// - Paths: AVX-512 (F, BW, VL), AVX2 + FMA + F16C (both checked at run time), or a portable
///   loop the compiler vectorizes for the baseline ISA.
/// - Texels are glm::vec3 (12 bytes) or `half_rgb` (IEEE binary16, 6 bytes: what a GL
///   RGB16F render target reads back as), converted in registers (F16C) on the AVX paths.
/// - Maps are projected in parallel (TBB), one map per task step; each map is summed in
///   the same order whatever the thread count, so results are bitwise reproducible for a
///   given path (the paths differ by rounding, a few float ulps of the result).
/// Float lanes add at most chunk_texels / 8 = 512 terms each, whatever the size, before
/// they go into double sums (relative rounding below 512 x 2^-24 = 3e-5 of the sum of the
/// terms' magnitudes; tests/sh checks the bound against a double reference).

#include <bounce/errors.hpp>
#include <bounce/image.hpp>
#include <bounce/sh/basis.hpp>
#include <bounce/sh/projection.hpp>
#include <bounce/sh/quadrature.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <new>
#include <span>
#include <type_traits>
#include <vector>

#include <glm/vec3.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <cpuid.h>
#include <immintrin.h>
#define BOUNCE_SH_PROJECTION_AVX2 1
#else
#define BOUNCE_SH_PROJECTION_AVX2 0
#endif

namespace bounce::cpu {

/// One RGB texel of three IEEE-754 binary16 numbers (GL_RGB16F read back with
/// GL_HALF_FLOAT), as raw bits.
struct half_rgb {
    std::uint16_t bits[3];
};
static_assert(sizeof(half_rgb) == 6, "half texels are read as packed rows");

/// The float value of binary16 bits `h` (exact: every binary16 value is a float).
constexpr float half_to_float(std::uint16_t h) noexcept {
    const std::uint32_t sign = std::uint32_t(h & 0x8000u) << 16, exponent = (h >> 10) & 0x1fu, mantissa = h & 0x3ffu;
    if (exponent == 0x1f) return std::bit_cast<float>(sign | 0x7f800000u | (mantissa << 13));  // inf, NaN
    if (exponent != 0) return std::bit_cast<float>(sign | ((exponent + 112) << 23) | (mantissa << 13));
    // Zero and subnormals: mantissa * 2^-24, exact in float.
    const float magnitude = float(mantissa) * 0x1p-24f;
    return sign ? -magnitude : magnitude;
}

/// The binary16 bits nearest to `f` (round to nearest, ties to even; overflow to
/// infinity, NaN to a quiet NaN), as GL converts floats to RGB16F.
constexpr std::uint16_t float_to_half(float f) noexcept {
    const std::uint32_t b = std::bit_cast<std::uint32_t>(f);
    const auto sign = std::uint16_t((b >> 16) & 0x8000u);
    const std::uint32_t a = b & 0x7fffffffu;
    if (a > 0x7f800000u) return std::uint16_t(sign | 0x7e00u);
    if (a >= 0x47800000u) return std::uint16_t(sign | 0x7c00u);  // >= 2^16
    if (a >= 0x38800000u) {                                       // >= 2^-14: a normal half
        std::uint32_t h = (((a >> 23) - 112) << 10) | ((a >> 13) & 0x3ffu);
        const std::uint32_t rest = a & 0x1fffu;
        if (rest > 0x1000u || (rest == 0x1000u && (h & 1u))) ++h;  // a carry may reach infinity, as it should
        return std::uint16_t(sign | h);
    }
    const std::uint32_t e = a >> 23;  // subnormal half: round(|f| 2^24)
    if (e < 102) return sign;         // below 2^-25
    const std::uint32_t m = (a & 0x7fffffu) | 0x800000u, shift = 126 - e;
    std::uint32_t h = m >> shift;
    const std::uint32_t rest = m & ((1u << shift) - 1), halfway = 1u << (shift - 1);
    if (rest > halfway || (rest == halfway && (h & 1u))) ++h;
    return std::uint16_t(sign | h);
}

/// An allocator on 64-byte boundaries (cache lines: whole-line 512-bit loads).
template <class T>
struct line_allocator {
    using value_type = T;
    static constexpr std::align_val_t alignment{64};
    line_allocator() noexcept = default;
    template <class U>
    line_allocator(const line_allocator<U>&) noexcept {}
    T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), alignment)); }
    void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, alignment); }
    template <class U>
    bool operator==(const line_allocator<U>&) const noexcept { return true; }
};

/// Which code `cube_map_sh_projector` runs.
enum class sh_projection_path {
    automatic,  ///< the widest of avx512 / avx2 the CPU has (checked at run time), else portable
    avx2,       ///< AVX2 + FMA + F16C where the CPU has them, else portable (for comparison and testing)
    portable,   ///< plain loops only (for comparison and testing)
};

/// Projects RGB cube maps of a fixed size (glm::vec3 or half_rgb texels) onto bands
/// 0 .. L - 1. Construct once per size (it tabulates ceil(size / 2) size L^2 weights), then
/// call `project` for each batch of maps.
template <int L>
class cube_map_sh_projector {
public:
    static constexpr std::size_t coefficients = sh_count(L);
    /// Texel pairs summed in float before the sums go into double: a float accumulator lane
    /// adds at most chunk_texels / 8 products, whatever the size (the error bound of tests/sh).
    static constexpr std::size_t chunk_texels = 4096;
    static constexpr std::size_t maps_per_task = 4;  ///< maps one TBB task projects (one after the other)
    /// How far ahead of the texel being multiplied the AVX paths ask for texels (bytes).
    static constexpr std::size_t prefetch_bytes = 4096;

    /// Tables for size x size faces (typical: 64; 1 to 4096). Throws parameter_error naming
    /// "size" outside that range.
    explicit cube_map_sh_projector(std::size_t size, sh_projection_path path = sh_projection_path::automatic)
        : size_(size), half_rows_((size + 1) / 2), stride_((half_rows_ * size + 15) / 16 * 16), kind_(choose(path)) {
        static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "texel rows are read as packed floats");
        require(size >= 1 && size <= 4096, "size", "cube-map size must be 1 to 4096 texels");
        // Each coefficient's weights start on a 64-byte boundary (whole-line vector loads);
        // 16 floats of padding: the vector loops read up to 15 weights past a run's end (times
        // zero texels).
        table_.assign(coefficients * stride_ + 16, 0.f);
        for (std::size_t y = 0; y < half_rows_; ++y)
            for (std::size_t x = 0; x < size_; ++x) {
                const auto basis = sh_basis<L, double, glm::dvec3>(cube_texel_direction(cube_face::positive_z, size_, x, y));
                const double dw = cube_texel_solid_angle(size_, x, y);
                for (std::size_t j = 0; j < coefficients; ++j) table_[j * stride_ + y * size_ + x] = float(basis[j] * dw);
            }
        face_mix_ = face_mixing_matrices();
    }

    std::size_t size() const noexcept { return size_; }
    /// The code that runs: "avx512", "avx2" or "portable".
    const char* path_name() const noexcept { return kind_ == kind::avx512 ? "avx512" : kind_ == kind::avx2 ? "avx2" : "portable"; }
    /// Bytes of the table (4 ceil(size / 2) size L^2: half of one face, shared by the six).
    std::size_t table_bytes() const noexcept { return table_.size() * sizeof(float); }

    /// SH coefficients of every map of `maps` into `out` (one per map), in parallel over
    /// maps. Throws parameter_error naming "out" when the counts differ and "maps" when a
    /// map is not a cube of this projector's size.
    void project(std::span<const cube_map_view<const glm::vec3>> maps, std::span<sh_coefficients<L, glm::vec3>> out) const {
        project_all(maps, out);
    }

    /// `project` for half-float maps.
    void project(std::span<const cube_map_view<const half_rgb>> maps, std::span<sh_coefficients<L, glm::vec3>> out) const {
        project_all(maps, out);
    }

    /// The coefficients of one map (no parallelism).
    sh_coefficients<L, glm::vec3> project(const cube_map_view<const glm::vec3>& map) const {
        require_cube_map(map, "map");
        require(map.size() == size_, "map", "the map's size differs from the projector's");
        return project_map(map);
    }

private:
    enum class kind { portable, avx2, avx512 };
    // Moment sums of one run, m[3 j + c] (coefficient j of the shared table, channel c).
    using moments = std::array<double, 3 * coefficients>;

    static kind choose(sh_projection_path path) noexcept {
#if BOUNCE_SH_PROJECTION_AVX2
        if (path == sh_projection_path::portable) return kind::portable;
        // F16C through CPUID leaf 1 (ECX bit 29): Clang 14's __builtin_cpu_supports does not know it.
        unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
        const bool f16c = __get_cpuid(1, &eax, &ebx, &ecx, &edx) && (ecx & (1u << 29));
        const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && f16c;
        if (avx2 && path == sh_projection_path::automatic && __builtin_cpu_supports("avx512f") &&
            __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl"))
            return kind::avx512;
        return avx2 ? kind::avx2 : kind::portable;
#else
        (void)path;
        return kind::portable;
#endif
    }

    // The six faces share the +z face's table: face f looks along R_f (u, -v, 1), R_f a
    // signed permutation (sh/projection.hpp), and each band of SH is closed under it, so
    // Y_i(R_f w) = sum_j M_f[i][j] Y_j(w) with M_f[i][j] = int Y_i(R_f w) Y_j(w) dw,
    // integrated exactly (to rounding) by a sphere rule of bands < L + 1.
    static std::array<std::array<double, coefficients * coefficients>, 6> face_mixing_matrices() {
        std::array<std::array<double, coefficients * coefficients>, 6> mix{};
        const auto rule = sphere_quadrature(L + 1, 2 * L + 2);
        for (int f = 0; f < 6; ++f) {
            const glm::dvec3 centre = cube_face_direction(cube_face(f), 0, 0);
            const glm::dvec3 along_u = cube_face_direction(cube_face(f), 1, 0) - centre;
            const glm::dvec3 along_v = centre - cube_face_direction(cube_face(f), 0, 1);  // local y is -v
            for (const auto& q : rule) {
                const auto local = sh_basis<L, double, glm::dvec3>(q.d);
                const auto world = sh_basis<L, double, glm::dvec3>(q.d.x * along_u + q.d.y * along_v + q.d.z * centre);
                for (std::size_t i = 0; i < coefficients; ++i)
                    for (std::size_t j = 0; j < coefficients; ++j) mix[std::size_t(f)][i * coefficients + j] += q.w * world[i] * local[j];
            }
            for (double& m : mix[std::size_t(f)]) m = std::abs(m) < 1e-12 ? 0.0 : m;  // exact zeros: rounding only
        }
        return mix;
    }

    template <class Texel>
    void project_all(std::span<const cube_map_view<const Texel>> maps, std::span<sh_coefficients<L, glm::vec3>> out) const {
        require(out.size() == maps.size(), "out", "one coefficient set per map");
        for (const auto& m : maps) {
            require_cube_map(m, "maps");
            require(m.size() == size_, "maps", "a map's size differs from the projector's");
        }
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, maps.size(), maps_per_task), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t k = r.begin(); k < r.end(); ++k) out[k] = project_map(maps[k]);
        });
    }

    // Row y of a face and its mirror row size - 1 - y see directions that differ only in the
    // sign of the local y (the table's face looks along (u, -v, 1)), under which Y_lm is even
    // for m >= 0 and odd for m < 0 (sin |m| phi). So only the top half of the face is
    // tabulated, and each texel pair is multiplied once: even coefficients by the sum of the
    // two texels, odd ones by their difference (13.5 multiply-adds a texel instead of 27).
    // parity_order_: the coefficients even in y (bands in order, m >= 0), then the odd ones.
    static constexpr std::size_t even_count = std::size_t(L) * std::size_t(L + 1) / 2;
    static constexpr std::array<std::size_t, coefficients> parity_order_ = [] {
        std::array<std::size_t, coefficients> order{};
        std::size_t k = 0;
        for (int odd = 0; odd < 2; ++odd)
            for (int l = 0; l < L; ++l)
                for (int m = -l; m <= l; ++m)
                    if ((m < 0) == bool(odd)) order[k++] = std::size_t(l * (l + 1) + m);
        return order;
    }();

    // The texels are split into r, g, b planes a block of whole rows (or one row's segment)
    // at a time: a streaming pass that leaves them in L1 (texels of the top rows in the first
    // three planes, their mirror rows in the last three), then multiplied by the table in
    // float lanes per channel (16 with AVX-512, 8 otherwise). The lanes go into double sums
    // before a float lane has added chunk_texels / 8 pairs. (Splitting in registers and
    // multiplying in the same pass measured 1.7x slower from memory: 27 accumulators, three
    // channels and the permutations' indices overflow the registers.)
    static constexpr std::size_t plane_texels = 512;
    static constexpr std::size_t acc_stride = 48;  // per coefficient: 16 lanes of r, of g, of b

    // One map: per face, the moments against the shared table, mixed into the coefficients.
    template <class Texel>
    sh_coefficients<L, glm::vec3> project_map(const cube_map_view<const Texel>& map) const {
        moments total{};
        alignas(64) float planes[6 * plane_texels];
        alignas(64) float acc[coefficients * acc_stride];
        const std::size_t rows = std::max<std::size_t>(1, plane_texels / size_), segment = std::min(size_, plane_texels);
        for (std::size_t f = 0; f < 6; ++f) {
            const auto& face = map.faces[f];
            moments m{};
            std::fill(std::begin(acc), std::end(acc), 0.f);
            std::size_t pending = 0;  // texel pairs in the float lanes
            for (std::size_t y0 = 0; y0 < half_rows_; y0 += rows) {
                const std::size_t y1 = std::min(half_rows_, y0 + rows);
                for (std::size_t x0 = 0; x0 < size_; x0 += segment) {
                    const std::size_t n = std::min(segment, size_ - x0), texels = (y1 - y0) * n, padded = (texels + 15) / 16 * 16;
                    for (std::size_t y = y0; y < y1; ++y) {
                        float* top = planes + (y - y0) * n;
                        split(&face(x0, y), n, top, std::ptrdiff_t(prefetch_bytes));
                        if (const std::size_t mirror = size_ - 1 - y; mirror != y)
                            split(&face(x0, mirror), n, top + 3 * plane_texels, -std::ptrdiff_t(prefetch_bytes));
                        else  // the middle row of an odd size: its own pair, once (odd weights are 0 there)
                            for (std::size_t c = 3; c < 6; ++c) std::fill_n(top + c * plane_texels, n, 0.f);
                    }
                    for (std::size_t c = 0; c < 6; ++c) std::fill(planes + c * plane_texels + texels, planes + c * plane_texels + padded, 0.f);
                    if (pending + texels > chunk_texels) {
                        flush(acc, m);
                        pending = 0;
                    }
                    multiply(planes, padded, table_.data() + y0 * size_ + x0, acc);
                    pending += texels;
                }
            }
            flush(acc, m);
            const auto& mix = face_mix_[f];
            for (std::size_t i = 0; i < coefficients; ++i)
                for (std::size_t j = 0; j < coefficients; ++j)
                    if (const double a = mix[i * coefficients + j]; a != 0)
                        for (std::size_t c = 0; c < 3; ++c) total[3 * i + c] += a * m[3 * j + c];
        }
        sh_coefficients<L, glm::vec3> out{};
        for (std::size_t i = 0; i < coefficients; ++i)
            for (std::size_t c = 0; c < 3; ++c) out[i][int(c)] = float(total[3 * i + c]);
        return out;
    }

    // The float lanes into the double moments, and cleared.
    static void flush(float* acc, moments& m) {
        for (std::size_t j = 0; j < coefficients; ++j)
            for (std::size_t c = 0; c < 3; ++c) {
                double s = 0;
                for (std::size_t lane = 0; lane < 16; ++lane) s += double(acc[j * acc_stride + 16 * c + lane]);
                m[3 * j + c] += s;
            }
        std::fill_n(acc, coefficients * acc_stride, 0.f);
    }

    // `texels` texels at src into planes r = out, g = out + plane_texels, b = out + 2 plane_texels,
    // asking for the texels `ahead` bytes on (negative for rows read bottom-up).
    template <class Texel>
    void split(const Texel* src, std::size_t texels, float* out, std::ptrdiff_t ahead) const {
        float *r = out, *g = out + plane_texels, *b = out + 2 * plane_texels;
        switch (kind_) {
#if BOUNCE_SH_PROJECTION_AVX2
            case kind::avx512: return deinterleave_avx512(src, texels, r, g, b, ahead);
            case kind::avx2: return deinterleave_avx2(src, texels, r, g, b, ahead);
#endif
            default: deinterleave_portable(src, texels, r, g, b);
        }
    }

    // Calls f(odd, k, g) (integral constants) for the coefficients parity_order_[k .. k + g)
    // of one parity, `Width` at a time.
    template <bool Odd, std::size_t Width, std::size_t First = 0, class F>
    static void for_groups(F&& f) {
        constexpr std::size_t begin = Odd ? even_count : 0, end = Odd ? coefficients : even_count;
        if constexpr (begin + First < end) {
            f(std::bool_constant<Odd>{}, std::integral_constant<std::size_t, begin + First>{},
              std::integral_constant<std::size_t, std::min(Width, end - begin - First)>{});
            for_groups<Odd, Width, First + Width>(f);
        }
    }

    void multiply(const float* planes, std::size_t padded, const float* w, float* acc) const {
        switch (kind_) {
#if BOUNCE_SH_PROJECTION_AVX2
            case kind::avx512: {
                const auto group = [&](auto odd, auto k, auto g) { group_avx512<odd(), k(), g()>(planes, padded, w, acc); };
                for_groups<false, 9>(group);
                return for_groups<true, 9>(group);
            }
            case kind::avx2: {
                const auto group = [&](auto odd, auto k, auto g) { group_avx2<odd(), k(), g()>(planes, padded, w, acc); };
                for_groups<false, 3>(group);
                return for_groups<true, 3>(group);
            }
#endif
            default: multiply_portable(planes, padded, w, acc);
        }
    }

    // The planes of `texels` texels (r, g, b, each plane_texels floats apart).
    template <class Texel>
    static void deinterleave_portable(const Texel* src, std::size_t texels, float* r, float* g, float* b) {
        for (std::size_t x = 0; x < texels; ++x) {
            if constexpr (std::is_same_v<Texel, half_rgb>) {
                r[x] = half_to_float(src[x].bits[0]);
                g[x] = half_to_float(src[x].bits[1]);
                b[x] = half_to_float(src[x].bits[2]);
            } else {
                r[x] = src[x].x;
                g[x] = src[x].y;
                b[x] = src[x].z;
            }
        }
    }

    // acc[j][c][lane] += sum over x = lane (mod 8) of w_j[x] (top_c[x] +- mirror_c[x]) over
    // `padded` pairs (lanes 0-7 of each channel's 16).
    void multiply_portable(const float* planes, std::size_t padded, const float* w0, float* acc) const {
        for (std::size_t k = 0; k < coefficients; ++k) {
            const std::size_t j = parity_order_[k];
            const float sign = k < even_count ? 1.f : -1.f;
            const float* w = w0 + j * stride_;
            // Local accumulators: through `acc` the compiler must assume they alias the
            // table and the planes, and would load and store them every step.
            float a[3][8];
            for (std::size_t c = 0; c < 3; ++c) std::copy_n(acc + j * acc_stride + 16 * c, 8, a[c]);
            for (std::size_t x = 0; x < padded; x += 8)
                for (std::size_t c = 0; c < 3; ++c)
                    for (std::size_t lane = 0; lane < 8; ++lane) {
                        const std::size_t at = c * plane_texels + x + lane;
                        a[c][lane] += w[x + lane] * (planes[at] + sign * planes[at + 3 * plane_texels]);
                    }
            for (std::size_t c = 0; c < 3; ++c) std::copy_n(a[c], 8, acc + j * acc_stride + 16 * c);
        }
    }

#if BOUNCE_SH_PROJECTION_AVX2
    // Eight interleaved RGB texels (three vectors) into r, g, b vectors: two blends pick
    // each channel's lanes, one permutation puts them in texel order.
    __attribute__((target("avx2,fma,f16c"))) static void deinterleave8(__m256 a, __m256 b, __m256 c, float* r, float* g,
                                                                       float* bl) {
        const __m256 rr = _mm256_blend_ps(_mm256_blend_ps(a, b, 0b10010010), c, 0b00100100);
        const __m256 gg = _mm256_blend_ps(_mm256_blend_ps(a, b, 0b00100100), c, 0b01001001);
        const __m256 bb = _mm256_blend_ps(_mm256_blend_ps(a, b, 0b01001001), c, 0b10010010);
        _mm256_storeu_ps(r, _mm256_permutevar8x32_ps(rr, _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5)));
        _mm256_storeu_ps(g, _mm256_permutevar8x32_ps(gg, _mm256_setr_epi32(1, 4, 7, 2, 5, 0, 3, 6)));
        _mm256_storeu_ps(bl, _mm256_permutevar8x32_ps(bb, _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7)));
    }

    template <class Texel>
    __attribute__((target("avx2,fma,f16c"))) static void deinterleave_avx2(const Texel* src, std::size_t texels, float* r,
                                                                           float* g, float* b, std::ptrdiff_t ahead) {
        std::size_t x = 0;
        for (; x + 8 <= texels; x += 8) {
            const char* next = reinterpret_cast<const char*>(src + x) + ahead;
            for (std::size_t line = 0; line < 8 * sizeof(Texel); line += 64) _mm_prefetch(next + line, _MM_HINT_T0);
            if constexpr (std::is_same_v<Texel, half_rgb>) {
                const auto* h = reinterpret_cast<const __m128i*>(src + x);
                deinterleave8(_mm256_cvtph_ps(_mm_loadu_si128(h)), _mm256_cvtph_ps(_mm_loadu_si128(h + 1)),
                              _mm256_cvtph_ps(_mm_loadu_si128(h + 2)), r + x, g + x, b + x);
            } else {
                const float* f = &src[x].x;
                deinterleave8(_mm256_loadu_ps(f), _mm256_loadu_ps(f + 8), _mm256_loadu_ps(f + 16), r + x, g + x, b + x);
            }
        }
        deinterleave_portable(src + x, texels - x, r + x, g + x, b + x);
    }

    // The products with 256-bit FMAs, G coefficients at a time: 3 G accumulators, the three
    // sums (or differences) of the pair and one weight vector in registers.
    template <bool Odd, std::size_t K, std::size_t G>
    __attribute__((target("avx2,fma,f16c"))) void group_avx2(const float* planes, std::size_t padded, const float* w0,
                                                              float* acc) const {
        __m256 a[G][3];
        const float* w[G];
        for (std::size_t g = 0; g < G; ++g) {
            w[g] = w0 + parity_order_[K + g] * stride_;
            for (std::size_t c = 0; c < 3; ++c) a[g][c] = _mm256_load_ps(acc + parity_order_[K + g] * acc_stride + 16 * c);
        }
        for (std::size_t x = 0; x < padded; x += 8) {
            __m256 p[3];
            for (std::size_t c = 0; c < 3; ++c) {
                const __m256 top = _mm256_load_ps(planes + c * plane_texels + x), low = _mm256_load_ps(planes + (c + 3) * plane_texels + x);
                p[c] = Odd ? _mm256_sub_ps(top, low) : _mm256_add_ps(top, low);
            }
            for (std::size_t g = 0; g < G; ++g) {
                const __m256 weight = _mm256_loadu_ps(w[g] + x);
                for (std::size_t c = 0; c < 3; ++c) a[g][c] = _mm256_fmadd_ps(weight, p[c], a[g][c]);
            }
        }
        for (std::size_t g = 0; g < G; ++g)
            for (std::size_t c = 0; c < 3; ++c) _mm256_store_ps(acc + parity_order_[K + g] * acc_stride + 16 * c, a[g][c]);
    }

    // AVX-512: 16 texels a step split with two two-source permutations per channel, the
    // tail by the portable loop.
    template <class Texel>
    __attribute__((target("avx512f,avx512bw,avx512vl,avx2,fma,f16c"))) static void
    deinterleave_avx512(const Texel* src, std::size_t texels, float* r, float* g, float* b, std::ptrdiff_t ahead) {
        alignas(64) static constexpr int from_ab[3][16] = {{0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 0, 0, 0, 0, 0},
                                                           {1, 4, 7, 10, 13, 16, 19, 22, 25, 28, 31, 0, 0, 0, 0, 0},
                                                           {2, 5, 8, 11, 14, 17, 20, 23, 26, 29, 0, 0, 0, 0, 0, 0}};
        alignas(64) static constexpr int from_tc[3][16] = {{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 17, 20, 23, 26, 29},
                                                           {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 18, 21, 24, 27, 30},
                                                           {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 16, 19, 22, 25, 28, 31}};
        float* out[3] = {r, g, b};
        std::size_t x = 0;
        for (; x + 16 <= texels; x += 16) {
            const char* next = reinterpret_cast<const char*>(src + x) + ahead;
            for (std::size_t line = 0; line < 16 * sizeof(Texel); line += 64) _mm_prefetch(next + line, _MM_HINT_T0);
            __m512 v[3];
            for (std::size_t k = 0; k < 3; ++k) {
                if constexpr (std::is_same_v<Texel, half_rgb>)  // maskz: GCC 12's plain form reads an undefined register
                    v[k] = _mm512_maskz_cvtph_ps(0xffff, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(src[x].bits + 16 * k)));
                else
                    v[k] = _mm512_loadu_ps(&src[x].x + 16 * k);
            }
            for (std::size_t c = 0; c < 3; ++c)
                _mm512_storeu_ps(out[c] + x, _mm512_permutex2var_ps(_mm512_permutex2var_ps(v[0], _mm512_load_si512(from_ab[c]), v[1]),
                                                                    _mm512_load_si512(from_tc[c]), v[2]));
        }
        deinterleave_portable(src + x, texels - x, r + x, g + x, b + x);
    }

    // The products, G <= 9 coefficients a pass: 3 G accumulators and the pair's three sums
    // (or differences) in registers, the weights as memory operands.
    template <bool Odd, std::size_t K, std::size_t G>
    __attribute__((target("avx512f,avx512bw,avx512vl,avx2,fma,f16c"))) void group_avx512(const float* planes, std::size_t padded,
                                                                                          const float* w0, float* acc) const {
        __m512 a[G][3];
#pragma GCC unroll 9
        for (std::size_t g = 0; g < G; ++g)
#pragma GCC unroll 3
            for (std::size_t c = 0; c < 3; ++c) a[g][c] = _mm512_load_ps(acc + parity_order_[K + g] * acc_stride + 16 * c);
        for (std::size_t x = 0; x < padded; x += 16) {
            __m512 p[3];
#pragma GCC unroll 3
            for (std::size_t c = 0; c < 3; ++c) {
                const __m512 top = _mm512_load_ps(planes + c * plane_texels + x), low = _mm512_load_ps(planes + (c + 3) * plane_texels + x);
                p[c] = Odd ? _mm512_sub_ps(top, low) : _mm512_add_ps(top, low);
            }
#pragma GCC unroll 9
            for (std::size_t g = 0; g < G; ++g) {
                const __m512 weight = _mm512_loadu_ps(w0 + parity_order_[K + g] * stride_ + x);
#pragma GCC unroll 3
                for (std::size_t c = 0; c < 3; ++c) a[g][c] = _mm512_fmadd_ps(weight, p[c], a[g][c]);
            }
        }
#pragma GCC unroll 9
        for (std::size_t g = 0; g < G; ++g)
#pragma GCC unroll 3
            for (std::size_t c = 0; c < 3; ++c) _mm512_store_ps(acc + parity_order_[K + g] * acc_stride + 16 * c, a[g][c]);
    }
#endif

    std::size_t size_, half_rows_, stride_;  // stride_: floats from one coefficient's weights to the next
    kind kind_;
    std::vector<float, line_allocator<float>> table_;  // [coefficient][texel of the +z face]
    std::array<std::array<double, coefficients * coefficients>, 6> face_mix_;
};

}  // namespace bounce::cpu
