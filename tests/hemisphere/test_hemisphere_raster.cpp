// The raster hemisphere sampler (gl::hemisphere_raster) and the plane kernels on the GPU:
// emitted kernels agree with their CPU instantiation; planes of a half-lit ceiling match the
// analytic plane texel by texel away from the edge; the GPU reduction agrees with the CPU
// sum; tiles of an atlas do not bleed; asynchronous read-backs come back in order.
#include "../core/half_lit_ceiling.hpp"
#include "../gl/shared_context.hpp"
#include "half_lit_ceiling_scene.hpp"
#include "raster_options.hpp"

#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/gl/kernel_map.hpp>
#include <bounce/gl/raster_record_sampler.hpp>
#include <bounce/cpu/plane_estimate.hpp>
#include <bounce/cache/plane_camera.hpp>
#include <bounce/cache/plane_weights.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <numbers>
#include <tuple>
#include <vector>

using namespace bounce;
using hemisphere_test::half_lit_ceiling_scene;

namespace {

constexpr double pi = std::numbers::pi;

template <real T>
T atan_kernel(T y, T x) {
    return atan(y, x);
}

// The analytic plane of that ceiling for a record at p = (px, 0, pz) with n = +y, in the
// frame the sampler uses (the camera's frame at p), eye offset by `offset` along n.
struct analytic_ceiling {
    float H, x_edge, L;  // L: radiance of the lit part
    glm::vec3 eye;
    std::array<glm::dvec3, 2> tb;  // the plane's x and y in world space
    analytic_ceiling(float H_, float x_edge_, float L_, const plane_camera& cam, glm::vec3 p, float offset)
        : H(H_), x_edge(x_edge_), L(L_), eye(p + glm::vec3(0, offset, 0)) {
        const auto f = cam.frame(p, glm::vec3(0, 1, 0));
        tb = {glm::dvec3(f[0]), glm::dvec3(f[1])};
    }
    std::pair<glm::vec3, float> trace(const glm::dvec3& d_local) const {
        const glm::dvec3 n(0, 1, 0);
        const glm::dvec3 d = tb[0] * d_local.x + tb[1] * d_local.y + n * d_local.z;
        const double t = (double(H) - eye.y) / d.y;
        const double x = eye.x + t * d.x;
        return {glm::vec3(x > x_edge ? L : 0.f), float(t)};
    }
};

struct rendered {
    image<glm::vec3> radiance;
    image<float> distance;
    plane_view view() const { return {radiance.view(), distance.view()}; }
};

rendered analytic_plane(const plane_camera& cam, const analytic_ceiling& c) {
    rendered p{image<glm::vec3>(cam.resolution, cam.resolution), image<float>(cam.resolution, cam.resolution)};
    sample_plane(cam, [&](const glm::dvec3& d) { return c.trace(d); }, p.radiance.view(), p.distance.view());
    return p;
}

// Whether the ceiling's edge x = x_edge crosses plane pixel (i, j) of a record whose eye is
// `eye` (n = +y): the ceiling point seen through plane point (u, v) is
// eye + h (t u + b v + n), so the edge is the line t.x u + b.x v = (x_edge - eye.x) / h.
bool edge_crosses_pixel(const plane_camera& cam, const analytic_ceiling& c, std::uint32_t i, std::uint32_t j) {
    const double k_edge = (c.x_edge - c.eye.x) / (c.H - c.eye.y);
    const auto side = [&](double u, double v) { return c.tb[0].x * u + c.tb[1].x * v > k_edge; };
    const auto b = plane_pixel_bounds<double>(i, j, cam.resolution, cam.half_extent());
    const bool s00 = side(b[0], b[1]);
    return s00 != side(b[2], b[1]) || s00 != side(b[0], b[3]) || s00 != side(b[2], b[3]);
}

// A half-lit ceiling (half_lit_ceiling_scene's parameters) on GL: its mesh, its light with
// shadow maps of `shadow_resolution`, and a hemisphere raster with `options`.
struct gl_ceiling {
    test::owned_scene scene;
    gl::scene_mesh mesh;
    gl::direct_light light;
    gl::hemisphere_raster raster;
    gl_ceiling(float H, float x_edge, float kd, float E_perp, int shadow_resolution,
               const gl::hemisphere_raster_options& options)
        : scene(half_lit_ceiling_scene(H, x_edge, kd, E_perp)), mesh(scene), light(scene, mesh, shadow_resolution),
          raster(scene, mesh, light, options) {}
};

}  // namespace

