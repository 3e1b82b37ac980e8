#pragma once
/// \file image_io.hpp
/// Images through OpenImageIO: EXR (float, linear) for data, PNG (tone-mapped, sRGB) for
/// people; and the error figures every technique reports against its reference.

#include <bounce/image.hpp>

#include <filesystem>
#include <glm/vec3.hpp>

namespace bounce::io {

/// Writes linear RGB float pixels as OpenEXR (any extension OIIO knows works).
/// Throws io::image_error naming the file on failure.
void write_exr(const std::filesystem::path& file, image_view<const glm::vec3> rgb);
/// Writes a single-channel float image as OpenEXR.
void write_exr(const std::filesystem::path& file, image_view<const float> value);
/// Reads an RGB(A) image as linear float RGB. Throws io::image_error.
image<glm::vec3> read_rgb(const std::filesystem::path& file);
/// Writes `rgb * exposure`, clamped and sRGB-encoded, as an 8-bit PNG.
void write_png(const std::filesystem::path& file, image_view<const glm::vec3> rgb, float exposure = 1.f);

/// Error of an image against a reference, on luminance (Rec. 709 weights), over the
/// pixels where `mask` is non-zero (all pixels when the mask is empty).
struct error_figures {
    double rel_rms = 0;  ///< sqrt(mean((x - ref)^2)) / sqrt(mean(ref^2))
    double max_abs = 0;  ///< max |x - ref|
    double sum_sq = 0;   ///< sum of squared differences (some seeds report it)
    std::size_t pixels = 0;
};
/// Throws parameter_error when sizes differ or an image is empty.
error_figures compare_luminance(image_view<const glm::vec3> x, image_view<const glm::vec3> ref,
                                image_view<const float> mask = {});

}  // namespace bounce::io
