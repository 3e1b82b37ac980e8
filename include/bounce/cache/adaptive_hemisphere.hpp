#pragma once
/// \file cache/adaptive_hemisphere.hpp
/// Adaptive rays per irradiance record: a stratified hemisphere whose strata take more
/// samples where the record's own estimate is uncertain, and a stopping rule on the
/// estimated standard error of its irradiance (docs/irradiance-splatting.md, "Adaptive rays
/// per record").
///
/// Strata are the M x N cells of cache/gradients.hpp (M rings of equal projected solid
/// angle, N wedges, N even). A first round puts one jittered sample in every cell. A cell is
/// refined by splitting: from n = 2^l samples, one in each of its n sub-strata, to 2n, each
/// sub-stratum halved (in phi on even levels, in theta on odd ones) and a new sample drawn
/// uniformly in the half its old sample does not occupy. Given the half it fell in, the old
/// sample is uniform there, so the cell mean (the average over its equal sub-strata) stays
/// unbiased, and a cell refined everywhere is the finer stratified grid. The irradiance
/// E = pi / (M N) * sum over cells of the cell means is then an unbiased stratified estimate
/// whatever the cells' sample counts (each stratum weighted by its measure, not its count).
///
/// Variance of E, from the record's own samples (luminance Y, Rec. 709), all by collapsed
/// strata (Cochran, Sampling Techniques, 5A.12): two strata of equal measure with one sample
/// each give (Y_a - Y_b)^2, whose expectation sigma_a^2 + sigma_b^2 + (mu_a - mu_b)^2 is never
/// below their true variance, and equals it where their means agree:
///  - cells are paired in phi, (j, 2i) with (j, 2i + 1); a pair is refined as a unit, so its
///    two cells always hold the same count n;
///  - a pair with n = 1 contributes (Y_a - Y_b)^2;
///  - a cell with n >= 2 contributes sum over sibling sub-strata (the two halves of the
///    last split, samples i and i + n/2) of (Y_i - Y_{i+n/2})^2 / n^2;
///  - V = (pi / (M N))^2 * sum over pairs: conservative, exact where paired strata have
///    equal means.
///
/// Which strata to refine: a pair's priority is the largest per-sample variance of its
/// neighbouring pairs (same ring, next pair in phi either side; same wedges, the rings on
/// either side), never its own. Light that is hard to integrate (the edge of a sunlit patch,
/// an occluder's silhouette) spans neighbouring strata, so the neighbours find it; and since
/// a pair's sample count never depends on its own samples, the cell means stay unbiased.
/// (Refining the strata whose own samples disagree keeps the high pilot sample with weight
/// 1/n and the low one with weight 1: at a stratum half covered by a bright patch that biases
/// its mean by a quarter of the patch's radiance.) Only the stopping rule and the size of a
/// round see every sample; their effect on any one stratum is of the order of one over the
/// number of pairs.

#include <bounce/errors.hpp>
#include <bounce/cache/gradients.hpp>
#include <bounce/luminance.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace bounce::inline cache {

/// How the rays after the first round are given to the strata.
enum class ray_allocation {
    /// To the strata whose neighbours' rays disagree, round by round, until the record's
    /// estimated standard error meets `target` (or max_rays): adaptive rays per record.
    variance,
    /// Importance sampling of the hemisphere by a coarse estimate of its incoming radiance
    /// (issue 28): every record casts max_rays, min_rays of them in the first round; the rest
    /// go to the strata in proportion to the luminance their neighbours' first-round rays saw
    /// (never their own) plus `defensive` times the mean, by adaptive_hemisphere::
    /// allocate_by_radiance. `target` and `irradiance_floor` are not used.
    radiance,
    /// As radiance, the importance being the range (largest less smallest) of the luminance
    /// the neighbours' first-round rays saw: rays go where the light changes, the strata
    /// whose own variance is large (Neyman's allocation, n ~ sigma), not to the inside of a
    /// bright patch, whose strata vary no more than a dark patch's.
    contrast,
};

