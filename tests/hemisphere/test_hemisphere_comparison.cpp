// The hemisphere study's library parts: embree::sample_planes against sample_plane one
// record at a time, study::ray_cast_plane_estimates against cpu::estimate_plane and a
// radial_profile fed the same planes by hand, the texel difference, the errors and the
// reference's cache, on the half-lit ceiling (half_lit_ceiling_scene.hpp).
#include "half_lit_ceiling_scene.hpp"

#include <bounce/cpu/plane_estimate.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/plane_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/cache/plane_weights.hpp>
#include <bounce/cache/radial_profile.hpp>
#include <bounce/sampling.hpp>
#include <bounce/study/hemisphere_comparison.hpp>

#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <vector>

using namespace bounce;

namespace {

struct ceiling {
    test::owned_scene scene = hemisphere_test::half_lit_ceiling_scene(1.5f, 0.4f, 0.75f, 2.f);
    embree::accel bvh{scene};
    embree::reference_integrator ref{bvh, scene};
};

// `count` records looking up (n = +y) at random points under the ceiling.
study::surface_points ceiling_points(std::size_t count) {
    pcg32 rng(5);
    study::surface_points pts;
    for (std::size_t k = 0; k < count; ++k) {
        const float x = float(2 * rng.next_double() - 1);  // two statements: argument order
        pts.positions.emplace_back(x, 0.f, float(2 * rng.next_double() - 1));
        pts.normals.emplace_back(0.f, 1.f, 0.f);
    }
    return pts;
}

struct plane_images {
    image<glm::vec3> radiance;
    image<float> distance;
    explicit plane_images(std::uint32_t N) : radiance(N, N), distance(N, N) {}
    plane_view view() const { return {radiance.view(), distance.view()}; }
};

}  // namespace

TEST_CASE("sample_planes gives each record the plane sample_plane gives it, once", "[hemisphere][embree][batches]") {
    const ceiling c;
    const plane_camera cam{16, 126.0, 30.0};
    const auto pts = ceiling_points(40);
    std::vector<plane_images> planes(pts.size(), plane_images(cam.resolution));
    std::vector<std::atomic<int>> calls(pts.size());
    embree::sample_planes(c.ref, cam, pts.positions, pts.normals, [&](std::size_t k, plane_view v) {
        ++calls[k];
        for (std::size_t j = 0; j < cam.resolution; ++j)
            for (std::size_t i = 0; i < cam.resolution; ++i) {
                planes[k].radiance(i, j) = v.radiance(i, j);
                planes[k].distance(i, j) = v.distance(i, j);
            }
    });
    for (std::size_t k = 0; k < pts.size(); ++k) {
        CAPTURE(k);
        CHECK(calls[k] == 1);
        plane_images one(cam.resolution);
        embree::sample_plane(c.ref, cam, pts.positions[k], pts.normals[k], one.radiance.view(), one.distance.view());
        bool same = true;
        for (std::size_t j = 0; j < cam.resolution; ++j)
            for (std::size_t i = 0; i < cam.resolution; ++i)
                same = same && one.radiance(i, j) == planes[k].radiance(i, j) &&
                       (one.distance(i, j) == planes[k].distance(i, j) ||
                        (std::isinf(one.distance(i, j)) && std::isinf(planes[k].distance(i, j))));
        CHECK(same);
    }
    CHECK_THROWS_AS(embree::sample_planes(c.ref, cam, pts.positions, std::span(pts.normals).first(3),
                                          [](std::size_t, plane_view) {}),
                    parameter_error);
    CHECK_THROWS_AS(embree::sample_planes(c.ref, cam, pts.positions, pts.normals, {}), parameter_error);
}

