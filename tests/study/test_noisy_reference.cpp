// The error against a noisy reference made of two independent halves A and B: with the
// reference's own noise taken out (compare_luminance_debiased), on synthetic images of known
// truth and Gaussian noise of known variance, and on real references of a hand-built scene
// (their halves are independent, cached apart from whole references, and Monte Carlo at equal
// debiased error measures what it says).
//
// The closed forms the tolerances come from. Per pixel, truth t, estimate x = t + delta, halves
// a = t + e_a, b = t + e_b with e_a, e_b ~ N(0, s2) independent; r = (a + b) / 2 = t + u,
// v = (a - b) / 2, u and v independent N(0, s2 / 2). The per-pixel terms
//   d = (x - r)^2 - v^2 = delta^2 - 2 delta u + u^2 - v^2      (mean: delta^2)
//   s = r^2 - v^2       = t^2 + 2 t u + u^2 - v^2              (mean: t^2)
// and for q = mean d / mean s near its value Q the fluctuation d - Q s has variance
//   2 s2 (delta + Q t)^2 + (1 - Q)^2 s2^2,
// so q's standard error is sqrt(sum of that) / (n mean t^2) (delta method).
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/sampling.hpp>
#include <bounce/study/equal_error.hpp>
#include <bounce/study/frame_comparison.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/reference_cache.hpp>

#include "../embree/hand_built_scenes.hpp"

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <numbers>
#include <vector>

#include <unistd.h>

using namespace bounce;
namespace fs = std::filesystem;

