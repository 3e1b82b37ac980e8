#pragma once
/// \file sh_projection.hpp
/// SH projection of many RGB cube maps of one size at once (a probe bake's worth): the
/// direction set of a size x size cube map is the same for every probe, so Y_i(texel) times
/// the texel's exact solid angle is tabulated once (sh/projection.hpp of the core defines
/// the layout and the quadrature), and projecting a map is a matrix product:
/// c_i = sum over texels of table_i(texel) f(texel).
///
/// How the product is laid out for the memory system:
/// - A block of rows of each map is first split into r, g and b planes (two blends and a
///   permutation per 8 texels on AVX2), so each weight of the table is loaded once and used
///   for three channels: per 8 texels 9 weight loads, 3 plane loads and 27 fused
///   multiply-adds, the minimum for 9 coefficients x 3 channels. (A table with each weight
///   repeated per channel, multiplying the interleaved texels directly, loads 3 times the
///   bytes and was 10-20% slower.)
/// - Maps are taken in groups (one TBB task each); the group walks the faces a few rows at
///   a time and projects those rows of every map in the group while the rows' table
///   (16 x 9 x 64 floats = 37 KB for L = 3, size 64) stays in L1/L2 (blocks of 16 rows
///   measured 1.0-1.2 Gtexel per CPU-second, 4 rows 0.7-0.8, 64 rows 0.8-0.9). The table
///   (0.9 MB at that size) is thus read from memory once per group, not once per map. The table's rows of
///   one coefficient are contiguous, so a block is one long run for the vector loop.
/// - On x86-64 with AVX2, FMA and F16C (checked at run time) the products use 256-bit
///   fused multiply-adds, three coefficients at a time (nine accumulators in registers);
///   elsewhere a portable loop the compiler vectorizes for the baseline ISA. (A 512-bit
///   variant with all 27 accumulators in registers was slower on the AMD EPYC this was
///   measured on, 0.45 against 0.58 Gtexel per CPU-second, and was dropped.)
/// - Texels are glm::vec3 (12 bytes) or `half_rgb` (IEEE binary16, 6 bytes: what a GL
///   RGB16F render target reads back as). A bake of many maps streams from memory, where
///   the bytes per texel set the pace (docs/sh-and-irradiance-volumes.md): half texels are
///   converted in registers (F16C) on the AVX2 path.
/// Float accumulators run over one face (at most 8 x 64 = 512 terms per lane for size 64:
/// relative rounding below 512 x 2^-24 = 3e-5, 1e-6 typical), then add into double sums.
/// Each map is summed in the same order whatever the thread count and the grouping, so
/// results are bitwise reproducible for a given path (the paths differ by rounding, a few
/// float ulps of the result).

#include <bounce/errors.hpp>
#include <bounce/image.hpp>
#include <bounce/sh/basis.hpp>
#include <bounce/sh/projection.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include <glm/vec3.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
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

/// Which row-product code `cube_map_sh_projector` runs.
enum class sh_projection_path {
    automatic,  ///< AVX2 + FMA + F16C where the CPU has them, else portable
    portable,   ///< plain loops only (for comparison and testing)
};

/// Projects RGB cube maps of a fixed size (glm::vec3 texels, packed rows) onto bands
/// 0 .. L - 1. Construct once per size (it computes 6 size^2 L^2 table entries), then call
/// `project` for each batch of maps.
template <int L>
class cube_map_sh_projector {
public:
    static constexpr std::size_t coefficients = sh_count(L);
    static constexpr std::size_t rows_per_block = 16;  ///< face rows projected per table block
    static constexpr std::size_t maps_per_task = 16;  ///< maps one TBB task projects together

