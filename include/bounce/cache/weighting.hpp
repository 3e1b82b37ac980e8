#pragma once
/// \file cache/weighting.hpp
/// Weighting functions of irradiance caching, as policy types (Ward et al. 1988; in the
/// notation of Gautron 2008, "Hardware Implementation", ch. 8 of Krivanek et al., SIGGRAPH
/// 2008 course Practical Global Illumination with Irradiance Caching, Eqs. 8.2-8.4).
///
/// Each policy is a stateless type with
///  - `weight(p, n, pk, nk, inv_r, a)`: the weight of record k (position pk, unit normal nk,
///    1/R_k) at the point p with unit normal n, for accuracy a; 0 where record k must not
///    contribute. A kernel: the CPU instantiates it with float/double and GLM vectors, the
///    GL adapter prints it as GLSL.
///  - `influence_radius(r, a)`: a radius outside which `weight` is 0 for every normal, so
///    splatting can bound the zone of influence by a sphere.
///
/// Two hazards every policy handles, because rounding makes both happen in practice:
///  - the singularity at p = pk, n = nk (1/0 in Ward's weight): the inverse weight is
///    clamped to `inverse_weight_floor`, as Gautron 2008's shader (Algorithm 3) clamps it
///    to EPSILON;
///  - n . nk slightly above or below 1 from rounding (unit vectors that are not quite unit):
///    the normal term allows for the rounding and clamps at 0, never NaN.

#include <bounce/vocabulary.hpp>

#include <cmath>
#include <numbers>
#include <optional>
#include <string_view>
#include <type_traits>
#include <variant>

namespace bounce::inline cache {

/// Smallest inverse weight: caps a record's weight at 1e4. With weights at most 1e4, a float
/// sum over 10^4 overlapping records stays below 1e8, where float still resolves a record of
/// weight 1/a >= 1 to within 1e8 * 2^-24 ~ 6 (relative 6e-8 of the total): the cap keeps the
/// singular record dominant without overflowing or swamping float accumulation.
inline constexpr double inverse_weight_floor = 1e-4;

/// Rounding allowance of 1 - n.nk. Two float unit vectors (each unit to within a couple of
/// ulps after normalize) have a dot product within ~5u of the exact one, u = 2^-24, so two
/// copies of one normal can give 1 - n.nk = 6e-8 instead of 0. The square root turns that
/// into 2.4e-4, above the inverse-weight floor: a record's weight at its own pixel would be
/// 4089 on one backend and 9993 on another (docs/irradiance-splatting.md shows where).
/// Below 8u = 2^-21 (0.056 degrees) normals count as equal.
inline constexpr double normal_rounding = 0x1p-21;

/// The normal-divergence term sqrt(1 - n.nk) of Eq. 8.2, less the rounding allowance, so it
/// is exactly 0 for equal normals on every backend and never NaN for n.nk > 1.
template <real T, vec3_of<T> V>
T normal_divergence(const V& n, const V& nk) {
    return sqrt(max(T(0), T(1) - dot(n, nk) - T(normal_rounding)));
}

/// Ward et al. 1988 (Gautron 2008, Eq. 8.2 with the test 8.3): w = 1 / (|p - pk| / R_k + sqrt(1 - n.nk)),
/// contributing where w >= 1/a. The zone of influence is the sphere of radius a R_k (Eq. 8.4).
struct ward_weight {
    static constexpr const char* name = "ward";

    template <real T, vec3_of<T> V>
    static T inverse_weight(const V& p, const V& n, const V& pk, const V& nk, T inv_r) {
        return max(T(inverse_weight_floor), length(p - pk) * inv_r + normal_divergence<T, V>(n, nk));
    }
    template <real T, vec3_of<T> V>
    static T weight(const V& p, const V& n, const V& pk, const V& nk, T inv_r, T a) {
        const T inv_w = inverse_weight<T, V>(p, n, pk, nk, inv_r);
        return select(inv_w <= a, T(1) / inv_w, T(0));
    }
    template <real T>
    static T influence_radius(T r, T a) { return a * r; }
};

/// The smoothed Ward weight (Gautron 2008, section 8.2): w - 1/a where w >= 1/a, so a record's
/// contribution falls continuously to zero at the border of its zone and the circular seams
/// of the plain test disappear. Same zone of influence as Ward's.
struct ward_smooth_weight {
    static constexpr const char* name = "ward-smooth";

