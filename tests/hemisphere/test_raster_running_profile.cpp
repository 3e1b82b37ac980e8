// gl::raster_record_sampler's fall-off modes: the running radial profile (each batch summed
// with the kappa of every plane rendered so far, its own included, as hemisphere_study has
// measured it) against a radial_profile fed the same planes by hand, the fixed modes against
// the raster's own render-and-reduce, and the options it refuses.
#include "../gl/shared_context.hpp"
#include "half_lit_ceiling_scene.hpp"

#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/gl/raster_record_sampler.hpp>
#include <bounce/cache/plane_weights.hpp>
#include <bounce/cache/radial_profile.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

using namespace bounce;
using hemisphere_test::half_lit_ceiling_scene;

namespace {

// The half-lit ceiling (half_lit_ceiling_scene.hpp: lit for x > 0.4, 1.5 above the records)
// on GL, with a raster of 16^2 planes at 126 degrees, `batch` planes per atlas.
struct running_ceiling {
    test::owned_scene scene;
    gl::scene_mesh mesh;
    gl::direct_light light;
    gl::hemisphere_raster raster;
    explicit running_ceiling(std::size_t batch)
        : scene(half_lit_ceiling_scene(1.5f, 0.4f, 0.75f, 2.f)), mesh(scene), light(scene, mesh, 512),
          raster(scene, mesh, light, gl::hemisphere_raster_options{{16, 126.0}, batch, 1e-3f}) {}
};

// `count` records looking up (n = +y) at x in [x0, x1], z in [-2, 2].
struct record_points {
    std::vector<glm::vec3> p, n;
    std::vector<double> footprint;
    record_points(pcg32& rng, std::size_t count, float x0, float x1) {
        for (std::size_t k = 0; k < count; ++k) {
            // Two statements: the order of a call's arguments is unspecified.
            const float x = x0 + (x1 - x0) * float(rng.next_double());
            p.emplace_back(x, 0.f, float(4 * rng.next_double() - 2));
            n.emplace_back(0.f, 1.f, 0.f);
            footprint.push_back(1e-3);
        }
    }
};

// The name parameter_error gives for what `f` does, or "(accepted)".
std::string refused_parameter(const std::function<void()>& f) {
    try {
        f();
    } catch (const parameter_error& e) {
        return e.parameter();
    }
    return "(accepted)";
}

bool same_record(const std::optional<irradiance_record>& a, const std::optional<irradiance_record>& b) {
    if (a.has_value() != b.has_value()) return false;
    if (!a) return true;
    bool same = a->irradiance == b->irradiance && a->radius == b->radius;
    for (int c = 0; c < 3; ++c) same = same && a->rotation[c] == b->rotation[c] && a->translation[c] == b->translation[c];
    return same;
}

}  // namespace

TEST_CASE("the running fall-off profile takes, per batch, the kappa of a radial profile fed every plane so far",
          "[hemisphere][gl][record][running]") {
    gl_test::shared_context();
    running_ceiling g(3);
    gl::hemisphere_raster& raster = g.raster;
    const plane_camera& cam = raster.options().camera;
    gl::raster_record_sampler running(raster, radius_limits{}, {plane_weighting::falloff, gl::falloff_mode::running});
    // Before any plane the profile is empty and the band is stretched (kappa 1).
    CHECK(running.falloff_kappa() == 1.0);
    CHECK(running.profile().planes() == 0);

    // Three calls: 4 records (batches of 3 and 1) on the lit side near the edge, whose planes
    // darken towards the border (the dark half creeps in from one side), then 3 across the
    // edge, then 2 on the dark side.
    pcg32 rng(15);
    const std::vector<record_points> calls = {record_points(rng, 4, 0.5f, 1.5f), record_points(rng, 3, -1.f, 1.5f),
                                              record_points(rng, 2, -2.f, 0.f)};
    radial_profile by_hand(cam);
    std::size_t interior = 0;  // batches whose kappa is inside (0, 1): the fit, not a clamp
    for (const record_points& call : calls) {
        std::vector<hemisphere_estimate> est(call.p.size());
        std::vector<double> kappas(call.p.size());
        running.estimate(call.p, call.n, est, kappas);
        for (std::size_t first = 0; first < call.p.size(); first += raster.capacity()) {
            const std::size_t count = std::min(raster.capacity(), call.p.size() - first);
            const auto p = std::span(call.p).subspan(first, count), n = std::span(call.n).subspan(first, count);
            // The same batch again: the same draw into the same tiles gives the same texels, and
            // its planes join the hand-fed profile in the order the sampler adds them, so the
            // kappas are equal, not merely close.
            raster.render(p, n);
            raster.start_read();
            const gl::plane_batch planes = raster.finish_read();
            for (std::size_t k = 0; k < planes.size(); ++k) by_hand.add(planes.radiance[k].view());
            const double kappa = by_hand.falloff_factor();
            CAPTURE(first, kappa);
            for (std::size_t k = first; k < first + count; ++k) CHECK(kappas[k] == kappa);
            if (kappa > 0.0 && kappa < 1.0) ++interior;
            // Summed with the matching table: the raster's own reduction with kappa's weights.
            raster.set_weights(make_plane_weights(cam, plane_weighting::falloff, kappa));
            const std::vector<hemisphere_estimate> direct = raster.reduce();
            for (std::size_t k = 0; k < count; ++k) {
                CHECK(est[first + k].irradiance == direct[k].irradiance);
                CHECK(est[first + k].harmonic_mean_distance == direct[k].harmonic_mean_distance);
                for (int c = 0; c < 3; ++c) CHECK(est[first + k].translation[c] == direct[k].translation[c]);
            }
        }
        CHECK(running.profile().planes() == by_hand.planes());
        CHECK(running.falloff_kappa() == by_hand.falloff_factor());
    }
    CHECK(by_hand.planes() == 9);
    // Without batches whose kappa is a fitted value, the equalities above would hold with the
    // clamps alone.
    CHECK(interior >= 2);
}

