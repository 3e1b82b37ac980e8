// The RSM kernels (include/bounce/indirect/rsm.hpp): convergence of the pixel-light sum to the
// closed-form one-bounce irradiance, the texel fluxes, the disc pattern's weights, and the
// numerical hard cases (coincident, grazing, behind, shared boundary, float accumulation);
// the map layouts of indirect/rsm_layout.hpp.
#include <bounce/indirect/rsm.hpp>
#include <bounce/indirect/rsm_layout.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <glm/glm.hpp>

using namespace bounce;
namespace {
constexpr double u32 = 0x1p-24;  // unit roundoff of float

// Point-to-parallel-square form factor from a point at height h above the centre of a
// square of side 2a (four corner rectangles, e.g. Howell's catalogue, configuration B-3):
// F = 4/pi X/sqrt(1+X^2) atan(X/sqrt(1+X^2)), X = a/h.
double centre_form_factor(double a, double h) {
    const double x = a / h, s = std::sqrt(1 + x * x);
    return 4.0 / std::numbers::pi * x / s * std::atan(x / s);
}

// The irradiance the texels of an N x N orthographic RSM of the square [-a, a]^2 (z = 0,
// facing +z, albedo rho) lit straight down by a distant light of irradiance e0 give a
// receiver at (0, 0, h) facing down; kernels in float, sum in double.
double rsm_sum_over_square(int n, double a, double h, float rho, float e0) {
    const float t = float(2 * a / n);
    const glm::vec3 x(0, 0, float(h)), nx(0, 0, -1), np(0, 0, 1);
    double sum = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const glm::vec3 xp(float(-a + (i + 0.5) * t), float(-a + (j + 0.5) * t), 0.f);
            const glm::vec3 flux = directional_light_texel_flux<float, glm::vec3>(
                glm::vec3(rho), np, glm::vec3(0, 0, -1), glm::vec3(e0), t * t);
            sum += pixel_light_irradiance<float, glm::vec3>(x, nx, xp, np, flux, 0.f, 0.f).x;
        }
    return sum;
}
}  // namespace

TEST_CASE("the sum over an RSM converges to the closed-form one-bounce irradiance of a lit square", "[rsm]") {
    // Exact: E = rho e0 F (the square's exitance rho e0 times the form factor). The texel sum
    // is the midpoint rule for E = int M/pi h^2 / (r^2 + h^2)^2 dA, whose error is at most
    // A t^2 / 24 (max|f_xx| + max|f_yy|); |f_xx| <= M/pi 4/h^4 (the second derivative of
    // (x^2 + c)^-2 is at most 4/c^3 in size, c >= h^2), so the bound is A t^2 M / (3 pi h^4).
    // Each float term adds at most ~10 u of itself (about ten roundings), 10 u E in all.
    const double a = 1, h = 1;
    const float rho = 0.7f, e0 = 3.f;
    const double m = double(rho) * double(e0), exact = m * centre_form_factor(a, h);
    double previous_error = 1e30;
    for (int n : {16, 64, 256}) {
        const double t = 2 * a / n;
        const double bound = 4 * a * a * t * t * m / (3 * std::numbers::pi * std::pow(h, 4)) + 10 * u32 * exact;
        const double error = std::abs(rsm_sum_over_square(n, a, h, rho, e0) - exact);
        INFO("n " << n << " error " << error << " bound " << bound);
        CHECK(error <= bound);
        CHECK(error < previous_error);
        previous_error = error;
    }
}

TEST_CASE("the texel solid angles of a cube-map face sum to 4 pi / 6", "[rsm]") {
    for (int r : {1, 7, 64}) {
        double sum = 0;
        float sum_f = 0;
        for (int j = 0; j < r; ++j)
            for (int i = 0; i < r; ++i) {
                const double x0 = -1 + 2.0 * i / r, x1 = -1 + 2.0 * (i + 1) / r;
                const double y0 = -1 + 2.0 * j / r, y1 = -1 + 2.0 * (j + 1) / r;
                const double w = rectangle_solid_angle<double>(x0, y0, x1, y1);
                CHECK(w > 0);
                sum += w;
                sum_f += rectangle_solid_angle<float>(float(x0), float(y0), float(x1), float(y1));
            }
        CHECK(sum == Approx(4 * std::numbers::pi / 6).epsilon(1e-12));
        // Each float texel is the difference of four atans of size <= pi/4: a few ulps of 1
        // absolute per texel, r^2 texels.
        CHECK(std::abs(double(sum_f) - 4 * std::numbers::pi / 6) <= 8 * u32 * r * r + 1e-6);
    }
}