TEST_CASE("plane kernels print to GLSL and agree with the CPU", "[hemisphere][gl][agreement]") {
    gl_test::shared_context();
    pcg32 rng(31);
    using glsl::f32;
    using glsl::vec2;
    using glsl::vec3;
    // Rectangles on [-4, 4]^2 (apertures up to 152 deg and the side planes).
    std::vector<std::tuple<float, float, float, float>> rects;
    for (int i = 0; i < 4000; ++i) {
        float u0 = float(8 * rng.next_double() - 4), u1 = float(8 * rng.next_double() - 4);
        float v0 = float(8 * rng.next_double() - 4), v1 = float(8 * rng.next_double() - 4);
        rects.emplace_back(std::min(u0, u1), std::min(v0, v1), std::max(u0, u1), std::max(v0, v1));
    }
    const auto moment = gl::map_kernel(rectangle_moment<f32, vec3>, rects);
    const auto omega = gl::map_kernel(rectangle_solid_angle<f32>, rects);
    // GLSL 4.50 leaves atan's precision to the implementation: measure the GPU's on the
    // arguments the corner functions pass (atan(v, sqrt(1 + u^2)), atan(u v, d)).
    std::vector<std::tuple<float, float>> atan_in;
    for (const auto& [u0, v0, u1, v1] : rects)
        for (const float u : {u0, u1})
            for (const float v : {v0, v1}) {
                atan_in.emplace_back(v, std::sqrt(1 + u * u));
                atan_in.emplace_back(u * v, std::sqrt(1 + u * u + v * v));
            }
    const auto gpu_atan = gl::map_kernel(atan_kernel<f32>, atan_in);
    double atan_error = 0;
    for (std::size_t k = 0; k < atan_in.size(); ++k)
        atan_error = std::max(atan_error, std::abs(double(gpu_atan[k]) - std::atan2(double(std::get<0>(atan_in[k])),
                                                                                       double(std::get<1>(atan_in[k])))));
    double worst = 0;
    for (std::size_t k = 0; k < rects.size(); ++k) {
        const auto [u0, v0, u1, v1] = rects[k];
        const glm::dvec3 m = rectangle_moment<double, glm::dvec3>(u0, v0, u1, v1);
        const double o = rectangle_solid_angle<double>(u0, v0, u1, v1);
        worst = std::max({worst, glm::length(glm::dvec3(moment[k]) - m), std::abs(double(omega[k]) - o)});
    }
    // Each output sums four corner values, each an atan times a factor of magnitude <= 1
    // (u / cu, 1 / (2 cu) ...) plus float rounding of values <= pi/2 (a few ulps, 2e-7 each):
    // 4 (atan_error + 4 ulp(pi/2)) bounds every component, sqrt(3) that for the vector.
    const double bound = std::sqrt(3.0) * 4 * (atan_error + 4 * 0x1p-23 * pi / 2);
    CAPTURE(worst, atan_error, bound);
    CHECK(worst <= bound);
    CHECK(atan_error < 1e-5);  // and the GPU's atan is usable (about 10 float ulps of pi/2)

    // plane_pixel_terms: weights of unit size, radiance in [0, 2), distances in (0.1, 10) or
    // escaped (+infinity); every output is a product of O(1) values and 1/r <= 10: a few
    // float ulps of 10 at most.
    using args = std::tuple<float, float, glm::vec2, glm::vec2, glm::vec2, glm::vec2, glm::vec3, glm::vec3, glm::vec3,
                            float, float, float>;
    std::vector<args> in;
    const auto rnd = [&] { return float(rng.next_double()); };
    const auto dist = [&] {
        return rng.next_double() < 0.1 ? std::numeric_limits<float>::infinity() : float(0.1 + 9.9 * rng.next_double());
    };
    for (int i = 0; i < 4000; ++i)
        in.emplace_back(rnd(), rnd(), glm::vec2(rnd() - .5f, rnd() - .5f), glm::vec2(rnd(), rnd()),
                        glm::vec2(rnd(), -rnd()), glm::vec2(rnd() - .5f, rnd() - .5f),
                        glm::vec3(2 * rnd(), 2 * rnd(), 2 * rnd()), glm::vec3(2 * rnd(), 2 * rnd(), 2 * rnd()),
                        glm::vec3(2 * rnd(), 2 * rnd(), 2 * rnd()), dist(), dist(), dist());
    const auto gpu = gl::map_kernel(plane_pixel_terms<f32, vec3, vec2>, in);
    double worst_terms = 0;
    for (std::size_t k = 0; k < in.size(); ++k) {
        const auto cpu = std::apply(plane_pixel_terms<float, glm::vec3, glm::vec2>, in[k]);
        const auto& g = gpu[k];
        worst_terms = std::max({worst_terms, double(glm::length(std::get<0>(g) - std::get<0>(cpu))),
                                double(glm::length(std::get<1>(g) - std::get<1>(cpu))),
                                double(glm::length(std::get<2>(g) - std::get<2>(cpu))),
                                double(glm::length(std::get<3>(g) - std::get<3>(cpu))),
                                double(glm::length(std::get<4>(g) - std::get<4>(cpu))),
                                double(std::abs(std::get<5>(g) - std::get<5>(cpu))),
                                double(std::abs(std::get<6>(g) - std::get<6>(cpu)))});
    }
    CAPTURE(worst_terms);
    CHECK(worst_terms < 1e-5);
}

