#pragma once
/// \file cache/record.hpp
/// Irradiance records: what a record holds, how it extrapolates to a nearby point with its
/// gradients (Gautron 2008, Algorithms 1 and 4), what it adds to the splat buffer, and how its
/// radius R is limited.

#include <bounce/errors.hpp>
#include <bounce/cache/gradients.hpp>
#include <bounce/sampling.hpp>
#include <bounce/vocabulary.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include <glm/glm.hpp>

namespace bounce::inline cache {

/// One irradiance cache record, in world space. View-independent: a record computed for
/// one camera is valid for every camera.
struct irradiance_record {
    glm::vec3 position{0.f};                    ///< p_k
    glm::vec3 normal{0, 0, 1};                  ///< n_k, unit
    glm::vec3 irradiance{0.f};                  ///< E_k per channel (W/m^2)
    std::array<glm::vec3, 3> rotation{};        ///< grad_r per channel R, G, B (W/m^2 per radian)
    std::array<glm::vec3, 3> translation{};     ///< grad_t per channel (W/m^2 per world unit)
    float radius = 1.f;                         ///< R_k, world units, after every clamp
    /// Estimated variance of the luminance of E_k from the record's own rays ((W/m^2)^2;
    /// cache/record_filter.hpp); 0: unknown (samplers that do not estimate it).
    float variance = 0.f;
};

/// E_k(p) = E_k + (n_k x n) . grad_r + (p - p_k) . grad_t per channel (Gautron 2008, Algorithm 4),
/// with the gradient term clamped to +-max_extrapolation * E_k per channel so that a record
/// never extrapolates to negative or runaway irradiance far from where it was measured.
/// Typical max_extrapolation: 1 (E_k(p) within [0, 2 E_k]).
template <real T, vec3_of<T> V>
V extrapolated_irradiance(const V& p, const V& n, const V& pk, const V& nk, const V& e,
                          const V& rot_r, const V& rot_g, const V& rot_b,
                          const V& tr_r, const V& tr_g, const V& tr_b, T max_extrapolation) {
    const V c = cross(nk, n);
    const V d = p - pk;
    const V delta(dot(c, rot_r) + dot(d, tr_r), dot(c, rot_g) + dot(d, tr_g), dot(c, rot_b) + dot(d, tr_b));
    const V limit = e * max_extrapolation;
    return e + clamp(delta, -limit, limit);
}

/// Irradiance without gradients, for `--gradients off`: same signature, E_k unchanged.
template <real T, vec3_of<T> V>
V constant_irradiance(const V&, const V&, const V&, const V&, const V& e, const V&, const V&, const V&,
                      const V&, const V&, const V&, T) {
    return e;
}

/// Ward et al. 1988's test against records in front of the shaded point. With the mean
/// normal (n + nk) / 2, d = (p - pk) . (n + nk) / 2 is the height of p above record k's
/// tangent plane: 0 up to rounding for two points of one plane or one sphere, whatever their
/// distance. d < 0 puts record k in front of p: a record on a step above p, or on the far
/// side of a crease, measured a hemisphere p does not see. True (record k must not
/// contribute) where d < -tolerance * a * R_k: the allowance is a fraction of the zone's
/// radius, so the test does not depend on the scene's scale and ignores the small depths
/// of tessellated curved surfaces. Inside the zone |d| <= a R_k, so tolerance >= 1 never
/// rejects (the test is off).
template <real T, vec3_of<T> V>
auto record_in_front(const V& p, const V& n, const V& pk, const V& nk, T inv_r, T a, T tolerance) {
    return dot(p - pk, n + nk) * inv_r < T(-2) * tolerance * a;
}

/// What record k adds to the splat buffer at a pixel (Gautron 2008, Algorithm 1): the weighted
/// outgoing radiance w * (rho_d / pi) * E_k(p) in rgb and the weight w in the fourth
/// component. `Weight` is a policy of cache/weighting.hpp; `Gradients` is true to extrapolate
/// with the record's gradients; `FrontTest` is true to apply record_in_front with
/// `front_tolerance` (ignored otherwise). Returns all zeros where the record does not
/// contribute.
template <class Weight, bool Gradients, bool FrontTest, real T, vec3_of<T> V>
std::array<T, 4> splat_contribution(const V& p, const V& n, const V& albedo, const V& pk, const V& nk, T inv_r,
                                    T a, const V& e, const V& rot_r, const V& rot_g, const V& rot_b,
                                    const V& tr_r, const V& tr_g, const V& tr_b, T max_extrapolation,
                                    [[maybe_unused]] T front_tolerance) {
    T w = Weight::template weight<T, V>(p, n, pk, nk, inv_r, a);
    if constexpr (FrontTest) w = select(record_in_front<T, V>(p, n, pk, nk, inv_r, a, front_tolerance), T(0), w);
    V ek = e;
    if constexpr (Gradients)
        ek = extrapolated_irradiance<T, V>(p, n, pk, nk, e, rot_r, rot_g, rot_b, tr_r, tr_g, tr_b, max_extrapolation);
    const V lo = albedo * ek * (w * T(1.0 / std::numbers::pi));
    return {lo.x, lo.y, lo.z, w};
}

/// What every splat of a frame shares, on every backend (cpu::splat_params and
/// gl::splat_params are this type).
struct splat_params {
    float a = 0.2f;                 ///< accuracy a of Eq. 8.3; typical 0.1-0.4 (smaller: more records)
    bool gradients = true;          ///< extrapolate with the records' gradients
    float max_extrapolation = 1.f;  ///< gradient term clamped to +-this * E_k per channel; typical 1
    /// Ward's in-front test (record_in_front): records whose tangent plane p lies more than
    /// this fraction of the zone's radius behind are skipped. In [0, 1]; 1 turns it off, and
    /// then backends run the kernel without the test (FrontTest = false).
    float front_tolerance = 1.f;

