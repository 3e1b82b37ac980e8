#pragma once
/// \file ssim.hpp
/// A perceptual error beside rel_rms: the structural similarity (SSIM) of an image's
/// tone-mapped luminance against its reference's. Monte Carlo's white noise and a cache's
/// smooth error of equal rel_rms do not look alike; SSIM, which weighs local structure,
/// tells them apart, so the benchmark reports both.

#include <bounce/errors.hpp>
#include <bounce/image.hpp>

#include <glm/vec3.hpp>

namespace bounce::study {

/// SSIM (Wang, Bovik, Sheikh, Simoncelli 2004, "Image quality assessment: from error
/// visibility to structural similarity", eq. 13 with the Gaussian window of section III-C:
/// 11 x 11, sigma 1.5; K1 = 0.01, K2 = 0.03, dynamic range 1) of the tone-mapped luminance
/// of `x` against that of `ref`, averaged over the window centres whose pixel is in `mask`.
///
/// Luminance is Rec. 709 (bounce::rec709_luminance), in double. The tone map is
/// t(L) = L / (|L| + k), k the mean luminance of `ref` over the mask, the SAME k for both
/// images:
/// - it maps the reference's scale into [0, 1) with its mean at 1/2, so the constants
///   C1 = (K1)^2 and C2 = (K2)^2 of a dynamic range of 1 mean the same on a scene lit in
///   watts or in kilowatts (scaling both images by c leaves the result unchanged);
/// - it is one fixed, strictly increasing function for both images. Tone-mapping each with
///   its own k would divide a global brightness error away (t is invariant under scaling L
///   and k together), and a technique that is uniformly 20% dark would score 1;
/// - |L| in the denominator keeps it defined, odd and increasing for the negative luminance
///   that ringing estimators (spherical harmonics) can return, mapping it into (-1, 0)
///   instead of clipping it to black and hiding that error.
///
/// Windows are restricted to the mask: a window's means, variances and covariance are
/// weighted sums over its pixels that are in the image and in the mask, normalised by their
/// total weight, so pixels that see no geometry (black in both images) neither enter a
/// window nor centre one. `mask` (same size as the images) selects pixels where it is
/// > 0; an empty view selects every pixel. Each window's value is in [-1, 1] (it is the
/// product of two factors bounded by 1 in magnitude, by |2ab| <= a^2 + b^2 and
/// Cauchy-Schwarz); a value rounding outside is clamped back. Identical images give 1.
///
/// Cost: two 11-tap passes over six statistics per pixel, serial (about 30 ms of CPU for
/// 256 x 256 on this machine).
///
/// Throws parameter_error when the sizes differ, an image is empty, a value is not finite,
/// the mask selects no pixel, or the reference's mean luminance over the mask is not
/// positive (a black reference has no scale to tone-map by).
double tonemapped_ssim(image_view<const glm::vec3> x, image_view<const glm::vec3> ref,
                       image_view<const float> mask = {});

}  // namespace bounce::study
