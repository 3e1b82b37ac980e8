// SSIM of tone-mapped luminance: exact where the algebra makes it exact (identical images,
// uniform images, masked-out pixels, power-of-two scales), ordered where its purpose is to
// order (more noise is worse; a smooth bias looks better than white noise of equal rel_rms),
// bounded, and refusing bad input.
#include <bounce/sampling.hpp>
#include <bounce/study/ssim.hpp>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <vector>

using namespace bounce;

namespace {
constexpr double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;

double luminance(glm::vec3 c) { return 0.2126 * double(c.r) + 0.7152 * double(c.g) + 0.0722 * double(c.b); }

double normal(pcg32& rng) {  // Box-Muller
    const double u1 = 1.0 - rng.next_double(), u2 = rng.next_double();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

image<glm::vec3> random_image(pcg32& rng, std::size_t w, std::size_t h) {
    image<glm::vec3> img(w, h);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t i = 0; i < w; ++i)
            img(i, y) = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 4.f;
    return img;
}

/// A smooth grey image with structure at every window: luminance 1 +- 0.5.
image<glm::vec3> smooth_reference(std::size_t w, std::size_t h) {
    image<glm::vec3> img(w, h);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t i = 0; i < w; ++i) {
            const double v = 1.0 + 0.5 * std::sin(2 * std::numbers::pi * double(i) / 32.0) *
                                       std::cos(2 * std::numbers::pi * double(y) / 24.0);
            img(i, y) = glm::vec3(float(v));
        }
    return img;
}

double rel_rms(const image<glm::vec3>& x, const image<glm::vec3>& ref) {
    double num = 0, den = 0;
    for (std::size_t y = 0; y < x.height(); ++y)
        for (std::size_t i = 0; i < x.width(); ++i) {
            const double d = luminance(x(i, y)) - luminance(ref(i, y));
            num += d * d;
            den += luminance(ref(i, y)) * luminance(ref(i, y));
        }
    return std::sqrt(num / den);
}
}  // namespace

TEST_CASE("tonemapped_ssim: an image against itself is exactly 1", "[study][ssim]") {
    // With x = ref every window's numerator and denominator are the same floating-point
    // products (2 mx mr = mx mx + mr mr exactly, cov = vx = vr term by term), so each window
    // is 1 and so is their mean: no tolerance is needed.
    pcg32 rng(101);
    const int trial = GENERATE(range(0, 12));
    const std::size_t w = 1 + rng.next_u32() % 50, h = 1 + rng.next_u32() % 50;
    const image<glm::vec3> ref = random_image(rng, w, h);
    image<float> mask(w, h, 1.f);
    if (trial % 2 == 1)
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t i = 0; i < w; ++i) mask(i, y) = rng.next_float() < 0.5f ? 0.f : 1.f;
    mask(0, 0) = 1.f;
    CHECK(study::tonemapped_ssim(ref.view(), ref.view(), mask.view()) == 1.0);
    CHECK(study::tonemapped_ssim(ref.view(), ref.view()) == 1.0);
}

TEST_CASE("tonemapped_ssim: a uniform image scaled by s scores the closed form of its luminance term",
          "[study][ssim]") {
    // Uniform grey c against grey s c: every window's variances and covariance vanish, so its
    // contrast-structure factor is C2 / C2 = 1 and the SSIM is the luminance factor
    // (2 tx tr + C1) / (tx^2 + tr^2 + C1), with k = L(ref), tr = 1/2 and tx = Lx / (Lx + k).
    // The window means are weighted averages of equal values (a few ulp off) and the
    // variances ~1e-32 against C2 = 9e-4: 1e-12 relative covers the rounding.
    pcg32 rng(103);
    const int trial = GENERATE(range(0, 20));
    (void)trial;
    const double c = 0.01 + 10 * rng.next_double(), s = std::exp(4.0 * (rng.next_double() - 0.5));
    const std::size_t w = 1 + rng.next_u32() % 30, h = 1 + rng.next_u32() % 30;
    const image<glm::vec3> ref(w, h, glm::vec3(float(c))), x(w, h, glm::vec3(float(s * c)));
    const double lr = luminance(ref(0, 0)), lx = luminance(x(0, 0)), k = lr;
    const double tr = lr / (lr + k), tx = lx / (lx + k);
    const double expected = (2 * tx * tr + c1) / (tx * tx + tr * tr + c1);
    const double got = study::tonemapped_ssim(x.view(), ref.view());
    CHECK(got == Approx(expected).epsilon(1e-12));
    CHECK(got < 1.0);
}

