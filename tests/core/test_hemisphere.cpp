// Single-plane hemisphere sampling (bounce/rectangle_solid_angle.hpp, cache/plane_pixel.hpp,
// cache/plane_camera.hpp, cache/plane_weights.hpp, cache/radial_profile.hpp, cpu/plane_estimate.hpp): the
// rectangle closed forms against quadrature, the three weight tables' totals against
// closed forms, exact answers for uniform and half-space environments, and irradiance,
// gradients and harmonic mean distance of a half-lit ceiling against the closed forms of
// test_irradiance_gradients.
#include "half_lit_ceiling.hpp"

#include <bounce/cpu/plane_estimate.hpp>
#include <bounce/luminance.hpp>
#include <bounce/cache/plane_camera.hpp>
#include <bounce/cache/plane_pixel.hpp>
#include <bounce/cache/plane_weights.hpp>
#include <bounce/cache/radial_profile.hpp>
#include <bounce/rectangle_solid_angle.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

using namespace bounce;
using namespace bounce::ceiling_test;

namespace {

constexpr double pi = std::numbers::pi;

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n from the Chebyshev guesses).
struct gauss_legendre {
    std::vector<double> x, w;
    explicit gauss_legendre(int n) {
        for (int k = 0; k < n; ++k) {
            double t = std::cos(pi * (k + 0.75) / (n + 0.5)), dp = 0;
            for (int it = 0; it < 100; ++it) {
                double p0 = 1, p1 = t;
                for (int m = 2; m <= n; ++m) {
                    const double p2 = ((2 * m - 1) * t * p1 - (m - 1) * p0) / m;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n * (t * p1 - p0) / (t * t - 1);
                const double step = p1 / dp;
                t -= step;
                if (std::abs(step) < 1e-16) break;
            }
            x.push_back(t);
            w.push_back(2 / ((1 - t * t) * dp * dp));
        }
    }
};

// Integral of f(u, v) over [u0, u1] x [v0, v1]: 16-point Gauss-Legendre on an 8 x 8 grid of
// sub-rectangles. The integrands here are analytic with poles at distance >= 1 from the real
// plane (1 + u^2 + v^2 = 0), so on sub-rectangles of side <= 1/2 the rule converges
// geometrically; 16 points leave an error far below 1e-13 of the integral.
double integrate(const std::function<double(double, double)>& f, double u0, double v0, double u1, double v1) {
    static const gauss_legendre g(16);
    const int parts = 8;
    double sum = 0;
    for (int pu = 0; pu < parts; ++pu)
        for (int pv = 0; pv < parts; ++pv) {
            const double a0 = u0 + (u1 - u0) * pu / parts, a1 = u0 + (u1 - u0) * (pu + 1) / parts;
            const double b0 = v0 + (v1 - v0) * pv / parts, b1 = v0 + (v1 - v0) * (pv + 1) / parts;
            for (std::size_t i = 0; i < g.x.size(); ++i)
                for (std::size_t k = 0; k < g.x.size(); ++k) {
                    const double u = (a0 + a1) / 2 + (a1 - a0) / 2 * g.x[i];
                    const double v = (b0 + b1) / 2 + (b1 - b0) / 2 * g.x[k];
                    sum += g.w[i] * g.w[k] * (a1 - a0) * (b1 - b0) / 4 * f(u, v);
                }
        }
    return sum;
}

// A random sub-interval [lo, hi] of [-3, 3], sometimes degenerate or touching 0.
std::pair<double, double> random_interval(pcg32& rng) {
    double lo = 6 * rng.next_double() - 3, hi = 6 * rng.next_double() - 3;
    if (lo > hi) std::swap(lo, hi);
    const double pick = rng.next_double();
    if (pick < 0.05) hi = lo;   // empty
    else if (pick < 0.1) lo = 0;  // a corner on the axis
    if (lo > hi) std::swap(lo, hi);
    return {lo, hi};
}

// Planes rendered by a function of the local direction.
struct rendered_plane {
    image<glm::vec3> radiance;
    image<float> distance;
    plane_view view() const { return {radiance.view(), distance.view()}; }
};
template <class F>
rendered_plane render(const plane_camera& cam, F&& trace) {
    rendered_plane p{image<glm::vec3>(cam.resolution, cam.resolution), image<float>(cam.resolution, cam.resolution)};
    sample_plane(cam, std::forward<F>(trace), p.radiance.view(), p.distance.view());
    return p;
}

}  // namespace

