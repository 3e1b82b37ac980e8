#pragma once
/// \file indirect/view_selection.hpp
/// Senders chosen by what the camera sees (after Georgiev and Slusallek 2010, "Simple and
/// robust iterative importance sampling of virtual point lights", and Segovia et al. 2006,
/// "Bidirectional instant radiosity"): a pool of `candidates` x count senders drawn as
/// usual (SII's VPLs by flux warping; the template takes any sender with a weight) is
/// measured at a sparse, fixed set of receivers (G-buffer pixels), with visibility, and count
/// of them are drawn again with probability
///
///   P_j = a / M + (1 - a) t_j / sum_i t_i,   t_j = sqrt(sum_g (rho_g E_jg V_jg)^2)
///
/// (M candidates, a the defensive share, E_jg the irradiance candidate j gives receiver g,
/// rho_g its albedo's luminance, V_jg 1 where g sees j). sqrt of the sum of squares is the
/// choice that minimises the summed variance over the receivers (a Lagrange multiplier on
/// sum_j P_j = 1), the rel_rms of an image; the defensive share keeps every candidate's
/// probability at a / M or more, so no sender the sparse receivers miss (a 1/d^2 spike in a
/// corner no receiver sits in) is lost, and where the receivers see none of them (t = 0)
/// the draw is uniform.
///
/// The draw is systematic resampling: the points (i + xi) / count, i < count, of the
/// probabilities' cumulative sum, draw i dealt to sub-buffer (i + r) mod cells for a uniform
/// rotation r. Each sub-buffer then holds a systematic sample of n_s = count / cells with a
/// uniform offset, so candidate j is drawn E[n_js] = n_s P_j times there, and each draw is
/// scaled by 1 / (cells n_s P_j): the sum over a sub-buffer's draws, times cells (the
/// interleaved weight), has the expectation of the candidates' own sum, for every sub-buffer
/// (Horvitz and Thompson's estimator), while the union of the sub-buffers' draws is one
/// stratified sample. (When cells does not divide count, each sub-buffer draws its own
/// systematic sample.) The candidates' sum has the expectation of the map's. Unbiased
/// whatever t is: t only decides the variance. The draws are listed so that light k goes to
/// sub-buffer k mod cells, as assign_lights(light_assignment::interleaved) deals them.
/// Candidates next to each other in the list given are drawn as strata (a candidate list
/// sorted along a space-filling curve gives spatially stratified draws).
///
/// Backend-free: the caller measures the terms (a functor per receiver) and answers the
/// occlusion queries (indirect/visibility.hpp).

#include <bounce/errors.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/indirect/visibility.hpp>
#include <bounce/luminance.hpp>
#include <bounce/sampling.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::inline indirect {

/// How a renderer chooses its senders by the view (indirect_options::view_selection).
struct view_selection_params {
    /// Candidate pool, in multiples of the frame's count (>= 1; 1: off, the senders drawn
    /// as without it). Typical 4.
    int candidates = 4;
    /// Receivers the candidates are measured at: covered G-buffer pixels on a regular grid
    /// of about this many (>= 1; typical 2048: fewer miss the 1/d^2 peaks that make the
    /// variance, docs section 15).
    std::size_t receivers = 2048;
    /// The share of the mixture that keeps the candidates' own distribution, (0, 1]
    /// (typical 0.3; 1: uniform over the candidates, no view importance).
    float defensive = 0.3f;
    /// The near field, in clamp distances (>= 0; 0: off; typical 4): each candidate is also
    /// measured at every covered pixel within this many of its own 1/d^2 clamp distances,
    /// the peak that falls between the grid's receivers (near_field_radius).
    float near_field = 4.f;

    bool operator==(const view_selection_params&) const = default;
    bool enabled() const noexcept { return candidates > 1; }

    void validate() const {
        require(candidates >= 1 && candidates <= 64, "view_selection.candidates", "must lie in [1, 64]");
        require(receivers >= 1, "view_selection.receivers", "must be positive");
        require(std::isfinite(defensive) && defensive > 0.f && defensive <= 1.f, "view_selection.defensive",
                "must lie in (0, 1]");
        require(std::isfinite(near_field) && near_field >= 0.f && near_field <= 64.f, "view_selection.near_field",
                "must lie in [0, 64]");
    }
};

/// A receiver the candidates are measured at: a G-buffer pixel's point, unit normal and the
/// luminance of its albedo (what turns irradiance into the image's radiance, up to 1/pi).
struct view_receiver {
    glm::vec3 position{0.f};
    glm::vec3 normal{0.f, 0.f, 1.f};
    float weight = 1.f;
};

