// The CPU passes and cpu::indirect_renderer: energy-correct interleaving (the expectation
// over relabellings of the sub-buffers is the non-interleaved value, the thesis's Section
// 5.2 loss avoided), thread-count independence, the splat cutoff's bound, the blur and
// upsampling at discontinuities, the core's split-buffer rectangles (indirect/rsm_sampling.hpp),
// and bad input.
#include "corner_scene.hpp"

#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/indirect/rsm_sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

#include <tbb/task_arena.h>

using namespace bounce;
using rsm_test::corner_scene;

namespace {
constexpr double u32 = 0x1p-24;
double higham_gamma(double n) { return n * u32 / (1 - n * u32); }

image<glm::vec3> render(const corner_scene& s, indirect_options o, indirect_timings* t = nullptr) {
    cpu::indirect_renderer r(o);
    image<glm::vec3> out(s.gb.width(), s.gb.height());
    const rsm_view maps[] = {s.map()};
    auto gbv = const_cast<gbuffer<float>&>(s.gb).view();
    const auto timings = r.render(gbv, s.cam, maps, out.view());
    if (t) *t = timings;
    return out;
}

// Luminance-free relative RMS over covered pixels, channel x.
double rel_rms(const corner_scene& s, const image<glm::vec3>& a, const image<glm::vec3>& ref) {
    double num = 0, den = 0;
    for (std::size_t y = 0; y < s.gb.height(); ++y)
        for (std::size_t x = 0; x < s.gb.width(); ++x) {
            if (!(s.gb.depth(x, y) < std::numeric_limits<float>::infinity())) continue;
            num += std::pow(double(a(x, y).x) - double(ref(x, y).x), 2);
            den += std::pow(double(ref(x, y).x), 2);
        }
    return std::sqrt(num / den);
}

// Sum of channel x over covered pixels.
double energy(const corner_scene& s, const image<glm::vec3>& a) {
    double sum = 0;
    for (std::size_t y = 0; y < s.gb.height(); ++y)
        for (std::size_t x = 0; x < s.gb.width(); ++x)
            if (s.gb.depth(x, y) < std::numeric_limits<float>::infinity()) sum += a(x, y).x;
    return sum;
}

// The full RSM sum (every texel a pixel light), in double: what RSM and SII estimate.
image<glm::vec3> full_rsm_sum(const corner_scene& s, double min_distance2 = 0) {
    image<glm::vec3> out(s.gb.width(), s.gb.height());
    for (std::size_t y = 0; y < s.gb.height(); ++y)
        for (std::size_t x = 0; x < s.gb.width(); ++x) {
            if (!(s.gb.depth(x, y) < std::numeric_limits<float>::infinity())) continue;
            glm::dvec3 e(0.0);
            for (std::size_t j = 0; j < s.map_flux.height(); ++j)
                for (std::size_t i = 0; i < s.map_flux.width(); ++i)
                    e += pixel_light_irradiance<double, glm::dvec3>(
                        glm::dvec3(s.gb.position(x, y)), glm::dvec3(s.gb.normal(x, y)),
                        glm::dvec3(s.map_position(i, j)), glm::dvec3(s.map_normal(i, j)), glm::dvec3(s.map_flux(i, j)),
                        0.0, min_distance2);
            out(x, y) = glm::vec3(e);
        }
    return out;
}
}  // namespace

