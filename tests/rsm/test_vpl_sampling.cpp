// VPL selection from an RSM (include/bounce/indirect/vpl_sampling.hpp): hierarchical warping reaches
// each texel with probability importance / total, and the VPL fluxes keep the total.
#include <bounce/indirect/vpl_sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
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