namespace {

// Standard normal deviates (Box-Muller).
double gaussian(pcg32& rng) {
    const double u1 = 1.0 - rng.next_double(), u2 = rng.next_double();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

// A grey image holds its luminance in every channel (the Rec. 709 weights sum to 1).
struct synthetic {
    std::size_t w, h;
    std::vector<double> t, delta;  // truth and the estimate's error, as stored (float-rounded)
    image<glm::vec3> x;
    double sigma;                  // each half's noise standard deviation

    synthetic(std::size_t w_, std::size_t h_, double relative_error, double sigma_, std::uint64_t seed)
        : w(w_), h(h_), t(w_ * h_), delta(w_ * h_), x(w_, h_), sigma(sigma_) {
        pcg32 rng(seed);
        for (std::size_t i = 0; i < w * h; ++i) {
            const float ti = float(0.2 + rng.next_double());
            const float xi = float(double(ti) * (1.0 + relative_error * gaussian(rng)));
            t[i] = ti;
            delta[i] = double(xi) - double(ti);
            x(i % w, i / w) = glm::vec3(xi);
        }
    }
    double mean_t2() const {
        double s = 0;
        for (double v : t) s += v * v;
        return s / double(t.size());
    }
    // mean (x - t)^2 / mean t^2: what the debiased error estimates.
    double true_rel_sq() const {
        double s = 0;
        for (double d : delta) s += d * d;
        return s / double(t.size()) / mean_t2();
    }
    // q's standard error from the closed form above.
    double theory_se() const {
        const double q = true_rel_sq(), s2 = sigma * sigma;
        double sum = 0;
        for (std::size_t i = 0; i < t.size(); ++i) {
            const double g = delta[i] + q * t[i];
            sum += 2.0 * s2 * g * g + (1.0 - q) * (1.0 - q) * s2 * s2;
        }
        return std::sqrt(sum) / (double(t.size()) * mean_t2());
    }
    // Two independent halves drawn with `seed`.
    std::pair<image<glm::vec3>, image<glm::vec3>> halves(std::uint64_t seed) const {
        pcg32 rng(seed, 7);
        image<glm::vec3> a(w, h), b(w, h);
        for (std::size_t i = 0; i < w * h; ++i) {
            a(i % w, i / w) = glm::vec3(float(t[i] + sigma * gaussian(rng)));
            b(i % w, i / w) = glm::vec3(float(t[i] + sigma * gaussian(rng)));
        }
        return {std::move(a), std::move(b)};
    }
};

// (a + b) / 2, pixel by pixel, as the reference in halves forms it.
image<glm::vec3> average(const image<glm::vec3>& a, const image<glm::vec3>& b) {
    image<glm::vec3> m(a.width(), a.height());
    for (std::size_t y = 0; y < a.height(); ++y)
        for (std::size_t x = 0; x < a.width(); ++x) m(x, y) = 0.5f * (a(x, y) + b(x, y));
    return m;
}

double mean_of(const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return s / double(v.size());
}
double sd_of(const std::vector<double>& v) {
    const double m = mean_of(v);
    double s = 0;
    for (double x : v) s += (x - m) * (x - m);
    return std::sqrt(s / double(v.size() - 1));
}

}  // namespace

TEST_CASE("compare_luminance_debiased recovers the true error under a noisy reference", "[study][image][noise]") {
    // 5 standard errors of the closed form: a false failure once in ~3 million runs.
    const std::size_t side = GENERATE(48, 128);
    const double sigma = GENERATE(0.02, 0.1, 0.3);
    const synthetic s(side, side, 0.05, sigma, 11 + side);
    const double q_true = s.true_rel_sq(), se = s.theory_se();
    const auto [a, b] = s.halves(101 + std::uint64_t(1000 * sigma));
    const auto e = study::compare_luminance_debiased(s.x.view(), a.view(), b.view());
    INFO("side " << side << ", sigma " << sigma << ": q " << e.rel_sq_debiased << " true " << q_true << " se " << se);
    CHECK(e.pixels == side * side);
    CHECK(std::abs(e.rel_sq_debiased - q_true) <= 5.0 * se);
    // The reported standard error is the closed form's, estimated from the pixels: its own
    // relative error is a few percent at these pixel counts (fourth moments over n pixels).
    CHECK(e.rel_sq_debiased_se == Approx(se).epsilon(0.15));
    CHECK(e.rel_rms_debiased == Approx(std::sqrt(std::max(0.0, e.rel_sq_debiased))).epsilon(1e-12));
    // The reference's own noise: Var r / mean t^2 = (sigma^2 / 2) / mean t^2, to its
    // standard error (sigma^2 / 2) sqrt(2 / n) / mean t^2 (a chi-square mean).
    const double noise = sigma * sigma / 2.0 / s.mean_t2();
    const double noise_se = sigma * sigma / 2.0 * std::sqrt(2.0 / double(side * side)) / s.mean_t2();
    CHECK(std::abs(e.reference_noise_rel_rms * e.reference_noise_rel_rms - noise) <= 5.0 * noise_se + 5.0 * se);
    // Where the reference's noise exceeds the error, the raw figure is the noise's, not the
    // error's: its square is off by about Var r / mean t^2.
    if (noise > 10.0 * (se + noise_se)) CHECK(e.rel_rms * e.rel_rms - q_true > 0.5 * noise);
}

TEST_CASE("the debiased square error is the raw one less the reference's noise", "[study][image][noise]") {
    const synthetic s(64, 64, 0.1, 0.1, 5);
    // Exactly, per comparison: q = mean d / mean s, raw^2 = mean (x-r)^2 / mean r^2,
    // noise^2 = mean v^2 / mean s with mean r^2 = mean s + mean v^2, so
    // q = raw^2 (1 + noise^2) - noise^2.
    std::vector<double> q, raw_sq_excess;
    const int seeds = 200;
    for (int k = 0; k < seeds; ++k) {
        const auto [a, b] = s.halves(9000 + k);
        const auto e = study::compare_luminance_debiased(s.x.view(), a.view(), b.view());
        const double n2 = e.reference_noise_rel_rms * e.reference_noise_rel_rms;
        CHECK(e.rel_sq_debiased == Approx(e.rel_rms * e.rel_rms * (1.0 + n2) - n2).margin(1e-12));
        // The raw figure agrees with compare_luminance's (float luminance there: 1e-5).
        CHECK(e.rel_rms == Approx(study::compare_luminance(s.x.view(), average(a, b).view()).rel_rms).epsilon(1e-5));
        q.push_back(e.rel_sq_debiased);
        raw_sq_excess.push_back(e.rel_rms * e.rel_rms * (1.0 + n2) - s.true_rel_sq());
    }
    // In expectation over the references: q is the true error, and the raw square error
    // (over mean t^2) exceeds it by the noise Var r / mean t^2 = (sigma^2 / 2) / mean t^2.
    // Both means over 200 draws, to 5 of their standard errors.
    const double se_mean = s.theory_se() / std::sqrt(double(seeds));
    CHECK(std::abs(mean_of(q) - s.true_rel_sq()) <= 5.0 * se_mean);
    const double noise = s.sigma * s.sigma / 2.0 / s.mean_t2();
    CHECK(std::abs(mean_of(raw_sq_excess) - noise) <= 5.0 * sd_of(raw_sq_excess) / std::sqrt(double(seeds)));
    CHECK(mean_of(raw_sq_excess) > 0.5 * noise);
}

TEST_CASE("the debiased error's standard error matches its spread over references", "[study][image][noise]") {
    // 300 pairs of halves over one truth and one estimate: the standard deviation of q over
    // them against the mean reported standard error. A sample standard deviation of 300
    // draws is within 1 / sqrt(2 * 299) = 4% of its value per standard error: 20% is 5 of them.
    const double sigma = GENERATE(0.05, 0.2);
    const synthetic s(64, 64, 0.1, sigma, 21);
    std::vector<double> q, se, rel, rel_se;
    for (int k = 0; k < 300; ++k) {
        const auto [a, b] = s.halves(500 + k);
        const auto e = study::compare_luminance_debiased(s.x.view(), a.view(), b.view());
        q.push_back(e.rel_sq_debiased);
        se.push_back(e.rel_sq_debiased_se);
        rel.push_back(e.rel_rms_debiased);
        rel_se.push_back(e.rel_rms_debiased_se);
        CHECK(e.resolved());  // the error (0.1) stands out of the noise here
    }
    INFO("sigma " << sigma << ": spread " << sd_of(q) << ", reported " << mean_of(se) << ", theory " << s.theory_se());
    CHECK(mean_of(se) == Approx(sd_of(q)).epsilon(0.2));
    CHECK(mean_of(se) == Approx(s.theory_se()).epsilon(0.1));
    // rel_rms_debiased = sqrt(q): where q is many standard errors from 0 its standard error
    // is the delta method's se / (2 sqrt q), and the spread of rel agrees with it.
    CHECK(mean_of(rel_se) == Approx(sd_of(rel)).epsilon(0.2));
}

TEST_CASE("compare_luminance_debiased: unresolved errors, masks, a black reference", "[study][image][noise]") {
    // x = the truth: the debiased error is 0 within its standard error, and flagged unresolved.
    synthetic s(64, 64, 0.0, 0.1, 3);
    const auto [a, b] = s.halves(77);
    const auto e = study::compare_luminance_debiased(s.x.view(), a.view(), b.view());
    CHECK(std::abs(e.rel_sq_debiased) <= 5.0 * e.rel_sq_debiased_se);
    CHECK_FALSE(e.resolved());
    CHECK(e.rel_rms_debiased_se >= std::sqrt(e.rel_sq_debiased_se) - e.rel_rms_debiased);

    // A mask compares its pixels alone: garbage elsewhere changes nothing.
    image<glm::vec3> x2 = s.x, a2 = a, b2 = b;
    image<float> mask(64, 64, 1.f);
    for (std::size_t y = 0; y < 64; ++y)
        for (std::size_t i = 0; i < 64; i += 3) {
            mask(i, y) = 0.f;
            x2(i, y) = glm::vec3(1e3f);
            a2(i, y) = glm::vec3(-7.f);
        }
    image<glm::vec3> xc(64 * 64 - 64 * 22, 1), ac(xc.width(), 1), bc(xc.width(), 1);
    std::size_t k = 0;
    for (std::size_t y = 0; y < 64; ++y)
        for (std::size_t i = 0; i < 64; ++i)
            if (mask(i, y) != 0.f) {
                xc(k, 0) = x2(i, y);
                ac(k, 0) = a2(i, y);
                bc(k, 0) = b2(i, y);
                ++k;
            }
    REQUIRE(k == xc.width());
    const auto m = study::compare_luminance_debiased(x2.view(), a2.view(), b2.view(), image_view<const float>(mask.view()));
    const auto c = study::compare_luminance_debiased(xc.view(), ac.view(), bc.view());
    CHECK(m.pixels == k);
    CHECK(m.rel_sq_debiased == Approx(c.rel_sq_debiased).epsilon(1e-12));
    CHECK(m.rel_sq_debiased_se == Approx(c.rel_sq_debiased_se).epsilon(1e-12));
    CHECK(m.reference_noise_rel_rms == Approx(c.reference_noise_rel_rms).epsilon(1e-12));

    // Black everywhere: 0; a black reference under a lit estimate: infinite.
    const image<glm::vec3> zero(8, 8, glm::vec3(0.f)), one(8, 8, glm::vec3(1.f));
    CHECK(study::compare_luminance_debiased(zero.view(), zero.view(), zero.view()).rel_rms_debiased == 0.0);
    CHECK(std::isinf(study::compare_luminance_debiased(one.view(), zero.view(), zero.view()).rel_rms_debiased));
}

TEST_CASE("compare_luminance_debiased refuses mismatched, empty, non-finite or fully masked input",
          "[study][image][noise]") {
    const image<glm::vec3> a(8, 8, glm::vec3(1.f)), wide(9, 8, glm::vec3(1.f));
    image<glm::vec3> nan_img(8, 8, glm::vec3(1.f)), inf_img(8, 8, glm::vec3(1.f));
    nan_img(3, 4).y = std::numeric_limits<float>::quiet_NaN();
    inf_img(0, 0).x = std::numeric_limits<float>::infinity();
    const image<float> no_pixel(8, 8, 0.f), wrong_mask(8, 7, 1.f);
    image<float> nan_mask(8, 8, 1.f);
    nan_mask(1, 1) = std::numeric_limits<float>::quiet_NaN();
    using study::compare_luminance_debiased;
    CHECK_THROWS_AS(compare_luminance_debiased(wide.view(), a.view(), a.view()), parameter_error);
    CHECK_THROWS_AS(compare_luminance_debiased(a.view(), wide.view(), a.view()), parameter_error);
    CHECK_THROWS_AS(compare_luminance_debiased(a.view(), a.view(), wide.view()), parameter_error);
    CHECK_THROWS_AS(compare_luminance_debiased(a.view(), image_view<const glm::vec3>{}, a.view()), parameter_error);
    CHECK_THROWS_AS(compare_luminance_debiased(nan_img.view(), a.view(), a.view()), parameter_error);
    CHECK_THROWS_AS(compare_luminance_debiased(a.view(), nan_img.view(), a.view()), parameter_error);
    CHECK_THROWS_AS(compare_luminance_debiased(a.view(), a.view(), inf_img.view()), parameter_error);
    CHECK_THROWS_AS(compare_luminance_debiased(a.view(), a.view(), a.view(), image_view<const float>(no_pixel.view())),
                    parameter_error);
    CHECK_THROWS_AS(compare_luminance_debiased(a.view(), a.view(), a.view(), image_view<const float>(wrong_mask.view())),
                    parameter_error);
    CHECK_THROWS_AS(compare_luminance_debiased(a.view(), a.view(), a.view(), image_view<const float>(nan_mask.view())),
                    parameter_error);
    try {
        compare_luminance_debiased(a.view(), a.view(), wide.view());
        FAIL("no exception");
    } catch (const parameter_error& e) {
        CHECK(std::string(e.what()).find("half_b") != std::string::npos);
    }
}

namespace {

// A small open box lit by a point light: floor, a red and a green wall, a back wall; indirect
// light everywhere the camera looks.
io::scene box_scene() {
    io::scene s;
    s.name = "noise box";
    const auto white = hand_built::add_material(s, glm::vec3(0.7f)), red = hand_built::add_material(s, {0.7f, 0.1f, 0.1f}),
               green = hand_built::add_material(s, {0.1f, 0.7f, 0.1f});
    hand_built::add_square_z(s, 0.f, 1.f, true, white);
    hand_built::add_quad(s, {-1, -1, 0}, {-1, 1, 0}, {-1, 1, 2}, {-1, -1, 2}, {1, 0, 0}, red);
    hand_built::add_quad(s, {1, -1, 0}, {1, -1, 2}, {1, 1, 2}, {1, 1, 0}, {-1, 0, 0}, green);
    hand_built::add_quad(s, {-1, 1, 0}, {1, 1, 0}, {1, 1, 2}, {-1, 1, 2}, {0, -1, 0}, white);
    s.lights.push_back(bounce::point_light{{0.3f, 0.2f, 1.6f}, glm::vec3(2.f)});
    s.camera.position = {0.f, -3.2f, 1.f};
    s.camera.look_at = {0.f, 0.f, 0.8f};
    s.camera.up = {0.f, 0.f, 1.f};
    return s;
}

struct temporary_folder {
    fs::path path = fs::temp_directory_path() / ("bounce-test-halves-" + std::to_string(::getpid()));
    temporary_folder() {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~temporary_folder() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

bool same_pixels(const image<glm::vec3>& a, const image<glm::vec3>& b) {
    if (a.width() != b.width() || a.height() != b.height()) return false;
    for (std::size_t y = 0; y < a.height(); ++y)
        for (std::size_t x = 0; x < a.width(); ++x)
            if (a(x, y) != b(x, y)) return false;
    return true;
}

}  // namespace

TEST_CASE("a real reference's halves are independent: their difference measures its noise", "[study][reference][noise]") {
    // The low reference R (64 spp as halves of 32) is itself an estimate: its debiased error
    // against a high reference (4096 spp, halves of 2048) estimates Var R / mean t^2, which
    // R's own halves estimate as mean (a - b)^2 / 4 / mean s. Halves that shared random
    // numbers would give a noise near 0 against an error that is not.
    const io::scene s = box_scene();
    const embree::accel bvh(s);
    const std::size_t w = 40, h = 30;
    auto g = embree::ray_cast_gbuffer(bvh, s, s.camera, w, h);
    const image<float> mask = study::coverage_mask(g.view());
    embree::reference_settings low_settings, high_settings;
    low_settings.hemisphere_samples = 64;
    high_settings.hemisphere_samples = 4096;
    const auto low = study::render_reference_halves(bvh, s, g.view(), low_settings);
    const auto high = study::render_reference_halves(bvh, s, g.view(), high_settings);
    CHECK(low.half_samples == 32);
    CHECK(same_pixels(low.whole.indirect, average(low.indirect_a, low.indirect_b)));

    const image_view<const float> m(mask.view());
    const auto own = study::compare_luminance_debiased(low.whole.indirect.view(), low.indirect_a.view(),
                                                       low.indirect_b.view(), m);
    const auto vs_high = study::compare_luminance_debiased(low.whole.indirect.view(), high.indirect_a.view(),
                                                           high.indirect_b.view(), m);
    // The standard error of R's noise estimate from its per-pixel terms (a - b)^2 / 4.
    std::vector<double> terms;
    double ref_sq = 0;
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            if (mask(x, y) == 0.f) continue;
            auto lum = [](glm::vec3 c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; };
            const double la = lum(low.indirect_a(x, y)), lb = lum(low.indirect_b(x, y)), r = 0.5 * (la + lb);
            terms.push_back(0.25 * (la - lb) * (la - lb));
            ref_sq += r * r;
        }
    const double n = double(terms.size());
    const double noise = own.reference_noise_rel_rms * own.reference_noise_rel_rms;
    const double s_mean = ref_sq / n - mean_of(terms);
    const double noise_se = sd_of(terms) / std::sqrt(n) / s_mean;
    INFO("noise " << noise << " +- " << noise_se << ", against the high reference " << vs_high.rel_sq_debiased << " +- "
                  << vs_high.rel_sq_debiased_se);
    REQUIRE(noise > 5.0 * noise_se);  // the test can tell independence from its absence
    CHECK(std::abs(vs_high.rel_sq_debiased - noise) <= 4.0 * std::hypot(noise_se, vs_high.rel_sq_debiased_se));