TEST_CASE("averaged over every relabelling of the sub-buffers, interleaved SII and RSM equal the plain ones",
          "[indirect][energy]") {
    // The interleaved pixel sums its subset's terms times N M; averaged over the N M
    // relabellings every term appears once, so the mean equals the plain sum. Both are float
    // sums of at most K positive terms (each within gamma_K of its exact sum, Higham), the
    // scale N M rounds each term once (u) and the mean of N M values adds gamma_(N M):
    // |mean - plain| <= (2 gamma_K + gamma_(N M) + 2 u) plain.
    const corner_scene s(50, 37);
    for (const auto tech : {indirect_technique::sii, indirect_technique::rsm_gather})
        for (const interleave_pattern p : {interleave_pattern{3, 2}, interleave_pattern{4, 4}})
            for (const auto how :
                 {light_assignment::interleaved, light_assignment::blocked, light_assignment::similarity}) {
                if (tech == indirect_technique::rsm_gather && how != light_assignment::interleaved) continue;
                indirect_options o;
                o.technique = tech;
                o.count = 301;  // not a multiple of N M
                o.pattern = {1, 1};
                const auto plain = render(s, o);
                o.pattern = p;
                o.assignment = how;
                o.blur = false;
                image<glm::dvec3> mean(s.gb.width(), s.gb.height(), glm::dvec3(0.0));
                for (int shift = 0; shift < p.cells(); ++shift) {
                    o.shift = shift;
                    const auto one = render(s, o);
                    for (std::size_t y = 0; y < s.gb.height(); ++y)
                        for (std::size_t x = 0; x < s.gb.width(); ++x)
                            mean(x, y) += glm::dvec3(one(x, y)) / double(p.cells());
                }
                const double tol = 2 * higham_gamma(double(o.count)) + higham_gamma(p.cells()) + 2 * u32;
                double worst = 0;
                for (std::size_t y = 0; y < s.gb.height(); ++y)
                    for (std::size_t x = 0; x < s.gb.width(); ++x)
                        for (int c = 0; c < 3; ++c) {
                            const double ref = plain(x, y)[c];
                            worst = std::max(worst, std::abs(mean(x, y)[c] - ref) / std::max(ref, 1e-30));
                        }
                INFO("technique " << int(tech) << " pattern " << p.n << "x" << p.m << " assignment " << int(how));
                CHECK(worst <= tol);
            }
}

TEST_CASE("blurred interleaved SII and RSM keep the energy and stay close to the full RSM sum", "[indirect][energy]") {
    // The thesis splatted each VPL into one sub-buffer at weight 1: its images held 1/(N M)
    // of the energy (1 - 1/(N M) >= 0.75 relative error from 2 x 2 on). With the N M weight
    // the blurred image keeps the plain image's energy up to noise, and its error against
    // the exact sum grows only with the blur's smoothing of steep gradients (the floor next
    // to the emitting wall). Measured on this scene (1024 VPLs/samples, d^2 clamped at a
    // texel's footprint squared): SII 0.040 plain, 0.044 / 0.063 / 0.118 for 2x2 / 4x4 / 8x8;
    // RSM gather 0.023 plain, 0.037 / 0.057 / 0.105. The bound 0.15 has margin for that.
    const corner_scene s(96, 72);
    const float texel = 2.f / 32.f;
    const auto exact = full_rsm_sum(s, texel * texel);
    for (const auto tech : {indirect_technique::sii, indirect_technique::rsm_gather}) {
        indirect_options o;
        o.technique = tech;
        o.count = 1024;
        o.light.min_distance2 = texel * texel;
        o.pattern = {1, 1};
        const auto plain = render(s, o);
        for (const interleave_pattern p :
             {interleave_pattern{2, 2}, interleave_pattern{4, 4}, interleave_pattern{8, 8}}) {
            o.pattern = p;
            const auto inter = render(s, o);
            const double e = rel_rms(s, inter, exact);
            const double ratio = energy(s, inter) / energy(s, plain);
            INFO("technique " << int(tech) << " pattern " << p.n << "x" << p.m << " rel_rms " << e << " energy ratio "
                              << ratio);
            CHECK(e < 0.15);
            CHECK(std::abs(ratio - 1) < 0.05);
            // The thesis's weight 1 keeps 1/(N M) of the energy (up to the same noise).
            o.energy_correct = false;
            const double lost = energy(s, render(s, o)) / energy(s, plain);
            o.energy_correct = true;
            INFO("weight 1: energy ratio " << lost);
            CHECK(std::abs(lost * p.cells() - 1) < 0.05);
        }
    }
}