TEST_CASE("the running profile's first batch takes the kappa of its own planes, not stretching's",
          "[hemisphere][gl][record][running]") {
    gl_test::shared_context();
    running_ceiling g(4);
    const plane_camera& cam = g.raster.options().camera;
    pcg32 rng(2);
    const record_points lit(rng, 4, 0.5f, 1.5f);
    gl::raster_record_sampler running(g.raster, radius_limits{}, {plane_weighting::falloff, gl::falloff_mode::running});
    std::vector<std::optional<irradiance_record>> records(4);
    running(lit.p, lit.n, lit.footprint, records);
    const double kappa = running.falloff_kappa();
    // The lit side's planes darken towards their border (the dark half enters their outer
    // rings from one side), so their profile's kappa is below stretching's 1: 0.94 here, which
    // 0.99 tells apart from 1 with room for the shadow maps' and llvmpipe's variations.
    CHECK(kappa < 0.99);
    // The first batch is summed with it: its records are those of a fixed sampler at that kappa,
    // and the band those records carry is less than stretching's.
    gl::raster_record_sampler fixed(g.raster, radius_limits{}, plane_weighting::falloff, kappa), stretch(g.raster, radius_limits{});
    std::vector<std::optional<irradiance_record>> at_kappa(4), stretched(4);
    fixed(lit.p, lit.n, lit.footprint, at_kappa);
    stretch(lit.p, lit.n, lit.footprint, stretched);
    for (std::size_t k = 0; k < 4; ++k) {
        CAPTURE(k);
        REQUIRE(records[k].has_value());
        CHECK(same_record(records[k], at_kappa[k]));
        CHECK(records[k]->irradiance.x < stretched[k]->irradiance.x);
    }
    // One record at a time, each call is a batch of one plane that joins the profile first.
    gl::raster_record_sampler one_by_one(g.raster, radius_limits{}, {plane_weighting::falloff, gl::falloff_mode::running});
    radial_profile first_plane(cam);
    (void)one_by_one(lit.p[0], lit.n[0], 1e-3);
    g.raster.render(std::span(lit.p).first(1), std::span(lit.n).first(1));
    g.raster.start_read();
    first_plane.add(g.raster.finish_read().radiance[0].view());
    CHECK(one_by_one.falloff_kappa() == first_plane.falloff_factor());
    CHECK(one_by_one.profile().planes() == 1);
}

