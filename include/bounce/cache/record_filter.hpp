#pragma once
/// \file cache/record_filter.hpp
/// Less noise per record at equal rays (issue 28): a new record's irradiance shrunk toward
/// what its overlapping neighbours predict at its point, each weighted by its variance.
///
/// A record's irradiance E is a Monte Carlo estimate with variance s^2 (its own rays:
/// stratified_luminance_variance). The records already in the cache predict the irradiance at
/// the new record's point as the cache would interpolate it there, E^ = sum w_j E_j(p) /
/// sum w_j (E_j(p) extrapolated with the gradients), with variance s^2^ = sum w_j^2 s_j^2 /
/// (sum w_j)^2 when the records' noise is independent. Two independent estimates of one value
/// combine best (least variance among unbiased linear combinations) as
///     E' = (E / s^2 + E^ / s^2^) / (1 / s^2 + 1 / s^2^) = E + lambda (E^ - E),
///     lambda = s^2 / (s^2 + s^2^),   var E' = s^2 s^2^ / (s^2 + s^2^),
/// the same lambda for every channel (the variances are of the luminance). Neighbours are not
/// the record's point: where the irradiance changes between them, E^ is biased by the
/// interpolation's own error, and the merge would carry that bias into the record. So a
/// record is merged only where its difference from the prediction is within k standard
/// errors, |Y(E) - Y(E^)| <= k sqrt(s^2 + s^2^) (Y: luminance); beyond, it keeps its own value
/// (real detail, a shadow edge the neighbours did not see). What bias the merge leaves is
/// measured in docs/irradiance-splatting.md against references (debiased error).
///
/// A variance that is not finite or not positive means "unknown" (records from samplers that
/// do not estimate it, or loaded from files that predate it, hold 0): such a record is left
/// as it is, and such a neighbour is left out of the prediction. A measured 0 (every ray saw
/// the same radiance) is treated alike, so no neighbour is ever trusted without limit.

#include <bounce/cache/gradients.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/errors.hpp>
#include <bounce/luminance.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>

#include <glm/glm.hpp>

namespace bounce::inline cache {

/// Variance of the luminance of E = pi / (M N) sum_i L_i over a stratified M x N grid of
/// cosine-distributed rays, one per cell (`radiance` row-major: cell j * N + k). One ray per
/// stratum gives no within-stratum spread, so the variance comes from differences of
/// neighbouring strata (collapsed strata, Cochran 1977, 5A.12), here second differences taken
/// cyclically in phi (Gasser, Sroka and Jennen-Steinmetz 1986): for each wedge k of a ring,
/// (Y_{k-1} - 2 Y_k + Y_{k+1})^2 / 6, whose expectation is the cells' variance where the
/// strata's means change linearly from wedge to wedge (first differences, (Y_k - Y_{k+1})^2 / 2,
/// also count the change itself: twice the spread over seeds on the Cornell box's back wall).
/// Still from above where the means jump (a wall's edge). Times (pi / (M N))^2. NaN when N < 3
/// or the sizes disagree (unknown).
inline double stratified_luminance_variance(std::span<const glm::vec3> radiance, std::uint32_t rings,
                                            std::uint32_t wedges) {
    if (wedges < 3 || radiance.size() != std::size_t(rings) * wedges || rings == 0)
        return std::numeric_limits<double>::quiet_NaN();
    double sum = 0;
    for (std::uint32_t j = 0; j < rings; ++j) {
        const glm::vec3* row = radiance.data() + std::size_t(j) * wedges;
        for (std::uint32_t k = 0; k < wedges; ++k) {
            const glm::dvec3 c = glm::dvec3(row[(k + wedges - 1) % wedges]) - 2.0 * glm::dvec3(row[k]) +
                                 glm::dvec3(row[(k + 1) % wedges]);
            const double d = rec709_luminance<double, glm::dvec3>(c);
            sum += d * d / 6.0;
        }
    }
    const double cell = std::numbers::pi / (double(rings) * double(wedges));
    return cell * cell * sum;
}

/// Settings of the neighbour filter (irradiance_cache_options::filter).
struct record_filter {
    /// Merge only within this many standard errors (the test above); 0 turns the filter off.
    /// Typical 2-3.
    float k = 0.f;
    /// The neighbours' weights are the cache's weighting function at accuracy `reach` * a:
    /// 1 asks only the records whose zones cover the point, as interpolation would (at a
    /// cache miss those are few and near their zones' edges); 2 also asks records up to
    /// twice as far, at more interpolation bias. Typical 1-2.
    float reach = 2.f;
    /// Also count the prediction's own bias, estimated from the difference D itself as
    /// b^2 = max(0, D^2 - s^2 - s^2^) (the positive-part empirical Bayes estimate), in lambda:
    /// lambda = s^2 / (s^2 + s^2^ + b^2), which moves a record by at most s^2 / |D| <= s where it
    /// disagrees with its neighbours beyond their noise, instead of by lambda D.
    bool soft = true;