TEST_CASE("SII and the RSM gather converge to the full RSM sum", "[indirect]") {
    const corner_scene s(64, 48);
    const auto exact = full_rsm_sum(s);
    indirect_options o;
    o.pattern = {1, 1};
    o.count = 4096;
    for (const auto tech : {indirect_technique::sii, indirect_technique::rsm_gather}) {
        o.technique = tech;
        const double e = rel_rms(s, render(s, o), exact);
        INFO("technique " << int(tech) << " rel_rms " << e);
        CHECK(e < 0.05);
    }
    // DS05's xi1^2 weights over-weight the disc's rim (docs, section 4): with a disc that
    // reaches the whole map the gather stays far from the sum however many samples
    // (measured 0.65 at 1024 and at 4096 on this scene).
    o.technique = indirect_technique::rsm_gather;
    o.disc = disc_weighting::xi1_squared;
    CHECK(rel_rms(s, render(s, o), exact) > 0.3);
    o.disc = disc_weighting::unbiased;
    // Every texel as a VPL (a grid the map's size) is the full sum itself, up to float
    // summation of 1024 terms.
    o.technique = indirect_technique::sii;
    o.selection = vpl_selection::grid;
    o.count = s.map_flux.width() * s.map_flux.height();
    CHECK(rel_rms(s, render(s, o), exact) < 2 * higham_gamma(double(o.count)) + 1e-5);
}

TEST_CASE("the plain splat and gather passes give what the renderer gives without interleaving, bit for bit",
          "[indirect]") {
    const corner_scene s(40, 30);
    auto gbv = const_cast<gbuffer<float>&>(s.gb).view();
    const rsm_view maps[] = {s.map()};
    indirect_options o;
    o.pattern = {1, 1};
    o.count = 300;
    const auto via_renderer = render(s, o);
    image<glm::vec3> direct(40, 30);
    cpu::splat_vpls(gbv, s.cam, vpls_by_flux_warping(s.map(), o.count, o.seed), {}, direct.view());
    for (std::size_t y = 0; y < 30; ++y)
        for (std::size_t x = 0; x < 40; ++x) REQUIRE(direct(x, y) == via_renderer(x, y));
    o.technique = indirect_technique::rsm_gather;
    const auto gathered = render(s, o);
    const auto pattern = rsm_disc_pattern(o.count, o.r_max, s.map_flux.width() * s.map_flux.height(), o.seed);
    cpu::rsm_gather(gbv, maps, pattern, {}, direct.view());
    for (std::size_t y = 0; y < 30; ++y)
        for (std::size_t x = 0; x < 40; ++x) REQUIRE(direct(x, y) == gathered(x, y));
}

TEST_CASE("the gather reaches every texel whatever the map's projection, receivers behind it included", "[indirect]") {
    // A perspective projection looking away from every receiver (all clip w < 0), as a
    // point light's cube face behind a receiver: the disc centres on the map's centre and
    // still covers the whole map, so the gather converges to the full sum as before.
    corner_scene s(64, 48);
    s.light_view_projection = glm::perspective(1.5f, 1.f, 0.1f, 10.f) *
                              glm::lookAt(glm::vec3(-5, 0, 1), glm::vec3(-10, 0, 1), glm::vec3(0, 0, 1));
    const glm::vec4 clip = s.light_view_projection * glm::vec4(s.gb.position(32, 24), 1.f);
    REQUIRE(clip.w < 0.f);
    indirect_options o;
    o.technique = indirect_technique::rsm_gather;
    o.pattern = {1, 1};
    // Unbiased but noisier than centring on the receiver's texel (the near texels fall where
    // the disc's samples are sparse): measured 0.25, 0.12, 0.022 at 1024, 4096, 16384
    // samples, against 0.008 at 4096 with the projection of section 4.
    const auto exact = full_rsm_sum(s);
    double previous = 1e30;
    for (std::size_t k : {std::size_t(1024), std::size_t(4096), std::size_t(16384)}) {
        o.count = k;
        const double e = rel_rms(s, render(s, o), exact);
        INFO("count " << k << " rel_rms " << e);
        CHECK(e < previous);
        previous = e;
    }
    CHECK(previous < 0.05);
}