TEST_CASE("the rectangle closed forms are the integrals of solid angle and direction", "[hemisphere][closed-form]") {
    pcg32 rng(401);
    for (int c = 0; c < 200; ++c) {
        const auto [u0, u1] = random_interval(rng);
        const auto [v0, v1] = random_interval(rng);
        CAPTURE(u0, u1, v0, v1);
        const auto d = [](double u, double v) { return std::sqrt(1 + u * u + v * v); };
        const double omega = integrate([&](double u, double v) { return 1 / std::pow(d(u, v), 3); }, u0, v0, u1, v1);
        const double mw = integrate([&](double u, double v) { return 1 / std::pow(d(u, v), 4); }, u0, v0, u1, v1);
        const double mu = integrate([&](double u, double v) { return u / std::pow(d(u, v), 4); }, u0, v0, u1, v1);
        const double mv = integrate([&](double u, double v) { return v / std::pow(d(u, v), 4); }, u0, v0, u1, v1);
        const glm::dvec3 m = rectangle_moment<double, glm::dvec3>(u0, v0, u1, v1);
        // Corner sums of O(1) values: absolute error ~1e-15; the quadrature's is below 1e-13.
        CHECK(std::abs(rectangle_solid_angle<double>(u0, v0, u1, v1) - omega) < 1e-12);
        CHECK(std::abs(m.z - mw) < 1e-12);
        CHECK(std::abs(m.x - mu) < 1e-12);
        CHECK(std::abs(m.y - mv) < 1e-12);
        CHECK(rectangle_cosine_solid_angle<double, glm::dvec3>(u0, v0, u1, v1) == m.z);
        // float instantiation (what GLSL computes): corners of magnitude <= pi/2 cancel, so
        // the absolute error is a few float ulps of pi/2.
        const glm::vec3 mf = rectangle_moment<float, glm::vec3>(float(u0), float(v0), float(u1), float(v1));
        CHECK(std::abs(double(mf.z) - mw) < 2e-6);
        CHECK(std::abs(double(rectangle_solid_angle<float>(float(u0), float(v0), float(u1), float(v1))) - omega) < 2e-6);
    }
}

TEST_CASE("pixels tile the plane: solid angles and cosine weights sum to the plane's closed forms", "[hemisphere][closed-form]") {
    const auto N = GENERATE(1u, 2u, 3u, 16u, 64u, 127u);
    const auto aperture = GENERATE(0.5, 60.0, 90.0, 126.0, 150.0, 179.0);
    CAPTURE(N, aperture);
    const plane_camera cam{N, aperture};
    const double a = cam.half_extent();
    double omega = 0, cosine = 0;
    for (std::uint32_t j = 0; j < N; ++j)
        for (std::uint32_t i = 0; i < N; ++i) {
            const auto b = plane_pixel_bounds<double>(i, j, N, a);
            const double o = rectangle_solid_angle<double>(b[0], b[1], b[2], b[3]);
            CHECK(o > 0);
            omega += o;
            cosine += rectangle_cosine_solid_angle<double, glm::dvec3>(b[0], b[1], b[2], b[3]);
            // The centre direction lies inside the pixel.
            const glm::dvec3 d = cam.direction(i, j);
            CHECK(d.x / d.z > b[0]);
            CHECK(d.x / d.z < b[2]);
            CHECK(d.y / d.z > b[1]);
            CHECK(d.y / d.z < b[3]);
        }
    // N^2 corner sums, each ~1e-16 absolute: 1e-11 covers N = 127 with margin.
    CHECK(omega == Approx(plane_solid_angle(aperture)).margin(1e-11));
    CHECK(cosine == Approx(plane_cosine_solid_angle(aperture)).margin(1e-11));
    const plane_weights plane = make_plane_weights(cam, plane_weighting::plane);
    CHECK(plane.total() == Approx(plane_cosine_solid_angle(aperture)).margin(1e-11));
}