    bool enabled() const noexcept { return k > 0.f; }
    /// Throws parameter_error naming the first bad field.
    void validate() const {
        require(std::isfinite(k) && k >= 0.f, "filter.k", "must be a non-negative number (0: off)");
        require(std::isfinite(reach) && reach > 0.f, "filter.reach", "must be a positive number");
    }
};

/// The neighbours' prediction at one point, accumulated one neighbour at a time.
struct neighbour_prediction {
    glm::dvec3 weighted{0.0};  ///< sum w_j E_j(p)
    double weight = 0;         ///< sum w_j
    double weighted_var = 0;   ///< sum w_j^2 s_j^2

    /// Adds a neighbour of weight w (> 0) predicting `e` at the point, with luminance
    /// variance `variance`; ignores it when w or the variance is not positive, or anything is
    /// not finite (unknown).
    void add(double w, const glm::dvec3& e, double variance) {
        if (!(w > 0.0) || !std::isfinite(w) || !std::isfinite(variance) || !(variance > 0.0)) return;
        if (!std::isfinite(e.x) || !std::isfinite(e.y) || !std::isfinite(e.z)) return;
        weighted += w * e;
        weight += w;
        weighted_var += w * w * variance;
    }
    bool empty() const noexcept { return !(weight > 0.0); }
    glm::dvec3 irradiance() const { return weighted / weight; }
    double variance() const { return weighted_var / (weight * weight); }
};

/// What filtering a record did.
struct filter_outcome {
    enum kind : std::uint8_t {
        unknown,   ///< no prediction, or a variance unknown: unchanged
        refused,   ///< record and prediction differ beyond k standard errors: unchanged
        merged,    ///< shrunk toward the prediction
    } what = unknown;
    double lambda = 0;  ///< the weight of the prediction (0 unless merged)
};

/// Shrinks `rec` (irradiance and variance) toward `p` as the file comment says, with the
/// test at `k` standard errors (and the bias estimate of record_filter::soft when `soft`);
/// returns what it did. `rec.variance` becomes the merged
/// estimate's variance. Leaves `rec` unchanged for an empty prediction, a record variance
/// not finite or not positive, a prediction variance not finite, or k <= 0.
inline filter_outcome shrink_to_prediction(irradiance_record& rec, const neighbour_prediction& p, double k,
                                           bool soft = false) {
    const double s2 = rec.variance;
    if (p.empty() || !(k > 0.0) || !std::isfinite(s2) || !(s2 > 0.0)) return {};
    const glm::dvec3 e_hat = p.irradiance();
    const double s2_hat = p.variance();
    if (!std::isfinite(s2_hat) || !std::isfinite(e_hat.x + e_hat.y + e_hat.z)) return {};
    const glm::dvec3 e(rec.irradiance);
    const double diff = rec709_luminance<double, glm::dvec3>(e - e_hat);
    if (diff * diff > k * k * (s2 + s2_hat)) return {filter_outcome::refused, 0.0};
    const double b2 = soft ? std::max(0.0, diff * diff - s2 - s2_hat) : 0.0;
    const double lambda = s2 / (s2 + s2_hat + b2);
    rec.irradiance = glm::vec3(e + lambda * (e_hat - e));
    rec.variance = float(s2 * (s2_hat + b2) / (s2 + s2_hat + b2));
    return {filter_outcome::merged, lambda};
}

/// Record `nb`'s share of the prediction at `rec`'s point: weight by `Weight` (a policy of
/// cache/weighting.hpp) at accuracy `a`, irradiance extrapolated with its gradients when
/// `gradients` (clamped at `max_extrapolation` E, as splatting does).
template <class Weight>
void add_neighbour(neighbour_prediction& p, const irradiance_record& rec, const irradiance_record& nb, double a,
                   bool gradients, double max_extrapolation) {
    using V = glm::dvec3;
    const V x(rec.position), n(rec.normal), xk(nb.position), nk(nb.normal), e(nb.irradiance);
    const double w = Weight::template weight<double, V>(x, n, xk, nk, 1.0 / double(nb.radius), a);
    if (!(w > 0.0)) return;
    V ek = e;
    if (gradients)
        ek = extrapolated_irradiance<double, V>(x, n, xk, nk, e, V(nb.rotation[0]), V(nb.rotation[1]), V(nb.rotation[2]),
                                                V(nb.translation[0]), V(nb.translation[1]), V(nb.translation[2]),
                                                max_extrapolation);
    p.add(w, ek, double(nb.variance));
}

}  // namespace bounce::cache
