#pragma once
/// \file image_comparison.hpp
/// The error figures every technique reports against its reference image: relative RMS,
/// largest and summed squared differences of luminance over the pixels that see geometry.

#include <bounce/errors.hpp>
#include <bounce/image.hpp>

#include <cstddef>

#include <glm/vec3.hpp>

namespace bounce::study {

/// Error of an image against a reference, on luminance (Rec. 709 weights), over the
/// pixels where `mask` is non-zero (all pixels when the mask is empty).
struct error_figures {
    double rel_rms = 0;  ///< sqrt(mean((x - ref)^2)) / sqrt(mean(ref^2))
    double max_abs = 0;  ///< max |x - ref|
    double sum_sq = 0;   ///< sum of squared differences (Hahn 2012's accuracy tables use it)
    std::size_t pixels = 0;  ///< pixels compared (non-zero in the mask)
};
/// Computed with OIIO's ImageBufAlgo::compare on luminance images whose unmasked pixels are
/// 0 in both (the pixel count cancels in the ratio). rel_rms is 0 when x and ref are both
/// 0 on the mask, and +infinity when ref alone is. `mask`, when given, has their size.
/// Throws parameter_error when sizes differ, an image is empty, a value is not finite, or
/// the mask selects no pixel.
error_figures compare_luminance(image_view<const glm::vec3> x, image_view<const glm::vec3> ref,
                                image_view<const float> mask = {});

/// Error of an image X against a Monte Carlo reference R = (A + B) / 2 made of two
/// independent halves A and B (each unbiased, same distribution, independent of X), with the
/// reference's own noise taken out. On luminance over the mask's n pixels (all when empty),
/// with d_i = (x_i - r_i)^2 - (a_i - b_i)^2 / 4 and s_i = r_i^2 - (a_i - b_i)^2 / 4:
/// E[(x - r)^2] = (x - t)^2 + Var r and E[(a - b)^2] / 4 = Var r, so mean d is an unbiased
/// estimate of mean (x - t)^2 and mean s one of mean t^2 (t the true image).
struct noisy_reference_error {
    double rel_rms = 0;              ///< raw: sqrt(mean (x - r)^2 / mean r^2), as compare_luminance
    double rel_sq_debiased = 0;      ///< q = mean d / mean s: estimates mean (x - t)^2 / mean t^2 (may be < 0)
    /// Standard error of q from the references' noise, the images fixed (pixels taken as
    /// independent; delta method): sqrt(sum_i (a_i - b_i)^2 (x_i - r_i + q r_i)^2) / (n mean s),
    /// each term an unbiased estimate of the variance of d_i - q s_i when the halves' noise is
    /// Gaussian (Monte Carlo's is not quite: then an approximation).
    double rel_sq_debiased_se = 0;
    double rel_rms_debiased = 0;     ///< sqrt(max(0, q))
    /// How far rel_rms_debiased moves when q moves up by one standard error:
    /// sqrt(max(0, q) + se) - sqrt(max(0, q)); the delta method's se / (2 sqrt q) when q >> se.
    double rel_rms_debiased_se = 0;
    double reference_noise_rel_rms = 0;  ///< the reference's own error: sqrt(mean (a - b)^2 / 4 / mean s)
    std::size_t pixels = 0;              ///< pixels compared
    /// Whether the debiased error stands out of its own noise: q above two standard errors.
    /// When false, rel_rms_debiased says only that the error is below about
    /// sqrt(max(0, q) + 2 se).
    bool resolved() const noexcept { return rel_sq_debiased > 2.0 * rel_sq_debiased_se; }
};
/// The figures above, in double precision (luminance Rec. 709 as compare_luminance).
/// When mean s <= 0 (a reference indistinguishable from black) every relative figure is
/// +infinity, or 0 when x, a and b are all 0 on the mask. Throws parameter_error when sizes
/// differ, an image is empty, a value is not finite, or the mask selects no pixel.
noisy_reference_error compare_luminance_debiased(image_view<const glm::vec3> x, image_view<const glm::vec3> half_a,
                                                 image_view<const glm::vec3> half_b, image_view<const float> mask = {});

}  // namespace bounce::study