TEST_CASE("the square plane's cosine-weighted solid angle is 4 sin(h) atan(sin h), not the cone's pi sin^2 h", "[hemisphere][closed-form]") {
    // 126 degrees: the seed's aperture; the square covers 82.57% of pi, the inscribed cone
    // pi sin^2(63 deg) = 79.4%.
    CHECK(plane_cosine_solid_angle(126.0) / pi == Approx(0.825691).epsilon(1e-6));
    CHECK(plane_cosine_solid_angle(126.0) > pi * std::pow(std::sin(63.0 * pi / 180), 2));
    // Limits: small apertures see a square of side 2a with cos ~ 1, area 4 a^2; 180 deg is pi.
    const double a = std::tan(0.5 * pi / 360);
    CHECK(plane_cosine_solid_angle(0.5) == Approx(4 * a * a).epsilon(1e-4));
    CHECK(plane_cosine_solid_angle(179.9999) == Approx(pi).epsilon(1e-6));
    // Independent check by quadrature.
    const double a126 = std::tan(63.0 * pi / 180);
    CHECK(integrate([](double u, double v) { return 1 / std::pow(1 + u * u + v * v, 2); }, -a126, -a126, a126, a126) ==
          Approx(plane_cosine_solid_angle(126.0)).epsilon(1e-12));
}

TEST_CASE("weight tables are non-negative, and stretching and coverage integrate the cosine over the whole hemisphere", "[hemisphere][weights]") {
    const auto N = GENERATE(1u, 2u, 3u, 5u, 16u, 64u, 128u);
    const auto aperture = GENERATE(1.0, 45.0, 90.0, 126.0, 150.0, 178.0);
    CAPTURE(N, aperture);
    const plane_camera cam{N, aperture};
    for (auto kind : {plane_weighting::plane, plane_weighting::coverage, plane_weighting::stretch}) {
        const plane_weights t = make_plane_weights(cam, kind);
        CAPTURE(to_string(kind));
        REQUIRE(t.irradiance.size() == cam.pixel_count());
        for (double w : t.irradiance) CHECK(w >= 0);
        if (kind != plane_weighting::plane) CHECK(std::abs(t.total() - pi) < 1e-6);
        // The stretched band equals the missing cosine-weighted solid angle.
        if (kind == plane_weighting::stretch) CHECK(std::abs(t.total() - pi) < 1e-11);
    }
}

TEST_CASE("a uniform environment gives E = pi L and no gradient for coverage and stretching", "[hemisphere][weights]") {
    const auto N = GENERATE(1u, 2u, 7u, 32u, 64u);
    const auto aperture = GENERATE(30.0, 126.0, 170.0);
    const plane_camera cam{N, aperture};
    const glm::vec3 L(0.25f, 1.f, 3.f);
    const auto plane = render(cam, [&](const glm::dvec3&) { return std::pair{L, 2.5f}; });
    for (auto kind : {plane_weighting::coverage, plane_weighting::stretch}) {
        const auto e = cpu::estimate_plane(make_plane_weights(cam, kind), plane.view());
        CAPTURE(N, aperture, to_string(kind));
        // N^2 positive terms summed in double: relative error ~N^2 * 1e-16.
        CHECK(e.irradiance.x == Approx(pi * 0.25).epsilon(1e-12));
        CHECK(e.irradiance.z == Approx(pi * 3.0).epsilon(1e-12));
        for (int c = 0; c < 3; ++c) {
            CHECK(glm::length(e.translation[c]) < 1e-12);
            // The rotation weights are antisymmetric about the plane's centre: they cancel.
            CHECK(glm::length(e.rotation[c]) < 1e-12);
        }
        CHECK(e.harmonic_mean_distance == Approx(2.5).epsilon(1e-12));
    }
    // The plane alone sees L times its own cosine-weighted solid angle.
    const auto e = cpu::estimate_plane(make_plane_weights(cam, plane_weighting::plane), plane.view());
    CHECK(e.irradiance.y == Approx(plane_cosine_solid_angle(aperture)).epsilon(1e-12));
}

