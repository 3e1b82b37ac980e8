// Senders chosen by the view (indirect/view_selection.hpp, cpu/view_selection.hpp): the draw
// is unbiased for every sub-buffer (its mean over seeds against the candidates' own sum, and
// a frame's mean over seeds against the frame of every texel, with visibility, within a
// tolerance from the seeds' spread), and the weights stay finite where the camera sees no
// candidate or no receiver sees anything; a candidate hidden from the whole view is drawn with
// the defensive share alone.
#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/cpu/view_selection.hpp>
#include <bounce/errors.hpp>

#include "lit_ceiling.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

using namespace bounce;

namespace {

// Blocks the segments whose receiver x plus sender z exceeds `edge` (all of them for a
// large negative edge): a fixed, thread-safe stand-in for an occluder.
class half_plane_occlusion final : public occlusion_query {
public:
    explicit half_plane_occlusion(float edge) : edge_(edge) {}
    void occluded(std::span<const visibility_segment> segments, std::span<std::uint8_t> blocked) const override {
        for (std::size_t i = 0; i < segments.size(); ++i)
            blocked[i] = segments[i].receiver.x + segments[i].sender.z > edge_ ? 1 : 0;
    }

private:
    float edge_;
};

// A lit ceiling (y = 1, facing down) of 16 x 16 texels over [-1, 1]^2, flux growing with x,
// above a floor seen from above by an 8 x 8 G-buffer (albedo 0.5, the corner pixel uncovered).
struct small_scene : test::lit_ceiling {
    gbuffer<float> gb{8, 8};
    camera cam;

    small_scene() {
        for (std::size_t y = 0; y < 8; ++y)
            for (std::size_t x = 0; x < 8; ++x) {
                gb.view().position(x, y) = {(float(x) + 0.5f) / 4.f - 1.f, 0.f, (float(y) + 0.5f) / 4.f - 1.f};
                gb.view().normal(x, y) = {0.f, 1.f, 0.f};
                gb.view().albedo(x, y) = glm::vec3(0.5f);
                gb.view().depth(x, y) = x + y == 0 ? std::numeric_limits<float>::infinity() : 1.f;
            }
        cam.position = {0.f, 3.f, 0.f};
        cam.look_at = {0.f, 0.f, 0.f};
        cam.up = {0.f, 0.f, 1.f};
    }
    rsm_view map() const { return {position.view(), normal.view(), flux.view(), glm::mat4(1.f)}; }
};

indirect_options options(int pattern, std::size_t count) {
    indirect_options o;
    o.technique = indirect_technique::sii;
    o.count = count;
    o.pattern = {pattern, pattern};
    o.blur = false;  // the blur's expectation is the blurred frame's; per pixel needs none
    o.light.min_distance2 = 0.05f;
    o.visibility = indirect_visibility::rays;
    o.view_selection = {4, 16, 0.3f};
    return o;
}

}  // namespace

TEST_CASE("each sub-buffer's draws, times their scales, have the candidates' sum as expectation",
          "[rsm][view_selection]") {
    // 40 candidates, values f_j with zeros among them, an importance that favours some
    // and misses others (0, NaN: the defensive share alone picks those).
    std::vector<double> f(40), t(40);
    for (std::size_t j = 0; j < f.size(); ++j) {
        f[j] = j % 7 == 3 ? 0.0 : 1.0 + double((j * 37) % 11);
        t[j] = j % 5 == 0 ? 0.0 : double((j * 13) % 17);
    }
    t[7] = std::numeric_limits<double>::quiet_NaN();
    double exact = 0;
    for (const double v : f) exact += v;
    const std::vector<double> p = view_selection_probabilities(t, 0.3);
    double total = 0;
    for (const double v : p) {
        CHECK(v >= 0.3 / 40.0 - 1e-15);
        total += v;
    }
    CHECK(total == Approx(1.0).epsilon(1e-12));
    for (const auto& [count, cells] : {std::pair{16, 4}, std::pair{18, 4}, std::pair{12, 1}}) {
        INFO(count << " draws for " << cells << " sub-buffers");
        const int seeds = 20000;
        std::vector<double> sum(std::size_t(cells), 0.0), sum2(std::size_t(cells), 0.0);
        for (int seed = 0; seed < seeds; ++seed) {
            const auto draws = draw_for_view(p, std::size_t(count), cells, std::uint64_t(seed), cells == 1);
            if (cells > 1) REQUIRE(draws.size() == std::size_t(count));
            std::vector<double> estimate(std::size_t(cells), 0.0);
            for (std::size_t k = 0; k < draws.size(); ++k)
                estimate[k % std::size_t(cells)] += double(cells) * draws[k].scale * f[draws[k].candidate];
            for (std::size_t s = 0; s < estimate.size(); ++s) {
                sum[s] += estimate[s];
                sum2[s] += estimate[s] * estimate[s];
            }
        }
        for (std::size_t s = 0; s < sum.size(); ++s) {
            const double mean = sum[s] / seeds, var = sum2[s] / seeds - mean * mean;
            INFO("sub-buffer " << s << ": mean " << mean << " against " << exact << ", sd " << std::sqrt(var));
            CHECK(std::abs(mean - exact) <= 4.5 * std::sqrt(var / seeds) + 1e-9 * exact);
        }
    }
}