/// Settings of adaptive rays per record. Default off: a sampler then casts a fixed grid.
struct adaptive_rays {
    bool enabled = false;
    /// First round: one sample in each cell of the grid adaptive_grid(min_rays) (about this
    /// many cells, N even). Typical 256-512. At least 4.
    std::uint32_t min_rays = 256;
    /// No record casts more (unless the first round's grid, rounded to whole strata, does).
    /// Typical 2048-4096. At least min_rays.
    std::uint32_t max_rays = 4096;
    /// Stop when the estimated standard error of the record's irradiance (luminance) is at
    /// most target * max(E, irradiance_floor): a relative standard error. Typical k * a with
    /// k about 0.2-0.3 (the error budget: docs/irradiance-splatting.md). Positive.
    double target = 0.04;
    /// W/m^2; 0 makes the target purely relative. A floor stops records in near darkness,
    /// whose relative error is large but whose absolute error is not, from taking max_rays.
    double irradiance_floor = 0.0;
    /// Which strata the later rounds' rays go to (variance: adaptive; radiance: importance).
    ray_allocation allocation = ray_allocation::variance;
    /// Importance allocations: the gradients (and the split sphere's harmonic mean distance)
    /// from the first-round grid itself, each cell at its samples' mean radiance and its
    /// nearest hit (adaptive_hemisphere::cell_samples), instead of the fine grid of
    /// fine_samples, which is up to 16 times larger. Not with the Hessian radius.
    bool cell_gradients = false;
    /// Radiance allocation: the floor added to every pair's importance, in units of the mean
    /// first-round luminance over the pairs, so that dark strata are still refined (the
    /// defensive part of the mixture). Non-negative; 0 gives rays to lit neighbourhoods only.
    double defensive = 0.5;

    /// Throws parameter_error naming the first bad field.
    void validate() const {
        require(min_rays >= 4, "min_rays", "needs at least 4 rays (two pairs of strata)");
        require(max_rays >= min_rays, "max_rays", "must not be below min_rays");
        require(max_rays <= (1u << 24), "max_rays", "must be at most 2^24");
        require(std::isfinite(target) && target > 0.0, "target", "must be a positive number");
        require(std::isfinite(irradiance_floor) && irradiance_floor >= 0.0, "irradiance_floor",
                "must be a non-negative number");
        require(std::isfinite(defensive) && defensive >= 0.0, "defensive", "must be a non-negative number");
        require(allocation == ray_allocation::variance || allocation == ray_allocation::radiance ||
                    allocation == ray_allocation::contrast,
                "allocation", "must be variance, radiance or contrast");
    }
};

/// The first round's grid for about `rays` samples: M = max(1, round(sqrt(rays / pi))) rings
/// and N = max(2, 2 round(rays / (2 M))) wedges (even, so cells pair up in phi; N ~ pi M as
/// in hemisphere_grid_for). Throws parameter_error when rays < 4.
struct adaptive_grid_size {
    std::uint32_t rings = 1, wedges = 2;
    std::uint32_t count() const noexcept { return rings * wedges; }
};
inline adaptive_grid_size adaptive_grid(std::uint32_t rays) {
    require(rays >= 4, "rays", "needs at least 4 rays");
    adaptive_grid_size g;
    g.rings = std::max(1u, std::uint32_t(std::lround(std::sqrt(double(rays) / std::numbers::pi))));
    g.wedges = std::max(2u, 2u * std::uint32_t(std::lround(double(rays) / (2.0 * g.rings))));
    return g;
}

/// The samples of one adaptive hemisphere, accumulated per cell (see the file comment).
class adaptive_hemisphere {
public:
    /// Throws parameter_error unless rings >= 1 and wedges is even and >= 2.
    adaptive_hemisphere(std::uint32_t rings, std::uint32_t wedges) : m_(rings), n_(wedges) {
        require(rings >= 1 && wedges >= 2 && wedges % 2 == 0, "rings/wedges",
                "need at least one ring and an even number of wedges (at least 2)");
        cells_.resize(std::size_t(rings) * wedges);
    }

