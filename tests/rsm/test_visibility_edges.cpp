// The blur's visibility edges (issue 29, fourth session; indirect/interleaved_sampling.hpp's
// visibility_discontinuity, cpu::add_visibility_edges): interleaved SII with rays cuts its
// geometry-aware tent where two neighbours see different shares of their senders, so the rim
// of a shadow on one flat surface stays as sharp as the plain frame has it, where the blur
// of geometry alone spreads the lit side into the shadow.
#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/errors.hpp>

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
