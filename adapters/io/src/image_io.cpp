// Images through OpenImageIO: files and tone mapping for people.
#include <bounce/io/image_io.hpp>
#include <bounce/io/detail/imagebuf_view.hpp>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace bounce::io {

namespace fs = std::filesystem;

image_error::image_error(fs::path file, const std::string& what)
    : bounce::error("bounce: " + file.string() + ": " + what), file_(std::move(file)) {}

namespace {

using detail::require_writable_size;
using detail::to_imagebuf;

// OIIO reports through geterror(); an empty message still deserves a word.
std::string oiio_message(std::string m) {
    while (!m.empty() && (m.back() == '\n' || m.back() == ' ')) m.pop_back();
    return m.empty() ? "OpenImageIO failed without a message" : m;
}

template <class T>
void write_float_image(const fs::path& file, image_view<const T> v, int channels) {
    require_writable_size(v.width(), v.height());
    auto out = OIIO::ImageOutput::create(file.string());
    if (!out) throw image_error(file, oiio_message(OIIO::geterror()));
    OIIO::ImageSpec spec(int(v.width()), int(v.height()), channels, OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");  // lossless: the round trip is exact
    if (!out->open(file.string(), spec)) throw image_error(file, oiio_message(out->geterror()));
    if (!out->write_image(OIIO::TypeDesc::FLOAT, v.data(), sizeof(T), OIIO::stride_t(v.stride() * sizeof(T)))) {
        const std::string m = oiio_message(out->geterror());
        out->close();
        throw image_error(file, m);
    }
    if (!out->close()) throw image_error(file, oiio_message(out->geterror()));
}

}  // namespace

void write_exr(const fs::path& file, image_view<const glm::vec3> rgb) { write_float_image(file, rgb, 3); }

void write_exr(const fs::path& file, image_view<const float> value) { write_float_image(file, value, 1); }

image<glm::vec3> read_rgb(const fs::path& file) {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) throw image_error(file, fs::exists(file, ec) ? "not a regular file" : "no such file");
    OIIO::ImageBuf in(file.string());
    if (!in.read(0, 0, /*force=*/true, OIIO::TypeDesc::FLOAT)) throw image_error(file, oiio_message(in.geterror()));
    const OIIO::ImageSpec& spec = in.spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.depth != 1 || spec.nchannels <= 0)
        throw image_error(file, "not a 2D image with pixels");
    // Grey (and grey + alpha) becomes three equal channels; otherwise the first three.
    const std::array<int, 3> order = spec.nchannels < 3 ? std::array<int, 3>{0, 0, 0} : std::array<int, 3>{0, 1, 2};
    OIIO::ImageBuf rgb = OIIO::ImageBufAlgo::channels(in, 3, order);
    if (rgb.has_error()) throw image_error(file, oiio_message(rgb.geterror()));
    // 8/16-bit files carry sRGB-encoded values; float files are linear already.
    const std::string space = spec.get_string_attribute("oiio:ColorSpace");
    if (!in.nativespec().format.is_floating_point() && (space == "sRGB" || space.empty())) {
        rgb = OIIO::ImageBufAlgo::colorconvert(rgb, "sRGB", "linear");
        if (rgb.has_error()) throw image_error(file, oiio_message(rgb.geterror()));
    }
    image<glm::vec3> out(std::size_t(spec.width), std::size_t(spec.height));
    if (!rgb.get_pixels(OIIO::ROI(0, spec.width, 0, spec.height, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT, out.data()))
        throw image_error(file, oiio_message(rgb.geterror()));
    return out;
}

float auto_exposure(image_view<const glm::vec3> rgb, image_view<const float> weight) {
    require(weight.empty() || (weight.width() == rgb.width() && weight.height() == rgb.height()), "weight",
            "size differs from the image");
    std::vector<float> lum;
    for (std::size_t y = 0; y < rgb.height(); ++y)
        for (std::size_t x = 0; x < rgb.width(); ++x)
            if (weight.empty() || (std::isfinite(weight(x, y)) && weight(x, y) > 0.f)) {
                const glm::vec3 c = rgb(x, y);
                lum.push_back(0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z);
            }
    if (lum.empty()) return 1.f;
    const auto k = std::size_t(0.99 * double(lum.size() - 1));
    std::nth_element(lum.begin(), lum.begin() + std::ptrdiff_t(k), lum.end());
    return lum[k] > 0.f ? 1.f / lum[k] : 1.f;
}

void write_png(const fs::path& file, image_view<const glm::vec3> rgb, float exposure) {
    require(std::isfinite(exposure) && exposure > 0.f, "exposure", "must be finite and > 0");
    require_writable_size(rgb.width(), rgb.height());
    namespace iba = OIIO::ImageBufAlgo;
    OIIO::ImageBuf img = iba::mul(to_imagebuf(rgb, 3), exposure);
    img = iba::fixNonFinite(img, iba::NONFINITE_BLACK);
    img = iba::clamp(img, 0.f, 1.f);
    img = iba::colorconvert(img, "linear", "sRGB");  // IEC 61966-2-1 transfer function
    if (img.has_error()) throw image_error(file, oiio_message(img.geterror()));
    img.specmod().attribute("oiio:ColorSpace", "sRGB");
    if (!img.write(file.string(), OIIO::TypeDesc::UINT8)) throw image_error(file, oiio_message(img.geterror()));
}

}  // namespace bounce::io