    template <real T, vec3_of<T> V>
    static T weight(const V& p, const V& n, const V& pk, const V& nk, T inv_r, T a) {
        const T inv_w = ward_weight::inverse_weight<T, V>(p, n, pk, nk, inv_r);
        return select(inv_w <= a, T(1) / inv_w - T(1) / a, T(0));
    }
    template <real T>
    static T influence_radius(T r, T a) { return a * r; }
};

/// Ward's weight with an early rejection on squared terms, the fragment-shader form of
/// Gautron 2008, Algorithm 3: e1 = |p - pk|^2 / R_k^2,
/// e2 = c (1 - n.nk); reject early when e1 + e2 > a^2 (no square root needed: since
/// (sqrt(e1) + sqrt(e2))^2 >= e1 + e2 the early test never rejects a contributing record),
/// then w = 1 / (sqrt(e1) + sqrt(e2)) with the test w >= 1/a.
/// That shader uses c = 0.2 where Eq. 8.2 implies c = 1; `NormalScale` selects c: 1 (the
/// default) reproduces Eq. 8.2 exactly, 1/5 the shader as printed (ward_scaled_normal_weight).
/// Nothing here needs a GPU: the CPU runs it as well. `name` keeps the command-line and
/// results spellings: `ward-gpu` for c = 1, `ward-gpu-shader` for c = 1/5 (any other
/// scale is `ward-gpu-scaled`, which no weighting_kind has).
template <int NormalScaleNumerator = 1, int NormalScaleDenominator = 1>
struct ward_early_reject_weight {
    static constexpr const char* name = NormalScaleNumerator == NormalScaleDenominator ? "ward-gpu"
                                        : NormalScaleDenominator == 5 * NormalScaleNumerator ? "ward-gpu-shader"
                                                                                             : "ward-gpu-scaled";
    static constexpr double normal_scale = double(NormalScaleNumerator) / NormalScaleDenominator;

    template <real T, vec3_of<T> V>
    static T weight(const V& p, const V& n, const V& pk, const V& nk, T inv_r, T a) {
        const V d = p - pk;
        const T e1 = dot(d, d) * (inv_r * inv_r);
        const T e2 = T(normal_scale) * max(T(0), T(1) - dot(n, nk) - T(normal_rounding));
        const T inv_w = max(T(inverse_weight_floor), sqrt(e1) + sqrt(e2));
        return select(e1 + e2 > a * a, T(0), select(inv_w <= a, T(1) / inv_w, T(0)));
    }
    template <real T>
    static T influence_radius(T r, T a) { return a * r; }
};

/// Gautron 2008's Algorithm 3 exactly as printed: the normal term scaled to 0.2 (1 - n.nk)
/// (command-line spelling `ward-gpu-shader`).
using ward_scaled_normal_weight = ward_early_reject_weight<1, 5>;

/// Tabellion and Lamorlette 2004: w = 1 - kappa max(|p - pk| / R_k, sqrt(1 - n.nk) /
/// sqrt(1 - cos 10 deg)), kappa = 1/a, contributing where w > 0. R_k is the record's
/// (already clamped) radius; the normal term reaches its limit at 10 degrees of divergence
/// for a = 1. The weight is bounded (at most 1), so it has no singularity at p = pk.
struct tabellion_weight {
    static constexpr const char* name = "tabellion";