TEST_CASE("stretching is exact for an environment split by a plane through the normal", "[hemisphere][weights]") {
    // Radiance L0 where omega.x > 0 (or omega.y > 0): with N even the split follows pixel
    // columns (rows) and the azimuth wedges of the bands, so the stretched table integrates
    // it exactly: E = pi L0 / 2 and grad_r = L0 int_{x > 0} n x omega = L0 (0, pi/2, 0).
    const auto N = GENERATE(2u, 8u, 64u);
    const auto aperture = GENERATE(60.0, 126.0, 160.0);
    const plane_camera cam{N, aperture};
    const auto t = make_plane_weights(cam, plane_weighting::stretch);
    const auto along_x = render(cam, [](const glm::dvec3& d) { return std::pair{glm::vec3(d.x > 0 ? 2.f : 0.f), 1.f}; });
    const auto along_y = render(cam, [](const glm::dvec3& d) { return std::pair{glm::vec3(d.y > 0 ? 2.f : 0.f), 1.f}; });
    const auto ex = cpu::estimate_plane(t, along_x.view()), ey = cpu::estimate_plane(t, along_y.view());
    CAPTURE(N, aperture);
    CHECK(ex.irradiance.x == Approx(pi).epsilon(1e-12));
    CHECK(ex.rotation[0].x == Approx(0).margin(1e-12));
    CHECK(ex.rotation[0].y == Approx(pi).epsilon(1e-12));
    CHECK(ey.irradiance.x == Approx(pi).epsilon(1e-12));
    CHECK(ey.rotation[0].x == Approx(-pi).epsilon(1e-12));
    CHECK(ey.rotation[0].y == Approx(0).margin(1e-12));
}

TEST_CASE("stretching recovers irradiance, gradients and distance of a half-lit ceiling", "[hemisphere][gradients]") {
    pcg32 rng(2025);
    const auto N = GENERATE(16u, 64u);
    const plane_camera cam{N, 126.0};
    const auto stretch = make_plane_weights(cam, plane_weighting::stretch);
    const double a = cam.half_extent(), theta_e = std::atan(a);
    const double sin_e = std::sin(theta_e), cos_e = std::cos(theta_e);
    // Translation budget (in units of pi L0 / (2 h)). (1) The band walls take the border
    // pixel's distance h / cos(theta_e) for the whole band, while a ceiling recedes as
    // h / cos(theta): per crossing of the plane's edge the wall term is overstated by
    // (1 - sin theta_e) cos theta_e - int_{theta_e}^{pi/2} cos^2 = the difference below,
    // largest where the edge is nearest (rho = a); the line crosses twice. (2) The walls
    // follow the pixel staircase instead of the straight edge: as for the strata of
    // test_irradiance_gradients, 1.5 / N.
    const double band_overstatement = (1 - sin_e) * cos_e - (pi / 4 - theta_e / 2 - sin_e * cos_e / 2);
    const double translation_budget = 2 * band_overstatement / (pi / 2) + 1.5 / N;
    // Harmonic mean distance: the band (cosine weight pi - plane) is given 1 / r between 0
    // and cos(theta_e) / h where the truth lies in the same range; the plane part is a
    // midpoint rule of a smooth integrand (O(1/N^2)). Relative to sum w / r = 2 pi / (3 h):
    const double distance_budget = (pi - plane_cosine_solid_angle(126.0)) * cos_e / (2 * pi / 3) + 1.0 / N;
    double worst_t = 0, worst_R = 0, E_margin = 1e9, rot_margin = 1e9;
    for (int c = 0; c < 200; ++c) {
        // L0 is representable in float, the radiance format of a plane, so the closed forms see the same L0.
        const half_lit_ceiling hc{0.5 + 2 * rng.next_double(), 0, double(float(1 + rng.next_double())), 2 * pi * rng.next_double()};
        const double x0 = hc.h * (3 * rng.next_double() - 1.5);  // the edge crosses the plane: |x0 / h| < a
        const half_lit_ceiling ceiling{hc.h, x0, hc.L0, hc.rot};
        const auto p = render(cam, [&](const glm::dvec3& d) { return ceiling.trace(d); });
        const auto e = cpu::estimate_plane(stretch, p.view());
        const auto bound = mixed_cells(cam, ceiling, true);
        CAPTURE(ceiling.h, ceiling.x0, ceiling.rot);
        // Rigorous: error <= L0 * (weights of the mixed cells), plus rounding.
        CHECK(std::abs(e.irradiance.x - ceiling.E()) <= ceiling.L0 * bound.E + 1e-12);
        CHECK(glm::length(e.rotation[0] - ceiling.rot_y() * ceiling.across()) <= ceiling.L0 * bound.rotation + 1e-12);
        E_margin = std::min(E_margin, ceiling.L0 * bound.E - std::abs(e.irradiance.x - ceiling.E()));
        rot_margin = std::min(rot_margin, ceiling.L0 * bound.rotation -
                                              glm::length(e.rotation[0] - ceiling.rot_y() * ceiling.across()));
        const double scale = pi * ceiling.L0 / 2;
        worst_t = std::max(worst_t, glm::length(e.translation[0] - ceiling.dE_dx() * ceiling.along()) * ceiling.h / scale);
        // Harmonic mean of h / cos(theta) with cosine weights: pi / (int cos^2 / h) = 1.5 h.
        worst_R = std::max(worst_R, std::abs(e.harmonic_mean_distance / (1.5 * ceiling.h) - 1));
        // Grey radiance: every channel agrees.
        CHECK(e.irradiance.x == e.irradiance.z);
    }
    CAPTURE(N, worst_t, translation_budget, worst_R, distance_budget, E_margin, rot_margin);
    CHECK(worst_t < translation_budget);
    CHECK(worst_R < distance_budget);
}