TEST_CASE("tonemapped_ssim: scaling both images by a power of two changes nothing", "[study][ssim]") {
    // The tone map's k is the reference's mean, so L and k scale together and
    // t = L / (|L| + k) is unchanged; by a power of two every step is exact.
    pcg32 rng(107);
    const image<glm::vec3> ref = random_image(rng, 40, 30), x = random_image(rng, 40, 30);
    image<glm::vec3> ref4 = ref, x4 = x;
    for (std::size_t y = 0; y < 30; ++y)
        for (std::size_t i = 0; i < 40; ++i) {
            ref4(i, y) *= 1024.f;
            x4(i, y) *= 1024.f;
        }
    CHECK(study::tonemapped_ssim(x4.view(), ref4.view()) == study::tonemapped_ssim(x.view(), ref.view()));
}

TEST_CASE("tonemapped_ssim: added Gaussian noise lowers it monotonically with sigma", "[study][ssim]") {
    // x = ref + sigma z with one draw z per seed. Each window loses about
    // sigma_t^2 / (2 vr + sigma_t^2 + C2) to the noise's variance sigma_t^2 (tone-mapped); the
    // mean over 64 x 64 windows averages ~4096 / (4 pi 1.5^2) ~ 145 independent windows, a
    // relative fluctuation of a few percent, far below the factor ~4 in sigma_t^2 between
    // the steps below: the order must hold for every seed.
    const image<glm::vec3> ref = smooth_reference(64, 64);
    const std::uint64_t seed = GENERATE(1u, 2u, 3u, 4u);
    pcg32 rng(seed);
    std::vector<double> z(64 * 64);
    for (double& v : z) v = normal(rng);
    double previous = 1.0;
    for (const double sigma : {0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5}) {
        image<glm::vec3> x = ref;
        for (std::size_t y = 0; y < 64; ++y)
            for (std::size_t i = 0; i < 64; ++i) x(i, y) += glm::vec3(float(sigma * z[y * 64 + i]));
        const double s = study::tonemapped_ssim(x.view(), ref.view());
        INFO("sigma " << sigma << ": " << s);
        CHECK(s < previous);
        previous = s;
    }
}

TEST_CASE("tonemapped_ssim: a smooth bias scores higher than white noise of equal rel_rms", "[study][ssim]") {
    // Both perturbations have rel_rms 0.1 against the same reference. The bias
    // ref (1 + a b), a ~ 0.14 and b varying over 100 pixels, keeps each window's structure:
    // it moves the window's mean (luminance factor ~1 - (dt)^2 / (2 t^2)) and scales its
    // contrast by 1 + a b (contrast factor 2 (1 + ab) / (1 + (1 + ab)^2) ~ 1 - (ab)^2 / 2),
    // a loss of order 5e-3. The noise adds a variance sigma_t^2 ~ (0.1 / 4)^2 ~ 7e-4
    // (tone-mapped: dt/dL = 1/4 at L = k) to windows whose own, from a gradient ~0.05 per
    // pixel over a sigma-1.5 window, is ~6e-4: the structure factor falls to
    // ~(2 * 6e-4 + C2) / (2 * 6e-4 + 7e-4 + C2) ~ 0.75. The two are far apart, which is
    // why the benchmark reports SSIM beside rel_rms.
    const std::size_t n = 64;
    const image<glm::vec3> ref = smooth_reference(n, n);
    image<glm::vec3> bias = ref, noise = ref;
    pcg32 rng(109);
    for (std::size_t y = 0; y < n; ++y)
        for (std::size_t i = 0; i < n; ++i) {
            const double b = std::cos(2 * std::numbers::pi * (double(i) + 0.5 * double(y)) / 100.0 + 0.3);
            bias(i, y) = ref(i, y) * float(1.0 + 0.1 * b);
            noise(i, y) = ref(i, y) + glm::vec3(float(0.1 * normal(rng)));
        }
    // Rescale both perturbations to rel_rms exactly 0.1 (to float rounding).
    for (image<glm::vec3>* img : {&bias, &noise}) {
        const double f = 0.1 / rel_rms(*img, ref);
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t i = 0; i < n; ++i) (*img)(i, y) = ref(i, y) + (((*img)(i, y) - ref(i, y)) * float(f));
    }
    REQUIRE(rel_rms(bias, ref) == Approx(0.1).epsilon(1e-5));
    REQUIRE(rel_rms(noise, ref) == Approx(0.1).epsilon(1e-5));
    const double s_bias = study::tonemapped_ssim(bias.view(), ref.view());
    const double s_noise = study::tonemapped_ssim(noise.view(), ref.view());
    INFO("bias " << s_bias << ", noise " << s_noise);
    CHECK(s_bias > 0.99);
    CHECK(s_noise < 0.9);
    CHECK(s_bias > s_noise);
}