TEST_CASE("images smaller than the pattern (empty sub-buffers) render, and keep the energy property", "[indirect]") {
    for (const auto& [w, h] : {std::pair{1, 1}, std::pair{3, 2}, std::pair{9, 5}}) {
        const corner_scene s{std::size_t(w), std::size_t(h)};
        for (const auto tech : {indirect_technique::sii, indirect_technique::rsm_gather}) {
            indirect_options o;
            o.technique = tech;
            o.count = 128;
            o.pattern = {1, 1};
            const auto plain = render(s, o);
            o.pattern = {8, 8};
            o.blur = false;
            image<glm::dvec3> mean(std::size_t(w), std::size_t(h), glm::dvec3(0.0));
            for (int shift = 0; shift < 64; ++shift) {
                o.shift = shift;
                const auto one = render(s, o);
                for (std::size_t y = 0; y < std::size_t(h); ++y)
                    for (std::size_t x = 0; x < std::size_t(w); ++x) mean(x, y) += glm::dvec3(one(x, y)) / 64.0;
            }
            // As in the energy test: (2 gamma_K + gamma_64 + 2 u) of the plain value.
            const double tol = 2 * higham_gamma(128) + higham_gamma(64) + 2 * u32;
            for (std::size_t y = 0; y < std::size_t(h); ++y)
                for (std::size_t x = 0; x < std::size_t(w); ++x)
                    REQUIRE(std::abs(mean(x, y).x - plain(x, y).x) <= tol * plain(x, y).x + 1e-30);
        }
    }
}

TEST_CASE("results are bitwise the same for one thread and for two", "[indirect]") {
    const corner_scene s(61, 45);
    for (const auto tech : {indirect_technique::sii, indirect_technique::rsm_gather}) {
        indirect_options o;
        o.technique = tech;
        o.count = 512;
        o.pattern = {4, 2};
        image<glm::vec3> one, two;
        tbb::task_arena(1).execute([&] { one = render(s, o); });
        tbb::task_arena(2).execute([&] { two = render(s, o); });
        for (std::size_t y = 0; y < s.gb.height(); ++y)
            for (std::size_t x = 0; x < s.gb.width(); ++x) REQUIRE(one(x, y) == two(x, y));
    }
}

TEST_CASE("the SII splat bounds cut off at most the cutoff at any pixel", "[indirect]") {
    const corner_scene s(64, 48);
    indirect_options o;
    o.pattern = {1, 1};
    o.count = 2048;
    const auto full = render(s, o);
    double mean = 0;
    for (std::size_t y = 0; y < 48; ++y)
        for (std::size_t x = 0; x < 64; ++x) mean += full(x, y).x / (64.0 * 48.0);
    for (float fraction : {1e-3f, 1e-2f, 1e-1f}) {
        o.sii_cutoff = fraction * float(mean);
        const auto cut = render(s, o);
        for (std::size_t y = 0; y < 48; ++y)
            for (std::size_t x = 0; x < 64; ++x)
                for (int c = 0; c < 3; ++c) {
                    const double lost = double(full(x, y)[c]) - double(cut(x, y)[c]);
                    // The cut sum drops terms of the same float sum: rounding gamma_K of the full value.
                    REQUIRE(lost <= double(o.sii_cutoff) + 2 * higham_gamma(2048) * double(full(x, y)[c]));
                    REQUIRE(lost >= -2 * higham_gamma(2048) * double(full(x, y)[c]));
                }
    }
}

