// Error figures of an image against its reference, through OpenImageIO's compare.
#include <bounce/study/image_comparison.hpp>
#include <bounce/io/detail/imagebuf_view.hpp>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <cmath>
#include <limits>

namespace bounce::study {

using io::detail::require_writable_size;
using io::detail::to_imagebuf;

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

}  // namespace bounce::study