    /// Empties every cell for a new hemisphere on a rings x wedges grid, keeping the buffers
    /// (a sampler reuses one object from record to record without allocating). Throws as the
    /// constructor.
    void reset(std::uint32_t rings, std::uint32_t wedges) {
        require(rings >= 1 && wedges >= 2 && wedges % 2 == 0, "rings/wedges",
                "need at least one ring and an even number of wedges (at least 2)");
        m_ = rings;
        n_ = wedges;
        cells_.resize(std::size_t(rings) * wedges);
        for (cell& c : cells_) {
            c.n = 0;
            c.sum = glm::dvec3(0.0);
            c.y = c.inverse_distance = 0;
            c.samples.clear();
        }
    }

    std::uint32_t rings() const noexcept { return m_; }
    std::uint32_t wedges() const noexcept { return n_; }
    std::size_t cells() const noexcept { return cells_.size(); }
    std::uint32_t count(std::size_t cell_index) const { return cells_.at(cell_index).n; }
    std::uint64_t samples() const noexcept {
        return std::accumulate(cells_.begin(), cells_.end(), std::uint64_t(0),
                               [](std::uint64_t s, const cell& c) { return s + c.n; });
    }

    /// The local direction (z along the normal) of jitter u in [0,1)^2 inside cell
    /// j * N + k: sin^2(theta) = (j + u.y) / M, phi = 2 pi (k + u.x) / N, as
    /// stratified_cosine_directions; uniform u gives directions uniform in projected solid
    /// angle over the cell.
    glm::vec3 direction_in(std::size_t cell_index, glm::vec2 u) const {
        require(cell_index < cells_.size(), "cell", "outside the grid");
        const double j = double(cell_index / n_), k = double(cell_index % n_);
        const double sin2 = std::min(1.0, (j + double(u.y)) / m_), sin_t = std::sqrt(sin2);
        const double cos_t = std::sqrt(std::max(0.0, 1.0 - sin2));
        const double phi = 2 * std::numbers::pi * (k + double(u.x)) / n_;
        return glm::vec3(float(sin_t * std::cos(phi)), float(sin_t * std::sin(phi)), float(cos_t));
    }

    /// The jitter u in [0,1)^2 of a local direction inside cell `cell_index` (the inverse of
    /// direction_in, clamped into the cell).
    glm::vec2 jitter_of(std::size_t cell_index, const glm::vec3& local_direction) const {
        require(cell_index < cells_.size(), "cell", "outside the grid");
        const double j = double(cell_index / n_), k = double(cell_index % n_);
        const glm::dvec3 d(local_direction);
        const double sin2 = d.x * d.x + d.y * d.y;
        double phi = std::atan2(d.y, d.x);
        if (phi < 0) phi += 2 * std::numbers::pi;
        const double below_one = 0x1.fffffep-1;
        const double ux = std::clamp(phi * n_ / (2 * std::numbers::pi) - k, 0.0, below_one);
        const double uy = std::clamp(sin2 * m_ - j, 0.0, below_one);
        return {float(ux), float(uy)};
    }

    /// One sample of cell `cell_index`: its jitter u (direction_in(cell_index, u) is its
    /// direction), local direction, incoming radiance (RGB) and hit distance (+infinity where
    /// the ray escaped). Throws parameter_error on non-finite radiance or a distance that is
    /// not positive.
    void add(std::size_t cell_index, glm::vec2 u, const glm::vec3& local_direction, const glm::vec3& radiance,
             float distance) {
        require(cell_index < cells_.size(), "cell", "outside the grid");
        require(std::isfinite(radiance.x) && std::isfinite(radiance.y) && std::isfinite(radiance.z), "radiance",
                "non-finite radiance sample");
        require(distance > 0.f && !std::isnan(distance), "distance", "hit distance must be positive");
        cell& c = cells_[cell_index];
        const glm::dvec3 L(radiance);
        const double y = rec709_luminance<double, glm::dvec3>(L);
        c.n += 1;
        c.sum += L;
        c.y += y;
        c.samples.push_back({u, y, L, 1.0 / double(distance), local_direction});
        c.inverse_distance += 1.0 / double(distance);  // 0 for escaped rays
    }

