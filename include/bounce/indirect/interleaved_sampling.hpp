#pragma once
/// \file indirect/interleaved_sampling.hpp
/// Interleaved sampling (Keller and Heidrich 2001) in the deferred form of Segovia, Iehl,
/// Mitanchey and Peroche 2006 ("Non-interleaved deferred shading of interleaved sample
/// patterns"): an N x M pattern splits a W x H buffer into N M sub-buffers, pixel (x, y)
/// going to sub-buffer (x mod N, y mod M); each sub-buffer is shaded with its own subset of
/// the lights; the results are gathered back and blurred by a geometry-aware filter whose
/// footprint covers the pattern.
///
/// The index maps are arithmetic, for any size (W and H need not be multiples of N and M),
/// so no lookup textures are needed (Hahn 2012, section 4.1.3, keeps four of them,
/// 15 MB at 1280x768, one set per resolution). Along one axis with size W = q N + r
/// (0 <= r < N), sub-buffer i holds the q + [i < r] pixels x = i, i + N, ... and starts at
/// column i q + min(i, r) of the split buffer; the split buffer is W x H, the sub-buffers
/// tile it. The 2D maps are the 1D maps applied to x and y.
///
/// The kernels compute on real numbers (GLSL has no integers in bounce's expression types):
/// floor((a + 1/2) / b) is the integer quotient of two integers a >= 0, b >= 1, exact in
/// float while 2.5 ulp(a / b) (GLSL's division accuracy) stays below the margin 1/(2b):
/// sizes below 2^14 with patterns up to 64 wide. The CPU passes use double.
///
/// Energy: each light (VPL, gather sample) reaches one sub-buffer of N M, so its weight is
/// multiplied by N M (`interleaved_weight_scale`): then the expected value of every pixel,
/// over a uniformly random relabelling of the sub-buffers, is the non-interleaved value
/// (docs/rsm-sii-interleaved.md, section 5). The thesis (Hahn 2012, section 5.2) splatted each
/// VPL into one sub-buffer at weight 1 and lost 1 - 1/(N M) of the energy.

#include <bounce/errors.hpp>
#include <bounce/vocabulary.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::inline indirect {

// ---- index maps (kernels) ---------------------------------------------------------------

/// Integer quotient floor(a / b) of integers a >= 0, b >= 1 held in reals, with the
/// half-unit margin that keeps it exact under GLSL's inexact division (file comment).
template <real T>
T integer_quotient(T a, T b) {
    return floor((a + T(0.5)) / b);
}

/// First column (row) of sub-buffer `i` in the split buffer, for an axis of `size` pixels
/// and a pattern `n` wide: i q + min(i, r), size = q n + r.
template <real T>
T interleave_sub_buffer_origin(T i, T size, T n) {
    const T q = integer_quotient<T>(size, n);
    const T r = size - q * n;
    return i * q + min(i, r);
}

/// Number of columns (rows) of sub-buffer `i`: q + 1 for i < r, else q.
template <real T>
T interleave_sub_buffer_extent(T i, T size, T n) {
    const T q = integer_quotient<T>(size, n);
    const T r = size - q * n;
    return q + select(i < r, T(1), T(0));
}

/// Where column (row) `x` of the image lands in the split buffer: sub-buffer i = x mod n,
/// local index floor(x / n), so at origin(i) + floor(x / n).
template <real T>
T interleave_split_coordinate(T x, T size, T n) {
    const T local = integer_quotient<T>(x, n);
    const T i = x - local * n;
    return interleave_sub_buffer_origin<T>(i, size, n) + local;
}

/// The inverse: which image column (row) split-buffer column `u` holds, and its sub-buffer
/// index, as {x, i}. The first r sub-buffers are q + 1 wide, the others q (q may be 0 when
/// size < n; then u < r always and the second branch, guarded by max(q, 1), is not taken).
template <real T>
std::array<T, 2> interleave_gather_coordinate(T u, T size, T n) {
    const T q = integer_quotient<T>(size, n);
    const T r = size - q * n;
    const T long_span = r * (q + T(1));
    const auto in_long = u < long_span;
    const T i_long = integer_quotient<T>(u, q + T(1));
    const T i_short = r + integer_quotient<T>(max(u - long_span, T(0)), max(q, T(1)));
    const T i = select(in_long, i_long, i_short);
    const T local = u - interleave_sub_buffer_origin<T>(i, size, n);
    return {local * n + i, i};
}

/// The factor every light's weight takes when it reaches one sub-buffer of an n x m
/// pattern: n m (file comment; docs section 5).
template <real T>
T interleaved_weight_scale(T n, T m) {
    return n * m;
}

// ---- the geometry-aware blur (kernels) --------------------------------------------------

