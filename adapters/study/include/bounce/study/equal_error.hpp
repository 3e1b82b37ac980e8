#pragma once
/// \file equal_error.hpp
/// The time brute-force Monte Carlo needs to reach a technique's error: the measure of
/// "faster at equal error" every study reports against the same ray tracer.

#include <bounce/embree/accel.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace bounce::study {

/// One Monte Carlo run: samples per pixel, wall time, indirect error against the reference.
struct monte_carlo_step {
    std::uint32_t spp = 0;
    double ms = 0, rel_rms = 0;
};

/// What monte_carlo_at_equal_error found.
struct monte_carlo_equal_error {
    double target = 0;                     ///< the technique's rel_rms
    std::vector<monte_carlo_step> sweep;   ///< spp 1, 2, 4 ... as run
    bool reached = false;                  ///< false: Monte Carlo stayed above target; ms is a lower bound
    double spp = 0, ms = 0;                ///< at equal error (interpolated when reached)

    /// The report's `mc_equal_error` object (with speedup = ms / technique_ms) and `mc_sweep`.
    nlohmann::ordered_json equal_error_json(double technique_ms) const;
    nlohmann::ordered_json sweep_json() const;
};

/// Brute-force Monte Carlo indirect light (the reference integrator with `spp` cosine rays
/// per pixel, a seed of its own) over `g` at spp = 1, 2, 4 ... up to `max_spp`, until its
/// relative RMS error against `reference` over `mask` reaches `target`. The equal-error
/// time is interpolated between the last two runs in log-log (error ~ spp^-1/2 away from the
/// reference's own noise floor; doubling alone would overstate it) and scaled with spp.
/// `progress` (optional) sees each run. Throws parameter_error for a target that is not a
/// positive number or max_spp 0.
monte_carlo_equal_error monte_carlo_at_equal_error(const embree::accel& bvh, const scene_view& scene,
                                                   const gbuffer_view<float>& g,
                                                   image_view<const glm::vec3> reference,
                                                   image_view<const float> mask, double target,
                                                   std::uint32_t max_spp,
                                                   const std::function<void(const monte_carlo_step&)>& progress = {});

}  // namespace bounce::study