TEST_CASE("a texel reflects rho I dw of a point or spot light, nothing from behind or outside the cone", "[rsm]") {
    const glm::vec3 light(0, 0, 2), albedo(0.5f, 0.25f, 1.f), intensity(4.f);
    const glm::vec3 p(0.3f, -0.2f, 0.f), up(0, 0, 1);
    const float dw = 1e-3f;
    const glm::vec3 f = point_light_texel_flux<float, glm::vec3>(albedo, p, up, light, intensity, dw);
    CHECK(f.x == Approx(0.5f * 4.f * dw));
    CHECK(f.z == Approx(1.f * 4.f * dw));
    CHECK(point_light_texel_flux<float, glm::vec3>(albedo, p, -up, light, intensity, dw).x == 0.f);
    const glm::vec3 axis(0, 0, -1);
    const float cos_cone = std::cos(0.5f);
    const glm::vec3 inside =
        spot_light_texel_flux<float, glm::vec3>(albedo, p, up, light, axis, intensity, cos_cone, 1.f, dw);
    const float cos_axis = 2.f / glm::length(p - light);
    CHECK(inside.x == Approx(0.5f * 4.f * cos_axis * dw));
    const glm::vec3 far_point(5.f, 0.f, 0.f);
    CHECK(spot_light_texel_flux<float, glm::vec3>(albedo, far_point, up, light, axis, intensity, cos_cone, 1.f, dw).x ==
          0.f);
    CHECK(directional_light_texel_flux<float, glm::vec3>(albedo, -up, axis, intensity, 0.01f).x == 0.f);
}

TEST_CASE("the disc pattern's weights estimate the sum over the disc without bias, and DS05's xi1^2 does not", "[rsm]") {
    // Sum of w f over K samples for f = (distance from the centre)^k over a disc of radius
    // r: exact integrals r^2 pi T (k = 0) and 2 pi r^3 T / 3 (k = 1), T texels per unit area.
    // Only xi1 matters and the estimate is (2 pi r^(2+k) T) mean(xi1^(1+k)); van der Corput's
    // star discrepancy D* <= (log2 K / 3 + 1) / K bounds |mean(g) - int g| by Var(g) D*
    // (Koksma-Hlawka; g = xi1 or xi1^2 has variation 1).
    const double r = 0.25, texels = 512.0 * 512.0;
    for (std::size_t count : {std::size_t(64), std::size_t(400), std::size_t(4096)}) {
        double w0 = 0, w1 = 0, ds05 = 0, ds05_norm = 0;
        for (std::size_t k = 0; k < count; ++k) {
            const double xi1 = radical_inverse(k, 2), xi2 = radical_inverse(k, 3);
            const glm::dvec3 s = rsm_disc_sample<double, glm::dvec3>(xi1, xi2, r, texels, double(count));
            CHECK(glm::length(glm::dvec2(s)) == Approx(r * xi1).margin(1e-15));
            w0 += s.z;
            w1 += s.z * glm::length(glm::dvec2(s));
            const glm::dvec3 d = rsm_disc_sample_xi1_squared<double, glm::dvec3>(xi1, xi2, r, texels, double(count));
            ds05 += d.z * glm::length(glm::dvec2(d));
            ds05_norm += d.z;
        }
        const double dstar = (std::log2(double(count)) / 3 + 1) / double(count);
        const double area = std::numbers::pi * r * r * texels;
        CHECK(std::abs(w0 / area - 1) <= 2 * dstar);
        CHECK(std::abs(w1 / (2 * std::numbers::pi * r * r * r * texels / 3) - 1) <= 3 * dstar * 1.5);
        // xi1^2 weights estimate the area without bias (E[3 xi1^2] = 1) but int f dA as
        // int f 3/2 (rho/r) dA: the mean distance comes out 3/4 r (the exact mean is 2/3 r).
        CHECK(ds05_norm / area == Approx(1.0).epsilon(0.05));
        CHECK(ds05 / ds05_norm == Approx(0.75 * r).epsilon(0.05));
    }
}