    template <real T, vec3_of<T> V>
    static T weight(const V& p, const V& n, const V& pk, const V& nk, T inv_r, T a) {
        // 1 / sqrt(1 - cos(10 deg)), evaluated once in double.
        const T inv_limit = T(1.0 / std::sqrt(1.0 - std::cos(10.0 * std::numbers::pi / 180.0)));
        const T e = max(length(p - pk) * inv_r, normal_divergence<T, V>(n, nk) * inv_limit);
        return max(T(0), T(1) - e / a);
    }
    template <real T>
    static T influence_radius(T r, T a) { return a * r; }
};

/// The weighting functions a program can choose at run time, one per named policy above.
/// Command-line spellings (each policy's `name`): ward, ward-smooth, ward-gpu
/// (ward_early_reject), ward-gpu-shader (ward_scaled_normal), tabellion.
///
/// One vocabulary, two forms: the CPU cache and splatting take the policy as a template
/// argument (`cpu::irradiance_cache<ward_smooth_weight>`), the GL splat pass compiles a
/// program per kind at run time (`gl::splat_pass::splat(..., weighting_kind)`). Either
/// reaches the other: `weighting_kind_of<Policy>` is the kind of a named policy,
/// `with_weighting(kind, f)` calls f with the policy of a kind, and the GL pass accepts the
/// policy object as well. A policy of one's own (or `ward_early_reject_weight` with another
/// scale) has no kind: the CPU runs it, the GL pass does not (it compiles the named ones).
enum class weighting_kind { ward, ward_smooth, ward_early_reject, ward_scaled_normal, tabellion };

/// Every kind, in declaration order.
inline constexpr weighting_kind weighting_kinds[] = {weighting_kind::ward, weighting_kind::ward_smooth,
                                                     weighting_kind::ward_early_reject, weighting_kind::ward_scaled_normal,
                                                     weighting_kind::tabellion};

/// Calls `f(Policy{})` with the policy type for `k`, so run-time choices reach compile-time
/// kernels: `with_weighting(k, [&](auto w) { splat<decltype(w)>(...); })`. For a CPU cache
/// chosen at run time, the choice wraps its use:
/// `with_weighting(k, [&](auto w) { cpu::irradiance_cache<decltype(w)> cache(lo, hi); ... })`,
/// or keep one in a `weighting_variant<cpu::irradiance_cache>`.
template <class F>
constexpr decltype(auto) with_weighting(weighting_kind k, F&& f) {
    switch (k) {
        case weighting_kind::ward_smooth: return f(ward_smooth_weight{});
        case weighting_kind::ward_early_reject: return f(ward_early_reject_weight<>{});
        case weighting_kind::ward_scaled_normal: return f(ward_scaled_normal_weight{});
        case weighting_kind::tabellion: return f(tabellion_weight{});
        case weighting_kind::ward: break;
    }
    return f(ward_weight{});
}

/// `T<Policy>` for every named policy, in the order of weighting_kind: a class template
/// over the policy (a CPU cache, a splatter of one's own) chosen at run time, e.g.
/// `weighting_variant<cpu::irradiance_cache>`, filled by `with_weighting` and used with
/// std::visit.
template <template <class> class T>
using weighting_variant = std::variant<T<ward_weight>, T<ward_smooth_weight>, T<ward_early_reject_weight<>>,
                                       T<ward_scaled_normal_weight>, T<tabellion_weight>>;

}  // namespace bounce::cache

namespace bounce::detail {
/// The kind of each named policy; undefined for the others.
template <class Policy>
struct weighting_kind_for;
template <>
struct weighting_kind_for<ward_weight> : std::integral_constant<weighting_kind, weighting_kind::ward> {};
template <>
struct weighting_kind_for<ward_smooth_weight> : std::integral_constant<weighting_kind, weighting_kind::ward_smooth> {};
template <>
struct weighting_kind_for<ward_early_reject_weight<>>
    : std::integral_constant<weighting_kind, weighting_kind::ward_early_reject> {};
template <>
struct weighting_kind_for<ward_scaled_normal_weight>
    : std::integral_constant<weighting_kind, weighting_kind::ward_scaled_normal> {};
template <>
struct weighting_kind_for<tabellion_weight> : std::integral_constant<weighting_kind, weighting_kind::tabellion> {};
}  // namespace bounce::detail

namespace bounce::inline cache {

/// A policy that has a weighting_kind (the five above), which the GL splat pass can compile.
template <class Policy>
concept named_weighting = requires { detail::weighting_kind_for<std::remove_cvref_t<Policy>>::value; };

/// The kind of a named policy: `weighting_kind_of<ward_smooth_weight>` is
/// weighting_kind::ward_smooth.
template <named_weighting Policy>
inline constexpr weighting_kind weighting_kind_of = detail::weighting_kind_for<std::remove_cvref_t<Policy>>::value;

// The two directions are one table: every kind maps to a policy that maps back to it.
static_assert([] {
    for (const weighting_kind k : weighting_kinds)
        if (!with_weighting(k, [k](auto w) { return weighting_kind_of<decltype(w)> == k; })) return false;
    return true;
}());

/// The command-line spelling of `k` (its policy's `name`).
constexpr std::string_view weighting_name(weighting_kind k) {
    return with_weighting(k, [](auto w) { return std::string_view(decltype(w)::name); });
}

/// The kind spelled `name` (weighting_name's inverse); nullopt for a name no kind has.
constexpr std::optional<weighting_kind> parse_weighting(std::string_view name) {
    for (const weighting_kind k : weighting_kinds)
        if (weighting_name(k) == name) return k;
    return std::nullopt;
}

}  // namespace bounce::cache