/// The side, in pixels, of the square of pixels each of view_receivers' `count` receivers
/// stands for on a w x h image (at least 1).
inline double receiver_stride(std::size_t w, std::size_t h, std::size_t count) {
    require(count > 0, "receivers", "must be positive");
    return std::max(1.0, std::sqrt(double(w) * double(h) / double(count)));
}

/// The covered pixels of `gb` on a regular grid of about `count` cells over the image (the
/// pixel at each cell's centre; uncovered ones skipped), row by row.
template <class T>
std::vector<view_receiver> view_receivers(const gbuffer_view<T>& gb, std::size_t count) {
    require(count > 0, "receivers", "must be positive");
    std::vector<view_receiver> out;
    const std::size_t w = gb.width(), h = gb.height();
    if (w == 0 || h == 0) return out;
    const double stride = receiver_stride(w, h, count);
    for (double y = stride / 2; y < double(h); y += stride)
        for (double x = stride / 2; x < double(w); x += stride) {
            const auto u = std::size_t(x), v = std::size_t(y);
            if (!gb.covered(u, v)) continue;
            out.push_back({glm::vec3(gb.position(u, v)), glm::vec3(gb.normal(u, v)),
                           rec709_luminance<float, glm::vec3>(glm::vec3(gb.albedo(u, v)))});
        }
    return out;
}

/// Scratch of one thread's view_importance.
struct view_importance_scratch {
    std::vector<visibility_segment> segments;
    std::vector<std::uint32_t> receiver;
    std::vector<float> value;
    std::vector<std::uint8_t> blocked;
};

/// t of one candidate: sqrt(sum_g (weight_g sum of its terms at g that g sees)^2).
/// `terms(r, add)` calls add(luminance of an irradiance term, its segment) for each term
/// the candidate gives receiver r (several for a disc sample read from several maps); terms
/// <= 0 are skipped, the others asked of `occlusion` in one batch (all visible without one).
template <class Terms>
double view_importance(std::span<const view_receiver> receivers, Terms&& terms, const occlusion_query* occlusion,
                       view_importance_scratch& s) {
    s.segments.clear();
    s.receiver.clear();
    s.value.clear();
    for (std::size_t g = 0; g < receivers.size(); ++g)
        terms(receivers[g], [&](float value, const visibility_segment& segment) {
            if (!(value > 0.f) || !std::isfinite(value)) return;
            s.segments.push_back(segment);
            s.receiver.push_back(std::uint32_t(g));
            s.value.push_back(value * receivers[g].weight);
        });
    s.blocked.assign(s.value.size(), 0);
    if (occlusion && !s.value.empty()) occlusion->occluded(s.segments, s.blocked);
    double sum2 = 0, at = 0;
    for (std::size_t k = 0; k < s.value.size(); ++k) {
        if (!s.blocked[k]) at += double(s.value[k]);
        if (k + 1 == s.value.size() || s.receiver[k + 1] != s.receiver[k]) {
            sum2 += at * at;
            at = 0;
        }
    }
    return std::sqrt(sum2);
}

/// The near field of a candidate clamped at d^2 >= min_distance2: the ball of `near_field`
/// clamp distances around it. Its irradiance's square integrated over a receiving surface,
/// int 1 / max(d^2, d_min^2)^2 dA, comes for (1 - 1 / near_field^2) of its part beyond d_min
/// from inside that ball (15/16 at 4): the peak of a sender next to a surface, narrower than
/// the grid's stride wherever the clamp distance is below a few pixels' footprint, so the
/// grid misses it or, landing on it, counts it for stride^2 pixels. The receivers in the
/// ball are measured each for itself (near_field_weight) and the grid's receivers inside it
/// are left out: one sum over the image's pixels, its near part exact.
inline float near_field_radius(float near_field, float min_distance2) noexcept {
    const float r = near_field * std::sqrt(std::max(0.f, min_distance2));
    return std::isfinite(r) ? r : 0.f;
}

/// The factor on a near-field receiver's term, relative to a grid receiver's (standing for
/// stride^2 pixels, so 1 / stride on the term before it is squared), when `taken` of the
/// `found` pixels in the ball are measured (each then standing for found / taken of them).
inline float near_field_weight(double stride, std::size_t found, std::size_t taken) noexcept {
    return taken == 0 ? 0.f : float(std::sqrt(double(found) / double(taken)) / stride);
}

/// t of a candidate from its grid part and its near part (each view_importance's root of the
/// summed squares, over receivers that do not overlap): the root of the sum of both squares.
inline double combined_importance(double grid, double near) noexcept { return std::sqrt(grid * grid + near * near); }

