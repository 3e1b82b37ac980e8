#pragma once
/// \file indirect/clamp_compensation.hpp
/// The light the 1/d^2 clamp removes, given back by short rays where visibility is exact
/// (Kollig and Keller 2004, "Illumination in the presence of weak singularities"; the "bias
/// compensation" of instant radiosity). docs/rsm-sii-interleaved.md, section
/// 15.5.
///
/// The RSM gather estimates, over the lit surfaces y its maps hold (radiance L(y) = M(y) / pi),
///   E_clamped(x) = int L(y) cos_x cos_y / max(d^2, r_c^2) dA_y = int L(y) cos_x min(1, d^2 / r_c^2) dw
/// (pixel_light_irradiance with min_distance2 = r_c^2, offset 0; dA cos_y / d^2 = dw, d the
/// distance from x to y). The clamp removes exactly
///   E_missing(x) = int L(y) cos_x (1 - d^2 / r_c^2)_+ dw,
/// over the directions whose first surface y lies nearer than r_c. With visibility by rays the
/// gather sums only the texels x sees, so y is the first hit of a ray from x, and K
/// cosine-distributed rays of length r_c (pdf cos_x / pi) estimate it without bias:
///   E_missing ~ pi / K sum_k L(y_k) (1 - d_k^2 / r_c^2)_+
/// (clamp_compensation_term; a ray that finds nothing within r_c adds exactly 0). Gather plus
/// compensation then converges to the unclamped integral of the light x sees.
///
/// Without visibility the gather sums every lit texel whatever lies between, and the clamp
/// removes the light of every surface q along each direction within r_c, not only the first:
///   E_missing_u(x) = int cos_x sum_{q on (x, w), d_q < r_c} L(q) (1 - d_q^2 / r_c^2)_+ dw,
/// where L(q) is q's light towards x as the unoccluded reference shades its senders (lit on
/// the side facing x, with the light's shadow ray; embree/rsm_unoccluded_reference.hpp). The
/// same rays estimate it by the same term summed over each ray's crossings
/// (near_field_query::crossings), and the gather plus it converges to that reference's
/// unclamped integral. The frames with and without visibility then carry the same
/// compensation of the same clamp, each of its own near field. With an offset
/// > 0 the gather's kernel also moves its senders: the compensation is the complement of the
/// clamp alone.
///
/// Units: distances in scene units, radiance in W/(m^2 sr), irradiance in W/m^2.

#include <bounce/concepts.hpp>
#include <bounce/sampling.hpp>
#include <bounce/vocabulary.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::inline indirect {

/// The share of a surface's light at squared distance `d2` that the clamp at `min_distance2`
/// (pixel_light_irradiance's) removes: (1 - d2 / min_distance2)_+, the exact complement of
/// its factor min(1, d2 / min_distance2). 0 for d2 >= min_distance2 and for no clamp.
template <real T>
T clamp_complement_weight(T d2, T min_distance2) {
    const auto clamped = min_distance2 > T(0);
    const T safe = select(clamped, min_distance2, T(1));
    return select(clamped, max(T(0), T(1) - d2 / safe), T(0));
}

/// The irradiance (W/m^2) one of `count` cosine-distributed rays adds to the compensation:
/// pi / count * radiance * clamp_complement_weight(d2, min_distance2), where `radiance` is
/// the outgoing radiance towards the receiver of the ray's first surface and `d2` its squared
/// distance from the receiver.
template <real T, vec3_of<T> V>
V clamp_compensation_term(const V& radiance, T d2, T min_distance2, T count) {
    return radiance * (T(std::numbers::pi) / count * clamp_complement_weight<T>(d2, min_distance2));
}

/// The M x N stratified cosine grid (sampling.hpp's stratified_cosine_direction) of about
/// `rays` rays: M = max(1, round(sqrt(rays / pi))) strata in theta, N = max(1, rays / M) in phi
/// (strata of roughly square solid angle, Ward and Heckbert's proportion). rays >= 1.
struct compensation_grid {
    std::uint32_t m = 1, n = 1;
    explicit compensation_grid(std::uint32_t rays) {
        m = std::max<std::uint32_t>(1, std::uint32_t(std::lround(std::sqrt(double(rays) / std::numbers::pi))));
        n = std::max<std::uint32_t>(1, rays / m);
    }
    std::uint32_t count() const noexcept { return m * n; }
};

/// One ray of the compensation: from the receiver (unit normal `normal`, the side it
/// receives on) along the unit `direction`, at most `length` long; `seed` draws whatever the
/// query samples at the hit (area lights).
struct near_field_ray {
    glm::vec3 receiver{0.f};
    glm::vec3 normal{0.f, 0.f, 1.f};
    glm::vec3 direction{0.f, 0.f, 1.f};
    float length = 0.f;
    std::uint64_t seed = 0;
};

/// One surface a near-field ray crosses: the ray's index in its batch, the surface's squared
/// distance from the receiver and its outgoing radiance towards the receiver.
struct near_field_crossing {
    std::uint32_t ray = 0;
    float distance2 = 0.f;
    glm::vec3 radiance{0.f};
};

/// What the compensation asks of a ray tracer (embree::near_field_rays on the CPU): the first
/// surface along each ray (or every one, without visibility) and the one-bounce light it sends
/// back. An implementation must be
/// safe to call from several threads at once.
class near_field_query {
public:
    virtual ~near_field_query() = default;
    /// radiance[i]: the outgoing radiance towards the receiver of the first surface ray i
    /// meets within its length, lit directly (with shadow rays), as the occluded one-bounce
    /// reference shades its hits; distance2[i]: that surface point's squared distance from the
    /// receiver, +infinity (and radiance 0) where the ray meets nothing. Sizes match.
    virtual void radiance(std::span<const near_field_ray> rays, std::span<glm::vec3> radiance,
                          std::span<float> distance2) const = 0;
    /// Every surface each ray crosses within its length, not only the first (the frame without
    /// visibility), shaded as the unoccluded one-bounce reference shades its senders, appended
    /// to `out` ray by ray in order along each ray (`out` is cleared first).
    virtual void crossings(std::span<const near_field_ray> rays, std::vector<near_field_crossing>& out) const = 0;

protected:
    near_field_query() = default;
    near_field_query(const near_field_query&) = default;
    near_field_query& operator=(const near_field_query&) = default;
};

/// The rays of the compensation at receiver x (unit normal n): grid.count() stratified
/// cosine-distributed directions of length sqrt(min_distance2), jittered by a pcg32 seeded
/// from `seed` and x's coordinates (the same receiver gets the same rays whatever the pass
/// or the thread), appended to `out`.
template <class Out>
void clamp_compensation_rays(const glm::vec3& x, const glm::vec3& n, float min_distance2, compensation_grid grid,
                             std::uint64_t seed, Out& out) {
    const std::uint64_t key = splitmix64(hash_floats({x.x, x.y, x.z}) ^ splitmix64(seed));
    pcg32 rng(key);
    const float length = std::sqrt(min_distance2);
    for (std::uint32_t j = 0; j < grid.m; ++j)
        for (std::uint32_t k = 0; k < grid.n; ++k) {
            const float u = rng.next_float(), v = rng.next_float();
            const glm::vec3 local = stratified_cosine_direction<float, glm::vec3>(float(j), float(k), float(grid.m),
                                                                                  float(grid.n), u, v);
            out.push_back({x, n, to_world<float, glm::vec3>(local, n), length,
                           splitmix64(key + std::uint64_t(j) * grid.n + k)});
        }
}

}  // namespace bounce::indirect
