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

/// Which error the equal-error search compares: the raw relative RMS against the reference,
/// or the debiased one (compare_luminance_debiased: the reference's own noise taken out).
enum class error_measure { raw, debiased };

/// One Monte Carlo run: samples per pixel, wall time, indirect error against the reference.
struct monte_carlo_step {
    std::uint32_t spp = 0;
    double ms = 0, rel_rms = 0;
    /// Against a reference in halves only: the debiased error and its standard error
    /// (noisy_reference_error::rel_rms_debiased, rel_rms_debiased_se).
    double rel_rms_debiased = 0, rel_rms_debiased_se = 0;
};

/// What monte_carlo_at_equal_error found.
struct monte_carlo_equal_error {
    double target = 0;                     ///< the technique's error, in `measure`
    error_measure measure = error_measure::raw;
    bool against_halves = false;           ///< the steps carry debiased errors too
    std::vector<monte_carlo_step> sweep;   ///< spp 1, 2, 4 ... as run
    bool reached = false;                  ///< false: Monte Carlo stayed above target; ms is a lower bound
    double spp = 0, ms = 0;                ///< at equal error (interpolated when reached)

    /// A step's error in `measure`.
    double error_of(const monte_carlo_step& s) const noexcept {
        return measure == error_measure::debiased ? s.rel_rms_debiased : s.rel_rms;
    }

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

/// The same search against a reference in two independent halves A and B (reference_halves):
/// every run's raw error is against (A + B) / 2 and its debiased error from
/// compare_luminance_debiased; `measure` says which of the two meets `target` (the
/// technique's error in the same measure). Debiased, a run's error may come out at or below
/// 0 (Monte Carlo's error lost in the reference's noise): the equal-error spp then follows
/// error ~ spp^-1/2 from the run before. The JSON then carries `measure` and each run's
/// debiased error. Throws parameter_error as above, and for halves of another size.
monte_carlo_equal_error monte_carlo_at_equal_error(const embree::accel& bvh, const scene_view& scene,
                                                   const gbuffer_view<float>& g, image_view<const glm::vec3> half_a,
                                                   image_view<const glm::vec3> half_b, image_view<const float> mask,
                                                   double target, error_measure measure, std::uint32_t max_spp,
                                                   const std::function<void(const monte_carlo_step&)>& progress = {});

}  // namespace bounce::study
