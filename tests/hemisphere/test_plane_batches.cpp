// The samplers' loops over many records: gl::hemisphere_raster::read_planes (batches
// rendered while the previous one is copied back) against the raster's own render /
// start_read / finish_read one batch at a time, and what it refuses or recovers from.
#include "../gl/shared_context.hpp"
#include "half_lit_ceiling_scene.hpp"
#include "raster_options.hpp"

#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <stdexcept>
#include <vector>

using namespace bounce;

namespace {

// `count` records looking up (n = +y) at random points under the half-lit ceiling.
void ceiling_points(std::size_t count, std::vector<glm::vec3>& p, std::vector<glm::vec3>& n) {
    pcg32 rng(17);
    for (std::size_t k = 0; k < count; ++k) {
        const float x = float(2 * rng.next_double() - 1);  // two statements: argument order
        p.emplace_back(x, 0.f, float(2 * rng.next_double() - 1));
        n.emplace_back(0.f, 1.f, 0.f);
    }
}

bool same_plane(const image<glm::vec3>& a, const image<glm::vec3>& b, const image<float>& da, const image<float>& db) {
    for (std::size_t j = 0; j < a.height(); ++j)
        for (std::size_t i = 0; i < a.width(); ++i)
            if (a(i, j) != b(i, j) || !(da(i, j) == db(i, j) || (std::isinf(da(i, j)) && std::isinf(db(i, j)))))
                return false;
    return true;
}

}  // namespace

TEST_CASE("read_planes hands every batch's planes over in order, as one render and read per batch gives them",
          "[hemisphere][gl][batches]") {
    gl_test::shared_context();
    const test::owned_scene s = hemisphere_test::half_lit_ceiling_scene(1.5f, 0.4f, 0.75f, 2.f);
    const gl::scene_mesh mesh(s);
    const gl::direct_light light(s, mesh, 512);
    gl::hemisphere_raster raster(s, mesh, light, raster_options(16, 126.0, 4, 1e-3f));
    std::vector<glm::vec3> p, n;
    ceiling_points(10, p, n);  // batches of 4, 4 and 2

    std::vector<std::size_t> firsts;
    std::vector<gl::plane_batch> got;
    raster.read_planes(p, n, [&](std::size_t first, const gl::plane_batch& b) {
        firsts.push_back(first);
        got.push_back(b);
        CHECK(b.views().size() == b.size());
    });
    REQUIRE(firsts == std::vector<std::size_t>{0, 4, 8});
    CHECK(raster.pending_reads() == 0);
    for (std::size_t b = 0; b < firsts.size(); ++b) {
        const std::size_t count = std::min<std::size_t>(4, p.size() - firsts[b]);
        raster.render(std::span(p).subspan(firsts[b], count), std::span(n).subspan(firsts[b], count));
        raster.start_read();
        const gl::plane_batch one = raster.finish_read();
        REQUIRE(got[b].size() == count);
        for (std::size_t k = 0; k < count; ++k) {
            CAPTURE(b, k);
            CHECK(same_plane(got[b].radiance[k], one.radiance[k], got[b].distance[k], one.distance[k]));
        }
    }

    SECTION("a consumer that throws leaves no read pending, and the raster works again") {
        int calls = 0;
        CHECK_THROWS_AS(raster.read_planes(p, n,
                                           [&](std::size_t, const gl::plane_batch&) {
                                               if (++calls == 1) throw std::runtime_error("consumer");
                                           }),
                        std::runtime_error);
        CHECK(raster.pending_reads() == 0);
        std::size_t records = 0;
        raster.read_planes(p, n, [&](std::size_t, const gl::plane_batch& b) { records += b.size(); });
        CHECK(records == p.size());
    }
    SECTION("no records: no call") {
        bool called = false;
        raster.read_planes({}, {}, [&](std::size_t, const gl::plane_batch&) { called = true; });
        CHECK_FALSE(called);
    }
    SECTION("refused: spans of different sizes, no consumer, reads pending") {
        const auto ignore = [](std::size_t, const gl::plane_batch&) {};
        CHECK_THROWS_AS(raster.read_planes(p, std::span(n).first(3), ignore), parameter_error);
        CHECK_THROWS_AS(raster.read_planes(p, n, {}), parameter_error);
        raster.render(std::span(p).first(2), std::span(n).first(2));
        raster.start_read();
        CHECK_THROWS_AS(raster.read_planes(p, n, ignore), parameter_error);
        raster.finish_read();
    }
}