TEST_CASE("the plane alone integrates the lit part of the square exactly up to its crossed column", "[hemisphere][gradients]") {
    // Edge parallel to the y axis (rot = 0): the lit part of the plane is the rectangle
    // [max(-a, -x0/h), a] x [-a, a], whose cosine-weighted solid angle and moments are closed
    // forms (Eqs. H2, H3); only the column of pixels the edge crosses is mixed.
    pcg32 rng(77);
    const plane_camera cam{64, 126.0};
    const auto plane = make_plane_weights(cam, plane_weighting::plane);
    const double a = cam.half_extent();
    for (int c = 0; c < 200; ++c) {
        const half_lit_ceiling hc{0.5 + 2 * rng.next_double(), 6 * rng.next_double() - 3, double(float(1 + rng.next_double())), 0.0};
        const auto p = render(cam, [&](const glm::dvec3& d) { return hc.trace(d); });
        const auto e = cpu::estimate_plane(plane, p.view());
        const double x_edge = std::clamp(-hc.x0 / hc.h, -a, a);
        const glm::dvec3 m = rectangle_moment<double, glm::dvec3>(x_edge, -a, a, a) * hc.L0;
        const auto bound = mixed_cells(cam, hc, false);
        CAPTURE(hc.h, hc.x0);
        CHECK(std::abs(e.irradiance.x - m.z) <= hc.L0 * bound.E + 1e-12);
        CHECK(glm::length(e.rotation[0] - glm::dvec3(-m.y, m.x, 0)) <= hc.L0 * bound.rotation + 1e-12);
        // Coverage scales the same estimate by pi / plane_cosine_solid_angle.
        const auto ec = cpu::estimate_plane(make_plane_weights(cam, plane_weighting::coverage), p.view());
        CHECK(ec.irradiance.x == Approx(e.irradiance.x * pi / plane_cosine_solid_angle(126.0)).epsilon(1e-12));
    }
}