TEST_CASE("tonemapped_ssim: pixels outside the mask do not matter", "[study][ssim]") {
    // Masked-out pixels neither centre a window, enter one, nor enter k: replacing them with
    // anything leaves the result bit for bit the same. A mask of ones is no mask.
    pcg32 rng(113);
    const int trial = GENERATE(range(0, 10));
    (void)trial;
    const std::size_t w = 5 + rng.next_u32() % 40, h = 5 + rng.next_u32() % 40;
    const image<glm::vec3> ref = random_image(rng, w, h), x = random_image(rng, w, h);
    image<float> mask(w, h, 0.f);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t i = 0; i < w; ++i) mask(i, y) = rng.next_float() < 0.6f ? 0.25f + rng.next_float() : 0.f;
    mask(w / 2, h / 2) = 1.f;
    image<glm::vec3> ref2 = ref, x2 = x;
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t i = 0; i < w; ++i)
            if (mask(i, y) == 0.f) {
                ref2(i, y) = glm::vec3(1e6f * rng.next_float());
                x2(i, y) = glm::vec3(-1e6f * rng.next_float());
            }
    CHECK(study::tonemapped_ssim(x2.view(), ref2.view(), mask.view()) ==
          study::tonemapped_ssim(x.view(), ref.view(), mask.view()));
    const image<float> ones(w, h, 1.f);
    CHECK(study::tonemapped_ssim(x.view(), ref.view(), ones.view()) == study::tonemapped_ssim(x.view(), ref.view()));
}

TEST_CASE("tonemapped_ssim: the result lies in [-1, 1] and reaches below 0 for an inverted image",
          "[study][ssim]") {
    pcg32 rng(127);
    for (int trial = 0; trial < 30; ++trial) {
        const std::size_t w = 1 + rng.next_u32() % 40, h = 1 + rng.next_u32() % 40;
        image<glm::vec3> ref = random_image(rng, w, h), x = random_image(rng, w, h);
        if (trial % 3 == 0)  // negative luminance, as ringing estimators give
            for (std::size_t y = 0; y < h; ++y)
                for (std::size_t i = 0; i < w; ++i) x(i, y) -= glm::vec3(2.f);
        const double s = study::tonemapped_ssim(x.view(), ref.view());
        CHECK(s >= -1.0);
        CHECK(s <= 1.0);
    }
    // A checkerboard against its complement: equal window means and variances, covariance
    // -variance, so each window is (-2 v + C2) / (2 v + C2) times a luminance factor near 1.
    image<glm::vec3> ref(32, 32), x(32, 32);
    for (std::size_t y = 0; y < 32; ++y)
        for (std::size_t i = 0; i < 32; ++i) {
            const bool odd = (i + y) % 2 == 1;
            ref(i, y) = glm::vec3(odd ? 10.f : 0.1f);
            x(i, y) = glm::vec3(odd ? 0.1f : 10.f);
        }
    const double s = study::tonemapped_ssim(x.view(), ref.view());
    CHECK(s >= -1.0);
    CHECK(s < -0.9);
}

TEST_CASE("tonemapped_ssim refuses mismatched, empty, non-finite and black input", "[study][ssim]") {
    const image<glm::vec3> a(8, 8, glm::vec3(1.f)), b(8, 9, glm::vec3(1.f)), black(8, 8, glm::vec3(0.f));
    const image<float> mask(8, 8, 1.f), small_mask(8, 7, 1.f), none(8, 8, 0.f), negative(8, 8, -1.f);
    CHECK_THROWS_AS(study::tonemapped_ssim(a.view(), b.view()), parameter_error);
    CHECK_THROWS_AS(study::tonemapped_ssim(a.view(), a.view(), small_mask.view()), parameter_error);
    CHECK_THROWS_AS(study::tonemapped_ssim(a.view(), a.view(), none.view()), parameter_error);
    CHECK_THROWS_AS(study::tonemapped_ssim(a.view(), a.view(), negative.view()), parameter_error);
    CHECK_THROWS_AS(study::tonemapped_ssim({}, {}), parameter_error);
    CHECK_THROWS_AS(study::tonemapped_ssim(a.view(), black.view()), parameter_error);
    image<glm::vec3> nan = a, inf = a;
    nan(3, 4).g = std::numeric_limits<float>::quiet_NaN();
    inf(7, 0).b = std::numeric_limits<float>::infinity();
    CHECK_THROWS_AS(study::tonemapped_ssim(nan.view(), a.view()), parameter_error);
    CHECK_THROWS_AS(study::tonemapped_ssim(a.view(), inf.view()), parameter_error);
    image<float> nan_mask = mask;
    nan_mask(1, 1) = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_AS(study::tonemapped_ssim(a.view(), a.view(), nan_mask.view()), parameter_error);
    // A black reference is refused even where x is black too: there is no scale to judge by.
    CHECK_THROWS_AS(study::tonemapped_ssim(black.view(), black.view()), parameter_error);
    CHECK(study::tonemapped_ssim(a.view(), a.view(), mask.view()) == 1.0);
}
