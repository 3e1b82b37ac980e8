// The error figures of an image against its reference match their definitions on images
// where they are known in closed form, with and without a mask, and refuse bad input.
#include <bounce/sampling.hpp>
#include <bounce/study/image_comparison.hpp>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

using namespace bounce;

namespace {
double luminance(glm::dvec3 c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }
}  // namespace

TEST_CASE("compare_luminance: a uniform relative error k gives rel_rms k", "[study][image][error]") {
    // ref = grey c (luminance c: the Rec. 709 weights sum to 1), x = (1 + k) ref:
    // rel_rms = k, max_abs = c k, sum_sq = N (c k)^2. Luminance is computed in float:
    // relative error ~1e-6 on the difference.
    pcg32 rng(31);
    const int i = GENERATE(range(0, 40));
    (void)i;
    const double c = 0.01 + 10 * rng.next_double(), k = (rng.next_double() - 0.5) * 0.4;
    const std::size_t w = 1 + rng.next_u32() % 40, h = 1 + rng.next_u32() % 40;
    const image<glm::vec3> ref(w, h, glm::vec3(float(c))), x(w, h, glm::vec3(float(c * (1 + k))));
    const auto e = study::compare_luminance(x.view(), ref.view());
    const double d = double(float(c * (1 + k))) - double(float(c));
    CHECK(e.pixels == w * h);
    CHECK(e.rel_rms == Approx(std::abs(d) / double(float(c))).epsilon(1e-5));
    CHECK(e.max_abs == Approx(std::abs(d)).epsilon(1e-5));
    CHECK(e.sum_sq == Approx(double(w * h) * d * d).epsilon(1e-5));
}

TEST_CASE("compare_luminance weighs the channels by Rec. 709", "[study][image][error]") {
    // A difference d in one channel alone changes the luminance by w_c d. OIIO sums the
    // weighted channels in float: luminances near 1 carry an absolute error of a few
    // 2^-24, so the difference is exact to 1e-6 absolute.
    const double weights[3] = {0.2126, 0.7152, 0.0722};
    const int channel = GENERATE(0, 1, 2);
    image<glm::vec3> ref(8, 8, glm::vec3(1.f)), x(8, 8, glm::vec3(1.f));
    for (std::size_t y = 0; y < 8; ++y)
        for (std::size_t i = 0; i < 8; ++i) x(i, y)[channel] += 0.5f;
    const auto e = study::compare_luminance(x.view(), ref.view());
    CHECK(e.max_abs == Approx(0.5 * weights[channel]).margin(1e-6));
    CHECK(e.rel_rms == Approx(0.5 * weights[channel]).margin(1e-6));
}

TEST_CASE("compare_luminance matches its definition on random images, with and without a mask",
          "[study][image][error]") {
    pcg32 rng(37);
    const int trial = GENERATE(range(0, 30));
    const bool masked = trial % 2 == 1;
    const std::size_t w = 3 + rng.next_u32() % 60, h = 3 + rng.next_u32() % 60;
    image<glm::vec3> x(w, h), ref(w, h);
    image<float> mask(w, h, 0.f);
    double num = 0, den = 0, mx = 0;
    std::size_t n = 0;
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t i = 0; i < w; ++i) {
            ref(i, y) = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 3.f;
            x(i, y) = ref(i, y) + glm::vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f);
            const bool in = !masked || (i + y) % 3 != 0;
            mask(i, y) = in ? (rng.next_float() + 0.1f) : 0.f;  // any non-zero value selects
            if (!in) {
                x(i, y) = glm::vec3(1e6f);  // masked-out pixels must not count
                continue;
            }
            const double d = luminance(glm::dvec3(x(i, y))) - luminance(glm::dvec3(ref(i, y)));
            num += d * d;
            den += luminance(glm::dvec3(ref(i, y))) * luminance(glm::dvec3(ref(i, y)));
            mx = std::max(mx, std::abs(d));
            ++n;
        }
    const auto e = masked ? study::compare_luminance(x.view(), ref.view(), image_view<const float>(mask.view()))
                          : study::compare_luminance(x.view(), ref.view());
    // Float luminances of values ~1: absolute error ~1e-7 on differences ~0.3.
    CHECK(e.pixels == n);
    CHECK(e.rel_rms == Approx(std::sqrt(num / den)).epsilon(1e-5));
    CHECK(e.sum_sq == Approx(num).epsilon(1e-5));
    CHECK(e.max_abs == Approx(mx).epsilon(1e-5));
}

TEST_CASE("compare_luminance on identical images and on a zero reference", "[study][image][error]") {
    const image<glm::vec3> a(5, 4, glm::vec3(0.3f, 0.2f, 0.1f)), zero(5, 4, glm::vec3(0.f));
    const auto same = study::compare_luminance(a.view(), a.view());
    CHECK(same.rel_rms == 0.0);
    CHECK(same.max_abs == 0.0);
    CHECK(same.sum_sq == 0.0);
    CHECK(study::compare_luminance(zero.view(), zero.view()).rel_rms == 0.0);
    CHECK(std::isinf(study::compare_luminance(a.view(), zero.view()).rel_rms));
}

TEST_CASE("compare_luminance refuses mismatched, empty, non-finite or fully masked input",
          "[study][image][error][bad-input]") {
    const image<glm::vec3> a(5, 4, glm::vec3(0.5f)), b(4, 5, glm::vec3(0.5f));
    image<glm::vec3> nan_img(5, 4, glm::vec3(0.5f));
    nan_img(2, 3).g = std::numeric_limits<float>::quiet_NaN();
    const image<float> no_pixel(5, 4, 0.f), wrong_mask(3, 3, 1.f);
    CHECK_THROWS_AS(study::compare_luminance(a.view(), b.view()), parameter_error);
    CHECK_THROWS_AS(study::compare_luminance(a.view(), image_view<const glm::vec3>{}), parameter_error);
    CHECK_THROWS_AS(study::compare_luminance(nan_img.view(), a.view()), parameter_error);
    CHECK_THROWS_AS(study::compare_luminance(a.view(), nan_img.view()), parameter_error);
    CHECK_THROWS_AS(study::compare_luminance(a.view(), a.view(), image_view<const float>(no_pixel.view())), parameter_error);
    CHECK_THROWS_AS(study::compare_luminance(a.view(), a.view(), image_view<const float>(wrong_mask.view())), parameter_error);
}
