#pragma once
/// \file image_io.hpp
/// Images through OpenImageIO: EXR (float, linear) for data, PNG (tone-mapped, sRGB) for
/// people. (Error figures against a reference: bounce/study/image_comparison.hpp.)

#include <bounce/errors.hpp>
#include <bounce/image.hpp>

#include <filesystem>
#include <string>
#include <glm/vec3.hpp>

namespace bounce::io {

/// An image file that cannot be read or written; `file()` names it.
struct image_error : bounce::error {
    image_error(std::filesystem::path file, const std::string& what);
    const std::filesystem::path& file() const noexcept { return file_; }

private:
    std::filesystem::path file_;
};

/// Writes linear RGB float pixels as OpenEXR (any extension OIIO knows works).
/// Throws io::image_error naming the file on failure.
void write_exr(const std::filesystem::path& file, image_view<const glm::vec3> rgb);
/// Writes a single-channel float image as OpenEXR.
void write_exr(const std::filesystem::path& file, image_view<const float> value);
/// Reads an image as linear float RGB: the first three channels (one channel: grey, two:
/// grey and alpha), 8/16-bit files tagged sRGB decoded to linear. Throws io::image_error.
image<glm::vec3> read_rgb(const std::filesystem::path& file);
/// Writes `rgb * exposure`, clamped to [0, 1] and sRGB-encoded (IEC 61966-2-1), as an 8-bit
/// PNG (any 8-bit format OIIO knows by the extension). Non-finite pixels are written black.
/// \param exposure linear scale before clamping, finite and > 0; typical: 1.
/// \throws parameter_error on a bad exposure or an empty image, io::image_error on I/O.
void write_png(const std::filesystem::path& file, image_view<const glm::vec3> rgb, float exposure = 1.f);
/// Exposure mapping the 99th percentile of luminance to 1, so a PNG shows the scene
/// whatever its light units, over the pixels whose `weight` is finite and positive (a 0/1
/// mask, or a G-buffer depth: +infinity marks background); all pixels when it is empty.
/// 1 when no such pixel is lit.
float auto_exposure(image_view<const glm::vec3> rgb, image_view<const float> weight = {});

}  // namespace bounce::io
