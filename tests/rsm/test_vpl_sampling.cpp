// VPL selection from an RSM (include/bounce/indirect/vpl_sampling.hpp): hierarchical warping reaches
// each texel with probability importance / total, and the VPL fluxes keep the total.
#include <bounce/indirect/options.hpp>
#include <bounce/indirect/vpl_sampling.hpp>

#include <catch2/catch.hpp>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/trigonometric.hpp>

#include <cmath>
#include <numbers>
#include <vector>

using namespace bounce;

namespace {
struct test_map {
    image<glm::vec3> position, normal, flux;
    test_map(std::size_t w, std::size_t h) : position(w, h), normal(w, h, glm::vec3(0, 0, 1)), flux(w, h) {
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t x = 0; x < w; ++x) position(x, y) = glm::vec3(float(x), float(y), 0.f);
    }
    rsm_view view() const { return {position.view(), normal.view(), flux.view()}; }
};
}  // namespace

TEST_CASE("hierarchical warping reaches each texel with probability importance / total, any map size", "[vpl]") {
    for (const auto& [w, h] : {std::pair{5, 3}, std::pair{8, 8}, std::pair{1, 7}, std::pair{13, 1}}) {
        test_map m{std::size_t(w), std::size_t(h)};
        double total = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                // Some texels dark, the rest uneven.
                const float f = (x + 2 * y) % 4 == 0 ? 0.f : float(1 + (x * 7 + y * 3) % 5);
                m.flux(std::size_t(x), std::size_t(y)) = glm::vec3(f, 0.5f * f, 0.25f * f);
                total += double(flux_importance(m.flux(std::size_t(x), std::size_t(y))));
            }
        const flux_warping warp(m.view());
        CHECK(warp.total() == Approx(total).epsilon(1e-12));
        // The preimage of a texel is a rectangle of area p (each split cuts one axis's
        // interval in proportion): a G x G grid of points counts p G^2 within the 2G + 1
        // grid points its boundary can cross.
        const int g = 400;
        std::vector<int> hits(std::size_t(w * h), 0);
        for (int j = 0; j < g; ++j)
            for (int i = 0; i < g; ++i) {
                const auto c = warp.warp({(i + 0.5) / g, (j + 0.5) / g});
                const double p = double(flux_importance(m.flux(c.x, c.y))) / total;
                REQUIRE(p > 0);  // a dark texel is never chosen
                REQUIRE(c.probability == Approx(p).epsilon(1e-9));
                ++hits[c.y * std::size_t(w) + c.x];
            }
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const double p = double(flux_importance(m.flux(std::size_t(x), std::size_t(y)))) / total;
                CHECK(std::abs(hits[std::size_t(y * w + x)] - p * g * g) <= 2.0 * g + 1);
            }
    }
}

TEST_CASE("warped VPLs each carry total / K of the importance, and grid VPLs keep a uniform map's total", "[vpl]") {
    test_map m(37, 23);
    double total = 0;
    for (std::size_t y = 0; y < 23; ++y)
        for (std::size_t x = 0; x < 37; ++x) {
            m.flux(x, y) = glm::vec3(float((x * y) % 9) * 0.1f);
            total += double(flux_importance(m.flux(x, y)));
        }
    for (std::size_t k : {std::size_t(1), std::size_t(100), std::size_t(4096)}) {
        const auto v = vpls_by_flux_warping(m.view(), k, 5);
        REQUIRE(v.size() == k);
        for (const auto& l : v) REQUIRE(double(flux_importance(l.flux)) == Approx(total / double(k)).epsilon(1e-5));
    }
    test_map uniform(16, 12);
    for (std::size_t y = 0; y < 12; ++y)
        for (std::size_t x = 0; x < 16; ++x) uniform.flux(x, y) = glm::vec3(0.5f);
    for (const auto& [gx, gy] : {std::pair{4, 4}, std::pair{16, 12}, std::pair{5, 7}}) {
        const auto v = vpls_on_grid(uniform.view(), std::size_t(gx), std::size_t(gy));
        REQUIRE(v.size() == std::size_t(gx * gy));
        double sum = 0;
        for (const auto& l : v) sum += l.flux.x;
        CHECK(sum == Approx(0.5 * 16 * 12).epsilon(1e-6));
    }
}

TEST_CASE("bad maps and counts raise parameter_error naming the parameter", "[vpl]") {
    test_map m(4, 4);
    CHECK(vpls_by_flux_warping(m.view(), 10).empty());  // a dark map has nothing to sample
    m.flux(1, 1) = glm::vec3(-1.f);
    try {
        flux_warping w(m.view());
        FAIL("negative flux accepted");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "rsm.flux");
    }
    m.flux(1, 1) = glm::vec3(1.f);
    CHECK_THROWS_AS(vpls_by_flux_warping(m.view(), 0), parameter_error);
    CHECK_THROWS_AS(vpls_on_grid(m.view(), 0, 3), parameter_error);
    rsm_view bad = m.view();
    bad.normal = image_view<const glm::vec3>(m.normal.data(), 2, 2);
    CHECK_THROWS_AS(vpls_on_grid(bad, 2, 2), parameter_error);
}