TEST_CASE("rasterized planes of a half-lit ceiling match the analytic plane, and both sums agree", "[hemisphere][gl]") {
    gl_test::shared_context();
    const float H = 1.5f, x_edge = 0.4f, kd = 0.75f, E_perp = 2.f;
    const float L = kd / float(pi) * E_perp;
    const auto N = GENERATE(16u, 64u);
    const auto aperture = GENERATE(90.0, 126.0, 150.0);
    const bool hashed = GENERATE(false, true);  // planes in orthonormal_basis(n), or each turned its own way
    const auto options = raster_options(N, aperture, 7, 1e-3f, hashed ? 10.0 : 0.0, hashed);  // 3 x 3 atlas, two tiles unused
    gl_ceiling g(H, x_edge, kd, E_perp, 512, options);
    gl::hemisphere_raster& raster = g.raster;
    pcg32 rng(N + unsigned(aperture));
    std::vector<glm::vec3> positions, normals;
    for (std::size_t k = 0; k < options.batch; ++k) {
        positions.emplace_back(float(4 * rng.next_double() - 2), 0.f, float(4 * rng.next_double() - 2));
        normals.emplace_back(0.f, 1.f, 0.f);
    }
    raster.render(positions, normals);
    raster.start_read();
    const auto gpu_stretch = [&] {
        raster.set_weights(make_plane_weights(options.camera, plane_weighting::stretch));
        return raster.reduce();
    }();
    const auto batch = raster.finish_read();
    REQUIRE(batch.size() == options.batch);
    const auto stretch = make_plane_weights(options.camera, plane_weighting::stretch);
    for (std::size_t k = 0; k < batch.size(); ++k) {
        const analytic_ceiling c(H, x_edge, L, options.camera, positions[k], options.offset);
        const auto expected = analytic_plane(options.camera, c);
        // Texel by texel: radiance equal except in texels the edge crosses (the rasterizer and
        // the analytic test may put a texel centre on different sides of it); distances to
        // the float rounding of the interpolated position (|p| <= 2000: 1e-4 relative).
        std::size_t mismatched_away_from_edge = 0;
        double worst_distance = 0;
        for (std::uint32_t j = 0; j < N; ++j)
            for (std::uint32_t i = 0; i < N; ++i) {
                const bool crossed = edge_crosses_pixel(options.camera, c, i, j);
                const glm::vec3 got = batch.radiance[k](i, j), want = expected.radiance(i, j);
                if (!crossed && glm::length(got - want) > 1e-5f * L) ++mismatched_away_from_edge;
                worst_distance = std::max(
                    worst_distance, std::abs(double(batch.distance[k](i, j)) / double(expected.distance(i, j)) - 1));
            }
        CAPTURE(k, N, aperture, hashed, mismatched_away_from_edge, worst_distance);
        CHECK(mismatched_away_from_edge == 0);
        CHECK(worst_distance < 1e-4);
        // CPU sum (double, from the read-back) and GPU reduction (float): sums of N^2 float
        // terms of size <= max weight * L; float accumulation in 256 partial sums and a tree
        // keeps the relative error within a few 1e-7 per level: 1e-5 relative covers it.
        const auto cpu = cpu::estimate_plane(stretch, batch.view(k));
        const auto& gpu = gpu_stretch[k];
        CHECK(gpu.irradiance.x == Approx(cpu.irradiance.x).epsilon(1e-5));
        CHECK(gpu.irradiance.z == Approx(cpu.irradiance.z).epsilon(1e-5));
        const double scale = cpu.irradiance.x + 1e-3;  // the gradients' natural size, per unit length
        CHECK(glm::length(gpu.rotation[0] - cpu.rotation[0]) < 1e-5 * scale);
        CHECK(glm::length(gpu.translation[0] - cpu.translation[0]) < 1e-5 * scale / H);
        CHECK(gpu.harmonic_mean_distance == Approx(cpu.harmonic_mean_distance).epsilon(1e-5));
    }
}

