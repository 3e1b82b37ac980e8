#pragma once
/// \file record_sampler.hpp
/// Irradiance records by ray tracing: a stratified hemisphere of rays through Embree, hits
/// shaded with direct light and shadow rays (the reference integrator's radiance), then
/// irradiance, gradients and radius from bounce/irradiance_gradients.hpp.
///
/// It models bounce::record_sampler (record_sampler.hpp), as the GL single-plane rasterizer
/// does, so a cache takes either; one record alone is
///   std::optional<irradiance_record> operator()(glm::vec3 p, glm::vec3 n, double pixel_footprint).

#include <bounce/embree/reference.hpp>
#include <bounce/irradiance_gradients.hpp>
#include <bounce/irradiance_record.hpp>
#include <bounce/record_sampler.hpp>
#include <bounce/sampling.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>

#include <tbb/parallel_for.h>

namespace bounce::embree {

class record_sampler {
public:
    /// `grid`: the M x N strata per record (typical 16 x 50); `limits`: radius clamps;
    /// `kind`: translation-gradient formula; `seed`: base of the per-record streams (each keyed by its point).
    record_sampler(const reference_integrator& integrator, hemisphere_grid grid, radius_limits limits,
                   translation_gradient_kind kind = translation_gradient_kind::krivanek_2005, std::uint64_t seed = 7)
        : integrator_(integrator), grid_(grid), limits_(limits), kind_(kind), seed_(seed) {
        require(grid.m > 0 && grid.n > 0, "grid", "need at least one stratum in each direction");
    }

    /// A record at (p, n); nullopt when the hemisphere yields no finite estimate.
    /// The rays are seeded by the bits of (p, n), so a record is a pure function of its
    /// point: the same whenever, and on whichever thread, it is asked for. That is what
    /// lets cpu::scan_cache_misses_batched measure records ahead of the scan. Thread-safe.
    std::optional<irradiance_record> operator()(glm::vec3 p, glm::vec3 n, double pixel_footprint) const {
        embree::hemisphere_samples samples;  // per call: nested TBB work may re-enter on this thread
        integrator_.sample_hemisphere(p, n, grid_, derive_seed(seed_, 0x1c, point_key(p, n)), samples);
        bounce::hemisphere_samples local;
        local.rings = grid_.m;
        local.wedges = grid_.n;
        const std::size_t count = samples.direction.size();
        local.direction.resize(count);
        for (std::size_t i = 0; i < count; ++i) {
            const glm::vec3 d = samples.direction[i];
            local.direction[i] = {glm::dot(d, samples.tangent), glm::dot(d, samples.bitangent), glm::dot(d, samples.normal)};
        }
        local.radiance = std::move(samples.radiance);
        local.distance = std::move(samples.distance);
        // Distances are measured from p + eps n and can be 0 where another surface touches
        // p (a corner); no surface is nearer than the offset itself, so floor them there.
        for (float& d : local.distance) d = std::max(d, integrator_.ray_epsilon());
        const hemisphere_estimate est = estimate_hemisphere(local, kind_);
        irradiance_record rec = make_record(p, samples.normal, samples.tangent, samples.bitangent, est, limits_,
                                            pixel_footprint);
        if (!std::isfinite(rec.radius) || !(rec.radius > 0.f)) return std::nullopt;
        return rec;
    }

    /// Records for points[k], normals[k], footprints[k] into out[k], the points on every
    /// core (each record is a pure function of its point, so the order does not matter).
    /// Throws parameter_error when the spans' sizes differ.
    void operator()(std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                    std::span<const double> footprints, std::span<std::optional<irradiance_record>> out) const {
        require(normals.size() == points.size() && footprints.size() == points.size() && out.size() == points.size(),
                "points", "points, normals, footprints and out must have one entry per record");
        tbb::parallel_for(std::size_t(0), points.size(),
                          [&](std::size_t k) { out[k] = (*this)(points[k], normals[k], footprints[k]); });
    }

    /// The hemisphere rays the records at points[k], normals[k] would cast, traced without
    /// shading, the points on every core; returns the rays cast. For comparing a record's
    /// cost with Embree's raw rate on the same rays.
    std::size_t trace_only(std::span<const glm::vec3> points, std::span<const glm::vec3> normals) const {
        require(normals.size() == points.size(), "normals", "must have one entry per point");
        tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t k) {
            integrator_.trace_hemisphere(points[k], normals[k], grid_, derive_seed(seed_, 0x1c, point_key(points[k], normals[k])));
        });
        return points.size() * grid_.count();
    }

    hemisphere_grid grid() const noexcept { return grid_; }

private:
    const reference_integrator& integrator_;
    hemisphere_grid grid_;
    radius_limits limits_;
    translation_gradient_kind kind_;
    std::uint64_t seed_;

    // Distinct points get independent streams, the same point the same stream.
    static std::uint64_t point_key(const glm::vec3& p, const glm::vec3& n) noexcept {
        return hash_floats({p.x, p.y, p.z, n.x, n.y, n.z});
    }
};

static_assert(bounce::record_sampler<const embree::record_sampler>);

}  // namespace bounce::embree