namespace {
/// A map of the plane through the origin with unit normal `n`, seen through `view_projection`:
/// each texel's centre ray met with the plane, flux 1 everywhere.
test_map plane_map(std::size_t w, std::size_t h, const glm::mat4& view_projection, glm::dvec3 n) {
    test_map m(w, h);
    const glm::dmat4 inv = glm::inverse(glm::dmat4(view_projection));
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            const double cx = 2.0 * (double(x) + 0.5) / double(w) - 1.0, cy = 1.0 - 2.0 * (double(y) + 0.5) / double(h);
            const glm::dvec4 a = inv * glm::dvec4(cx, cy, -1, 1), b = inv * glm::dvec4(cx, cy, 1, 1);
            const glm::dvec3 from = glm::dvec3(a) / a.w, dir = glm::dvec3(b) / b.w - from;
            m.position(x, y) = glm::vec3(from - dir * (glm::dot(from, n) / glm::dot(dir, n)));
            m.normal(x, y) = glm::vec3(n);
            m.flux(x, y) = glm::vec3(1.f);
        }
    return m;
}
}  // namespace

TEST_CASE("a texel's world area: a point light's face over a plane, a directional light's slanted map", "[vpl]") {
    // A 90-degree face at height h over the plane it faces: every texel covers (2 h / W)^2.
    const float h = 3.f;
    const glm::mat4 face = glm::perspective(glm::radians(90.f), 1.f, 0.01f, 100.f) *
                           glm::lookAt(glm::vec3(0, h, 0), glm::vec3(0, 0, 0), glm::vec3(0, 0, -1));
    test_map m = plane_map(32, 32, face, {0, 1, 0});
    rsm_view v = m.view();
    v.light_view_projection = face;
    const glm::dmat4 inv = glm::inverse(glm::dmat4(face));
    for (const auto& [x, y] : {std::pair{0, 0}, std::pair{15, 16}, std::pair{31, 7}})
        CHECK(texel_world_area(v, inv, std::size_t(x), std::size_t(y)) ==
              Approx(std::pow(2.0 * h / 32, 2)).epsilon(1e-5));
    // An orthographic map of extent 4 x 4 on a plane tilted by 60 degrees: (4 / W)^2 / cos 60.
    const double tilt = glm::radians(60.0);
    const glm::dvec3 n(0, std::cos(tilt), std::sin(tilt));
    const glm::mat4 ortho = glm::ortho(-2.f, 2.f, -2.f, 2.f, 0.1f, 20.f) *
                            glm::lookAt(glm::vec3(0, 5, 0), glm::vec3(0, 0, 0), glm::vec3(0, 0, -1));
    test_map slanted = plane_map(16, 16, ortho, n);
    rsm_view sv = slanted.view();
    sv.light_view_projection = ortho;
    CHECK(texel_world_area(sv, glm::inverse(glm::dmat4(ortho)), 5, 9) ==
          Approx(std::pow(4.0 / 16, 2) / std::cos(tilt)).epsilon(1e-5));
    // Seen edge-on, the area stays finite (the grazing cosine is taken at 1e-3).
    slanted.normal(5, 9) = glm::vec3(1, 0, 0);
    const double edge_on = texel_world_area(sv, glm::inverse(glm::dmat4(ortho)), 5, 9);
    CHECK(std::isfinite(edge_on));
    CHECK(edge_on <= 1.001e3 * std::pow(4.0 / 16, 2));
}

TEST_CASE("VPL areas sum to the lit area, and the footprint clamp shrinks as VPLs are added", "[vpl]") {
    const glm::mat4 face = glm::perspective(glm::radians(90.f), 1.f, 0.01f, 100.f) *
                           glm::lookAt(glm::vec3(0, 2, 0), glm::vec3(0, 0, 0), glm::vec3(0, 0, -1));
    test_map m = plane_map(24, 24, face, {0, 1, 0});
    for (std::size_t y = 0; y < 24; ++y)
        for (std::size_t x = 12; x < 24; ++x) m.flux(x, y) = glm::vec3(0.f);  // half the map dark
    rsm_view v = m.view();
    v.light_view_projection = face;
    const double lit = 24 * 12 * std::pow(2.0 * 2 / 24, 2);  // uniform flux: every VPL stands for lit / K
    pixel_light_params lp;
    lp.min_distance2 = 0.25f;
    CHECK(lp.min_distance2_for(1.f) == 0.25f);  // footprint off: the fixed clamp
    lp.footprint_scale = 1.f;
    for (const std::size_t k : {std::size_t(64), std::size_t(256)}) {
        const auto warped = vpls_by_flux_warping(v, k, 3);
        double sum = 0;
        for (const auto& l : warped) {
            sum += double(l.area);
            CHECK(lp.min_distance2_for(l.area) == Approx(lit / double(k) / std::numbers::pi).epsilon(1e-4));
        }
        CHECK(sum == Approx(lit).epsilon(1e-5));
    }
    const auto grid = vpls_on_grid(v, 6, 6);  // the 18 grid cells over the lit half give VPLs
    double sum = 0;
    for (const auto& l : grid) sum += double(l.area);
    CHECK(sum == Approx(lit).epsilon(1e-5));
    lp.footprint_scale = 2.f;
    CHECK(lp.min_distance2_for(float(std::numbers::pi)) == Approx(4.0));
    lp.footprint_scale = -1.f;
    CHECK_THROWS_AS(lp.validate(), parameter_error);
}