    bool front_test() const noexcept { return front_tolerance < 1.f; }

    /// Throws parameter_error naming the first bad field.
    void validate() const {
        require(std::isfinite(a) && a > 0.f, "a", "accuracy must be a positive number");
        require(std::isfinite(max_extrapolation) && max_extrapolation >= 0.f, "max_extrapolation",
                "must be a non-negative number");
        require(front_tolerance >= 0.f && front_tolerance <= 1.f, "front_tolerance", "must be in [0, 1] (1: off)");
    }
};

/// Calls f(std::bool_constant<Gradients>{}, std::bool_constant<FrontTest>{}) with the
/// compile-time flags of splat_contribution, so a run-time setting reaches a kernel that
/// pays only for what it uses (as with_weighting does for policies).
template <class F>
decltype(auto) with_kernel_flags(bool gradients, bool front_test, F&& f) {
    const auto front = [&](auto g) -> decltype(auto) {
        return front_test ? f(g, std::true_type{}) : f(g, std::false_type{});
    };
    return gradients ? front(std::true_type{}) : front(std::false_type{});
}

/// The flags `sp` asks for.
template <class F>
decltype(auto) with_kernel_flags(const splat_params& sp, F&& f) {
    return with_kernel_flags(sp.gradients, sp.front_test(), std::forward<F>(f));
}

/// Normalization of the splat buffer (Gautron 2008, Algorithm 5, last loop): sum / weight, black
/// where no record reached the pixel.
template <real T, vec3_of<T> V>
V normalized_splat(const V& sum, T weight) {
    return select(weight > T(0), sum / select(weight > T(0), weight, T(1)), sum * T(0));
}

/// Progressive display, where a record budget leaves pixels no zone reaches: the splat at
/// a blended with a splat of the same records at a wider a' (typically 4a), scaled by a
/// small lambda (typically 1e-3). Where the a-zones reach, the result moves from the
/// normalized splat by at most lambda W'/W relative; where they do not, it is the wide
/// splat's normalized value; black only where neither reaches.
template <real T, vec3_of<T> V>
V hole_filled_splat(const V& sum, T weight, const V& wide_sum, T wide_weight, T lambda) {
    return normalized_splat<T, V>(sum + wide_sum * lambda, weight + wide_weight * lambda);
}

/// Where a record's radius R comes from before the limits.
enum class radius_policy {
    /// The split sphere (Ward et al. 1988): R = the harmonic mean hit distance, the distance
    /// at which its first-order error bound reaches 100%; the zone a R bounds it by a.
    split_sphere,
    /// Hessian-based error control (Schwarzhaupt, Jensen and Jarosz 2012): the zone a R from
    /// the error of the record's own interpolation as its occlusion Hessian
    /// (add_translation_hessian) predicts it, budgeted over the zone's area as the paper
    /// does (its total-error metric R = (4 eps / lambda)^(1/4)) rather than at the zone's
    /// edge, so that records concentrate where irradiance curves without piling up where
    /// it merely curves fast over a small area. See hessian_radius for the rule and
    /// docs/irradiance-splatting.md for why: relative error a spread over a disc of the
    /// record's mean hit distance. Records depend on a.
    hessian,
};

/// Limits on a record's radius R (Tabellion and Lamorlette 2004; Krivanek et al. 2006).
/// Every value is optional; defaults leave R unchanged.
struct radius_limits {
    radius_policy policy = radius_policy::split_sphere;  ///< where R comes from
    float hessian_a = 0.15f;  ///< radius_policy::hessian: the cache's accuracy a the radius is made for
    float min_world = 0.f;  ///< R >= this (world units); see scene_radius_limits
    float max_world = std::numeric_limits<float>::infinity();  ///< R <= this (world units)
    /// R >= this times the record's mean hit distance (hemisphere_estimate::mean_distance):
    /// a floor in world space that follows the size of the space around the record, where
    /// the harmonic mean goes to 0 in a corner or a crack while the mean stays the room's
    /// size. View-independent, scale-free. Typical 1/64; 0 disables.
    float min_mean_distance = 0.f;
    /// R >= min_pixels * footprint: stops records piling up where geometry is close.
    /// Typical: 1-3 pixels (0 disables).
    float min_pixels = 0.f;
    /// R <= max_pixels * footprint: stops one record covering a whole image region with
    /// a single value. Typical: 20-100 pixels (infinity disables).
    float max_pixels = std::numeric_limits<float>::infinity();
    /// R <= E / |grad_t E| per channel: the distance over which the first-order
    /// extrapolation would change E by 100% (Ward and Heckbert 1992). Typical: on.
    bool gradient_limit = true;
    /// radius_policy::hessian: whether the cache extrapolates records with their gradients
    /// (splat_params::gradients), which decides the order of the error the radius bounds
    /// (hessian_radius). With gradients the gradient limit applies to the zone a R instead
    /// of R: the zone ends where the first-order term reaches E, where the extrapolation's
    /// clamp (splat_params::max_extrapolation, typically 1) starts to bite; R <= E / |grad E|
    /// would cut the zone to a E / |grad E|, where the extrapolation is still exact to first
    /// order.
    bool hessian_gradients = true;
    /// radius_policy::hessian: the zone a R at most this times the record's harmonic mean
    /// distance, the split sphere's own R, where Ward's first-order bound on the error of
    /// moving the record reaches 100% (near occluders the irradiance may change by as much
    /// as itself, however flat its Hessian looked from the record). 1: the Hessian zone may
    /// grow up to 1/a times the split sphere's zone where the light is smooth, never past
    /// where the split sphere's error test says the record is no longer valid. Infinity: off.
    float hessian_zone_cap = std::numeric_limits<float>::infinity();
};

/// R from a hemisphere's harmonic mean distance and translation gradient, with the limits
/// applied in order: gradient limit, mean-distance floor (given a finite `mean_distance`),
/// world clamp, pixel-footprint clamp (the footprint is the world size of one pixel at the
/// record, see camera::pixel_footprint). A hemisphere that saw nothing (R = infinity) gets
/// the largest radius the limits allow.
inline float limit_radius(double harmonic_mean, const glm::dvec3& e, const std::array<glm::dvec3, 3>& translation,
                          const radius_limits& lim, double pixel_footprint,
                          double mean_distance = std::numeric_limits<double>::infinity()) {
    double r = harmonic_mean;
    if (lim.gradient_limit)
        for (int c = 0; c < 3; ++c) {
            const double g = glm::length(translation[c]);
            if (g > 0 && e[c] > 0) r = std::min(r, e[c] / g);
        }
    if (std::isfinite(mean_distance)) r = std::max(r, lim.min_mean_distance * mean_distance);
    r = std::clamp(r, double(lim.min_world), double(lim.max_world));
    if (pixel_footprint > 0 && std::isfinite(pixel_footprint))
        r = std::clamp(r, lim.min_pixels * pixel_footprint, std::max(lim.min_pixels * pixel_footprint, lim.max_pixels * pixel_footprint));
    return float(r);
}

/// World limits from the scene's size, as Radiance's ambient resolution `-ar` sets them
/// (`src/rt/ambient.c`): min_world = size / resolution and max_world = max_ratio *
/// min_world, at most the size, where size is the largest extent of the bounds [lo, hi].
/// resolution 0 leaves both unlimited (the scene then has no scale of its own in R).
inline radius_limits scene_radius_limits(radius_limits lim, const glm::vec3& lo, const glm::vec3& hi, float resolution,
                                         float max_ratio = 64.f) {
    require(std::isfinite(resolution) && resolution >= 0.f, "resolution", "must be a non-negative number");
    require(std::isfinite(max_ratio) && max_ratio >= 1.f, "max_ratio", "must be at least 1");
    const glm::vec3 extent = hi - lo;
    const float size = std::max({extent.x, extent.y, extent.z});
    if (!(resolution > 0.f) || !(size > 0.f) || !std::isfinite(size)) return lim;
    lim.min_world = size / resolution;
    lim.max_world = std::min(size, max_ratio * lim.min_world);
    return lim;
}

/// The largest |eigenvalue| of a symmetric 2x2 matrix: |mid| + sqrt(((h00 - h11) / 2)^2 + h01^2).
inline double largest_abs_eigenvalue(const glm::dmat2& h) {
    const double mid = 0.5 * (h[0][0] + h[1][1]);
    return std::abs(mid) + std::sqrt(0.25 * (h[0][0] - h[1][1]) * (h[0][0] - h[1][1]) + h[0][1] * h[0][1]);
}

/// The Hessian radius (radius_policy::hessian), R = d / a for a zone d found in two steps.
/// First the pointwise zone d_p, where the predicted relative error of the record's
/// interpolation at distance d_p reaches a, the smallest over channels with E_c > 0,
/// lambda_c the largest |eigenvalue| of channel c's symmetric 2x2 Hessian:
///  - `first_order` null (the cache extrapolates with gradients): 1/2 lambda d_p^2 = a E,
///    d_p = sqrt(2 a E / lambda);
///  - `first_order` the translation gradients (no gradients in the interpolation):
///    g d_p + 1/2 lambda d_p^2 = a E with g = |grad_t E_c|,
///    d_p = 2 a E / (g + sqrt(g^2 + 2 a E lambda)) (the root without cancellation).
/// Then, given a finite `length` l (the record's mean hit distance), the total-error rule
/// of Schwarzhaupt et al. 2012: the zone's integrated second-order relative error,
/// int_disc 1/2 (lambda / E) r^2 dA = pi (lambda / E) d^4 / 4, equals a spread over a disc
/// of radius l, a pi l^2: d = (4 a l^2 E / lambda)^(1/4) = sqrt(sqrt(2) l d_p), the
/// geometric mean of d_p and sqrt(2) l. Where no channel has a curvature d = l (uniform
/// radiance, or none); without a length d = d_p (+infinity where no channel curves).
inline double hessian_radius(const glm::dvec3& e, const std::array<glm::dmat2, 3>& hessian, double a,
                             const std::array<glm::dvec3, 3>* first_order = nullptr,
                             double length = std::numeric_limits<double>::infinity()) {
    double zone = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 3; ++c) {
        if (!(e[c] > 0)) continue;
        const double lambda = largest_abs_eigenvalue(hessian[c]);
        const double g = first_order ? glm::length((*first_order)[c]) : 0.0;
        const double denominator = g + std::sqrt(g * g + 2 * a * e[c] * lambda);
        if (denominator > 0) zone = std::min(zone, 2 * a * e[c] / denominator);
    }
    if (std::isfinite(length) && length > 0)
        zone = std::isfinite(zone) ? std::sqrt(std::sqrt(2.0) * length * zone) : length;
    return zone / a;
}