TEST_CASE("ray_cast_plane_estimates: each record's sums, and per batch the kappa of every plane so far",
          "[hemisphere][embree][study]") {
    const ceiling c;
    const plane_camera cam{16, 126.0};
    const auto pts = ceiling_points(23);  // batches of 5: 5 5 5 5 3
    const std::size_t batch = 5;
    const study::plane_estimates e = study::ray_cast_plane_estimates(c.ref, pts, cam, batch);
    REQUIRE(e.size() == pts.size());
    const auto plane_w = make_plane_weights(cam, plane_weighting::plane);
    const auto stretch_w = make_plane_weights(cam, plane_weighting::stretch);
    radial_profile profile(cam);
    std::vector<double> kappas;
    for (std::size_t k = 0; k < pts.size(); ++k) {
        plane_images one(cam.resolution);
        embree::sample_plane(c.ref, cam, pts.positions[k], pts.normals[k], one.radiance.view(), one.distance.view());
        CHECK(e.plane[k] == cpu::estimate_plane(plane_w, one.view()).irradiance);
        CHECK(e.stretch[k] == cpu::estimate_plane(stretch_w, one.view()).irradiance);
        profile.add(one.radiance.view());
        if (k % batch == batch - 1 || k + 1 == pts.size()) kappas.insert(kappas.end(), k % batch + 1, profile.falloff_factor());
    }
    REQUIRE(kappas.size() == pts.size());
    for (std::size_t k = 0; k < pts.size(); ++k) CHECK(e.running_kappa[k] == Approx(kappas[k]).margin(1e-12));
    CHECK(e.kappa == e.running_kappa.back());
    CHECK(e.coverage_scale == make_plane_weights(cam, plane_weighting::coverage).scale);
    CHECK(e.coverage()[3] == e.plane[3] * e.coverage_scale);
    CHECK(e.falloff()[3] == e.plane[3] + e.kappa * (e.stretch[3] - e.plane[3]));
    CHECK(e.ms > 0);

    // Errors: zero against themselves; the headline is the raster's where it ran.
    const auto self = study::plane_estimate_errors(e, e.stretch);
    CHECK(self["rms_stretch"].get<double>() == 0.0);
    CHECK(self["rms_plane"].get<double>() > 0.0);
    CHECK(study::max_relative_luminance_difference(e.stretch, e.stretch) == 0.0);
    CHECK(study::max_relative_luminance_difference(e.plane, e.stretch) > 0.0);
    nlohmann::ordered_json both = {{"ray_cast", {{"rms_stretch", 0.1}}}, {"raster", {{"rms_stretch", 0.2}}}};
    CHECK(study::with_headline_errors(both)["rel_rms"].get<double>() == 0.2);
    both.erase("raster");
    CHECK(study::with_headline_errors(both)["rel_rms"].get<double>() == 0.1);

    // The texel difference of the same planes is 0, and of planes of other points is not.
    study::plane_texel_difference same(c.ref, cam, pts), other(c.ref, cam, pts);
    const auto shifted = ceiling_points(24);
    for (std::size_t k = 0; k < pts.size(); ++k) {
        plane_images mine(cam.resolution), theirs(cam.resolution);
        embree::sample_plane(c.ref, cam, pts.positions[k], pts.normals[k], mine.radiance.view(), mine.distance.view());
        embree::sample_plane(c.ref, cam, shifted.positions[k + 1], shifted.normals[k + 1], theirs.radiance.view(),
                             theirs.distance.view());
        const plane_view a = mine.view(), b = theirs.view();
        same.add(k, std::span(&a, 1));
        other.add(k, std::span(&b, 1));
    }
    CHECK(same.value() == 0.0);
    CHECK(other.value() > 0.01);
    CHECK_THROWS_AS(study::ray_cast_plane_estimates(c.ref, pts, cam, 0), parameter_error);
}

TEST_CASE("the points' reference is cached under their hash and read back as computed", "[hemisphere][embree][study]") {
    const ceiling c;
    const auto pts = ceiling_points(8);
    study::point_reference_settings s;
    s.spp = 64;
    s.target = 0.5;
    s.scene_name = "half-lit-ceiling";
    s.cache_dir = std::filesystem::temp_directory_path() / "bounce-test-hemisphere-reference";
    std::filesystem::remove_all(s.cache_dir);
    const auto first = study::indirect_point_reference(c.ref, pts, s);
    const auto again = study::indirect_point_reference(c.ref, pts, s);
    CHECK_FALSE(first.from_cache);
    CHECK(again.from_cache);
    CHECK(again.irradiance == first.irradiance);
    CHECK(again.own_rel_rms == first.own_rel_rms);
    // Other points are another entry.
    auto other = pts;
    other.positions[0].x += 0.125f;
    const auto moved = study::indirect_point_reference(c.ref, other, s);
    CHECK_FALSE(moved.from_cache);
    std::filesystem::remove_all(s.cache_dir);
    s.target = std::nan("");
    CHECK_THROWS_AS(study::indirect_point_reference(c.ref, pts, s), parameter_error);
}