    // Halves that are one image twice claim no noise at all, and fail the same comparison.
    const auto same = study::compare_luminance_debiased(low.whole.indirect.view(), low.indirect_a.view(),
                                                        low.indirect_a.view(), m);
    CHECK(same.reference_noise_rel_rms == 0.0);
    CHECK(vs_high.rel_sq_debiased > 5.0 * vs_high.rel_sq_debiased_se);

    // The halves' seeds are neither the base seed nor each other, nor Monte Carlo's 99.
    CHECK(study::half_seed(1, 0) != study::half_seed(1, 1));
    CHECK(study::half_seed(1, 0) != 1);
    CHECK(study::half_seed(1, 1) != 99);
    CHECK_THROWS_AS(study::half_seed(1, 2), parameter_error);
    low_settings.hemisphere_samples = 1;
    CHECK_THROWS_AS(study::render_reference_halves(bvh, s, g.view(), low_settings), parameter_error);
}

TEST_CASE("references in halves are cached apart from whole references and come back bitwise",
          "[study][reference][cache][noise]") {
    const temporary_folder dir;
    const io::scene s = box_scene();
    const embree::accel bvh(s);
    embree::reference_settings settings;
    settings.hemisphere_samples = 16;
    const std::string key = study::reference_halves_cache_key(s, s.camera, 24, 18, settings, bvh.owner().config());
    CHECK(key.find("noise_box-24x18-16spp-halves-") == 0);
    CHECK(key != study::reference_cache_key(s, s.camera, 24, 18, settings, bvh.owner().config()));
    embree::reference_settings other_seed = settings;
    other_seed.seed = 2;
    CHECK(key != study::reference_halves_cache_key(s, s.camera, 24, 18, other_seed, bvh.owner().config()));

    // A whole reference in the same folder is not taken for halves, nor the reverse.
    bool from_cache = true;
    (void)study::cached_reference(bvh, s, s.camera, 24, 18, settings, dir.path, &from_cache);
    CHECK_FALSE(from_cache);
    const auto first = study::cached_reference_halves(bvh, s, s.camera, 24, 18, settings, dir.path, &from_cache);
    CHECK_FALSE(from_cache);
    for (const char* suffix : {".direct.exr", ".indirect-a.exr", ".indirect-b.exr", ".json"})
        CHECK(fs::exists(dir.path / (key + suffix)));
    const auto second = study::cached_reference_halves(bvh, s, s.camera, 24, 18, settings, dir.path, &from_cache);
    CHECK(from_cache);
    CHECK(same_pixels(first.indirect_a, second.indirect_a));
    CHECK(same_pixels(first.indirect_b, second.indirect_b));
    CHECK(same_pixels(first.whole.direct, second.whole.direct));
    CHECK(same_pixels(first.whole.indirect, second.whole.indirect));
    CHECK(same_pixels(first.whole.combined, second.whole.combined));
    CHECK(second.half_samples == 8);
    CHECK(second.whole.grid.count() == first.whole.grid.count());
    // The halves are what render_reference_halves makes over the ray-cast G-buffer.
    auto g = embree::ray_cast_gbuffer(bvh, s, s.camera, 24, 18);
    const auto direct = study::render_reference_halves(bvh, s, g.view(), settings);
    CHECK(same_pixels(direct.indirect_a, first.indirect_a));
    CHECK(same_pixels(direct.indirect_b, first.indirect_b));

    // A damaged half is recomputed, not trusted; another size is a miss.
    CHECK_FALSE(study::load_cached_reference_halves(dir.path, key, 12, 18, settings).has_value());
    fs::resize_file(dir.path / (key + ".indirect-b.exr"), 64);
    CHECK_FALSE(study::load_cached_reference_halves(dir.path, key, 24, 18, settings).has_value());
    const auto third = study::cached_reference_halves(bvh, s, s.camera, 24, 18, settings, dir.path, &from_cache);
    CHECK_FALSE(from_cache);
    CHECK(same_pixels(third.indirect_b, first.indirect_b));
}

TEST_CASE("Monte Carlo at equal debiased error: its runs' errors and the interpolation", "[study][equal_error][noise]") {
    const io::scene s = box_scene();
    const embree::accel bvh(s);
    auto g = embree::ray_cast_gbuffer(bvh, s, s.camera, 32, 24);
    const image<float> mask = study::coverage_mask(g.view());
    const image_view<const float> m(mask.view());
    embree::reference_settings settings;
    settings.hemisphere_samples = 128;
    const auto ref = study::render_reference_halves(bvh, s, g.view(), settings);

    // A target no run reaches: the sweep goes to max_spp, each run's errors those of Monte
    // Carlo's image (seed 99) against the halves.
    const auto all = study::monte_carlo_at_equal_error(bvh, s, g.view(), ref.indirect_a.view(), ref.indirect_b.view(), m,
                                                       1e-9, study::error_measure::debiased, 8);
    REQUIRE(all.sweep.size() == 4);
    CHECK_FALSE(all.reached);
    embree::reference_settings mc;
    mc.hemisphere_samples = 4;
    mc.seed = 99;
    const auto four = embree::reference_integrator(bvh, s, mc).indirect_image(g.view());
    const auto e4 = study::compare_luminance_debiased(four.view(), ref.indirect_a.view(), ref.indirect_b.view(), m);
    CHECK(all.sweep[2].spp == 4);
    CHECK(all.sweep[2].rel_rms == e4.rel_rms);
    CHECK(all.sweep[2].rel_rms_debiased == e4.rel_rms_debiased);
    CHECK(all.sweep[2].rel_rms_debiased_se == e4.rel_rms_debiased_se);
    // With the reference's noise taken out of both sums, an error below 1 goes down and one
    // above 1 (as at 1 spp here) up: q - raw^2 = noise^2 (raw^2 - 1).
    for (const auto& step : all.sweep)
        if (step.rel_rms < 1.0) CHECK(step.rel_rms_debiased < step.rel_rms);

    // A target between the 2- and 4-spp runs' debiased errors: reached between them.
    const double target = std::sqrt(all.sweep[1].rel_rms_debiased * all.sweep[2].rel_rms_debiased);
    REQUIRE(all.sweep[1].rel_rms_debiased > all.sweep[2].rel_rms_debiased);
    const auto hit = study::monte_carlo_at_equal_error(bvh, s, g.view(), ref.indirect_a.view(), ref.indirect_b.view(), m,
                                                       target, study::error_measure::debiased, 8);
    CHECK(hit.reached);
    CHECK(hit.sweep.size() == 3);
    CHECK(hit.spp == Approx(std::sqrt(2.0 * 4.0)).epsilon(1e-9));  // the log-log midpoint
    const auto j = hit.equal_error_json(10.0);
    CHECK(j.at("measure") == "debiased");
    CHECK(j.at("rel_rms") == target);
    CHECK(hit.sweep_json()[0].contains("rel_rms_debiased"));

    // The raw measure on the same runs, and the old overload's JSON without the new keys.
    const auto raw = study::monte_carlo_at_equal_error(bvh, s, g.view(), ref.whole.indirect.view(), m,
                                                       all.sweep[3].rel_rms * 1.0001, 8);
    CHECK(raw.reached);
    CHECK_FALSE(raw.equal_error_json(10.0).contains("measure"));
    CHECK_FALSE(raw.sweep_json()[0].contains("rel_rms_debiased"));
    const auto wrong = image<glm::vec3>(31, 24);
    CHECK_THROWS_AS(study::monte_carlo_at_equal_error(bvh, s, g.view(), wrong.view(), ref.indirect_b.view(), m, 0.1,
                                                      study::error_measure::debiased, 8),
                    parameter_error);
    CHECK_THROWS_AS(study::monte_carlo_at_equal_error(bvh, s, g.view(), ref.indirect_a.view(), ref.indirect_b.view(), m,
                                                      0.0, study::error_measure::debiased, 8),
                    parameter_error);
}