TEST_CASE("over seeds, a frame of VPLs chosen by the view has the frame of every texel as expectation",
          "[rsm][view_selection]") {
    const small_scene s;
    const rsm_view map = s.map();
    const half_plane_occlusion occluder(0.2f);
    // The unselected estimator taken to its limit: every texel a VPL of its own flux.
    std::vector<vpl> texels;
    for (std::size_t y = 0; y < 16; ++y)
        for (std::size_t x = 0; x < 16; ++x) texels.push_back({s.position(x, y), s.normal(x, y), s.flux(x, y)});
    for (const int pattern : {1, 2}) {
        INFO("pattern " << pattern << "x" << pattern);
        const indirect_options o = options(pattern, 16);
        gbuffer<float> gb = s.gb;
        image<glm::vec3> exact(8, 8);
        cpu::sii_params sp;
        sp.light = o.light;
        cpu::splat_vpls(gb.view(), s.cam, texels, sp, exact.view(), &occluder);
        image<glm::vec3> open(8, 8);
        cpu::splat_vpls(gb.view(), s.cam, texels, sp, open.view());
        const int seeds = 3000;
        image<glm::dvec3> sum(8, 8), sum2(8, 8);
        image<glm::vec3> frame(8, 8);
        for (int seed = 1; seed <= seeds; ++seed) {
            indirect_options so = o;
            so.seed = std::uint64_t(seed);
            cpu::indirect_renderer r(so, &occluder);
            r.render(gb.view(), s.cam, std::span<const rsm_view>(&map, 1), frame.view());
            for (std::size_t y = 0; y < 8; ++y)
                for (std::size_t x = 0; x < 8; ++x) {
                    sum(x, y) += glm::dvec3(frame(x, y));
                    sum2(x, y) += glm::dvec3(frame(x, y)) * glm::dvec3(frame(x, y));
                }
        }
        int lit = 0, shadowed = 0;
        for (std::size_t y = 0; y < 8; ++y)
            for (std::size_t x = 0; x < 8; ++x)
                for (int c = 0; c < 3; ++c) {
                    const double mean = sum(x, y)[c] / seeds, var = sum2(x, y)[c] / seeds - mean * mean;
                    const double want = exact(x, y)[c];
                    INFO("pixel " << x << ", " << y << " channel " << c << ": mean " << mean << ", every texel "
                                  << want << ", sd " << std::sqrt(std::max(0.0, var)));
                    CHECK(std::abs(mean - want) <= 4.5 * std::sqrt(std::max(0.0, var) / seeds) + 1e-6 * want + 1e-12);
                    lit += want > 0 ? 1 : 0;
                    shadowed += want < 0.9 * double(open(x, y)[c]) ? 1 : 0;
                }
        CHECK(lit > 60);       // the occluder leaves light to compare
        CHECK(shadowed > 30);  // and hides much of it from some pixels
    }
}

