// SSIM of tone-mapped luminance over a mask (Wang et al. 2004), windows restricted to the mask.
#include <bounce/study/ssim.hpp>
#include <bounce/luminance.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::study {

namespace {
constexpr int radius = 5;            // 11 x 11 window
constexpr double window_sigma = 1.5;
constexpr double c1 = 0.01 * 0.01;   // (K1 L)^2, dynamic range L = 1
constexpr double c2 = 0.03 * 0.03;   // (K2 L)^2

double luminance(glm::vec3 c) { return rec709_luminance<double>(glm::dvec3(c)); }
}  // namespace

double tonemapped_ssim(image_view<const glm::vec3> x, image_view<const glm::vec3> ref, image_view<const float> mask) {
    require(!x.empty() && !ref.empty(), "x/ref", "empty image");
    require(x.width() == ref.width() && x.height() == ref.height(), "x/ref", "sizes differ");
    require(mask.empty() || (mask.width() == x.width() && mask.height() == x.height()), "mask",
            "size differs from the images");
    require_finite(x, "x");
    require_finite(ref, "ref");
    if (!mask.empty()) require_finite(mask, "mask");

    const std::size_t w = x.width(), h = x.height();
    std::vector<double> tx(w * h), tr(w * h);
    std::vector<unsigned char> in(w * h);
    std::size_t count = 0;
    double ref_sum = 0;
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t i = 0; i < w; ++i) {
            const std::size_t p = y * w + i;
            in[p] = mask.empty() || mask(i, y) > 0.f;
            tx[p] = luminance(x(i, y));
            tr[p] = luminance(ref(i, y));
            if (in[p]) {
                ++count;
                ref_sum += tr[p];
            }
        }
    require(count > 0, "mask", "selects no pixel");
    const double k = ref_sum / double(count);
    require(k > 0.0, "ref", "mean luminance over the mask is not positive: no scale to tone-map by");
    for (std::size_t p = 0; p < w * h; ++p) {
        tx[p] = tx[p] / (std::abs(tx[p]) + k);
        tr[p] = tr[p] / (std::abs(tr[p]) + k);
    }

    std::array<double, 2 * radius + 1> g{};
    for (int d = -radius; d <= radius; ++d) g[std::size_t(d + radius)] = std::exp(-0.5 * d * d / (window_sigma * window_sigma));

    // The window sums of the six masked statistics (weight, x, r, x^2, r^2, x r), by the
    // Gaussian's separability: a horizontal then a vertical 11-tap pass, clipped at the
    // image's edges, in double. The variances come out as E[x^2] - E[x]^2, whose
    // cancellation error (~1e-16 for tone-mapped values below 1 in magnitude) is 13 orders
    // below C2; with x = r every statistic of x equals that of r bit for bit, so identical
    // images still give exactly 1.
    constexpr std::size_t stats = 6;
    std::vector<double> f(w * h * stats, 0.0), across(w * h * stats);
    for (std::size_t p = 0; p < w * h; ++p) {
        if (!in[p]) continue;
        double* q = &f[p * stats];
        q[0] = 1.0;
        q[1] = tx[p];
        q[2] = tr[p];
        q[3] = tx[p] * tx[p];
        q[4] = tr[p] * tr[p];
        q[5] = tx[p] * tr[p];
    }
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t i = 0; i < w; ++i) {
            std::array<double, stats> sum{};
            const std::size_t i0 = i >= radius ? i - radius : 0, i1 = std::min(w - 1, i + radius);
            for (std::size_t j = i0; j <= i1; ++j) {
                const double wt = g[j + radius - i];
                const double* q = &f[(y * w + j) * stats];
                for (std::size_t s = 0; s < stats; ++s) sum[s] += wt * q[s];
            }
            std::copy(sum.begin(), sum.end(), &across[(y * w + i) * stats]);
        }

    double total = 0;
    for (std::size_t cy = 0; cy < h; ++cy)
        for (std::size_t cx = 0; cx < w; ++cx) {
            if (!in[cy * w + cx]) continue;
            std::array<double, stats> sum{};
            const std::size_t y0 = cy >= radius ? cy - radius : 0, y1 = std::min(h - 1, cy + radius);
            for (std::size_t y = y0; y <= y1; ++y) {
                const double wt = g[y + radius - cy];
                const double* q = &across[(y * w + cx) * stats];
                for (std::size_t s = 0; s < stats; ++s) sum[s] += wt * q[s];
            }
            const double sw = sum[0];  // >= 1: the centre is in the mask
            const double mx = sum[1] / sw, mr = sum[2] / sw;
            const double vx = sum[3] / sw - mx * mx, vr = sum[4] / sw - mr * mr, cov = sum[5] / sw - mx * mr;
            const double s = ((2.0 * mx * mr + c1) * (2.0 * cov + c2)) / ((mx * mx + mr * mr + c1) * (vx + vr + c2));
            total += std::clamp(s, -1.0, 1.0);  // the algebra bounds it; rounding may not
        }
    return total / double(count);
}

}  // namespace bounce::study