TEST_CASE("split rectangles hold the sub-buffer's pixels", "[indirect]") {
    pcg32 rng(3);
    // A split rectangle holds exactly the pixels of the image rectangle in its sub-buffer.
    const interleave_pattern p{3, 2};
    const std::size_t w = 13, h = 9;
    const cpu::interleave_maps maps(p, w, h);
    for (int k = 0; k < 60; ++k) {
        bounce::pixel_rect r;
        r.x0 = int(rng.next_u32() % w);
        r.x1 = int(rng.next_u32() % w);
        r.y0 = int(rng.next_u32() % h);
        r.y1 = int(rng.next_u32() % h);
        for (int j = 0; j < p.m; ++j)
            for (int i = 0; i < p.n; ++i) {
                const bounce::pixel_rect q = split_buffer_rect(r, p, i, j, maps.sub_buffer(i, j));
                for (std::size_t y = 0; y < h; ++y)
                    for (std::size_t x = 0; x < w; ++x) {
                        const bool in_image = int(x) >= r.x0 && int(x) <= r.x1 && int(y) >= r.y0 && int(y) <= r.y1 &&
                                              int(x) % p.n == i && int(y) % p.m == j;
                        const int u = int(maps.split_x[x]), v = int(maps.split_y[y]);
                        const bool in_split = !q.empty() && u >= q.x0 && u <= q.x1 && v >= q.y0 && v <= q.y1;
                        CHECK(in_image == in_split);
                    }
            }
    }
}

TEST_CASE("the geometry-aware blur keeps each surface's value: nothing bleeds across the floor-wall edge",
          "[indirect]") {
    const corner_scene s(53, 40);
    const interleave_pattern p{8, 8};
    image<glm::vec3> in(53, 40), scratch(53, 40), out(53, 40);
    image<glm::vec2> edges(53, 40);
    for (std::size_t y = 0; y < 40; ++y)
        for (std::size_t x = 0; x < 53; ++x) in(x, y) = glm::vec3(s.gb.normal(x, y).z > 0.5f ? 1.f : 7.f);
    auto gbv = const_cast<gbuffer<float>&>(s.gb).view();
    cpu::discontinuity_buffer(gbv, {}, edges.view());
    cpu::geometry_aware_blur(in.view(), edges.view(), s.gb.depth.view(), p, scratch.view(), out.view());
    int floor = 0, wall = 0;
    for (std::size_t y = 0; y < 40; ++y)
        for (std::size_t x = 0; x < 53; ++x) {
            if (!(s.gb.depth(x, y) < std::numeric_limits<float>::infinity())) continue;
            (in(x, y).x == 1.f ? floor : wall)++;
            REQUIRE(out(x, y).x == Approx(in(x, y).x).epsilon(1e-6));
        }
    CHECK(floor > 100);
    CHECK(wall > 100);
}

TEST_CASE("the low-resolution gather interpolates on smooth surfaces and gathers at full resolution at edges",
          "[indirect]") {
    indirect_options o;
    o.technique = indirect_technique::rsm_gather;
    o.count = 256;
    o.pattern = {1, 1};
    const corner_scene floor_only(64, 48, 32, false);
    o.light.min_distance2 = 0.0625f * 0.0625f;
    o.low_resolution = 2;
    indirect_timings t;
    const auto low = render(floor_only, o, &t);
    // On one plane every sample is suitable, except beside the floor's silhouette, where a
    // low-resolution sample may see nothing: only pixels within f = 2 pixels of an uncovered
    // one may fall back.
    std::size_t band = 0;
    const auto covered = [&](int x, int y) {
        return x < 0 || y < 0 || x >= 64 || y >= 48 ||
               floor_only.gb.depth(std::size_t(x), std::size_t(y)) < std::numeric_limits<float>::infinity();
    };
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x) {
            if (!covered(x, y)) continue;
            bool near_hole = false;
            for (int dy = -2; dy <= 2; ++dy)
                for (int dx = -2; dx <= 2; ++dx) near_hole = near_hole || !covered(x + dx, y + dy);
            band += near_hole ? 1 : 0;
        }
    CHECK(t.fallback_pixels <= band);
    o.low_resolution = 1;
    const auto full = render(floor_only, o);
    const double e = rel_rms(floor_only, low, full);
    // Bilinear interpolation of a smooth field over 2-pixel cells; measured 0.02 (the field
    // is steep where the floor meets the emitting wall).
    INFO("floor only: rel_rms of the upsampled gather " << e);
    CHECK(e < 0.04);

    const corner_scene corner(64, 48);
    o.low_resolution = 2;
    render(corner, o, &t);
    CHECK(t.fallback_pixels > 0);
    CHECK(t.fallback_pixels < 64 * 48 / 4);
}

