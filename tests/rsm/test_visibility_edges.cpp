// The blur's visibility edges (issue 29, fourth session; indirect/interleaved_sampling.hpp's
// visibility_discontinuity, cpu::add_visibility_edges): interleaved SII with rays cuts its
// geometry-aware tent where two neighbours see different shares of their senders, so the rim
// of a shadow on one flat surface stays as sharp as the plain frame has it, where the blur
// of geometry alone spreads the lit side into the shadow.
#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/errors.hpp>
#include <bounce/sampling.hpp>

#include "lit_ceiling.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>

using namespace bounce;

namespace {

// Blocks every segment whose receiver lies at x < 0: a shadow with a straight rim on the floor.
class left_half_shadow final : public occlusion_query {
public:
    void occluded(std::span<const visibility_segment> segments, std::span<std::uint8_t> blocked) const override {
        for (std::size_t i = 0; i < segments.size(); ++i) blocked[i] = segments[i].receiver.x < 0.f ? 1 : 0;
    }
};

// A lit ceiling (y = 1, facing down) of 16 x 16 texels over [-1, 1]^2 above a floor (y = 0)
// seen from above by a size x size G-buffer; the rim x = 0 falls between two columns.
struct shadowed_floor : test::lit_ceiling {
    static constexpr std::size_t size = 40;
    gbuffer<float> gb{size, size};
    camera cam;

    shadowed_floor() {
        for (std::size_t y = 0; y < size; ++y)
            for (std::size_t x = 0; x < size; ++x) {
                const float h = float(size) / 2.f;
                gb.view().position(x, y) = {(float(x) + 0.5f - h) / h, 0.f, (float(y) + 0.5f - h) / h};
                gb.view().normal(x, y) = {0.f, 1.f, 0.f};
                gb.view().albedo(x, y) = glm::vec3(0.5f);
                gb.view().depth(x, y) = 1.f;
            }
        cam.position = {0.f, 3.f, 0.f};
        cam.look_at = {0.f, 0.f, 0.f};
        cam.up = {0.f, 0.f, 1.f};
    }
    rsm_view map() const { return {position.view(), normal.view(), flux.view(), glm::mat4(1.f)}; }

    image<glm::vec3> frame(const indirect_options& o, const occlusion_query& q) {
        cpu::indirect_renderer r(o, &q);
        image<glm::vec3> e(size, size);
        const rsm_view m = map();
        r.render(gb.view(), cam, std::span<const rsm_view>(&m, 1), e.view());
        return e;
    }
};

indirect_options shadow_options(int pattern, float sigmas) {
    indirect_options o;
    o.technique = indirect_technique::sii;
    o.count = 1024;
    o.pattern = {pattern, pattern};
    o.light.min_distance2 = 0.05f;
    o.visibility = indirect_visibility::rays;
    o.view_selection.candidates = 1;  // the same VPLs plain and interleaved
    o.discontinuity.visibility_sigmas = sigmas;
    return o;
}

double brightness(const glm::vec3& e) { return double(e.x) + double(e.y) + double(e.z); }

}  // namespace