TEST_CASE("the fixed fall-off modes are the raster's render and reduction with their table, and keep no profile",
          "[hemisphere][gl][record][running]") {
    gl_test::shared_context();
    running_ceiling g(3);
    gl::hemisphere_raster& raster = g.raster;
    const plane_camera& cam = raster.options().camera;
    pcg32 rng(7);
    const record_points pts(rng, 5, -2.f, 2.f);
    struct mode {
        plane_weighting kind;
        double kappa;
    };
    for (const mode m : {mode{plane_weighting::plane, 1.0}, mode{plane_weighting::coverage, 1.0},
                         mode{plane_weighting::stretch, 1.0}, mode{plane_weighting::falloff, 0.6}}) {
        CAPTURE(to_string(m.kind), m.kappa);
        gl::raster_record_sampler from_options(raster, radius_limits{}, {m.kind, gl::falloff_mode::fixed, m.kappa}),
            from_arguments(raster, radius_limits{}, m.kind, m.kappa);
        const plane_weights table = make_plane_weights(cam, m.kind, m.kappa);
        CHECK(from_options.falloff_kappa() == table.band_factor);
        std::vector<std::optional<irradiance_record>> a(5), b(5), again(5);
        from_options(pts.p, pts.n, pts.footprint, a);
        from_arguments(pts.p, pts.n, pts.footprint, b);
        from_options(pts.p, pts.n, pts.footprint, again);  // a pure function of the points
        for (std::size_t first = 0; first < 5; first += raster.capacity()) {
            const std::size_t count = std::min(raster.capacity(), 5 - first);
            raster.render(std::span(pts.p).subspan(first, count), std::span(pts.n).subspan(first, count));
            raster.set_weights(table);
            const auto est = raster.reduce();
            for (std::size_t k = first; k < first + count; ++k) {
                const auto tb = cam.frame(pts.p[k], pts.n[k]);
                std::optional<irradiance_record> direct =
                    make_record(pts.p[k], pts.n[k], tb[0], tb[1], est[k - first], radius_limits{}, pts.footprint[k]);
                if (!(std::isfinite(direct->radius) && direct->radius > 0.f)) direct.reset();
                CAPTURE(k);
                CHECK(same_record(a[k], direct));
                CHECK(same_record(b[k], direct));
                CHECK(same_record(again[k], direct));
            }
        }
        CHECK(from_options.profile().planes() == 0);
        CHECK(from_options.falloff_kappa() == table.band_factor);
    }
}

TEST_CASE("the raster record sampler refuses bad fall-off options, naming them", "[hemisphere][gl][record][running]") {
    gl_test::shared_context();
    running_ceiling g(2);
    gl::hemisphere_raster& raster = g.raster;
    using gl::falloff_mode;
    const auto make = [&](gl::raster_record_sampler_options o) {
        return [&raster, o] { gl::raster_record_sampler s(raster, radius_limits{}, o); };
    };
    CHECK(refused_parameter(make({plane_weighting::falloff, falloff_mode::fixed, 1.5})) == "kappa");
    CHECK(refused_parameter(make({plane_weighting::falloff, falloff_mode::fixed, -0.1})) == "kappa");
    CHECK(refused_parameter(make({plane_weighting::falloff, falloff_mode::fixed, std::nan("")})) == "kappa");
    CHECK(refused_parameter(make({plane_weighting::stretch, falloff_mode::fixed, 0.5})) == "kappa");
    CHECK(refused_parameter(make({plane_weighting::stretch, falloff_mode::running, 1.0})) == "falloff");
    CHECK(refused_parameter(make({plane_weighting::falloff, falloff_mode::running, 0.8})) == "kappa");
    CHECK(refused_parameter(make({plane_weighting::falloff, falloff_mode(7), 1.0})) == "falloff");
    CHECK(refused_parameter(make({plane_weighting::falloff, falloff_mode::running, 1.0})) == "(accepted)");
    CHECK(refused_parameter(make({plane_weighting::falloff, falloff_mode::fixed, 0.0})) == "(accepted)");

    gl::raster_record_sampler running(raster, radius_limits{}, {plane_weighting::falloff, falloff_mode::running});
    const std::vector<glm::vec3> p = {{1, 0, 0}, {2, 0, 0}}, n(2, glm::vec3(0, 1, 0));
    std::vector<hemisphere_estimate> est(2), one(1);
    std::vector<double> kappas(1);
    CHECK(refused_parameter([&] { running.estimate(p, n, one, {}); }) == "points");
    CHECK(refused_parameter([&] { running.estimate(p, n, est, kappas); }) == "kappas");
    // A read someone else started would be collected as this batch's planes.
    raster.render(p, n);
    raster.start_read();
    CHECK(refused_parameter([&] { running.estimate(p, n, est, {}); }) == "raster");
    (void)raster.finish_read();
    CHECK(refused_parameter([&] { running.estimate(p, n, est, {}); }) == "(accepted)");
    CHECK(running.profile().planes() == 2);
}