TEST_CASE("asynchronous read-backs return each batch's planes in order", "[hemisphere][gl]") {
    gl_test::shared_context();
    const auto options = raster_options(8, 120.0, 3, 0.f);
    gl_ceiling g(2.f, 0.f, 0.5f, 1.f, 256, options);
    gl::hemisphere_raster& raster = g.raster;
    CHECK_THROWS_AS(raster.start_read(), parameter_error);  // nothing rendered
    CHECK_THROWS_AS(raster.finish_read(), parameter_error);  // nothing pending
    const std::vector<glm::vec3> up(3, glm::vec3(0, 1, 0));
    // Batch A sees the lit side only (x >> 0), batch B the dark side only.
    const std::vector<glm::vec3> lit = {{30, 0, 0}, {40, 0, 1}, {50, 0, 2}}, dark = {{-30, 0, 0}, {-40, 0, 1}};
    raster.render(lit, up);
    raster.start_read();
    raster.render(dark, std::span(up).first(2));
    raster.start_read();
    CHECK(raster.pending_reads() == 2);
    CHECK_THROWS_AS(raster.start_read(), parameter_error);  // both buffers in flight
    const auto a = raster.finish_read(), b = raster.finish_read();
    REQUIRE(a.size() == 3);
    REQUIRE(b.size() == 2);
    const float L = 0.5f / float(pi);
    for (std::size_t k = 0; k < 3; ++k) CHECK(a.radiance[k](4, 4).x == Approx(L).epsilon(1e-6));
    for (std::size_t k = 0; k < 2; ++k) CHECK(b.radiance[k](4, 4).x == 0.f);
    CHECK(raster.pending_reads() == 0);
    // Bad input.
    CHECK_THROWS_AS(raster.render({}, {}), parameter_error);
    const std::vector<glm::vec3> four(4, glm::vec3(0, 1, 0));
    CHECK_THROWS_AS(raster.render(four, four), parameter_error);  // over capacity
    CHECK_THROWS_AS(raster.render(lit, std::vector<glm::vec3>(3, glm::vec3(0, 2, 0))), parameter_error);
    CHECK_THROWS_AS(raster.set_weights(make_plane_weights(plane_camera{9, 120.0}, plane_weighting::stretch)),
                    parameter_error);
    gl::hemisphere_raster_options bad = options;
    bad.batch = 0;
    CHECK_THROWS_AS(gl::hemisphere_raster(g.scene, g.mesh, g.light, bad), parameter_error);
    bad = options;
    bad.camera.aperture_deg = 180.0;
    CHECK_THROWS_AS(gl::hemisphere_raster(g.scene, g.mesh, g.light, bad), parameter_error);
}