TEST_CASE("where the camera sees no candidate the draw is uniform and every weight finite",
          "[rsm][view_selection]") {
    const small_scene s;
    const rsm_view map = s.map();
    const half_plane_occlusion everything(-1e9f);
    gbuffer<float> gb = s.gb;
    gbuffer<float> empty = s.gb;
    for (std::size_t y = 0; y < 8; ++y)
        for (std::size_t x = 0; x < 8; ++x) empty.view().depth(x, y) = std::numeric_limits<float>::infinity();
    for (const gbuffer<float>* g : {&gb, &empty})
        for (const int cells : {1, 4}) {
            const indirect_options o = options(cells == 1 ? 1 : 2, 16);
            gbuffer<float> copy = *g;
            const std::vector<vpl> v =
                cpu::select_vpls_for_view(std::span<const rsm_view>(&map, 1), o, copy.view(), &everything, cells);
            const std::vector<vpl> candidates = select_vpls(std::span<const rsm_view>(&map, 1), 64, o.selection, o.seed);
            double flux = 0, candidate_flux = 0;
            for (const vpl& l : v) {
                CHECK(std::isfinite(l.flux.x));
                CHECK(std::isfinite(l.area));
                CHECK(l.flux.x > 0.f);
                flux += double(l.flux.x);
            }
            for (const vpl& l : candidates) candidate_flux += double(l.flux.x);
            // Uniform over 64 candidates: 16 draws of 4 times a candidate's flux (merged
            // duplicates carry their count), so the total matches the candidates' within
            // the draw's spread.
            CHECK(flux == Approx(candidate_flux).epsilon(0.25));
        }
    // The frame with every pair blocked is black, not NaN.
    cpu::indirect_renderer r(options(2, 16), &everything);
    image<glm::vec3> frame(8, 8);
    r.render(gb.view(), s.cam, std::span<const rsm_view>(&map, 1), frame.view());
    for (std::size_t y = 0; y < 8; ++y)
        for (std::size_t x = 0; x < 8; ++x) CHECK(frame(x, y) == glm::vec3(0.f));
}

// Blocks every segment whose sender lies at z > 0: that half of the ceiling is hidden from
// the whole view.
class hidden_senders final : public occlusion_query {
public:
    void occluded(std::span<const visibility_segment> segments, std::span<std::uint8_t> blocked) const override {
        for (std::size_t i = 0; i < segments.size(); ++i) blocked[i] = segments[i].sender.z > 0.f ? 1 : 0;
    }
};

TEST_CASE("a VPL the view cannot see is drawn with the defensive share alone", "[rsm][view_selection]") {
    // Each drawn VPL's flux is its candidate's times 1 / (cells n_s P): a hidden candidate
    // has P = defensive / M exactly, a seen one more; over seeds the hidden half of the
    // candidates gets count x (hidden / M) x defensive draws, within the seeds' spread.
    const small_scene s;
    const rsm_view map = s.map();
    const hidden_senders occluder;
    const std::size_t count = 16, cells = 4;
    const indirect_options base = options(2, count);
    const double m = double(count) * base.view_selection.candidates, a = base.view_selection.defensive;
    const int seeds = 400;
    double drawn = 0, expected = 0, sum2 = 0;
    for (int seed = 1; seed <= seeds; ++seed) {
        indirect_options o = base;
        o.seed = std::uint64_t(seed);
        gbuffer<float> gb = s.gb;
        const std::vector<vpl> v =
            cpu::select_vpls_for_view(std::span<const rsm_view>(&map, 1), o, gb.view(), &occluder, int(cells));
        const std::vector<vpl> candidates =
            select_vpls(std::span<const rsm_view>(&map, 1), std::size_t(m), o.selection, o.seed);
        REQUIRE(v.size() == count);
        double hidden_candidates = 0, hidden_draws = 0;
        for (const vpl& c : candidates) hidden_candidates += c.position.z > 0.f ? 1 : 0;
        for (const vpl& l : v) {
            const auto c = std::find_if(candidates.begin(), candidates.end(),
                                        [&](const vpl& x) { return x.position == l.position; });
            REQUIRE(c != candidates.end());
            const double p = double(c->flux.y) / (double(l.flux.y) * double(count));  // 1 / (cells n_s factor)
            if (l.position.z > 0.f) {
                CHECK(p == Approx(a / m).epsilon(1e-5));
                hidden_draws += 1;
            } else {
                CHECK(p > 1.5 * a / m);
            }
        }
        const double want = double(count) * hidden_candidates / m * a;
        drawn += hidden_draws;
        expected += want;
        sum2 += (hidden_draws - want) * (hidden_draws - want);
    }
    INFO("hidden draws " << drawn << " against " << expected);
    CHECK(expected > 0.5 * seeds);  // hidden candidates in most seeds
    CHECK(std::abs(drawn - expected) <= 4.5 * std::sqrt(sum2) + 1e-9);
}