    /// Tables for size x size faces (typical: 64; 1 to 4096). Throws parameter_error naming
    /// "size" outside that range.
    explicit cube_map_sh_projector(std::size_t size, sh_projection_path path = sh_projection_path::automatic)
        : size_(size), avx2_(path == sh_projection_path::automatic && cpu_has_avx2_fma()) {
        static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "texel rows are read as packed floats");
        require(size >= 1 && size <= 4096, "size", "cube-map size must be 1 to 4096 texels");
        // 8 floats of padding: a block whose texel count is not a multiple of 8 reads up
        // to 7 weights past its end, multiplied by the zero padding of the planar texels.
        table_.assign(6 * coefficients * size_ * size_ + 8, 0.f);
        for (int f = 0; f < 6; ++f)
            for (std::size_t y = 0; y < size_; ++y)
                for (std::size_t x = 0; x < size_; ++x) {
                    const auto basis = sh_basis<L, double, glm::dvec3>(cube_texel_direction(cube_face(f), size_, x, y));
                    const double dw = cube_texel_solid_angle(size_, x, y);
                    for (std::size_t i = 0; i < coefficients; ++i) table_[table_row(std::size_t(f), y, i) + x] = float(basis[i] * dw);
                }
    }

    std::size_t size() const noexcept { return size_; }
    /// The row product that runs: "avx2" or "portable".
    const char* path_name() const noexcept { return avx2_ ? "avx2" : "portable"; }
    /// Bytes of the table (4 x 6 size^2 L^2).
    std::size_t table_bytes() const noexcept { return table_.size() * sizeof(float); }

    /// SH coefficients of every map of `maps` into `out` (one per map), in parallel over
    /// groups of maps. Throws parameter_error naming "out" when the counts differ and
    /// "maps" when a map is not a cube of this projector's size.
    void project(std::span<const cube_map_view<const glm::vec3>> maps, std::span<sh_coefficients<L, glm::vec3>> out) const {
        require(out.size() == maps.size(), "out", "one coefficient set per map");
        for (const auto& m : maps) {
            require_cube_map(m, "maps");
            require(m.size() == size_, "maps", "a map's size differs from the projector's");
        }
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, maps.size(), maps_per_task),
                          [&](const tbb::blocked_range<std::size_t>& r) { project_group(maps, out, r.begin(), r.end()); });
    }

    /// `project` for half-float maps.
    void project(std::span<const cube_map_view<const half_rgb>> maps, std::span<sh_coefficients<L, glm::vec3>> out) const {
        require(out.size() == maps.size(), "out", "one coefficient set per map");
        for (const auto& m : maps) {
            require_cube_map(m, "maps");
            require(m.size() == size_, "maps", "a map's size differs from the projector's");
        }
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, maps.size(), maps_per_task),
                          [&](const tbb::blocked_range<std::size_t>& r) { project_group(maps, out, r.begin(), r.end()); });
    }

    /// The coefficients of one map (no parallelism).
    sh_coefficients<L, glm::vec3> project(const cube_map_view<const glm::vec3>& map) const {
        require_cube_map(map, "map");
        require(map.size() == size_, "map", "the map's size differs from the projector's");
        sh_coefficients<L, glm::vec3> out{};
        const std::array<cube_map_view<const glm::vec3>, 1> one{map};
        project_group(std::span<const cube_map_view<const glm::vec3>>(one), std::span<sh_coefficients<L, glm::vec3>>(&out, 1), 0, 1);
        return out;
    }