/// P_j = defensive / M + (1 - defensive) t_j / sum t (uniform where the sum is 0 or not
/// finite). Every P_j >= defensive / M > 0; they sum to 1.
inline std::vector<double> view_selection_probabilities(std::span<const double> importance, double defensive) {
    require(!importance.empty(), "importance", "needs at least one candidate");
    require(defensive > 0 && defensive <= 1, "defensive", "must lie in (0, 1]");
    double total = 0;
    for (const double t : importance) total += std::isfinite(t) && t > 0 ? t : 0;
    const double m = double(importance.size());
    std::vector<double> p(importance.size());
    const bool uniform = !(total > 0) || !std::isfinite(total);
    for (std::size_t j = 0; j < p.size(); ++j) {
        const double t = std::isfinite(importance[j]) && importance[j] > 0 ? importance[j] : 0;
        p[j] = uniform ? 1 / m : defensive / m + (1 - defensive) * t / total;
    }
    return p;
}

/// One draw of a selection: the candidate and the factor its weight (flux, sample weight)
/// is multiplied by, 1 / (cells n_s P_j), times the number of draws merged into it.
struct selection_draw {
    std::uint32_t candidate = 0;
    double scale = 0;
};

/// `count` draws from the candidates by `probability`, systematic and dealt to the `cells`
/// sub-buffers with a rotation (file comment), listed so that draw k belongs to sub-buffer
/// k mod cells. With `merge` (a single sub-buffer only) a candidate drawn several times
/// comes back once with the scales added: the same sum with fewer senders.
inline std::vector<selection_draw> draw_for_view(std::span<const double> probability, std::size_t count, int cells,
                                                 std::uint64_t seed, bool merge = false) {
    require(!probability.empty(), "probability", "needs at least one candidate");
    require(cells >= 1 && count >= std::size_t(cells), "count", "must be at least the number of sub-buffers");
    std::vector<double> cdf(probability.size());
    double run = 0;
    for (std::size_t j = 0; j < cdf.size(); ++j) cdf[j] = run += probability[j];
    const std::size_t c = std::size_t(cells);
    std::vector<selection_draw> out(count);
    pcg32 rng(seed, 0x5e1ec7ed);
    // place(i, j) for draws i < n at (i + xi) / n of the cumulative sum, j the candidate there.
    const auto systematic = [&](std::size_t n, double xi, auto&& place) {
        std::size_t j = 0;
        for (std::size_t i = 0; i < n; ++i) {
            const double u = (double(i) + xi) / double(n) * run;
            while (j + 1 < cdf.size() && cdf[j] <= u) ++j;
            place(i, j);
        }
    };
    if (count % c == 0) {
        // One systematic sample of `count` (the union stratified like one frame's), draw i to
        // sub-buffer (i + r) mod c for a uniform rotation r: each sub-buffer's draws are a
        // systematic sample of count / c whose offset is uniform, so E[n_js] = n_s P_j.
        const std::size_t n_s = count / c, r = std::size_t(rng.next_u32() % std::uint32_t(c));
        systematic(count, rng.next_double(), [&](std::size_t i, std::size_t j) {
            const std::size_t s = (i + r) % c;
            out[s + (i / c) * c] = {std::uint32_t(j), 1.0 / (double(c) * double(n_s) * probability[j])};
        });
    } else {
        for (std::size_t s = 0; s < c; ++s) {
            const std::size_t n = (count - s + c - 1) / c;  // draws k < count with k mod c == s
            systematic(n, rng.next_double(), [&](std::size_t i, std::size_t j) {
                out[s + i * c] = {std::uint32_t(j), 1.0 / (double(c) * double(n) * probability[j])};
            });
        }
    }
    if (!merge || c != 1) return out;
    std::vector<selection_draw> merged;
    for (const selection_draw& d : out)
        if (!merged.empty() && merged.back().candidate == d.candidate)
            merged.back().scale += d.scale;
        else
            merged.push_back(d);
    return merged;
}

/// The senders of a frame: `count` of `candidates` drawn by `importance` (view_importance
/// per candidate) with the defensive share, each a copy of its candidate that `scaled(c,
/// factor)` has multiplied by its draw's factor (its flux and area, or its sample weight).
template <class Candidate, class Scaled>
std::vector<Candidate> select_for_view(std::span<const Candidate> candidates, std::span<const double> importance,
                                       std::size_t count, int cells, double defensive, std::uint64_t seed, bool merge,
                                       Scaled&& scaled) {
    require(importance.size() == candidates.size(), "importance", "needs one value per candidate");
    const std::vector<double> p = view_selection_probabilities(importance, defensive);
    std::vector<Candidate> out;
    for (const selection_draw& d : draw_for_view(p, count, cells, seed, merge))
        out.push_back(scaled(candidates[d.candidate], d.scale));
    return out;
}

}  // namespace bounce::indirect