TEST_CASE("fall-off stretching interpolates between the plane and stretching", "[hemisphere][falloff]") {
    const auto N = GENERATE(1u, 2u, 9u, 64u);
    const auto aperture = GENERATE(90.0, 126.0, 150.0);
    const plane_camera cam{N, aperture};
    const auto plane = make_plane_weights(cam, plane_weighting::plane);
    const auto stretch = make_plane_weights(cam, plane_weighting::stretch);
    const auto one = make_plane_weights(cam, plane_weighting::falloff, 1.0);
    const auto zero = make_plane_weights(cam, plane_weighting::falloff, 0.0);
    for (std::size_t k = 0; k < cam.pixel_count(); ++k) {
        // kappa = 1 is stretching, entry for entry; kappa = 0 carries the plane's radiance
        // but keeps the band's distances (the harmonic mean still spans the hemisphere).
        CHECK(one.irradiance[k] == Approx(stretch.irradiance[k]).margin(1e-15));
        CHECK(glm::length(one.rotation[k] - stretch.rotation[k]) < 1e-15);
        CHECK(glm::length(one.left_wall[k] - stretch.left_wall[k]) < 1e-15);
        CHECK(glm::length(one.edge_wall[k]) == 0.0);
        CHECK(zero.irradiance[k] == Approx(plane.irradiance[k]).margin(1e-15));
        CHECK(zero.distance[k] == stretch.distance[k]);
    }
    // Linear in kappa: E_falloff = E_plane + kappa (E_stretch - E_plane) for any plane.
    pcg32 rng(N * 1000 + unsigned(aperture));
    const auto p = render(cam, [&](const glm::dvec3&) {
        return std::pair{glm::vec3(float(rng.next_double()), float(rng.next_double()), 0.f), float(0.5 + rng.next_double())};
    });
    const double kappa = 0.8;
    const auto ef = cpu::estimate_plane(make_plane_weights(cam, plane_weighting::falloff, kappa), p.view());
    const auto ep = cpu::estimate_plane(plane, p.view()), es = cpu::estimate_plane(stretch, p.view());
    CHECK(ef.irradiance.x == Approx(ep.irradiance.x + kappa * (es.irradiance.x - ep.irradiance.x)).epsilon(1e-12));
    CHECK(ef.harmonic_mean_distance == Approx(es.harmonic_mean_distance).epsilon(1e-12));
    // A uniform environment: the steps at the plane's edge cancel around it.
    const auto u = render(cam, [](const glm::dvec3&) { return std::pair{glm::vec3(1.f), 2.f}; });
    const auto eu = cpu::estimate_plane(make_plane_weights(cam, plane_weighting::falloff, kappa), u.view());
    CHECK(glm::length(eu.translation[0]) < 1e-12);
    CHECK(glm::length(eu.rotation[0]) < 1e-12);
    CHECK_THROWS_AS(make_plane_weights(cam, plane_weighting::falloff, 1.5), parameter_error);
    CHECK_THROWS_AS(make_plane_weights(cam, plane_weighting::falloff, -0.1), parameter_error);
}

TEST_CASE("the band's mean cosine matches quadrature over the band", "[hemisphere][falloff]") {
    const auto aperture = GENERATE(20.0, 90.0, 126.0, 150.0, 175.0);
    const double a = std::tan(aperture * pi / 360);
    // The right edge's band on the side plane x = 1 (u = y / x, v = z / x):
    // [-1, 1] x [0, 1/a], where cos(theta) = v / d and d omega = du dv / d^3.
    const auto d = [](double u, double v) { return std::sqrt(1 + u * u + v * v); };
    const double c2 = integrate([&](double u, double v) { return v * v / std::pow(d(u, v), 5); }, -1, 0, 1, 1 / a);
    const double c1 = integrate([&](double u, double v) { return v / std::pow(d(u, v), 4); }, -1, 0, 1, 1 / a);
    CHECK(band_mean_cosine(aperture) == Approx(c2 / c1).epsilon(1e-10));
}

TEST_CASE("the radial profile recovers a radiance linear in cos(theta) exactly", "[hemisphere][falloff]") {
    pcg32 rng(5150);
    const auto N = GENERATE(4u, 16u, 65u);
    const auto aperture = GENERATE(100.0, 126.0, 150.0);
    const plane_camera cam{N, aperture};
    const double cbar = band_mean_cosine(aperture);
    for (int c = 0; c < 20; ++c) {
        // L = alpha + beta cos(theta), positive over the hemisphere, beta > 0 (darker towards
        // the horizon). Each ring's cosine-weighted mean is alpha + beta c_m exactly, so the
        // fit is exact and kappa = L(c_band) / L(c_0), c_0 the border ring's mean cosine.
        const double alpha = 0.2 * rng.next_double(), beta = 0.1 + rng.next_double();
        radial_profile profile(cam);
        const int planes = 3;
        for (int k = 0; k < planes; ++k) {
            const auto p = render(cam, [&](const glm::dvec3& dir) {
                return std::pair{glm::vec3(float(alpha + beta * dir.z)), 1.f};
            });
            profile.add(p.radiance.view());
        }
        CHECK(profile.planes() == std::size_t(planes));
        // The border ring's mean cosine, from the same weights the profile uses.
        const auto plane = make_plane_weights(cam, plane_weighting::plane);
        double w0 = 0, c0 = 0;
        for (std::uint32_t j = 0; j < N; ++j)
            for (std::uint32_t i = 0; i < N; ++i)
                if (i == 0 || j == 0 || i == N - 1 || j == N - 1) {
                    w0 += plane.irradiance[j * N + i];
                    c0 += plane.irradiance[j * N + i] * cam.direction(i, j).z;
                }
        c0 /= w0;
        // Radiance is stored in float: the ring means carry ~1e-7 relative error, which the
        // two-parameter fit carries over with a conditioning ~1 / (c_fit spread) ~ 10.
        CHECK(profile.falloff_factor() == Approx((alpha + beta * cbar) / (alpha + beta * c0)).epsilon(1e-5));
    }
    // A uniform environment has no fall-off; an empty profile and a one-pixel plane say 1.
    radial_profile uniform(cam);
    uniform.add(render(cam, [](const glm::dvec3&) { return std::pair{glm::vec3(1.f), 1.f}; }).radiance.view());
    CHECK(uniform.falloff_factor() == Approx(1.0).epsilon(1e-6));
    CHECK(radial_profile(cam).falloff_factor() == 1.0);
    radial_profile single(plane_camera{1, 126.0});
    single.add(render(plane_camera{1, 126.0}, [](const glm::dvec3&) { return std::pair{glm::vec3(1.f), 1.f}; }).radiance.view());
    CHECK(single.falloff_factor() == 1.0);
    image<glm::vec3> wrong(N + 1, N);
    CHECK_THROWS_AS(radial_profile(cam).add(wrong.view()), parameter_error);
}