/// Weight of the tent filter of radius n - 1 at integer offset `offset`: (n - |o|) / n^2.
/// It is the box of width n convolved with itself, so the taps congruent to each residue
/// mod n sum to exactly 1/n: every sub-buffer of the pattern along this axis gets the same
/// total weight, and the filtered value is the average of the n sub-buffers' estimates
/// (docs, section 6). Symmetric for even n too, unlike a box of width n.
template <real T>
T interleave_tent_weight(T offset, T n) {
    return max(T(0), n - abs(offset)) / (n * n);
}

/// One output pixel of a pass of the separable geometry-aware tent (Segovia et al. 2006
/// step 6): `values` are the 2R + 1 pixels centred on it along the pass's axis; `edges[k]`
/// is 1 where a discontinuity separates taps k and k + 1 (0 otherwise), so a tap counts
/// only if no edge lies between it and the centre. The centre always counts; the pattern is
/// `n` <= R + 1 wide along this axis, and a compile-time R keeps GLSL's loop bounds constant.
///
/// Renormalized per sub-buffer rather than per tap: every residue class mod n that is
/// reached gets the same weight, its taps (offsets o and o - n) shared by their tent
/// weights. Inside a surface this is the tent itself (each class already weighs 1/n); where
/// an edge cuts the tent short it keeps the sub-buffers equal, so one sub-buffer's subset of
/// lights does not outweigh the others (docs, section 6). With L taps reached on the left and
/// Rr on the right (at most n - 1 each), right tap o shares its class with left tap n - o,
/// reached when n - o <= L, so its class weight is (n - o) / n^2 + [n - o <= L] o / n^2;
/// 1 + min(n - 1, L + Rr) classes are reached.
template <int R, real T, vec3_of<T> V>
V geometry_aware_tent(const std::array<V, 2 * R + 1>& values, const std::array<T, 2 * R>& edges, T n) {
    std::array<T, R + 1> reach_right, reach_left;  // [k]: tap +-k reached (k < n)
    reach_right[0] = T(1);
    reach_left[0] = T(1);
    T count_right = T(0), count_left = T(0);
    for (int k = 1; k <= R; ++k) {
        const T in_tent = select(T(k) < n, T(1), T(0));
        reach_right[std::size_t(k)] = reach_right[std::size_t(k - 1)] * (T(1) - edges[std::size_t(R + k - 1)]);
        reach_left[std::size_t(k)] = reach_left[std::size_t(k - 1)] * (T(1) - edges[std::size_t(R - k)]);
        count_right = count_right + reach_right[std::size_t(k)] * in_tent;
        count_left = count_left + reach_left[std::size_t(k)] * in_tent;
    }
    V sum = values[R];  // class 0: the centre alone, weight 1 within its class
    const T inv_n2 = T(1) / (n * n);
    for (int k = 1; k <= R; ++k) {
        const T own = max(T(0), n - T(k)) * inv_n2;  // tent weight of taps +-k
        const T partner = T(k) * inv_n2;             // tent weight of taps -+(n - k)
        const T class_right = own + select(n - T(k) <= count_left, partner, T(0));
        const T class_left = own + select(n - T(k) <= count_right, partner, T(0));
        const T w_right = reach_right[std::size_t(k)] * own / max(class_right, inv_n2);
        const T w_left = reach_left[std::size_t(k)] * own / max(class_left, inv_n2);
        sum = sum + values[std::size_t(R + k)] * w_right + values[std::size_t(R - k)] * w_left;
    }
    return sum / (T(1) + min(n - T(1), count_left + count_right));
}

/// Whether two neighbouring G-buffer pixels lie on different surfaces (the discontinuity
/// buffer of Segovia et al. 2006 step 5): 1 when their view depths differ by more than
/// `relative_depth` of the nearer (typical: 0.05) or their unit normals by more than the
/// angle whose cosine is `cos_normal` (typical: cos 25 deg = 0.9), else 0.
template <real T, vec3_of<T> V>
T geometry_discontinuity(T depth_a, const V& n_a, T depth_b, const V& n_b, T relative_depth, T cos_normal) {
    const auto far_apart = abs(depth_a - depth_b) > relative_depth * min(depth_a, depth_b);
    const auto turned = dot(n_a, n_b) < cos_normal;
    return select(far_apart || turned, T(1), T(0));
}

