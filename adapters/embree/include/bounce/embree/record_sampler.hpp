#pragma once
/// \file record_sampler.hpp
/// Irradiance records by ray tracing: a stratified hemisphere of rays through Embree, hits
/// shaded with direct light and shadow rays (the reference integrator's radiance), then
/// irradiance, gradients and radius from bounce/irradiance_gradients.hpp.
///
/// Record samplers share one interface, so the renderer can swap them:
///   std::optional<irradiance_record> operator()(glm::vec3 p, glm::vec3 n, double pixel_footprint)
/// (the GL single-plane rasterizer is the other one).

#include <bounce/embree/reference.hpp>
#include <bounce/irradiance_gradients.hpp>
#include <bounce/irradiance_record.hpp>

#include <algorithm>
#include <cmath>
#include <optional>

namespace bounce::embree {

class record_sampler {
public:
    /// `grid`: the M x N strata per record (typical 16 x 50); `limits`: radius clamps;
    /// `kind`: translation-gradient formula; `seed`: base of the per-record streams.
    record_sampler(const reference_integrator& integrator, hemisphere_grid grid, radius_limits limits,
                   translation_gradient_kind kind = translation_gradient_kind::krivanek_2005, std::uint64_t seed = 7)
        : integrator_(integrator), grid_(grid), limits_(limits), kind_(kind), seed_(seed) {
        require(grid.m > 0 && grid.n > 0, "grid", "need at least one stratum in each direction");
    }

    /// A record at (p, n); nullopt when the hemisphere yields no finite estimate.
    /// Each call draws from its own stream (derive_seed of the call count), so a sequence
    /// of calls is reproducible.
    std::optional<irradiance_record> operator()(glm::vec3 p, glm::vec3 n, double pixel_footprint) {
        const std::uint64_t index = calls_++;
        integrator_.sample_hemisphere(p, n, grid_, derive_seed(seed_, 0x1c, index), samples_);
        hemisphere_samples_.rings = grid_.m;
        hemisphere_samples_.wedges = grid_.n;
        const std::size_t count = samples_.direction.size();
        hemisphere_samples_.direction.resize(count);
        for (std::size_t i = 0; i < count; ++i) {
            const glm::vec3 d = samples_.direction[i];
            hemisphere_samples_.direction[i] = {glm::dot(d, samples_.tangent), glm::dot(d, samples_.bitangent),
                                                glm::dot(d, samples_.normal)};
        }
        hemisphere_samples_.radiance = samples_.radiance;
        hemisphere_samples_.distance = samples_.distance;
        // Distances are measured from p + eps n and can be 0 where another surface touches
        // p (a corner); no surface is nearer than the offset itself, so floor them there.
        for (float& d : hemisphere_samples_.distance) d = std::max(d, integrator_.ray_epsilon());
        const hemisphere_estimate est = estimate_hemisphere(hemisphere_samples_, kind_);
        irradiance_record rec = make_record(p, samples_.normal, samples_.tangent, samples_.bitangent, est, limits_,
                                            pixel_footprint);
        if (!std::isfinite(rec.radius) || !(rec.radius > 0.f)) return std::nullopt;
        return rec;
    }

    std::uint64_t calls() const noexcept { return calls_; }

private:
    const reference_integrator& integrator_;
    hemisphere_grid grid_;
    radius_limits limits_;
    translation_gradient_kind kind_;
    std::uint64_t seed_;
    std::uint64_t calls_ = 0;
    embree::hemisphere_samples samples_;               // reused buffers: no allocation per record
    bounce::hemisphere_samples hemisphere_samples_;
};

}  // namespace bounce::embree
