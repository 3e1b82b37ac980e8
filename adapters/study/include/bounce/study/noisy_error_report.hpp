#pragma once
/// \file noisy_error_report.hpp
/// A technique's error against a reference in two independent halves (reference_halves), as
/// every study reports it: the raw figures against the halves' mean beside the error with the
/// reference's own noise taken out (compare_luminance_debiased), in the run report's JSON and
/// in one line of text.

#include <bounce/image.hpp>
#include <bounce/study/equal_error.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/reference_cache.hpp>

#include <string>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace bounce::study {

/// An image's error against a reference in halves: the raw figures against their mean, and
/// the error with the reference's own noise taken out.
struct noisy_error {
    error_figures raw;
    noisy_reference_error debiased;
    /// The error an equal-error search compares in `measure`: raw.rel_rms or
    /// debiased.rel_rms_debiased.
    double target(error_measure measure) const noexcept {
        return measure == error_measure::raw ? raw.rel_rms : debiased.rel_rms_debiased;
    }
};

/// The indirect image `indirect` against the indirect halves of `ref` over `mask` (empty: every
/// pixel). Throws parameter_error as compare_luminance does (sizes, non-finite values, an
/// empty mask).
noisy_error measure_error(image_view<const glm::vec3> indirect, const reference_halves& ref,
                          image_view<const float> mask = {});

/// `v`, or null where it is not finite (JSON has no infinity).
nlohmann::ordered_json finite_or_null(double v);

/// Adds the debiased figures to `j`: rel_rms_debiased, rel_rms_debiased_se, rel_sq_debiased,
/// rel_sq_debiased_se, debiased_resolved, reference_noise_rel_rms.
void add_debiased(nlohmann::ordered_json& j, const noisy_reference_error& d);

/// {rel_rms, max_abs, sum_sq, pixels} and the debiased figures (add_debiased).
nlohmann::ordered_json error_json(const noisy_error& e);

/// "0.0312 (debiased 0.0290 +- 0.0011)", or "0.0312 (debiased < 0.0050, unresolved)" when the
/// debiased error is within two standard errors of 0.
std::string error_text(const noisy_error& e);

}  // namespace bounce::study