TEST_CASE("pixel-light irradiance: coincident, grazing and back-facing pairs give 0, never NaN", "[rsm][hard]") {
    const glm::vec3 flux(1.f), up(0, 0, 1), down(0, 0, -1);
    const glm::vec3 xp(0.25f, -0.5f, 1.f);
    const auto e = [&](glm::vec3 x, glm::vec3 n, glm::vec3 np, float offset = 0.f, float d2 = 0.f) {
        return pixel_light_irradiance<float, glm::vec3>(x, n, xp, np, flux, offset, d2).x;
    };
    CHECK(e(xp, down, up) == 0.f);  // coincident
    CHECK(e(xp, up, up) == 0.f);
    const float tiny = std::numeric_limits<float>::denorm_min();
    CHECK(e(xp + glm::vec3(0, 0, tiny), down, up) == 0.f);             // below the coincidence radius
    CHECK(std::isfinite(e(xp + glm::vec3(0, 0, 1e-15f), down, up)));   // just above it: finite
    CHECK(e(xp + glm::vec3(1, 0, 0), down, up) == 0.f);                // receiver in the sender's plane
    CHECK(e(xp + glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), up) == 0.f);  // grazing at the receiver
    CHECK(e(xp - glm::vec3(0, 0, 1), up, up) == 0.f);                  // receiver behind the sender
    CHECK(e(xp + glm::vec3(0, 0, 1), up, up) == 0.f);                  // sender behind the receiver
    CHECK(e(xp + glm::vec3(0, 0, 2), down, up) == Approx(1.0 / (std::numbers::pi * 4)));
    for (float offset : {0.f, 0.01f})
        for (float d2 : {0.f, 1e-4f}) CHECK(e(xp, down, up, offset, d2) >= 0.f);
}

TEST_CASE("at a shared boundary the offset and the clamp bound the irradiance as documented", "[rsm][hard]") {
    // A floor texel at the foot of a wall (x = 0 plane, normal +x) sends to wall points ever
    // closer to it. Plain: grows as 1/d^2. Offset delta: E <= Phi / (pi delta^2) on the
    // sender's side. Clamp: E <= Phi / (pi min_distance2).
    const glm::vec3 np(0, 0, 1), wall_n(1, 0, 0), flux(2.f);
    const glm::vec3 xp(1e-3f, 0, 0);
    const float delta = 0.01f, dmin2 = 1e-4f;
    pcg32 rng(7);
    for (int k = 0; k < 2000; ++k) {
        const glm::vec3 x(0.f, rng.next_float() * 0.02f - 0.01f, rng.next_float() * 0.02f);
        const float off = pixel_light_irradiance<float, glm::vec3>(x, wall_n, xp, np, flux, delta, 0.f).x;
        const float clamp = pixel_light_irradiance<float, glm::vec3>(x, wall_n, xp, np, flux, 0.f, dmin2).x;
        REQUIRE(std::isfinite(off));
        REQUIRE(off <= 2.f / (std::numbers::pi_v<float> * delta * delta) * (1 + 1e-5f));
        REQUIRE(clamp <= 2.f / (std::numbers::pi_v<float> * dmin2) * (1 + 1e-5f));
    }
}

