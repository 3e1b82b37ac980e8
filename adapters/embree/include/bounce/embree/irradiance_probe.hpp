#pragma once
/// \file embree/irradiance_probe.hpp
/// A cheap Monte Carlo estimate of one-bounce indirect irradiance at a point, with its own
/// variance: the probe of the cache's verification pass (cache/verification.hpp,
/// cpu::irradiance_cache::set_probe). The same rays and shading as the records'
/// (reference_integrator::sample_hemisphere on a small stratified grid), seeded by the pixel.

#include <bounce/cache/verification.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/errors.hpp>
#include <bounce/luminance.hpp>

#include <cstddef>
#include <cstdint>
#include <numbers>

#include <glm/glm.hpp>

namespace bounce::embree {

class irradiance_probe {
public:
    /// About `rays` cosine-distributed rays per point (hemisphere_grid_for's grid). The
    /// integrator must outlive the probe. Throws parameter_error when rays is 0.
    irradiance_probe(const reference_integrator& integrator, std::uint32_t rays, std::uint64_t seed = 0x5eed)
        : integrator_(integrator), grid_(hemisphere_grid_for(rays)), seed_(seed) {}

    /// E at (p, n) and the variance of its luminance, from the rays' spread taken as
    /// independent (the grid's strata only lower the true variance: an upper estimate).
    /// Thread-safe; a pure function of (p, n, pixel).
    probe_estimate operator()(glm::vec3 p, glm::vec3 n, std::size_t pixel) const {
        thread_local hemisphere_samples s;
        integrator_.sample_hemisphere(p, n, grid_, derive_seed(seed_, 0x1f, pixel), s);
        const std::size_t count = s.radiance.size();
        probe_estimate e;
        e.irradiance = s.irradiance();
        e.rays = std::uint32_t(count);
        if (count < 2) {
            e.variance = -1.f;  // unknown
            return e;
        }
        double sum = 0, sum2 = 0;
        for (const glm::vec3& l : s.radiance) {
            const double y = std::numbers::pi * double(rec709_luminance<float>(l));
            sum += y;
            sum2 += y * y;
        }
        const double mean = sum / double(count);
        const double var = std::max(0.0, (sum2 - double(count) * mean * mean) / double(count - 1));
        e.variance = float(var / double(count));
        return e;
    }

    hemisphere_grid grid() const noexcept { return grid_; }

private:
    const reference_integrator& integrator_;
    hemisphere_grid grid_;
    std::uint64_t seed_;
};

}  // namespace bounce::embree
