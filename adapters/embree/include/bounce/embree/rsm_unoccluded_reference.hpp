#pragma once
/// \file rsm_unoccluded_reference.hpp
/// The ground truth of what reflective shadow maps (Dachsbacher and Stamminger 2005) and
/// splatting indirect illumination (Dachsbacher and Stamminger 2006) approximate: one-bounce
/// indirect irradiance whose senders are the surfaces the lights reach directly (with the
/// lights' shadows), with the visibility between receiver and sender ignored.
///
///   E_u(x, n) = int_H  sum over every surface q along the ray (x, w)  L(q -> x) cos theta dw,
///   L(q -> x) = rho(q) / pi * E_d(q, n_q),
///
/// where E_d is the direct irradiance of the point, spot and directional lights with a shadow
/// ray (direct_light.hpp's kernels), n_q is q's normal turned towards x, and the sum runs over all
/// intersections of the ray, not only the first: that is the one difference from
/// reference_integrator's indirect irradiance (reference.hpp), which keeps the first hit and
/// so includes the receiver-sender visibility. Changing the variables from solid angle to
/// area turns it into sum over senders of int L cos theta cos theta_q / d^2 dA, the limit of
/// the RSM's texel sum (indirect/rsm.hpp) as its texels shrink. Emissive triangles are not senders'
/// sources here (RSMs are made for point-like lights).
///
/// Estimator: stratified cosine-weighted directions on the M x N grid of hemisphere_grid_for,
/// E ~ pi / (M N) sum over rays of the sum of L over the ray's surfaces. Bias: surfaces
/// closer than the ray offset epsilon to x along the ray, or to the previous surface on it,
/// are skipped, and a ray counts at most `max_surfaces` surfaces (docs/rsm-sii-interleaved.md
/// section 12); no other. Variance: the integrand is bounded by pi max L times the number of
/// layers a ray crosses (unlike a sum over light-traced points, whose cos cos / d^2 term is
/// unbounded at creases), so the per-pixel standard deviation falls as (M N)^(-1/2) or
/// faster (stratification). render_unoccluded_reference measures it: two halves of the
/// samples with independent seeds, A and B, give the mean (A + B) / 2, whose relative RMS
/// noise is rel_rms(A - B) / 2 exactly in expectation (Var((A + B)/2) = E[(A - B)^2] / 4 for
/// independent, identically distributed halves).

#include <bounce/embree/accel.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/light.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <numbers>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::embree {

/// Parameters of the unoccluded one-bounce reference.
struct unoccluded_reference_settings {
    /// Cosine-weighted hemisphere rays per pixel (an M x N stratified grid, N ~ pi M);
    /// typical: 1024-4096.
    std::uint32_t hemisphere_samples = 1024;
    /// Surfaces counted along one ray at most (the scene's depth complexity is far below
    /// this in closed rooms; Sponza's rays cross about 10). Typical: 256.
    std::uint32_t max_surfaces = 256;
    /// Offset of ray origins along the normal and past each surface crossed (world units);
    /// 0 selects accel::ray_epsilon() (1e-4 of the scene size).
    float ray_epsilon = 0.f;
    /// Base seed; the same seed gives bitwise the same images for any thread count.
    std::uint64_t seed = 1;

    void validate() const;
};

/// The estimator over one scene and its BVH (held by reference: both must outlive it).
/// Immutable; every member is safe to call from many threads.
class unoccluded_reference {
public:
    /// Validates the scene's lights and the settings; throws parameter_error naming them.
    unoccluded_reference(const accel& bvh, const scene_view& scene, unoccluded_reference_settings settings = {});

    const unoccluded_reference_settings& settings() const noexcept { return settings_; }
    float ray_epsilon() const noexcept { return epsilon_; }

    /// Direct irradiance (W/m^2) at `p` with unit normal `n` from the point, spot and
    /// directional lights, each times its shadow ray, which leaves along `offset_normal`.
    glm::vec3 direct_irradiance(glm::vec3 p, glm::vec3 n, glm::vec3 offset_normal) const;
    /// Calls f(t, L) for each surface along `r` (unit direction, from r.tnear to r.tfar) in
    /// order, as E_u counts them: each at least ray_epsilon() past the previous, at most
    /// settings().max_surfaces; t its distance along r, L = rho / pi E_d (a dvec3) its
    /// radiance towards r's origin. indirect_irradiance's senders, and the unoccluded near
    /// field of the RSM gather's clamp compensation (embree::near_field_rays).
    template <class F>
    void for_each_sender(ray r, F&& f) const {
        for (std::uint32_t s = 0; s < settings_.max_surfaces; ++s) {
            const hit h = bvh_.intersect(r);
            if (!h.found()) break;
            const surface q = surface_at(scene_, r, h);
            const glm::vec3 e = direct_irradiance(q.position, q.normal, q.geometric_normal);
            f(h.t, glm::dvec3(q.albedo) * (1.0 / std::numbers::pi) * glm::dvec3(e));
            r.tnear = h.t + epsilon_;  // the direction is unit: t is a distance
        }
    }
    /// E_u(p, n) (W/m^2) from about `samples` stratified rays drawn from `seed`. Throws
    /// parameter_error on a non-finite p or a non-unit n.
    glm::vec3 indirect_irradiance(glm::vec3 p, glm::vec3 n, std::uint32_t samples, std::uint64_t seed) const;
    /// rho / pi * E_u per pixel of `g` (radiance towards the camera, the unit of
    /// reference_images::indirect), 0 where g sees nothing; rows in parallel.
    image<glm::vec3> indirect_image(const gbuffer_view<float>& g) const;

private:
    const accel& bvh_;
    scene_view scene_;
    unoccluded_reference_settings settings_;
    float epsilon_;
    std::vector<packed_light> lights_;
};

/// An unoccluded reference image and its measured noise.
struct unoccluded_reference_image {
    image<glm::vec3> indirect;   ///< rho / pi * E_u, the mean of the two halves
    double noise_rel_rms = 0;    ///< relative RMS (Rec. 709 luminance) noise of `indirect`: rel_rms(A - B) / 2
    std::uint32_t samples = 0;   ///< rays per pixel in all (both halves)
};

/// Renders the two halves (hemisphere_samples / 2 each, seeds settings.seed and
/// settings.seed + 1) and returns their mean with its noise figure. Throws parameter_error
/// naming hemisphere_samples unless it is even and at least 4 (before any ray).
unoccluded_reference_image render_unoccluded_reference(const accel& bvh, const scene_view& scene,
                                                       const gbuffer_view<float>& g,
                                                       const unoccluded_reference_settings& settings);

}  // namespace bounce::embree