TEST_CASE("float32 accumulation over thousands of pixel lights stays within Higham's bound of double", "[rsm][hard]") {
    // Recursive summation of K terms: |fl(sum) - sum| <= gamma_(K-1) sum |x_k|, gamma_n =
    // n u / (1 - n u) (Higham 2002, Eq. 4.4). Each float term differs from the double kernel
    // by at most ~30 u of itself (about 30 roundings, no cancellation: senders are at least
    // 0.1 away), so the total bound is (gamma_(K-1) + 30 u) sum |x_k|.
    pcg32 rng(11);
    const glm::vec3 x(0.f), n(0, 0, 1);
    for (int count : {1000, 4096, 16384}) {
        float sum_f = 0;
        double sum_d = 0, sum_abs = 0;
        for (int k = 0; k < count; ++k) {
            const glm::vec3 xp(rng.next_float() * 4 - 2, rng.next_float() * 4 - 2, 0.1f + rng.next_float() * 2);
            const glm::vec3 np = glm::normalize(glm::vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, -1.f));
            const glm::vec3 flux(rng.next_float() * 0.01f);
            sum_f += pixel_light_irradiance<float, glm::vec3>(x, n, xp, np, flux, 0.f, 0.f).x;
            const double term = pixel_light_irradiance<double, glm::dvec3>(glm::dvec3(x), glm::dvec3(n), glm::dvec3(xp),
                                                                           glm::dvec3(np), glm::dvec3(flux), 0.0, 0.0)
                                    .x;
            sum_d += term;
            sum_abs += std::abs(term);
        }
        const double gamma = (count - 1) * u32 / (1 - (count - 1) * u32);
        INFO("K " << count << " error " << std::abs(sum_f - sum_d) << " bound " << (gamma + 30 * u32) * sum_abs);
        CHECK(std::abs(double(sum_f) - sum_d) <= (gamma + 30 * u32) * sum_abs);
    }
}

TEST_CASE("outside its bounding sphere a pixel light gives less than the cutoff", "[rsm]") {
    pcg32 rng(3);
    const float cutoff = 1e-3f, flux = 0.5f;
    for (float offset : {0.f, 0.05f}) {
        const glm::vec3 xp(0.1f, 0.2f, 0.3f), np = glm::normalize(glm::vec3(0.3f, -0.2f, 1.f));
        const auto [centre, radius] = pixel_light_bounding_sphere<float, glm::vec3>(xp, np, flux, cutoff, offset);
        const float reach = std::sqrt(flux / (std::numbers::pi_v<float> * cutoff));
        CHECK(radius < 0.63f * reach);
        int outside = 0;
        for (int k = 0; k < 20000; ++k) {
            const glm::vec3 d =
                glm::vec3(rng.next_float() * 2 - 1, rng.next_float() * 2 - 1, rng.next_float() * 2 - 1) * reach * 1.2f;
            const glm::vec3 x = xp + d;
            if (glm::length(x - centre) <= radius) continue;
            ++outside;
            // The receiver faces the sender exactly (cos theta = 1), the worst case.
            const glm::vec3 n = glm::normalize((xp - np * offset) - x);
            const float e = pixel_light_irradiance<float, glm::vec3>(x, n, xp, np, glm::vec3(flux), offset, 0.f).x;
            REQUIRE(e < cutoff);
        }
        CHECK(outside > 1000);
    }
}

TEST_CASE(
    "the midpoint texel solid angle is within 1.3 t^2 of the exact one, and beats float's exact form on fine maps",
    "[rsm]") {
    for (int r : {16, 128, 1024}) {
        const double t = 2.0 / r;
        double worst_mid = 0, worst_exact_float = 0;
        for (int j = 0; j < r; j += 1 + r / 64)
            for (int i = 0; i < r; i += 1 + r / 64) {
                const double x0 = -1 + t * i, y0 = -1 + t * j;
                const double exact = rectangle_solid_angle<double>(x0, y0, x0 + t, y0 + t);
                const double mid = perspective_texel_solid_angle_midpoint<float>(float(x0 + t / 2), float(y0 + t / 2),
                                                                                 float(t), float(t));
                const double ef = rectangle_solid_angle<float>(float(x0), float(y0), float(x0 + t), float(y0 + t));
                worst_mid = std::max(worst_mid, std::abs(mid / exact - 1));
                worst_exact_float = std::max(worst_exact_float, std::abs(ef / exact - 1));
            }
        INFO("r " << r << " midpoint " << worst_mid << " exact in float " << worst_exact_float);
        CHECK(worst_mid <= 1.3 * t * t + 8 * u32);
        if (r >= 128) CHECK(worst_mid < worst_exact_float);
    }
}