TEST_CASE("bad view selection parameters are refused by name", "[rsm][view_selection]") {
    indirect_options o;
    o.view_selection.candidates = 0;
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("view_selection.candidates"));
    o.view_selection = {};
    o.view_selection.defensive = 0.f;
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("view_selection.defensive"));
    o.view_selection = {};
    o.view_selection.receivers = 0;
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("view_selection.receivers"));
}

TEST_CASE("the near field finds the pixels in each candidate's ball and weighs them against the grid's",
          "[rsm][view_selection]") {
    small_scene s;
    const gbuffer_view<float> gb = s.gb.view();
    const double stride = receiver_stride(8, 8, 16);
    REQUIRE(stride == 2.0);
    const cpu::near_pixels pixels(gb, 0.1f);
    std::vector<view_receiver> out;
    for (const auto& [centre, radius] : {std::pair{glm::vec3(0.1f, 0.05f, -0.2f), 0.4f},
                                         std::pair{glm::vec3(-0.9f, 0.f, -0.9f), 0.3f},
                                         std::pair{glm::vec3(0.f, 0.f, 0.f), 5.f}}) {
        pixels.within(centre, radius, stride, 1024, out);
        std::size_t want = 0;
        for (std::size_t y = 0; y < 8; ++y)
            for (std::size_t x = 0; x < 8; ++x)
                want += gb.covered(x, y) && glm::length(glm::vec3(gb.position(x, y)) - centre) < radius ? 1 : 0;
        CHECK(out.size() == want);
        for (const view_receiver& r : out) {
            CHECK(glm::length(r.position - centre) < radius);
            CHECK(r.weight == Approx(0.5f * near_field_weight(stride, want, want)));
        }
    }
    // At most `cap`, each then standing for found / taken pixels.
    pixels.within(glm::vec3(0.f), 5.f, stride, 9, out);
    CHECK(out.size() == 9);
    CHECK(out[0].weight == Approx(0.5 * std::sqrt(63.0 / 9.0) / stride));
    CHECK(near_field_radius(4.f, 0.25f) == 2.f);
    CHECK(near_field_radius(0.f, 0.25f) == 0.f);
    CHECK(combined_importance(3.0, 4.0) == Approx(5.0));
}

TEST_CASE("a sender's peak between the grid's receivers is measured with the near field",
          "[rsm][view_selection]") {
    // Two senders 2 cm above the floor, one over a grid receiver (pixel 1, 1 of the 2-pixel
    // grid), one over a pixel between receivers (2, 2): without the near field the grid sees
    // the first's peak and only the far tail of the second's; with it both are measured alike.
    small_scene s;
    const gbuffer_view<float> gb = s.gb.view();
    const auto above = [&](std::size_t x, std::size_t y) {
        return vpl{glm::vec3(gb.position(x, y)) + glm::vec3(0.f, 0.02f, 0.f), {0.f, -1.f, 0.f}, glm::vec3(1.f), 1e-4f};
    };
    const std::vector<vpl> senders{above(1, 1), above(2, 2)};
    const float d2 = 0.0004f;  // the clamp at 2 cm
    const auto terms = [&](const vpl& c, const view_receiver& r, auto&& add) {
        const glm::vec3 d = c.position - r.position;
        add(1.f / std::max(glm::dot(d, d), d2), visibility_segment{r.position, r.normal, c.position, c.normal});
    };
    const std::vector<view_receiver> grid = view_receivers(gb, 16);
    const std::vector<double> plain = cpu::view_importances<vpl>(senders, grid, nullptr, terms);
    CHECK(plain[0] > 20 * plain[1]);
    const float radius = near_field_radius(4.f, d2);
    const auto far_terms = [&](const vpl& c, const view_receiver& r, auto&& add) {
        if (glm::length(r.position - c.position) >= radius) terms(c, r, add);
    };
    const std::vector<double> far = cpu::view_importances<vpl>(senders, grid, nullptr, far_terms);
    const cpu::near_pixels pixels(gb, radius);
    const std::vector<double> near = cpu::near_field_importances<vpl>(
        senders, pixels, receiver_stride(8, 8, 16), nullptr, [&](const vpl&) { return radius; }, terms);
    const double t0 = combined_importance(far[0], near[0]), t1 = combined_importance(far[1], near[1]);
    CHECK(t1 == Approx(t0).epsilon(0.05));
}