    /// The jitters of the samples that double cell `cell_index` (one per sample it holds, in
    /// the half of that sample's sub-stratum it does not occupy), uniform from `next`, a
    /// function returning uniform floats in [0, 1). Throws parameter_error unless the cell
    /// holds a power of two samples.
    template <class Uniform>
    std::vector<glm::vec2> refinement_jitters(std::size_t cell_index, Uniform&& next) const {
        require(cell_index < cells_.size(), "cell", "outside the grid");
        const cell& c = cells_[cell_index];
        require(c.n > 0 && (c.n & (c.n - 1)) == 0, "cell", "refines from a power of two samples");
        unsigned level = 0;
        while ((1u << level) < c.n) ++level;
        std::vector<glm::vec2> out;
        out.reserve(c.n);
        for (const sample& s : c.samples) {
            glm::dvec2 lo(0.0), hi(1.0);
            for (unsigned t = 0; t < level; ++t) {  // the box of s's sub-stratum
                const int d = int(t % 2);
                const double mid = 0.5 * (lo[d] + hi[d]);
                (double(s.u[d]) < mid ? hi[d] : lo[d]) = mid;
            }
            const int d = int(level % 2);
            const double mid = 0.5 * (lo[d] + hi[d]);
            (double(s.u[d]) < mid ? lo[d] : hi[d]) = mid;  // the other half
            const double a = double(next()), b = double(next());
            const glm::dvec2 u(lo.x + a * (hi.x - lo.x), lo.y + b * (hi.y - lo.y));
            // Kept below the half's upper bound after rounding to float: the double just below
            // it can round up onto the bound, putting the sample in its sibling's half (then
            // two samples share a sub-stratum and fine_samples refuses the cell).
            const auto below = [](double x, double upper) {
                return std::min(float(x), std::nextafter(float(upper), 0.f));
            };
            out.emplace_back(below(u.x, hi.x), below(u.y, hi.y));
        }
        return out;
    }

    /// pi / (M N): each cell's share of the irradiance integral.
    double cell_weight() const noexcept { return std::numbers::pi / double(cells_.size()); }

    /// E per channel: pi / (M N) * sum of cell means. Throws parameter_error if a cell is empty.
    glm::dvec3 irradiance() const {
        glm::dvec3 e(0.0);
        for (const cell& c : cells_) e += c.sum / double(nonempty(c));
        return e * cell_weight();
    }
    /// E's luminance.
    double luminance_irradiance() const {
        double e = 0;
        for (const cell& c : cells_) e += c.y / double(nonempty(c));
        return e * cell_weight();
    }

    /// Per-sample variance of luminance in pair p (cells 2p and 2p + 1 of its ring, p =
    /// j * N/2 + i): pair_variance(p) * n / 2, n the pair's count; (Y_a - Y_b)^2 / 2 at n = 1.
    double pair_sample_variance(std::size_t p) const { return pair_variance(p) * double(pair_count(p)) / 2; }

    /// The pair's share of the variance of E's luminance, before the factor (pi / (M N))^2:
    /// (Y_a - Y_b)^2 while both cells hold one sample, else the sum of its cells' sibling
    /// terms (a single-sample cell beside a refined one takes (Y_a - mean_b)^2, still
    /// conservative).
    double pair_variance(std::size_t p) const {
        const cell& a = cells_.at(2 * p);
        const cell& b = cells_.at(2 * p + 1);
        const std::uint32_t na = nonempty(a), nb = nonempty(b);
        if (na == 1 && nb == 1) {
            const double d = a.y - b.y;
            return d * d;
        }
        auto term = [](const cell& c, const cell& other) {
            if (c.n >= 2) return sibling_variance(c);
            const double d = c.y - other.y / other.n;
            return d * d;
        };
        return term(a, b) + term(b, a);
    }