TEST_CASE("the sum over a spot light's RSM converges to the closed-form irradiance of the disc it lights", "[rsm]") {
    // A spot light (flat profile, half-angle alpha) at height H lights a disc of radius
    // H tan alpha on the floor, exitance M(r) = rho I H / (r^2 + H^2)^(3/2). At a receiver
    // at the light's height on its axis, facing down:
    //   E = 2 rho I H^3 int_0^R r (r^2 + H^2)^(-7/2) dr = 2 rho I / (5 H^2) (1 - cos^5 alpha).
    // The map is the perspective square around the cone, texel flux rho I dw (exact texel
    // solid angles), the point at the texel centre's ray. Errors: texels straddling the cone's
    // edge are counted whole or not at all; they lie within sqrt(2) t (tangent units) of the
    // edge circle of circumference 2 pi tan alpha (dw/dA <= 1 there), where the integrand per
    // unit solid angle is rho I cos^4 / (pi H^2) <= rho I cos^4(alpha - sqrt 2 t) / (pi H^2);
    // the interior is the midpoint rule, O(t^2), far below that edge term here.
    const double h = 1, alpha = std::numbers::pi / 4, rho = 0.6, intensity = 2;
    const double exact = 2 * rho * intensity / (5 * h * h) * (1 - std::pow(std::cos(alpha), 5));
    const double tan_a = std::tan(alpha);
    const glm::vec3 light(0, 0, float(h)), axis(0, 0, -1), x(0, 0, float(h)), nx(0, 0, -1), np(0, 0, 1);
    for (int n : {16, 64, 256}) {
        const double t = 2 * tan_a / n;
        double sum = 0;
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double x0 = -tan_a + t * i, y0 = -tan_a + t * j;
                const double dw = rectangle_solid_angle<double>(x0, y0, x0 + t, y0 + t);
                const glm::vec3 p(float((x0 + t / 2) * h), float((y0 + t / 2) * h), 0.f);
                const glm::vec3 f = spot_light_texel_flux<float, glm::vec3>(glm::vec3(float(rho)), p, np, light, axis,
                                                                            glm::vec3(float(intensity)),
                                                                            float(std::cos(alpha)), 0.f, float(dw));
                sum += pixel_light_irradiance<float, glm::vec3>(x, nx, p, np, f, 0.f, 0.f).x;
            }
        const double edge = 2 * std::numbers::pi * tan_a * std::sqrt(2.0) * t * rho * intensity *
                            std::pow(std::cos(std::max(0.0, alpha - std::sqrt(2.0) * t)), 4) /
                            (std::numbers::pi * h * h);
        INFO("n " << n << " error " << std::abs(sum - exact) << " bound " << edge);
        CHECK(std::abs(sum - exact) <= edge + 10 * u32 * exact);
    }
}

// ---- map layouts (include/bounce/indirect/rsm_layout.hpp) ----------------------------------------