TEST_CASE("visibility_discontinuity separates fractions further apart than their standard errors", "[rsm][blur]") {
    // 100 equal terms each: n = 100, the bound's standard error of the difference
    // sqrt((1/100 + 1/100) / 4) = 0.0707.
    const auto edge = [](float ra, float rb, float sigmas) {
        return visibility_discontinuity<float>(100.f, 100.f * ra, 100.f, 100.f, 100.f * rb, 100.f, sigmas);
    };
    CHECK(edge(1.f, 0.f, 3.f) == 1.f);
    CHECK(edge(0.8f, 0.5f, 3.f) == 1.f);   // 0.3 > 3 x 0.0707
    CHECK(edge(0.8f, 0.65f, 3.f) == 0.f);  // 0.15 < 0.212
    CHECK(edge(0.8f, 0.65f, 2.f) == 1.f);  // 0.15 > 0.141
    CHECK(edge(0.5f, 0.5f, 3.f) == 0.f);
    CHECK(edge(1.f, 0.f, 0.f) == 0.f);     // sigmas 0: never
    // One term each, fully seen against fully blocked: 1 < 3 sqrt(2 / 4), no claim of certainty.
    CHECK(visibility_discontinuity<float>(2.f, 2.f, 4.f, 2.f, 0.f, 4.f, 3.f) == 0.f);
    // A pixel that no term reaches has no visible fraction: never an edge.
    CHECK(visibility_discontinuity<float>(0.f, 0.f, 0.f, 100.f, 100.f, 100.f, 3.f) == 0.f);
    CHECK(visibility_discontinuity<float>(100.f, 0.f, 100.f, 0.f, 0.f, 0.f, 3.f) == 0.f);
}

TEST_CASE("with visibility edges the blurred interleaved frame keeps a shadow's rim where the plain frame has it",
          "[rsm][blur]") {
    shadowed_floor s;
    const left_half_shadow shadow;
    const image<glm::vec3> plain = s.frame(shadow_options(1, 3.f), shadow);
    const image<glm::vec3> geometry_only = s.frame(shadow_options(4, 0.f), shadow);
    const image<glm::vec3> with_edges = s.frame(shadow_options(4, 3.f), shadow);
    const std::size_t h = shadowed_floor::size / 2;  // columns x < h are in the shadow
    double lit_plain = 0, lit_edges = 0, dark_geometry = 0, dark_edges = 0;
    for (std::size_t y = 0; y < shadowed_floor::size; ++y) {
        for (std::size_t x = h - 3; x < h; ++x) {
            REQUIRE(brightness(plain(x, y)) == 0.0);
            dark_geometry += brightness(geometry_only(x, y));
            dark_edges += brightness(with_edges(x, y));
        }
        for (std::size_t x = h; x < h + 3; ++x) {
            lit_plain += brightness(plain(x, y));
            lit_edges += brightness(with_edges(x, y));
        }
    }
    REQUIRE(lit_plain > 0.0);
    // The geometry's blur spreads the lit side 3 columns into the shadow (a tent of radius 3).
    CHECK(dark_geometry > 0.05 * lit_plain);
    // With the visibility edges the shadow stays black and the lit side keeps its light.
    CHECK(dark_edges == 0.0);
    CHECK(lit_edges == Approx(lit_plain).epsilon(0.1));
}

TEST_CASE("a bad visibility_sigmas is refused by its name", "[rsm][blur]") {
    indirect_options o;
    for (const float bad : {-1.f, std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()}) {
        o.discontinuity.visibility_sigmas = bad;
        try {
            o.validate();
            FAIL("accepted visibility_sigmas " << bad);
        } catch (const parameter_error& e) {
            CHECK(std::string(e.what()).find("visibility_sigmas") != std::string::npos);
        }
    }
}

// Isolated pixels (issue 29, fifth session; cpu::reached_sub_buffers, complete_isolated_pixels).