TEST_CASE("the raster record sampler makes the same records one at a time and in atlas batches", "[hemisphere][gl][record]") {
    gl_test::shared_context();
    const float H = 1.5f, x_edge = 0.4f, kd = 0.75f, E_perp = 2.f;
    const auto options = raster_options(32, 126.0, 4, 1e-3f);
    gl_ceiling g(H, x_edge, kd, E_perp, 512, options);
    radius_limits limits;
    gl::raster_record_sampler sampler(g.raster, limits);
    pcg32 rng(9);
    std::vector<glm::vec3> p, n;
    std::vector<double> footprint;
    for (int k = 0; k < 11; ++k) {  // 11 records: batches of 4, 4 and 3
        // Two statements: the order of a call's arguments is unspecified (GCC and Clang differ).
        const float z = float(4 * rng.next_double() - 2);
        p.emplace_back(float(4 * rng.next_double() - 2), 0.f, z);
        n.emplace_back(0.f, 1.f, 0.f);
        footprint.push_back(1e-3);
    }
    std::vector<std::optional<irradiance_record>> batched(p.size());
    sampler(p, n, footprint, batched);
    const auto stretch = make_plane_weights(options.camera, plane_weighting::stretch);
    const float L = kd / float(pi) * E_perp;
    for (std::size_t k = 0; k < p.size(); ++k) {
        const auto one = sampler(p[k], n[k], footprint[k]);
        REQUIRE(one.has_value());
        REQUIRE(batched[k].has_value());
        // Same plane in another tile of the atlas: the tile placement's rounding only.
        for (int c = 0; c < 3; ++c) CHECK(batched[k]->irradiance[c] == Approx(one->irradiance[c]).epsilon(1e-5));
        CHECK(batched[k]->radius == Approx(one->radius).epsilon(1e-5));
        // The estimate from the analytic plane: the raster plane differs only in texels the
        // edge crosses (test above), each by at most L, so by at most L times their weights.
        const analytic_ceiling c(H, x_edge, L, options.camera, p[k], options.offset);
        const auto analytic = cpu::estimate_plane(stretch, analytic_plane(options.camera, c).view());
        double crossed = 0;
        for (std::uint32_t j = 0; j < options.camera.resolution; ++j)
            for (std::uint32_t i = 0; i < options.camera.resolution; ++i)
                if (edge_crosses_pixel(options.camera, c, i, j)) crossed += stretch.irradiance[j * options.camera.resolution + i];
        CAPTURE(k, crossed);
        CHECK(std::abs(batched[k]->irradiance.x - analytic.irradiance.x) <= L * crossed + 1e-5 * analytic.irradiance.x);
        // The closed form of the half-lit ceiling, E = (pi L / 2)(1 + x0 / sqrt(x0^2 + H^2)),
        // x0 the distance past the edge. Stretching gives a band direction its border pixel's
        // radiance and a pixel its centre's, each in [0, L]: they can be wrong only in the band
        // (cosine-weighted solid angle pi - plane) and in the pixels the edge crosses.
        const double x0 = double(c.eye.x - x_edge);
        const double exact = pi * L / 2 * (1 + x0 / std::sqrt(x0 * x0 + double(H - c.eye.y) * (H - c.eye.y)));
        const double crossed_or_band = crossed + pi - plane_cosine_solid_angle(options.camera.aperture_deg);
        CHECK(std::abs(analytic.irradiance.x - exact) <= L * crossed_or_band + 1e-9);
    }
    std::vector<std::optional<irradiance_record>> wrong(2);
    CHECK_THROWS_AS(sampler(p, n, footprint, wrong), parameter_error);
}