TEST_CASE("rsm_layout: six faces per point light, one map or the reachable faces per spot, one "
          "orthographic map per distant light",
          "[rsm][layout]") {
    const glm::vec3 lo(-1.f, -2.f, -1.f), hi(3.f, 2.f, 1.f);
    const std::vector<light> lights{point_light{{0.f, 0.f, 0.f}, glm::vec3(1.f)},
                                    spot_light{{0.f, 1.f, 0.f}, {0.f, -2.f, 0.f}, glm::vec3(1.f), 30.f},
                                    spot_light{{0.f, 1.f, 0.f}, {0.f, -1.f, 0.f}, glm::vec3(1.f), 89.f},
                                    spot_light{{0.f, 1.f, 0.f}, {0.f, -1.f, 0.f}, glm::vec3(1.f), 180.f},
                                    directional_light{{0.f, 0.f, -1.f}, glm::vec3(1.f)}};
    const rsm_layout_settings settings{64, 60.f};
    const auto maps = rsm_layout(lights, lo, hi, settings);
    REQUIRE(maps.size() == 6 + 1 + 5 + 6 + 1);
    std::size_t k = 0;
    for (int f = 0; f < 6; ++f, ++k) {  // point light: every face, in table order
        CHECK(maps[k].light == 0);
        CHECK(maps[k].cube_face == f);
        CHECK(maps[k].forward == rsm_cube_faces[std::size_t(f)].forward);
        CHECK(maps[k].fov_deg == 90.f);
        CHECK(!maps[k].orthographic);
        CHECK(std::abs(maps[k].texel_size - 2.f / 64.f) < 1e-7f);
    }
    // Narrow spot: one map along the (unit) axis, twice the cone.
    CHECK(maps[k].light == 1);
    CHECK(maps[k].cube_face == -1);
    CHECK(maps[k].fov_deg == 60.f);
    CHECK(glm::length(maps[k].forward - glm::vec3(0.f, -1.f, 0.f)) < 1e-7f);
    CHECK(maps[k].up == glm::vec3(1.f, 0.f, 0.f));  // the axis is (anti)parallel to +y
    ++k;
    // An 89-degree spot looking down cannot reach the face looking up (+y, index 2).
    for (int f : {0, 1, 3, 4, 5}) {
        CHECK(maps[k].light == 2);
        CHECK(maps[k].cube_face == f);
        ++k;
    }
    for (int f = 0; f < 6; ++f, ++k) CHECK(maps[k].cube_face == f);  // a full sphere: every face
    // Distant light: orthographic across the beam, over the bounds' sphere.
    const rsm_map_layout& d = maps[k];
    CHECK(d.light == 4);
    CHECK(d.orthographic);
    const float radius = 0.5f * glm::length(hi - lo) * 1.001f;
    CHECK(d.radius == radius);
    CHECK(d.texel_size == float(2.0 * double(radius) / 64.0));
    CHECK(glm::length(d.position - (0.5f * (lo + hi) + glm::vec3(0.f, 0.f, 2.f * radius))) < 1e-5f);
    // The centre of the bounds lands in the middle of the map, at mid depth.
    const glm::vec4 c = d.light_view_projection * glm::vec4(0.5f * (lo + hi), 1.f);
    CHECK(std::abs(c.x) < 1e-5f);
    CHECK(std::abs(c.y) < 1e-5f);
    CHECK(std::abs(c.z) < 1e-5f);

    // Bad lights are refused by index.
    const std::vector<light> bad{point_light{{0.f, 0.f, 0.f}, glm::vec3(-1.f)}};
    CHECK_THROWS_AS(rsm_layout(bad, lo, hi, settings), parameter_error);
    CHECK_THROWS_AS((rsm_layout_settings{0, 60.f}.validate()), parameter_error);
    CHECK_THROWS_AS((rsm_layout_settings{64, 90.f}.validate()), parameter_error);
}

TEST_CASE("rsm_layout: a directional light's map has the scene's size at any scale", "[rsm][layout]") {
    // A scene of 1e-4 units (a tenth of a millimetre in metres) had a map of radius 1e-3 (a
    // fixed floor): the scene covered 1% of its texels. The map follows the bounds now.
    const std::vector<light> sun{directional_light{{0.f, -1.f, 0.f}, glm::vec3(1.f)}};
    for (const float size : {1e-6f, 1e-4f, 1.f, 1e4f, 1e12f}) {
        const glm::vec3 lo(0.f), hi(size);
        const auto maps = rsm_layout(sun, lo, hi, rsm_layout_settings{64, 60.f});
        REQUIRE(maps.size() == 1);
        const float bounding = 0.5f * std::sqrt(3.f) * size;
        INFO("scene size " << size);
        CHECK(maps[0].radius >= bounding);
        CHECK(maps[0].radius <= 1.01f * bounding);
    }
    // A scene in one point still gets a usable (finite, non-degenerate) map.
    const auto point = rsm_layout(sun, glm::vec3(0.f), glm::vec3(0.f), rsm_layout_settings{64, 60.f});
    CHECK(point[0].radius > 0.f);
    CHECK(std::isfinite(point[0].light_view_projection[0][0]));
    CHECK(std::isfinite(point[0].light_view_projection[3][2]));
}

TEST_CASE("rsm_layout: the texel solid angles of a cube face sum to 4 pi / 6", "[rsm][layout]") {
    const double t = std::tan(0.25 * std::numbers::pi);
    double sum = 0;
    for (std::size_t y = 0; y < 16; ++y)
        for (std::size_t x = 0; x < 16; ++x) sum += rsm_texel_solid_angle(t, 16, x, y);
    CHECK(std::abs(sum - 4 * std::numbers::pi / 6) < 1e-12);
    // Symmetric about the centre: a corner texel is the smallest, the same at each corner.
    CHECK(std::abs(rsm_texel_solid_angle(t, 16, 0, 0) / rsm_texel_solid_angle(t, 16, 15, 15) - 1) < 1e-12);
    CHECK(rsm_texel_solid_angle(t, 16, 0, 0) < rsm_texel_solid_angle(t, 16, 7, 7));
}