TEST_CASE("reached_sub_buffers counts the sub-buffers the blur itself averages", "[rsm][blur]") {
    // Random edges: the count at each pixel equals the number of sub-buffers whose indicator
    // image the blur carries to that pixel.
    const std::size_t w = 37, h = 29;
    const interleave_pattern p{4, 3};
    image<glm::vec2> edges(w, h);
    image<float> depth(w, h, 1.f), reached(w, h);
    pcg32 rng(7, 3);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x)
            edges(x, y) = glm::vec2(rng.next_double() < 0.25 ? 1.f : 0.f, rng.next_double() < 0.25 ? 1.f : 0.f);
    // A pixel without geometry, cut off on every side as discontinuity_buffer marks it.
    depth(5, 5) = std::numeric_limits<float>::infinity();
    edges(5, 5) = glm::vec2(1.f);
    edges(4, 5).x = 1.f;
    edges(5, 4).y = 1.f;
    cpu::reached_sub_buffers(edges.view(), depth.view(), p, reached.view());
    image<float> count(w, h);
    image<glm::vec3> one(w, h), scratch(w, h), blurred(w, h);
    for (int j = 0; j < p.m; ++j)
        for (int i = 0; i < p.n; ++i) {
            for (std::size_t y = 0; y < h; ++y)
                for (std::size_t x = 0; x < w; ++x)
                    one(x, y) = glm::vec3(int(x) % p.n == i && int(y) % p.m == j ? 1.f : 0.f);
            cpu::geometry_aware_blur(one.view(), edges.view(), depth.view(), p, scratch.view(), blurred.view());
            for (std::size_t y = 0; y < h; ++y)
                for (std::size_t x = 0; x < w; ++x) count(x, y) += blurred(x, y).x > 0.f ? 1.f : 0.f;
        }
    std::size_t isolated = 0;
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            if (x == 5 && y == 5) {
                CHECK(reached(x, y) == float(p.cells()));  // no geometry: copied, never completed
                continue;
            }
            CHECK(reached(x, y) == count(x, y));
            isolated += reached(x, y) < float(p.cells()) ? 1 : 0;
        }
    CHECK(isolated > w * h / 4);  // the edges do cut: the case is not trivial
}

TEST_CASE("a pixel the blur isolates is completed with every VPL, as the plain frame has it", "[rsm][blur]") {
    shadowed_floor s;
    const left_half_shadow shadow;
    // Two pixels with their own depth (a post seen end-on): edges all round, so the blur keeps
    // only their own sub-buffer's VPLs at 16 times the weight. One is lit, one in the shadow.
    const std::size_t lit_x = 30, dark_x = 9, row = 17;
    s.gb.view().depth(lit_x, row) = 2.f;
    s.gb.view().depth(dark_x, row) = 2.f;
    const image<glm::vec3> plain = s.frame(shadow_options(1, 3.f), shadow);
    const image<glm::vec3> blurred = s.frame(shadow_options(4, 3.f), shadow);
    indirect_options o = shadow_options(4, 3.f);
    o.discontinuity.complete_below = 0.5f;
    const image<glm::vec3> completed = s.frame(o, shadow);
    REQUIRE(brightness(plain(lit_x, row)) > 0.0);
    // Without completion the lit pixel is its sub-buffer's 64 VPLs at 16 times the weight.
    CHECK(std::abs(brightness(blurred(lit_x, row)) / brightness(plain(lit_x, row)) - 1.0) > 0.01);
    for (int c = 0; c < 3; ++c) {
        CHECK(completed(lit_x, row)[c] == Approx(plain(lit_x, row)[c]).epsilon(1e-5));
        CHECK(completed(dark_x, row)[c] == 0.f);  // visibility holds for the completed pixel too
    }
    std::size_t changed = 0;
    for (std::size_t y = 0; y < shadowed_floor::size; ++y)
        for (std::size_t x = 0; x < shadowed_floor::size; ++x)
            if (!(y == row && (x == lit_x || x == dark_x)))
                changed += completed(x, y) == blurred(x, y) ? 0 : 1;
    CHECK(changed == 0);  // every other pixel reaches at least 8 of the 16 sub-buffers: unchanged
}

TEST_CASE("a bad complete_below is refused by its name, and with imperfect shadow maps", "[rsm][blur]") {
    indirect_options o;
    for (const float bad : {-0.1f, 1.5f, std::numeric_limits<float>::quiet_NaN()}) {
        o.discontinuity.complete_below = bad;
        CHECK_THROWS_WITH(o.validate(), Catch::Contains("complete_below"));
    }
    o.discontinuity.complete_below = 0.5f;
    o.visibility = indirect_visibility::ism;
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("complete_below"));
}