/// Neighbour clamping (Krivanek et al. 2006): R_i <= R_j + |p_i - p_j|, so the radius
/// field is 1-Lipschitz and a small record is never surrounded by much larger ones that
/// hide the detail it found. Returns the clamped R of `rec` against `others`.
template <class Range>
float neighbour_clamped_radius(const irradiance_record& rec, const Range& others) {
    float r = rec.radius;
    for (const irradiance_record& o : others) r = std::min(r, o.radius + glm::length(rec.position - o.position));
    return r;
}

/// A record at (p, n) from a hemisphere estimate in the local frame (tangent, bitangent, n)
/// the samples were taken in (see cache/gradients.hpp), with its radius limited as
/// above.
inline irradiance_record make_record(const glm::vec3& p, const glm::vec3& n, const glm::vec3& tangent,
                                     const glm::vec3& bitangent, const hemisphere_estimate& est,
                                     const radius_limits& lim, double pixel_footprint) {
    const glm::dmat3 to_world{glm::dvec3(tangent), glm::dvec3(bitangent), glm::dvec3(n)};
    irradiance_record r;
    r.position = p;
    r.normal = n;
    r.irradiance = glm::vec3(est.irradiance);
    std::array<glm::dvec3, 3> translation_world;
    for (int c = 0; c < 3; ++c) {
        r.rotation[c] = glm::vec3(to_world * est.rotation[c]);
        translation_world[c] = to_world * est.translation[c];
        r.translation[c] = glm::vec3(translation_world[c]);
    }
    require(lim.policy != radius_policy::hessian || (std::isfinite(lim.hessian_a) && lim.hessian_a > 0.f), "hessian_a",
            "must be a positive number");
    if (lim.policy != radius_policy::hessian) {
        r.radius = limit_radius(est.harmonic_mean_distance, est.irradiance, translation_world, lim, pixel_footprint,
                                est.mean_distance);
        return r;
    }
    const double a = lim.hessian_a;
    double unlimited = hessian_radius(est.irradiance, est.hessian, a, lim.hessian_gradients ? nullptr : &est.translation,
                                      est.mean_distance);
    // The split sphere's bound on the zone where its error test needs it (hessian_zone_cap).
    if (std::isfinite(lim.hessian_zone_cap))
        unlimited = std::min(unlimited, double(lim.hessian_zone_cap) * est.harmonic_mean_distance / a);
    radius_limits rest = lim;
    if (lim.gradient_limit && lim.hessian_gradients) {
        // The gradient limit on the zone: a R <= E / |grad E| (see radius_limits::hessian_gradients).
        for (int c = 0; c < 3; ++c) {
            const double g = glm::length(est.translation[c]);
            if (g > 0 && est.irradiance[c] > 0) unlimited = std::min(unlimited, est.irradiance[c] / (a * g));
        }
        rest.gradient_limit = false;
    }
    r.radius = limit_radius(unlimited, est.irradiance, translation_world, rest, pixel_footprint, est.mean_distance);
    return r;
}

}  // namespace bounce::cache
