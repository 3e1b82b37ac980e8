// Images through OpenImageIO: files, tone mapping for people, and the error figures.
#include <bounce/io/image_io.hpp>

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

// OIIO reports through geterror(); an empty message still deserves a word.
std::string oiio_message(std::string m) {
    while (!m.empty() && (m.back() == '\n' || m.back() == ' ')) m.pop_back();
    return m.empty() ? "OpenImageIO failed without a message" : m;
}

// A float ImageBuf holding a copy of a view (whatever its row stride).
template <class T>
OIIO::ImageBuf to_imagebuf(image_view<const T> v, int channels) {
    OIIO::ImageSpec spec(int(v.width()), int(v.height()), channels, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf buf(spec, OIIO::InitializePixels::No);
    buf.set_pixels(OIIO::ROI(0, int(v.width()), 0, int(v.height()), 0, 1, 0, channels), OIIO::TypeDesc::FLOAT,
                   v.data(), sizeof(T), OIIO::stride_t(v.stride() * sizeof(T)));
    return buf;
}

void require_writable_size(std::size_t w, std::size_t h) {
    require(w > 0 && h > 0, "image", "empty image");
    require(w <= std::size_t(std::numeric_limits<int>::max()) && h <= std::size_t(std::numeric_limits<int>::max()),
            "image", "too large for OpenImageIO");
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

error_figures compare_luminance(image_view<const glm::vec3> x, image_view<const glm::vec3> ref,
                                image_view<const float> mask) {
    require(!x.empty() && !ref.empty(), "x/ref", "empty image");
    require(x.width() == ref.width() && x.height() == ref.height(), "x/ref", "sizes differ");
    require(mask.empty() || (mask.width() == x.width() && mask.height() == x.height()), "mask",
            "size differs from the images");
    require_writable_size(x.width(), x.height());
    require_finite(x, "x");
    require_finite(ref, "ref");
    if (!mask.empty()) require_finite(mask, "mask");

    namespace iba = OIIO::ImageBufAlgo;
    // Rec. 709 / sRGB primaries: Y = 0.2126 R + 0.7152 G + 0.0722 B.
    const float rec709[3] = {0.2126f, 0.7152f, 0.0722f};
    OIIO::ImageBuf lx = iba::channel_sum(to_imagebuf(x, 3), rec709);
    OIIO::ImageBuf lr = iba::channel_sum(to_imagebuf(ref, 3), rec709);

    const std::size_t w = x.width(), h = x.height();
    std::size_t pixels = w * h;
    if (!mask.empty()) {
        // Unmasked pixels become 0 in both images, so they add nothing to either sum of
        // squares, and the ratio rms(x - ref) / rms(ref) is that over the mask alone.
        image<float> m01(w, h);
        pixels = 0;
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t i = 0; i < w; ++i) {
                m01(i, y) = mask(i, y) != 0.f ? 1.f : 0.f;
                pixels += mask(i, y) != 0.f ? 1 : 0;
            }
        require(pixels > 0, "mask", "selects no pixel");
        const OIIO::ImageBuf mb = to_imagebuf(image_view<const float>(m01.view()), 1);
        lx = iba::mul(lx, mb);
        lr = iba::mul(lr, mb);
    }
    const OIIO::ImageBuf zero(lr.spec(), OIIO::InitializePixels::Yes);
    // Thresholds at infinity: compare() flags `error` for any pixel above them, and we
    // want the figures, not a verdict.
    const float never = std::numeric_limits<float>::max();
    const auto diff = iba::compare(lx, lr, never, never);
    const auto size = iba::compare(lr, zero, never, never);
    if (diff.error || size.error || lx.has_error() || lr.has_error())
        throw bounce::error("bounce: compare_luminance: OpenImageIO failed");

    error_figures e;
    e.pixels = pixels;
    e.max_abs = diff.maxerror;
    // compare() reports sqrt(sum / (w h)) over the whole image.
    e.sum_sq = diff.rms_error * diff.rms_error * double(w * h);
    e.rel_rms = size.rms_error > 0.0 ? diff.rms_error / size.rms_error
                : diff.rms_error > 0.0 ? std::numeric_limits<double>::infinity()
                                       : 0.0;
    return e;
}

}  // namespace bounce::io