TEST_CASE("bad options and sizes raise parameter_error naming the parameter", "[indirect]") {
    const auto name_of = [](auto&& f) {
        try {
            f();
        } catch (const parameter_error& e) {
            return e.parameter();
        }
        return std::string("(nothing thrown)");
    };
    indirect_options o;
    o.count = 0;
    CHECK(name_of([&] { cpu::indirect_renderer r(o); }) == "count");
    o = {};
    o.shift = 16;
    CHECK(name_of([&] { cpu::indirect_renderer r(o); }) == "shift");
    o = {};
    o.low_resolution = 2;  // SII
    CHECK(name_of([&] { cpu::indirect_renderer r(o); }) == "low_resolution");
    o = {};
    o.light.offset = -1.f;
    CHECK(name_of([&] { cpu::indirect_renderer r(o); }) == "offset");
    o = {};
    o.r_max = 0.f;
    CHECK(name_of([&] { cpu::indirect_renderer r(o); }) == "r_max");
    const corner_scene s(16, 12);
    cpu::indirect_renderer r;
    image<glm::vec3> wrong(15, 12);
    const rsm_view maps[] = {s.map()};
    auto gbv = const_cast<gbuffer<float>&>(s.gb).view();
    CHECK(name_of([&] { r.render(gbv, s.cam, maps, wrong.view()); }) == "out");
}

TEST_CASE("asked for radiance, the renderer gives rho over pi times its irradiance with the G-buffer's albedo",
          "[indirect][outputs]") {
    const corner_scene s(16, 12);
    const image<glm::vec3> e = render(s, {});  // the default: irradiance
    cpu::indirect_renderer r;
    image<glm::vec3> l(s.gb.width(), s.gb.height());
    const rsm_view maps[] = {s.map()};
    auto gbv = const_cast<gbuffer<float>&>(s.gb).view();
    r.render(gbv, s.cam, maps, l.view(), output_quantity::radiance);
    std::size_t lit = 0;
    for (std::size_t y = 0; y < s.gb.height(); ++y)
        for (std::size_t x = 0; x < s.gb.width(); ++x) {
            CHECK(l(x, y) == lambertian_radiance<float, glm::vec3>(s.gb.albedo(x, y), e(x, y)));
            lit += e(x, y).x > 0.f ? 1 : 0;
        }
    CHECK(lit > 0);
}