    std::size_t pairs() const noexcept { return cells_.size() / 2; }

    /// Mean luminance of pair p's two cells (each its own samples' mean). Throws
    /// parameter_error if either is empty.
    double pair_luminance(std::size_t p) const {
        const cell& a = cells_.at(2 * p);
        const cell& b = cells_.at(2 * p + 1);
        return 0.5 * (a.y / double(nonempty(a)) + b.y / double(nonempty(b)));
    }

    /// Estimated variance of luminance_irradiance() (see the file comment).
    double variance() const {
        double v = 0;
        for (std::size_t p = 0; p < pairs(); ++p) v += pair_variance(p);
        const double w = cell_weight();
        return w * w * v;
    }

    /// sqrt(variance()) / max(E_Y, floor); 0 where the variance is 0, +infinity where it is
    /// not and the denominator is 0.
    double relative_standard_error(double floor = 0.0) const {
        const double v = variance();
        if (!(v > 0)) return 0.0;
        const double scale = std::max(luminance_irradiance(), floor);
        return scale > 0 ? std::sqrt(v) / scale : std::numeric_limits<double>::infinity();
    }

    /// Extra samples per cell for one round of at most `budget` rays. Pairs are taken in
    /// decreasing order of (their neighbours' largest per-sample variance + a quarter of the
    /// mean over all pairs) / n; each taken pair has its count doubled (2n rays; pairs the
    /// rest of the budget cannot double are passed over). The round stops once it has
    /// spent at least `min_spend` rays and the variance predicted from the pairs' own
    /// estimates has fallen to `target_variance` (in units of variance(), i.e. with the
    /// cell weight squared), or when the budget is spent. Empty where nothing can be added.
    std::vector<std::uint32_t> plan(std::uint64_t budget, double target_variance, std::uint64_t min_spend = 0) const {
        std::vector<std::uint32_t> extra(cells_.size(), 0);
        const std::size_t np = pairs();
        const std::uint32_t half_n = n_ / 2;
        std::vector<double> own(np);  // per-sample variance of each pair
        double mean_own = 0;
        for (std::size_t p = 0; p < np; ++p) mean_own += own[p] = pair_sample_variance(p);
        mean_own /= double(np);
        std::vector<double> key(np);
        for (std::size_t p = 0; p < np; ++p) {
            const std::size_t j = p / half_n, i = p % half_n;
            double nb = 0;
            if (half_n > 1) {
                nb = std::max(nb, own[j * half_n + (i + 1) % half_n]);
                nb = std::max(nb, own[j * half_n + (i + half_n - 1) % half_n]);
            }
            if (j > 0) nb = std::max(nb, own[(j - 1) * half_n + i]);
            if (j + 1 < m_) nb = std::max(nb, own[(j + 1) * half_n + i]);
            key[p] = (nb + 0.25 * mean_own) / double(pair_count(p));
        }
        std::vector<std::size_t> order(np);
        std::iota(order.begin(), order.end(), std::size_t(0));
        std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return key[x] > key[y]; });
        const double w2 = cell_weight() * cell_weight();
        double predicted = variance();
        std::uint64_t spent = 0;
        for (const std::size_t p : order) {
            if (!(key[p] > 0) || budget - spent < 2) break;
            if (spent >= min_spend && predicted <= target_variance) break;
            const std::uint32_t n = pair_count(p);
            if (2 * std::uint64_t(n) > budget - spent) continue;
            extra[2 * p] = extra[2 * p + 1] = n;
            spent += 2 * std::uint64_t(n);
            // The pair's own estimate says how much the doubling should remove (at least
            // half for independent samples; splitting strata removes more where they are smooth).
            predicted -= w2 * 0.5 * pair_variance(p);
        }
        if (spent == 0) extra.clear();
        return extra;
    }

    /// The most samples allocate_by_radiance gives one cell (4 splits: the fine grid of
    /// fine_samples is then at most 4 x 4 times the first round's).
    static constexpr std::uint32_t max_allocated_per_cell = 16;

    /// Importance allocation (ray_allocation::radiance): the sample count every cell should
    /// reach (a power of two, equal in the two cells of a pair, never below the count it holds)
    /// with at most `budget` more samples. A pair's importance is the largest mean luminance
    /// of its neighbouring pairs (the next pair either side in phi, the rings above and
    /// below, as plan's neighbours), never its own, plus `defensive` times the mean over all
    /// pairs (all pairs alike where everything is black). Pairs are doubled greedily in
    /// decreasing order of importance / count, each doubling of a pair of n costing 2n, up to
    /// max_allocated_per_cell, so counts end up about proportional to the importance.
    ///
    /// Unbiasedness: a cell's count depends on its neighbours' samples, not on its own, so
    /// its mean (each sub-stratum by its measure) stays an unbiased estimate of the cell's
    /// mean radiance; only the greedy order, through the neighbours' keys, sees a cell's own
    /// sample, an effect of order one over the number of pairs. Letting a cell's own first
    /// sample pick its count biases it: a bright first sample in a half-lit cell gets a dark
    /// second, a dark one none (the mean is a quarter of the patch low; tested).
    /// With `contrast`, a pair's importance is instead the range (largest less smallest) of
    /// those neighbours' mean luminance (ray_allocation::contrast), plus the same floor.
    /// Throws parameter_error if a cell is empty or `defensive` is negative or not finite.
    std::vector<std::uint32_t> allocate_by_radiance(std::uint64_t budget, double defensive, bool contrast = false) const {
        require(std::isfinite(defensive) && defensive >= 0.0, "defensive", "must be a non-negative number");
        const std::size_t np = pairs();
        const std::uint32_t half_n = n_ / 2;
        std::vector<double> lum(np);
        double mean = 0;
        for (std::size_t p = 0; p < np; ++p) mean += lum[p] = std::max(pair_luminance(p), 0.0);
        mean /= double(np);
        std::vector<double> key(np, 1.0);
        if (mean > 0)
            for (std::size_t p = 0; p < np; ++p) {
                const std::size_t j = p / half_n, i = p % half_n;
                double hi = 0, lo = std::numeric_limits<double>::infinity();
                auto see = [&](double y) {
                    hi = std::max(hi, y);
                    lo = std::min(lo, y);
                };
                if (half_n > 1) {
                    see(lum[j * half_n + (i + 1) % half_n]);
                    see(lum[j * half_n + (i + half_n - 1) % half_n]);
                }
                if (j > 0) see(lum[(j - 1) * half_n + i]);
                if (j + 1 < m_) see(lum[(j + 1) * half_n + i]);
                const double importance = contrast ? (lo <= hi ? hi - lo : 0.0) : hi;
                key[p] = importance + defensive * mean;
            }
        std::vector<std::uint32_t> count(np);
        std::vector<std::uint64_t> held(np);  // samples the pair's two cells hold (or will)
        using entry = std::pair<double, std::size_t>;  // (importance / count, pair); ties to the lower pair
        auto before = [](const entry& x, const entry& y) { return x.first < y.first || (x.first == y.first && x.second > y.second); };
        std::vector<entry> heap;
        heap.reserve(np);
        for (std::size_t p = 0; p < np; ++p) {
            count[p] = std::max(cells_[2 * p].n, cells_[2 * p + 1].n);
            held[p] = std::uint64_t(cells_[2 * p].n) + cells_[2 * p + 1].n;
            if (key[p] > 0 && count[p] < max_allocated_per_cell) heap.emplace_back(key[p] / count[p], p);
        }
        std::make_heap(heap.begin(), heap.end(), before);
        std::uint64_t spent = 0;
        while (!heap.empty() && budget - spent >= 2) {
            std::pop_heap(heap.begin(), heap.end(), before);
            const std::size_t p = heap.back().second;
            heap.pop_back();
            const std::uint32_t n = count[p];
            const std::uint64_t cost = 4 * std::uint64_t(n) - held[p];  // both cells to 2n
            if (cost > budget - spent) continue;  // its next doubling never fits; smaller ones may
            count[p] = 2 * n;
            held[p] = 4 * std::uint64_t(n);
            spent += cost;
            if (count[p] < max_allocated_per_cell) {
                heap.emplace_back(key[p] / count[p], p);
                std::push_heap(heap.begin(), heap.end(), before);
            }
        }
        std::vector<std::uint32_t> target(cells_.size());
        for (std::size_t p = 0; p < np; ++p) target[2 * p] = target[2 * p + 1] = count[p];
        return target;
    }

    /// The first-round grid for estimate_hemisphere, each cell at its samples' mean radiance
    /// (the unbiased cell mean), its nearest hit (the wall terms of the translation gradient
    /// take the nearer of two cells' distances) and its first sample's direction. Throws
    /// parameter_error if a cell is empty.
    void cell_samples(hemisphere_samples& s) const {
        s.rings = m_;
        s.wedges = n_;
        s.direction.resize(cells_.size());
        s.radiance.resize(cells_.size());
        s.distance.resize(cells_.size());
        for (std::size_t i = 0; i < cells_.size(); ++i) {
            const cell& c = cells_[i];
            s.radiance[i] = glm::vec3(c.sum / double(nonempty(c)));
            double nearest = 0;  // the largest inverse distance
            for (const sample& x : c.samples) nearest = std::max(nearest, x.inverse_distance);
            s.distance[i] = nearest > 0 ? float(1.0 / nearest) : std::numeric_limits<float>::infinity();
            s.direction[i] = c.samples.front().direction;
        }
    }
    /// The mean over the hemisphere (each cell by its measure) of the samples' inverse hit
    /// distances, 0 for escaped rays: one over the split sphere's harmonic mean distance.
    double mean_inverse_distance() const {
        double sum = 0;
        for (const cell& c : cells_) sum += c.inverse_distance / double(nonempty(c));
        return sum / double(cells_.size());
    }

    /// The samples as one grid for estimate_hemisphere, fine enough for the most refined
    /// cell: with L = max(2, the deepest split level), every cell is cut into 2^ceil(L/2)
    /// wedges by 2^floor(L/2) rings (the kd splits alternate phi, theta), and each fine cell
    /// takes the one sample of the cell's sub-stratum that contains it: its radiance and hit
    /// distance, and its direction where the sample lies inside the fine cell (the fine cell's
    /// centre otherwise). Each sample's value thus covers exactly its sub-stratum's measure,
    /// so the irradiance is the cell-mean estimate, and the gradients see every split at its
    /// own resolution (walls inside one sub-stratum carry no difference). No two samples are
    /// averaged into one fine cell: the translation gradient's wall term takes the nearer of
    /// two distances, and a mean of distances there would shrink it. Throws parameter_error
    /// if a cell is empty.
    hemisphere_samples fine_samples() const {
        hemisphere_samples s;
        fine_samples(s);
        return s;
    }
    /// As above into `s`, reusing its vectors. `centre_directions` false gives every fine cell
    /// its sample's direction instead of the centre (no trigonometry): for callers that read
    /// no directions (Krivanek's gradient without the Hessian), the estimate is the same.
    void fine_samples(hemisphere_samples& s, bool centre_directions = true) const {
        unsigned deepest = 2;
        for (const cell& c : cells_) deepest = std::max(deepest, level_of(nonempty(c)));
        const unsigned lx = (deepest + 1) / 2, ly = deepest / 2;
        const std::uint32_t sx = 1u << lx, sy = 1u << ly;
        s.rings = m_ * sy;
        s.wedges = n_ * sx;
        const std::size_t fine = std::size_t(s.rings) * s.wedges;
        s.direction.resize(fine);
        s.radiance.resize(fine);
        s.distance.resize(fine);
        thread_local std::vector<std::int32_t> owner;
        for (std::size_t index = 0; index < cells_.size(); ++index) {
            const cell& c = cells_[index];
            const unsigned level = level_of(c.n);
            // The sample in each of the cell's 2^level sub-strata (kd path bits, first split highest).
            owner.assign(std::size_t(1) << level, -1);
            for (std::size_t i = 0; i < c.samples.size(); ++i) owner[box_of(c.samples[i].u, level)] = std::int32_t(i);
            const std::size_t j = index / n_, k = index % n_;
            for (std::uint32_t b = 0; b < sy; ++b)
                for (std::uint32_t a = 0; a < sx; ++a) {
                    const glm::vec2 centre((float(a) + 0.5f) / float(sx), (float(b) + 0.5f) / float(sy));
                    const std::int32_t who = owner[box_of(centre, level)];
                    require(who >= 0, "cell", "samples must come from refinement_jitters (one per sub-stratum)");
                    const sample& x = c.samples[std::size_t(who)];
                    const std::size_t f = (j * sy + b) * s.wedges + k * sx + a;
                    s.radiance[f] = glm::vec3(x.radiance);
                    s.distance[f] = x.inverse_distance > 0 ? float(1.0 / x.inverse_distance) : std::numeric_limits<float>::infinity();
                    const bool inside = std::uint32_t(x.u.x * float(sx)) == a && std::uint32_t(x.u.y * float(sy)) == b;
                    s.direction[f] = inside || !centre_directions ? x.direction : direction_in(index, centre);
                }
        }
    }