TEST_CASE("the raster record sampler's fall-off kappa moves the band between plane and stretching", "[hemisphere][gl][record]") {
    gl_test::shared_context();
    gl_ceiling g(1.5f, 0.4f, 0.75f, 2.f, 512, raster_options(16, 126.0, 2, 1e-3f));
    gl::hemisphere_raster& raster = g.raster;
    const radius_limits limits;
    // Four samplers on one raster, called in turn: each must sum with its own weights.
    gl::raster_record_sampler stretch(raster, limits), none(raster, limits, plane_weighting::falloff, 0.0),
        half(raster, limits, plane_weighting::falloff, 0.5), full(raster, limits, plane_weighting::falloff, 1.0);
    pcg32 rng(4);
    for (int k = 0; k < 20; ++k) {
        const float x = float(4 * rng.next_double() - 2);
        const glm::vec3 p(x, 0.f, float(4 * rng.next_double() - 2)), n(0.f, 1.f, 0.f);
        const auto e1 = stretch(p, n, 1e-3), e0 = none(p, n, 1e-3), eh = half(p, n, 1e-3), ef = full(p, n, 1e-3);
        REQUIRE((e1 && e0 && eh && ef));
        CAPTURE(k, x);
        // E is linear in kappa; kappa = 1 is stretching. Float sums on the GPU: 1e-5 relative.
        CHECK(ef->irradiance.x == Approx(e1->irradiance.x).epsilon(1e-5));
        CHECK(eh->irradiance.x == Approx(0.5f * (e0->irradiance.x + e1->irradiance.x)).epsilon(1e-5).margin(1e-6));
        // The lit half of the ceiling reaches the horizon on one side, so the band always
        // sees light (at least 2% of E here): less kappa, less irradiance.
        CHECK(e0->irradiance.x < 0.98f * e1->irradiance.x);
    }
    CHECK_THROWS_AS(gl::raster_record_sampler(raster, limits, plane_weighting::stretch, 0.5), parameter_error);
    CHECK_THROWS_AS(gl::raster_record_sampler(raster, limits, plane_weighting::falloff, 1.5), parameter_error);
    CHECK_THROWS_AS(gl::raster_record_sampler(raster, limits, plane_weighting::falloff, std::nan("")), parameter_error);
}

TEST_CASE("turned raster planes give world-space records of the half-lit ceiling's closed forms", "[hemisphere][gl][record]") {
    gl_test::shared_context();
    const float H = 1.5f, x_edge = 0.4f, kd = 0.75f, E_perp = 2.f;
    const double L = double(kd / float(pi) * E_perp);
    const double turn = GENERATE(0.0, 30.0, 45.0);
    const bool hashed = GENERATE(false, true);
    const auto options = raster_options(64, 126.0, 4, 1e-3f, turn, hashed);
    gl_ceiling g(H, x_edge, kd, E_perp, 512, options);
    gl::raster_record_sampler sampler(g.raster, radius_limits{});
    pcg32 rng(17);
    for (int k = 0; k < 12; ++k) {
        const float x = float(4 * rng.next_double() - 2);
        const glm::vec3 p(x, 0.f, float(4 * rng.next_double() - 2)), n(0.f, 1.f, 0.f);
        const auto rec = sampler(p, n, 1e-3);
        REQUIRE(rec.has_value());
        // The plane sees the core test's ceiling (ceiling_seen_from). Its closed forms do not
        // depend on the frame: the rotation gradient is rot_y (n x world x) = rot_y (0, 0, -1). An
        // estimate from the analytic plane is within L times the mixed cells' weights of
        // them; the raster plane differs from the analytic one in those cells only, by at
        // most L each: twice the bound. A record expressed in the wrong frame would be off
        // by 2 sin(turn / 2) |rot_y| (52% at 30 deg).
        const auto hc = hemisphere_test::ceiling_seen_from(options.camera, p, H, options.offset, x_edge, L);
        const auto bound = ceiling_test::mixed_cells(options.camera, hc, true);
        CAPTURE(k, x, turn, hashed, options.camera.turn_at(p), rec->irradiance.x, hc.E(), bound.E, bound.rotation);
        CHECK(std::abs(double(rec->irradiance.x) - hc.E()) <= 2 * L * bound.E + 1e-5 * hc.E());
        CHECK(glm::length(glm::dvec3(rec->rotation[0]) - hc.rot_y() * glm::dvec3(0, 0, -1)) <=
              2 * L * bound.rotation + 1e-5 * hc.E());
    }
}