/// Whether two neighbouring pixels of the gathered buffer see different shares of their
/// senders (a visibility edge the G-buffer does not show: the rim of a shadow on one surface,
/// docs/rsm-sii-interleaved.md, section 15.3). Each pixel brings the sums of its
/// own sub-buffer's terms before visibility: `sum` = sum_k e_k, `visible` = sum_k e_k V_k and
/// `sum_sq` = sum_k e_k^2 (e_k a term's brightness, V_k in {0, 1}). Its visible fraction is
/// r = visible / sum, from Kish's effective number of terms n = sum^2 / sum_sq; r's variance
/// is at most r (1 - r) / n <= 1 / (4 n) (the binomial bound, kept because a handful of
/// terms that agree would otherwise claim certainty). Returns 1 when both pixels receive
/// light and |r_a - r_b| exceeds `sigmas` standard errors of the difference,
/// sigmas^2 (1 / n_a + 1 / n_b) / 4 < (r_a - r_b)^2; 0 otherwise (sigmas 0: never).
template <real T>
T visibility_discontinuity(T sum_a, T visible_a, T sum_sq_a, T sum_b, T visible_b, T sum_sq_b, T sigmas) {
    const auto lit = sum_a > T(0) && sum_b > T(0) && sum_sq_a > T(0) && sum_sq_b > T(0) && sigmas > T(0);
    const T sa = select(lit, sum_a, T(1)), sb = select(lit, sum_b, T(1));
    const T d = visible_a / sa - visible_b / sb;
    // 1 / n = sum_sq / sum^2 for each pixel.
    const T inv_n = select(lit, sum_sq_a / (sa * sa) + sum_sq_b / (sb * sb), T(0));
    return select(lit && T(4) * d * d > sigmas * sigmas * inv_n, T(1), T(0));
}

/// Weights of the geometry-aware bilinear upsampling of a low-resolution result (DS05
/// section 3.3): the four low-resolution samples around a full-resolution pixel at `x`
/// (unit normal `n`) with bilinear weights from `frac` (the pixel's position between them,
/// in [0, 1]^2; samples ordered (0,0), (1,0), (0,1), (1,1)) count when their normal is
/// within `cos_normal` of n and their position within `max_plane_distance` (m) of the
/// pixel's tangent plane. Returns the renormalized weights of the suitable samples and their
/// number; DS05 interpolates when at least three qualify and gathers the pixel at full
/// resolution otherwise.
template <real T, vec3_of<T> V>
std::array<T, 5> geometry_aware_upsample_weights(const V& x, const V& n, const std::array<V, 4>& positions,
                                                 const std::array<V, 4>& normals, T frac_x, T frac_y,
                                                 T max_plane_distance, T cos_normal) {
    const std::array<T, 4> bilinear = {(T(1) - frac_x) * (T(1) - frac_y), frac_x * (T(1) - frac_y),
                                       (T(1) - frac_x) * frac_y, frac_x * frac_y};
    std::array<T, 5> out;
    T total = T(0), count = T(0);
    for (std::size_t k = 0; k < 4; ++k) {
        const auto ok = dot(n, normals[k]) >= cos_normal && abs(dot(n, positions[k] - x)) <= max_plane_distance;
        const T suitable = select(ok, T(1), T(0));
        out[k] = bilinear[k] * suitable;
        total = total + out[k];
        count = count + suitable;
    }
    // A suitable sample with bilinear weight 0 (the pixel on the far edge) still counts; if
    // all suitable weights are 0 the weights stay 0 and the caller gathers.
    const T inv = T(1) / select(total > T(0), total, T(1));
    for (std::size_t k = 0; k < 4; ++k) out[k] = out[k] * inv;
    out[4] = count;
    return out;
}

// ---- the pattern and the assignment of lights (CPU side) --------------------------------

/// An N x M interleave pattern: `n` columns by `m` rows of sub-buffers (typical: 4 x 4,
/// 8 x 8; 1 x 1 is no interleaving).
struct interleave_pattern {
    int n = 4, m = 4;

    int cells() const noexcept { return n * m; }
    bool operator==(const interleave_pattern&) const = default;
    /// Throws parameter_error unless 1 <= n, m <= 64 (the range the float maps are exact
    /// for; see the file comment).
    void validate() const {
        require(n >= 1 && n <= 64, "pattern.n", "must lie in [1, 64]");
        require(m >= 1 && m <= 64, "pattern.m", "must lie in [1, 64]");
    }
};

/// Pixel rectangle of sub-buffer (i, j) in the split buffer of a width x height image.
struct sub_buffer_rect {
    std::size_t x0 = 0, y0 = 0, width = 0, height = 0;
};

/// The rectangle of sub-buffer (i, j) (0 <= i < n, 0 <= j < m), from the kernels.
inline sub_buffer_rect sub_buffer_of(const interleave_pattern& p, int i, int j, std::size_t width, std::size_t height) {
    const double w = double(width), h = double(height), n = p.n, m = p.m;
    return {std::size_t(interleave_sub_buffer_origin<double>(i, w, n)),
            std::size_t(interleave_sub_buffer_origin<double>(j, h, m)),
            std::size_t(interleave_sub_buffer_extent<double>(i, w, n)),
            std::size_t(interleave_sub_buffer_extent<double>(j, h, m))};
}