private:
    struct sample {
        glm::vec2 u;                 // jitter inside the cell
        double y;                    // luminance
        glm::dvec3 radiance;
        double inverse_distance;     // 0 for escaped rays
        glm::vec3 direction;         // local
    };
    struct cell {
        std::uint32_t n = 0;
        glm::dvec3 sum{0.0};
        double y = 0, inverse_distance = 0;
        std::vector<sample> samples;  // in the order added: i and i + n/2 are siblings
    };
    std::uint32_t m_, n_;
    std::vector<cell> cells_;

    static unsigned level_of(std::uint32_t n) {
        unsigned level = 0;
        while ((1u << level) < n) ++level;
        return level;
    }
    // The kd path of u down `level` splits (phi first, then theta, alternately).
    static std::size_t box_of(glm::vec2 u, unsigned level) {
        glm::dvec2 lo(0.0), hi(1.0);
        std::size_t path = 0;
        for (unsigned t = 0; t < level; ++t) {
            const int d = int(t % 2);
            const double mid = 0.5 * (lo[d] + hi[d]);
            const bool upper = double(u[d]) >= mid;
            (upper ? lo[d] : hi[d]) = mid;
            path = 2 * path + (upper ? 1 : 0);
        }
        return path;
    }
    static std::uint32_t nonempty(const cell& c) {
        require(c.n > 0, "cell", "every cell needs at least one sample");
        return c.n;
    }
    // sum over the last split's sibling sub-strata of (Y_i - Y_{i+n/2})^2 / n^2.
    static double sibling_variance(const cell& c) {
        const std::size_t half = c.samples.size() / 2;
        double v = 0;
        for (std::size_t i = 0; i < half; ++i) {
            const double d = c.samples[i].y - c.samples[i + half].y;
            v += d * d;
        }
        return v / (double(c.n) * double(c.n));
    }
    std::uint32_t pair_count(std::size_t p) const { return std::min(cells_[2 * p].n, cells_[2 * p + 1].n); }
};

}  // namespace bounce::cache