TEST_CASE("a plane's frame is orthonormal, right-handed about n, and turned by the camera's angle", "[hemisphere][frame]") {
    pcg32 rng(90);
    std::vector<glm::vec3> normals = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1},
                                      glm::normalize(glm::vec3(1e-4f, 0, -1)), glm::normalize(glm::vec3(0, -3e-4f, -1)),
                                      glm::normalize(glm::vec3(1, 1, 1e-7f))};
    for (int k = 0; k < 300; ++k) {  // uniform on the sphere
        const double z = 2 * rng.next_double() - 1, phi = 2 * pi * rng.next_double(), r = std::sqrt(1 - z * z);
        normals.push_back(glm::normalize(glm::vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z))));
    }
    const auto [turn, hashed] = GENERATE(std::pair{0.0, false}, std::pair{30.0, false}, std::pair{89.999, false},
                                         std::pair{0.0, true}, std::pair{45.0, true});
    const plane_camera cam{16, 126.0, turn, hashed};
    REQUIRE_NOTHROW(cam.validate());
    // orthonormal_basis is orthonormal to a few float ulps; turning it rounds each
    // component of c t + s b twice more: 8 ulps of 1 bound every product below.
    const double tol = 8 * 0x1p-24;
    for (std::size_t k = 0; k < normals.size(); ++k) {
        const glm::vec3 n = normals[k];
        const glm::vec3 p(float(rng.next_double()), float(rng.next_double() - 7), float(1e3 * rng.next_double()));
        const auto f = cam.frame(p, n);
        const auto tb = orthonormal_basis<float, glm::vec3>(n);
        const glm::dvec3 x(f[0]), y(f[1]), nd(n);
        CAPTURE(turn, hashed, k, n.x, n.y, n.z);
        CHECK(std::abs(glm::length(x) - 1) < tol);
        CHECK(std::abs(glm::length(y) - 1) < tol);
        CHECK(std::abs(glm::dot(x, y)) < tol);
        CHECK(std::abs(glm::dot(x, nd)) < tol);
        CHECK(std::abs(glm::dot(y, nd)) < tol);
        CHECK(glm::length(glm::cross(x, y) - nd) < 2 * tol);
        // The turn: the angle from the basis's tangent to x, measured about n.
        const double want = cam.turn_at(p);
        CHECK(want >= turn);
        CHECK(want < turn + (hashed ? 90 : 1e-12));
        const double got = std::atan2(glm::dot(x, glm::dvec3(tb[1])), glm::dot(x, glm::dvec3(tb[0]))) * 180 / pi;
        CHECK(std::remainder(got - want, 360.0) == Approx(0).margin(1e-4));
        if (want == 0) CHECK((f[0] == tb[0] && f[1] == tb[1]));  // no turn: the basis itself, bit for bit
    }
}