private:
    // Accumulators per coefficient: 8 lanes of red, 8 of green, 8 of blue.
    static constexpr std::size_t acc_stride = 24;

    static bool cpu_has_avx2_fma() noexcept {
#if BOUNCE_SH_PROJECTION_AVX2
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("f16c");
#else
        return false;
#endif
    }

    // Table layout [face][coefficient][row][size]: one coefficient's rows follow each
    // other, so a block of rows is one contiguous run of weights.
    std::size_t table_row(std::size_t face, std::size_t y, std::size_t i) const noexcept {
        return ((face * coefficients + i) * size_ + y) * size_;
    }

    // The block's texels as three planes (r, g, b), each `stride` floats apart, zero-padded
    // to a multiple of 8 texels.
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

    // acc[i][c][lane] += sum over x = lane (mod 8) of w_i[x] plane_c[x] over `padded` texels.
    void accumulate_portable(const float* planes, std::size_t stride, std::size_t padded, std::size_t face, std::size_t y0,
                             float* acc) const {
        for (std::size_t i = 0; i < coefficients; ++i) {
            const float* w = table_.data() + table_row(face, y0, i);
            // Local accumulators: through `acc` the compiler must assume they alias the
            // table and the planes, and would load and store them every step.
            float a[acc_stride];
            std::copy_n(acc + i * acc_stride, acc_stride, a);
            for (std::size_t x = 0; x < padded; x += 8)
                for (std::size_t c = 0; c < 3; ++c)
                    for (std::size_t lane = 0; lane < 8; ++lane) a[8 * c + lane] += w[x + lane] * planes[c * stride + x + lane];
            std::copy_n(a, acc_stride, acc + i * acc_stride);
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
                                                                           float* g, float* b) {
        std::size_t x = 0;
        for (; x + 8 <= texels; x += 8) {
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
    // planes and one weight vector in registers (13 of 16 for G = 3).
    template <std::size_t G>
    __attribute__((target("avx2,fma,f16c"))) void accumulate_group_avx2(const float* planes, std::size_t stride,
                                                                         std::size_t padded, std::size_t face, std::size_t y0,
                                                                         std::size_t first, float* acc) const {
        __m256 a[G][3];
        const float* w[G];
        for (std::size_t g = 0; g < G; ++g) {
            w[g] = table_.data() + table_row(face, y0, first + g);
            for (std::size_t c = 0; c < 3; ++c) a[g][c] = _mm256_loadu_ps(acc + (first + g) * acc_stride + 8 * c);
        }
        for (std::size_t x = 0; x < padded; x += 8) {
            const __m256 r = _mm256_loadu_ps(planes + x), gr = _mm256_loadu_ps(planes + stride + x),
                         b = _mm256_loadu_ps(planes + 2 * stride + x);
            for (std::size_t g = 0; g < G; ++g) {
                const __m256 weight = _mm256_loadu_ps(w[g] + x);
                a[g][0] = _mm256_fmadd_ps(weight, r, a[g][0]);
                a[g][1] = _mm256_fmadd_ps(weight, gr, a[g][1]);
                a[g][2] = _mm256_fmadd_ps(weight, b, a[g][2]);
            }
        }
        for (std::size_t g = 0; g < G; ++g)
            for (std::size_t c = 0; c < 3; ++c) _mm256_storeu_ps(acc + (first + g) * acc_stride + 8 * c, a[g][c]);
    }

    void accumulate_avx2(const float* planes, std::size_t stride, std::size_t padded, std::size_t face, std::size_t y0,
                         float* acc) const {
        std::size_t i = 0;
        for (; i + 3 <= coefficients; i += 3) accumulate_group_avx2<3>(planes, stride, padded, face, y0, i, acc);
        if constexpr (coefficients % 3 == 1) accumulate_group_avx2<1>(planes, stride, padded, face, y0, i, acc);
        if constexpr (coefficients % 3 == 2) accumulate_group_avx2<2>(planes, stride, padded, face, y0, i, acc);
    }
#endif

    template <class Texel>
    void project_group(std::span<const cube_map_view<const Texel>> maps, std::span<sh_coefficients<L, glm::vec3>> out,
                       std::size_t begin, std::size_t end) const {
        const std::size_t count = end - begin;
        std::vector<float> acc(count * coefficients * acc_stride);
        std::vector<double> sums(count * coefficients * 3, 0.0);
        // One block's texels as planes, padded to whole vectors with zeros.
        const std::size_t stride = (rows_per_block * size_ + 7) / 8 * 8;
        std::vector<float> planes(3 * stride, 0.f);
        for (std::size_t face = 0; face < 6; ++face) {
            std::fill(acc.begin(), acc.end(), 0.f);
            for (std::size_t y0 = 0; y0 < size_; y0 += rows_per_block) {
                const std::size_t y1 = std::min(size_, y0 + rows_per_block), texels = (y1 - y0) * size_;
                const std::size_t padded = (texels + 7) / 8 * 8;
                // A face's last block can be shorter than the others: zero its padding, which
                // still holds texels of the block before.
                for (std::size_t c = 0; c < 3; ++c)
                    std::fill(planes.begin() + std::ptrdiff_t(c * stride + texels), planes.begin() + std::ptrdiff_t(c * stride + padded), 0.f);
                for (std::size_t k = 0; k < count; ++k) {
                    const auto& face_view = maps[begin + k].faces[face];
                    float* a = acc.data() + k * coefficients * acc_stride;
                    // The next map's rows are a separate stream the hardware prefetcher has
                    // not seen yet: ask for them while this map's rows are multiplied.
                    if (k + 1 < count)
                        for (std::size_t y = y0; y < y1; ++y) {
                            const char* next = reinterpret_cast<const char*>(&maps[begin + k + 1].faces[face](0, y));
                            for (std::size_t b = 0; b < sizeof(Texel) * size_; b += 64) __builtin_prefetch(next + b);
                        }
                    // Packed rows (stride = width) are one run; otherwise row by row.
                    const std::size_t run = face_view.stride() == size_ ? y1 - y0 : 1;
                    for (std::size_t y = y0; y < y1; y += run) {
                        const std::size_t at = (y - y0) * size_;
                        float* r = planes.data() + at;
#if BOUNCE_SH_PROJECTION_AVX2
                        if (avx2_) {
                            deinterleave_avx2(&face_view(0, y), run * size_, r, r + stride, r + 2 * stride);
                            continue;
                        }
#endif
                        deinterleave_portable(&face_view(0, y), run * size_, r, r + stride, r + 2 * stride);
                    }
#if BOUNCE_SH_PROJECTION_AVX2
                    if (avx2_) {
                        accumulate_avx2(planes.data(), stride, padded, face, y0, a);
                        continue;
                    }
#endif
                    accumulate_portable(planes.data(), stride, padded, face, y0, a);
                }
            }
            // Lanes [8c, 8c + 8) hold channel c.
            for (std::size_t k = 0; k < count; ++k)
                for (std::size_t i = 0; i < coefficients; ++i) {
                    const float* a = acc.data() + (k * coefficients + i) * acc_stride;
                    double* sum = sums.data() + (k * coefficients + i) * 3;
                    for (std::size_t c = 0; c < 3; ++c) {
                        double s = 0;
                        for (std::size_t lane = 0; lane < 8; ++lane) s += double(a[8 * c + lane]);
                        sum[c] += s;
                    }
                }
        }
        for (std::size_t k = 0; k < count; ++k)
            for (std::size_t i = 0; i < coefficients; ++i)
                for (std::size_t c = 0; c < 3; ++c)
                    out[begin + k][i][int(c)] = float(sums[(k * coefficients + i) * 3 + c]);
    }

    std::size_t size_;
    bool avx2_;
    std::vector<float> table_;
};

}  // namespace bounce::cpu