/// How lights are dealt to the sub-buffers (Hahn 2012, sections 4.1.3 and 5.2).
enum class light_assignment {
    interleaved,  ///< light k to sub-buffer k mod (N M): each gets every (N M)-th light
    blocked,      ///< consecutive runs of ceil(K / (N M)) lights to each sub-buffer
    similarity,   ///< lights ordered along a Morton curve of their positions, then dealt
                  ///< interleaved: neighbours in space go to neighbouring sub-buffers and
                  ///< each sub-buffer gets a spatially stratified subset (the thesis's
                  ///< suggestion of placing similar VPLs in adjacent sub-buffers)
};

/// Lights grouped by sub-buffer: sub-buffer s (= j n + i) uses the lights
/// `order[begin[s]] ... order[begin[s + 1] - 1]`, in ascending order of their index within
/// the group as dealt (the summation order, which the CPU passes keep fixed).
struct light_groups {
    std::vector<std::uint32_t> order;
    std::vector<std::uint32_t> begin;  ///< cells + 1 entries

    std::span<const std::uint32_t> group(int s) const {
        return {order.data() + begin[std::size_t(s)], order.data() + begin[std::size_t(s) + 1]};
    }
};

}  // namespace bounce::indirect

namespace bounce::detail {
/// Spreads the low 10 bits of v to every third bit (Morton code helper).
constexpr std::uint32_t spread_bits3(std::uint32_t v) noexcept {
    v &= 0x3ffu;
    v = (v | (v << 16)) & 0x030000ffu;
    v = (v | (v << 8)) & 0x0300f00fu;
    v = (v | (v << 4)) & 0x030c30c3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

/// The 30-bit Morton code of each of `positions` on a 1024^3 grid over their bounding box.
inline std::vector<std::uint32_t> morton_codes(std::span<const glm::vec3> positions) {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const auto& p : positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const glm::vec3 extent = glm::max(hi - lo, glm::vec3(1e-30f));
    std::vector<std::uint32_t> code(positions.size());
    for (std::size_t k = 0; k < positions.size(); ++k) {
        const glm::vec3 t = (positions[k] - lo) / extent * 1023.f;
        code[k] = spread_bits3(std::uint32_t(t.x)) | (spread_bits3(std::uint32_t(t.y)) << 1) |
                  (spread_bits3(std::uint32_t(t.z)) << 2);
    }
    return code;
}
}  // namespace bounce::detail

namespace bounce::inline indirect {

/// Deals `count` lights to the `cells` sub-buffers by `how`; `positions` (one per light)
/// are read for `light_assignment::similarity` only. `shift` (0 <= shift < cells) relabels
/// sub-buffer s as (s + shift) mod cells: averaging a pixel over every shift averages over
/// which sub-buffer each light reaches, the expectation the energy weight preserves.
inline light_groups assign_lights(std::size_t count, int cells, light_assignment how,
                                  std::span<const glm::vec3> positions = {}, int shift = 0) {
    require(cells >= 1, "cells", "must be positive");
    require(shift >= 0 && shift < cells, "shift", "must lie in [0, cells)");
    require(count <= std::size_t(UINT32_MAX), "count", "more lights than 32-bit indices hold");
    std::vector<std::uint32_t> rank(count);
    std::iota(rank.begin(), rank.end(), 0u);
    if (how == light_assignment::similarity) {
        require(positions.size() == count, "positions", "need one position per light for similarity assignment");
        const std::vector<std::uint32_t> code = detail::morton_codes(positions);
        std::stable_sort(rank.begin(), rank.end(), [&](std::uint32_t a, std::uint32_t b) { return code[a] < code[b]; });
    }
    const std::size_t c = std::size_t(cells);
    const std::size_t block = std::max<std::size_t>(1, (count + c - 1) / c);
    std::vector<std::uint32_t> cell_of(count);
    for (std::size_t k = 0; k < count; ++k) {
        const std::size_t dealt = how == light_assignment::blocked ? std::min(k / block, c - 1) : k % c;
        cell_of[k] = std::uint32_t((dealt + std::size_t(shift)) % c);
    }
    light_groups g;
    g.begin.assign(c + 1, 0);
    for (std::size_t k = 0; k < count; ++k) ++g.begin[cell_of[k] + 1];
    std::partial_sum(g.begin.begin(), g.begin.end(), g.begin.begin());
    g.order.resize(count);
    std::vector<std::uint32_t> fill(g.begin.begin(), g.begin.end() - 1);
    for (std::size_t k = 0; k < count; ++k) g.order[fill[cell_of[k]]++] = rank[k];
    return g;
}

}  // namespace bounce::indirect