TEST_CASE("more sub-buffers than lights is refused by the options, naming both numbers", "[indirect]") {
    // 16 VPLs over 64 x 64 sub-buffers left 4080 sub-buffers dark: a black image, no error.
    const auto message_of = [](const indirect_options& o) {
        try {
            o.validate();
        } catch (const parameter_error& e) {
            return e.parameter() + ": " + e.what();
        }
        return std::string("(nothing thrown)");
    };
    indirect_options o;
    o.count = 16;
    o.pattern = {64, 64};
    const std::string sii = message_of(o);
    CHECK_THAT(sii, Catch::StartsWith("count: "));
    CHECK_THAT(sii, Catch::Contains("16 VPLs") && Catch::Contains("4096 sub-buffers") && Catch::Contains("64x64"));
    o.technique = indirect_technique::rsm_gather;
    o.count = 15;
    o.pattern = {4, 4};
    CHECK_THAT(message_of(o), Catch::Contains("15 disc samples") && Catch::Contains("16 sub-buffers"));
    // Every renderer gets it: the CPU renderer's constructor and set_options.
    CHECK_THROWS_AS(cpu::indirect_renderer(o), parameter_error);
    cpu::indirect_renderer r;
    CHECK_THROWS_AS(r.set_options(o), parameter_error);
    CHECK(r.options() == indirect_options{});  // the old options stay
    o.count = 16;  // one per sub-buffer is enough
    CHECK(message_of(o) == "(nothing thrown)");
    CHECK_NOTHROW(r.set_options(o));
}

TEST_CASE("options compare field by field, and a renderer given new options renders as a new one", "[indirect]") {
    const indirect_options a;
    CHECK(a == indirect_options{});
    // Each field, nested ones included, makes two option sets differ.
    const std::vector<void (*)(indirect_options&)> changes = {
        [](indirect_options& o) { o.technique = indirect_technique::rsm_gather; },
        [](indirect_options& o) { o.count = 401; },
        [](indirect_options& o) { o.pattern.n = 2; },
        [](indirect_options& o) { o.pattern.m = 2; },
        [](indirect_options& o) { o.assignment = light_assignment::blocked; },
        [](indirect_options& o) { o.shift = 1; },
        [](indirect_options& o) { o.blur = false; },
        [](indirect_options& o) { o.energy_correct = false; },
        [](indirect_options& o) { o.discontinuity.relative_depth = 0.1f; },
        [](indirect_options& o) { o.discontinuity.cos_normal = 0.8f; },
        [](indirect_options& o) { o.selection = vpl_selection::grid; },
        [](indirect_options& o) { o.r_max = 1.f; },
        [](indirect_options& o) { o.disc = disc_weighting::xi1_squared; },
        [](indirect_options& o) { o.light.offset = 0.1f; },
        [](indirect_options& o) { o.light.min_distance2 = 0.1f; },
        [](indirect_options& o) { o.sii_cutoff = 1.f; },
        [](indirect_options& o) { o.low_resolution = 2; },
        [](indirect_options& o) { o.upsample.cos_normal = 0.8f; },
        [](indirect_options& o) { o.upsample.plane_footprints = 3.f; },
        [](indirect_options& o) { o.seed = 2; },
    };
    for (std::size_t i = 0; i < changes.size(); ++i) {
        indirect_options b;
        changes[i](b);
        INFO("change " << i);
        CHECK_FALSE(a == b);
    }
    // One renderer switched between option sets gives what a fresh renderer gives for each
    // (the disc pattern is redrawn when r_max or the seed change, not only the count).
    const corner_scene s(24, 18);
    const rsm_view maps[] = {s.map()};
    auto gbv = const_cast<gbuffer<float>&>(s.gb).view();
    cpu::indirect_renderer shared;
    image<glm::vec3> out(s.gb.width(), s.gb.height());
    for (const auto technique : {indirect_technique::rsm_gather, indirect_technique::sii})
        for (const std::uint64_t seed : {1u, 7u})
            for (const float r_max : {1.5f, 0.5f}) {
                indirect_options o;
                o.technique = technique;
                o.count = 64;
                o.seed = seed;
                o.r_max = r_max;
                shared.render(o, gbv, s.cam, maps, out.view());
                const image<glm::vec3> fresh = render(s, o);
                bool same = true;
                for (std::size_t y = 0; y < out.height(); ++y)
                    for (std::size_t x = 0; x < out.width(); ++x) same = same && out(x, y) == fresh(x, y);
                CHECK(same);
            }
}
