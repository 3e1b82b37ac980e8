// Error figures of an image against its reference, through OpenImageIO's compare.
#include <bounce/study/image_comparison.hpp>
#include <bounce/io/detail/imagebuf_view.hpp>
#include <bounce/luminance.hpp>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>  // the vec3_of concept of rec709_luminance

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
    // The weights of rec709_luminance (luminance.hpp), as OpenImageIO's channel sum takes them.
    const float rec709[3] = {rec709_luminance<float, glm::vec3>(glm::vec3(1, 0, 0)),
                             rec709_luminance<float, glm::vec3>(glm::vec3(0, 1, 0)),
                             rec709_luminance<float, glm::vec3>(glm::vec3(0, 0, 1))};
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

namespace {
double luminance(glm::vec3 c) { return rec709_luminance<double, glm::dvec3>(glm::dvec3(c)); }
}  // namespace

noisy_reference_error compare_luminance_debiased(image_view<const glm::vec3> x, image_view<const glm::vec3> half_a,
                                                 image_view<const glm::vec3> half_b, image_view<const float> mask) {
    require(!x.empty() && !half_a.empty() && !half_b.empty(), "x/half_a/half_b", "empty image");
    require(x.width() == half_a.width() && x.height() == half_a.height(), "x/half_a", "sizes differ");
    require(x.width() == half_b.width() && x.height() == half_b.height(), "x/half_b", "sizes differ");
    require(mask.empty() || (mask.width() == x.width() && mask.height() == x.height()), "mask",
            "size differs from the images");
    require_finite(x, "x");
    require_finite(half_a, "half_a");
    require_finite(half_b, "half_b");
    if (!mask.empty()) require_finite(mask, "mask");

    // Per pixel: raw squared error, the reference's noise term, and r^2.
    struct terms {
        double raw, noise, ref_sq, signed_diff, r;  // (x-r)^2, (a-b)^2/4, r^2, x-r, r
    };
    std::vector<terms> t;
    t.reserve(x.width() * x.height());
    for (std::size_t y = 0; y < x.height(); ++y)
        for (std::size_t i = 0; i < x.width(); ++i) {
            if (!mask.empty() && mask(i, y) == 0.f) continue;
            const double lx = luminance(x(i, y)), la = luminance(half_a(i, y)), lb = luminance(half_b(i, y));
            const double r = 0.5 * (la + lb);
            t.push_back({(lx - r) * (lx - r), 0.25 * (la - lb) * (la - lb), r * r, lx - r, r});
        }
    require(!t.empty(), "mask", "selects no pixel");

    const double n = double(t.size());
    double raw = 0, noise = 0, ref_sq = 0;
    for (const terms& p : t) {
        raw += p.raw;
        noise += p.noise;
        ref_sq += p.ref_sq;
    }
    raw /= n;
    noise /= n;
    ref_sq /= n;
    const double d = raw - noise, s = ref_sq - noise;  // mean d_i, mean s_i

    noisy_reference_error e;
    e.pixels = t.size();
    const double inf = std::numeric_limits<double>::infinity();
    if (!(s > 0.0)) {
        const bool all_zero = raw == 0.0 && ref_sq == 0.0;
        e.rel_rms = e.rel_sq_debiased = e.rel_rms_debiased = e.reference_noise_rel_rms = all_zero ? 0.0 : inf;
        e.rel_sq_debiased_se = e.rel_rms_debiased_se = all_zero ? 0.0 : inf;
        return e;
    }
    e.rel_rms = ref_sq > 0.0 ? std::sqrt(raw / ref_sq) : inf;
    const double q = d / s;
    // q's standard error given the images (the truth fixed; the references' noise is what
    // varies): with r = t + u and v = (a - b) / 2, u and v independent with variance
    // sigma_i^2 / 2 (exact for Gaussian noise), the fluctuation of d_i - q s_i is
    // -2 u (delta_i + q t_i) + (1 - q)(u^2 - v^2), of variance
    // 2 sigma_i^2 (delta_i + q t_i)^2 + (1 - q)^2 sigma_i^4, and
    // (a_i - b_i)^2 (x_i - r_i + q r_i)^2 is an unbiased estimate of it from the pixel alone.
    // The spread of the pixels' own errors over the image is no uncertainty about this
    // image's error, so it is not in (a sample variance of d_i - q s_i would count it).
    double var = 0;
    for (const terms& p : t) {
        const double g = p.signed_diff + q * p.r;
        var += 4.0 * p.noise * g * g;  // (a - b)^2 = 4 noise
    }
    e.rel_sq_debiased = q;
    e.rel_sq_debiased_se = std::sqrt(var) / (n * s);
    const double q0 = std::max(0.0, q);
    e.rel_rms_debiased = std::sqrt(q0);
    e.rel_rms_debiased_se = std::sqrt(q0 + e.rel_sq_debiased_se) - e.rel_rms_debiased;
    e.reference_noise_rel_rms = std::sqrt(noise / s);
    return e;
}

}  // namespace bounce::study
