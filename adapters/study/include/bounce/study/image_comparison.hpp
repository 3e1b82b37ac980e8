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

}  // namespace bounce::study