TEST_CASE("the hashed turn is the same for the same point and uniform over neighbouring points", "[hemisphere][frame]") {
    const glm::vec3 p(1.25f, -3.5f, 1e4f);
    CHECK(plane_turn_hash(p) == plane_turn_hash(p));
    CHECK(plane_turn_hash(glm::vec3(0.f, 2.f, -0.f)) == plane_turn_hash(glm::vec3(-0.f, 2.f, 0.f)));
    // The hardest inputs: points one float ulp apart, along each axis in turn. 16 bins of
    // 6000 hashes: chi-square with 15 degrees of freedom, whose 0.999 quantile is 37.7.
    // Consecutive hashes must not be correlated: |r| below 4 standard errors, 4 / sqrt(n).
    const int axis = GENERATE(0, 1, 2);
    const int count = 6000, bins = 16;
    std::vector<int> histogram(bins, 0);
    std::vector<double> h;
    glm::vec3 q(0.75f, 12.f, -2.f);
    for (int k = 0; k < count; ++k) {
        h.push_back(plane_turn_hash(q));
        q[axis] = std::nextafter(q[axis], 1e30f);
        REQUIRE(h.back() >= 0);
        REQUIRE(h.back() < 1);
        ++histogram[std::size_t(h.back() * bins)];
    }
    double chi2 = 0;
    for (int c : histogram) chi2 += (c - double(count) / bins) * (c - double(count) / bins) / (double(count) / bins);
    double mean = 0, var = 0, cov = 0;
    for (double v : h) mean += v / count;
    for (int k = 0; k < count; ++k) var += (h[k] - mean) * (h[k] - mean);
    for (int k = 0; k + 1 < count; ++k) cov += (h[k] - mean) * (h[k + 1] - mean);
    const double r = cov / var;
    CAPTURE(axis, chi2, r);
    CHECK(chi2 < 37.7);
    CHECK(std::abs(r) < 4 / std::sqrt(double(count)));
}

TEST_CASE("a hit at the eye keeps a positive distance", "[hemisphere][bad-input]") {
    const glm::vec3 eye(10.f, 5.f, -3.f);
    CHECK(plane_hit_distance<float, glm::vec3>(eye, eye) > 0.f);
    CHECK(plane_hit_distance<double, glm::dvec3>(glm::dvec3(1, 2, 2), glm::dvec3(0)) == 3.0);
}

TEST_CASE("bad cameras and planes are refused", "[hemisphere][bad-input]") {
    CHECK_THROWS_AS(make_plane_weights(plane_camera{0, 126.0}, plane_weighting::stretch), parameter_error);
    CHECK_THROWS_AS(make_plane_weights(plane_camera{64, 180.0}, plane_weighting::stretch), parameter_error);
    CHECK_THROWS_AS(make_plane_weights(plane_camera{64, 0.0}, plane_weighting::plane), parameter_error);
    CHECK_THROWS_AS(make_plane_weights(plane_camera{64, std::nan("")}, plane_weighting::plane), parameter_error);
    for (const double turn : {-1e-9, 90.0, 135.0, std::nan(""), std::numeric_limits<double>::infinity()})
        CHECK_THROWS_AS(make_plane_weights(plane_camera{64, 126.0, turn}, plane_weighting::plane), parameter_error);
    const plane_camera cam{4, 90.0};
    const auto t = make_plane_weights(cam, plane_weighting::stretch);
    auto p = render(cam, [](const glm::dvec3&) { return std::pair{glm::vec3(1.f), 1.f}; });
    CHECK_NOTHROW(cpu::estimate_plane(t, p.view()));
    image<glm::vec3> small(3, 4);
    CHECK_THROWS_AS(cpu::estimate_plane(t, plane_view{small.view(), p.distance.view()}), parameter_error);
    p.radiance(1, 2).y = std::numeric_limits<float>::infinity();
    CHECK_THROWS_AS(cpu::estimate_plane(t, p.view()), parameter_error);
    p.radiance(1, 2).y = 1.f;
    p.distance(3, 3) = 0.f;
    CHECK_THROWS_AS(cpu::estimate_plane(t, p.view()), parameter_error);
    p.distance(3, 3) = std::numeric_limits<float>::infinity();  // an escaped ray is fine
    CHECK(cpu::estimate_plane(t, p.view()).harmonic_mean_distance > 1.0);
    const auto other = make_plane_weights(plane_camera{5, 90.0}, plane_weighting::stretch);
    CHECK_THROWS_AS(cpu::estimate_plane(other, p.view()), parameter_error);
}
