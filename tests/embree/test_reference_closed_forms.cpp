// The reference integrator against closed forms. Monte Carlo results must lie within
// 4 standard errors (computed from the sample variance, which bounds the stratified
// estimator's error from above) plus the geometric discretisation bound derived per test,
// plus 1e-5 relative for float arithmetic (positions and rays are single precision).
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/sampling.hpp>

#include "hand_built_scenes.hpp"

#include <catch2/catch.hpp>
#include <glm/glm.hpp>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <numbers>

using namespace bounce;
using namespace bounce::embree;

namespace {

constexpr double pi = std::numbers::pi;
constexpr double float_slack = 1e-5;

// Mean and standard error per channel of the estimator pi * L_i over hemisphere samples.
struct estimate {
    glm::dvec3 mean{0}, sigma{0};
};
estimate hemisphere_estimate(const hemisphere_samples& hs) {
    const double n = double(hs.radiance.size());
    glm::dvec3 sum(0), sum2(0);
    for (const auto& l : hs.radiance) {
        const glm::dvec3 e = pi * glm::dvec3(l);
        sum += e;
        sum2 += e * e;
    }
    estimate r;
    r.mean = sum / n;
    r.sigma = glm::sqrt(glm::max(glm::dvec3(0), sum2 / n - r.mean * r.mean) / n);
    return r;
}

// |got - expected| <= 4 sigma + float slack, per channel.
bool within(glm::dvec3 got, glm::dvec3 expected, glm::dvec3 sigma) {
    for (int c = 0; c < 3; ++c)
        if (!(std::abs(got[c] - expected[c]) <= 4 * sigma[c] + float_slack * std::abs(expected[c]) + 1e-12))
            return false;
    return true;
}

// A floor z = 0 of half-size `half`, facing up.
test::owned_scene floor_scene(float half = 10.f, glm::vec3 kd = glm::vec3(0.5f)) {
    test::owned_scene s;
    s.name = "floor";
    const auto m = hand_built::add_material(s, kd);
    hand_built::add_square_z(s, 0.f, half, true, m);
    return s;
}

glm::vec3 random_floor_point(pcg32& rng, float extent) {
    return {extent * float(2 * rng.next_double() - 1), extent * float(2 * rng.next_double() - 1), 0.f};
}

std::vector<glm::dvec3> square_corners(double z, double half, glm::dvec2 c = {0, 0}) {
    return {{c.x - half, c.y - half, z}, {c.x + half, c.y - half, z}, {c.x + half, c.y + half, z}, {c.x - half, c.y + half, z}};
}

}  // namespace

TEST_CASE("a plane under a uniform sky receives E = pi L", "[reference][closed-form][sky]") {
    const test::owned_scene s = floor_scene();
    const accel bvh(s);
    reference_settings settings;
    settings.environment = {1.f, 0.5f, 0.25f};
    const reference_integrator ri(bvh, s, settings);
    const auto i = GENERATE(range(0, 20));
    pcg32 rng(300 + std::uint64_t(i));
    const glm::vec3 p = random_floor_point(rng, 1.f);
    const auto hs = ri.sample_hemisphere(p, {0, 0, 1}, hemisphere_grid_for(256), std::uint64_t(i));
    for (float d : hs.distance) CHECK(std::isinf(d));  // nothing above the plane
    const estimate e = hemisphere_estimate(hs);
    CHECK(within(e.mean, pi * glm::dvec3(settings.environment), e.sigma));
    CHECK(within(glm::dvec3(ri.indirect_irradiance(p, {0, 0, 1}, 256, 7)), pi * glm::dvec3(settings.environment), e.sigma));
}

TEST_CASE("a black square under a uniform sky removes L times its projected solid angle", "[reference][closed-form][sky]") {
    // E = pi L - L * Lambert(square): exact for a polygon, so only Monte Carlo error remains.
    test::owned_scene s = floor_scene();
    const auto black = hand_built::add_material(s, glm::vec3(0.f));
    const float h = 0.5f, half = 0.4f;
    hand_built::add_square_z(s, h, half, false, black, {0.1f, -0.2f});
    const accel bvh(s);
    reference_settings settings;
    settings.environment = {0.8f, 1.f, 1.2f};
    const reference_integrator ri(bvh, s, settings);
    const auto i = GENERATE(range(0, 12));
    pcg32 rng(400 + std::uint64_t(i));
    const glm::vec3 p = random_floor_point(rng, 0.3f);
    const auto hs = ri.sample_hemisphere(p, {0, 0, 1}, hemisphere_grid_for(1024), 11 + std::uint64_t(i));
    const double blocked = hand_built::lambert_polygon(glm::dvec3(p), {0, 0, 1}, square_corners(h, half, {0.1, -0.2}));
    REQUIRE(blocked > 0.3);  // the square covers a sizeable part of the hemisphere
    const estimate e = hemisphere_estimate(hs);
    CHECK(within(e.mean, glm::dvec3(settings.environment) * (pi - blocked), e.sigma));
}

TEST_CASE("a point light above a plane gives E = I cos(theta) / d^2 exactly", "[reference][closed-form][point]") {
    test::owned_scene s = floor_scene();
    const auto i = GENERATE(range(0, 100));
    pcg32 rng(500 + std::uint64_t(i));
    const glm::vec3 light(float(4 * rng.next_double() - 2), float(4 * rng.next_double() - 2), float(0.2 + 3 * rng.next_double()));
    const glm::vec3 intensity(3.f, 2.f, 1.f);
    s.lights.push_back(bounce::point_light{light, intensity});
    const accel bvh(s);
    const reference_integrator ri(bvh, s);
    const glm::vec3 p = random_floor_point(rng, 3.f);
    const glm::dvec3 d = glm::dvec3(light) - glm::dvec3(p);
    const double dist = glm::length(d);
    const glm::dvec3 expected = glm::dvec3(intensity) * (d.z / dist) / (dist * dist);
    const glm::dvec3 got(ri.direct_irradiance(p, {0, 0, 1}, 1));
    CHECK(glm::length(got - expected) <= float_slack * glm::length(expected));
    // Light below the receiving side: nothing.
    CHECK(ri.direct_irradiance(p, {0, 0, -1}, 1) == glm::vec3(0.f));
}

TEST_CASE("a spot light lights its cone with the chosen falloff and nothing outside", "[reference][closed-form][spot]") {
    const auto falloff = GENERATE(bounce::spot_light::falloff_kind::none, bounce::spot_light::falloff_kind::cosine);
    test::owned_scene s = floor_scene();
    const float height = 1.5f, cone_deg = 30.f;
    s.lights.push_back(bounce::spot_light{{0.f, 0.f, height}, {0.f, 0.f, -1.f}, {2.f, 2.f, 2.f}, cone_deg, falloff});
    const accel bvh(s);
    const reference_integrator ri(bvh, s);
    pcg32 rng(600);
    const double cos_cone = std::cos(cone_deg * pi / 180);
    int lit = 0, dark = 0;
    for (int k = 0; k < 300; ++k) {
        const glm::vec3 p = random_floor_point(rng, 2.f);
        const glm::dvec3 d = glm::dvec3(0, 0, height) - glm::dvec3(p);
        const double dist = glm::length(d), cos_axis = d.z / dist, cos_theta = d.z / dist;
        if (std::abs(cos_axis - cos_cone) < 1e-4) continue;  // float rounding decides the edge
        const double profile =
            cos_axis >= cos_cone ? (falloff == bounce::spot_light::falloff_kind::cosine ? cos_axis : 1.0) : 0.0;
        const double expected = 2.0 * profile * cos_theta / (dist * dist);
        const double got = ri.direct_irradiance(p, {0, 0, 1}, 1).x;
        CHECK(std::abs(got - expected) <= float_slack * expected + 1e-12);
        (profile > 0 ? lit : dark) += 1;
    }
    CHECK(lit > 20);
    CHECK(dark > 20);
}

TEST_CASE("an occluder casts an exact shadow of a point light", "[reference][closed-form][shadow]") {
    // Light at height 2 over a square of half-size 0.25 at height 1: its umbra on the floor
    // is the square of half-size 0.5 (similar triangles).
    test::owned_scene s = floor_scene();
    const auto m = hand_built::add_material(s, glm::vec3(0.7f));
    hand_built::add_square_z(s, 1.f, 0.25f, false, m);
    s.lights.push_back(bounce::point_light{{0.f, 0.f, 2.f}, glm::vec3(4.f)});
    const accel bvh(s);
    const reference_integrator ri(bvh, s);
    pcg32 rng(700);
    int shadowed = 0, lit = 0;
    for (int k = 0; k < 400; ++k) {
        const glm::vec3 p = random_floor_point(rng, 1.5f);
        const double edge = std::max(std::abs(p.x), std::abs(p.y));
        const double got = ri.direct_irradiance(p, {0, 0, 1}, 1).x;
        if (edge < 0.49) {
            CHECK(got == 0.0);
            ++shadowed;
        } else if (edge > 0.51) {
            const glm::dvec3 d = glm::dvec3(0, 0, 2) - glm::dvec3(p);
            const double dist = glm::length(d), expected = 4.0 * (d.z / dist) / (dist * dist);
            CHECK(std::abs(got - expected) <= float_slack * expected);
            ++lit;
        }
    }
    CHECK(shadowed > 20);
    CHECK(lit > 100);
}

TEST_CASE("an emissive square lights the floor with L times Lambert's polygon irradiance", "[reference][closed-form][area]") {
    // The area estimate is compared with the exact polygon irradiance; its standard error
    // comes from 32 independent estimates (different seeds) at each point.
    test::owned_scene s = floor_scene();
    const glm::vec3 le(2.f, 4.f, 1.f);
    const auto emitter = hand_built::add_material(s, glm::vec3(0.f), le);
    const float h = 0.6f, half = 0.3f;
    hand_built::add_square_z(s, h, half, false, emitter);  // facing down, onto the floor
    s.use_emission = true;
    const accel bvh(s);
    const reference_integrator ri(bvh, s);
    CHECK(ri.emitter_area() == Approx(4.0 * half * half).epsilon(1e-6));
    const auto i = GENERATE(range(0, 10));
    pcg32 rng(800 + std::uint64_t(i));
    const glm::vec3 p = random_floor_point(rng, 0.8f);
    const double exact = hand_built::lambert_polygon(glm::dvec3(p), {0, 0, 1}, square_corners(h, half));
    const int runs = 32;
    glm::dvec3 sum(0), sum2(0);
    for (int r = 0; r < runs; ++r) {
        const glm::dvec3 e(ri.direct_irradiance(p, {0, 0, 1}, 16, std::uint64_t(1000 * i + r)));
        sum += e;
        sum2 += e * e;
    }
    const glm::dvec3 mean = sum / double(runs);
    const glm::dvec3 sigma = glm::sqrt(glm::max(glm::dvec3(0), sum2 / double(runs) - mean * mean) / double(runs - 1));
    CHECK(within(mean, glm::dvec3(le) * exact, sigma));
    // The emitter emits downwards only: a point above it, facing it, receives nothing.
    CHECK(ri.direct_irradiance({0.f, 0.f, 1.2f}, {0, 0, -1}, 16, 1) == glm::vec3(0.f));
}

TEST_CASE("furnace: inside a closed sphere lit from its centre, E_indirect = rho I / R^2", "[reference][closed-form][furnace]") {
    // Exact sphere: E_direct = I / R^2 everywhere, so one bounce gives rho I / R^2. On the
    // tessellated sphere the interpolated radial normals point at the centre exactly, so
    // E_direct(q) = I / |q - c|^2 with h_min <= |q - c| <= R (h_min: the smallest distance
    // from the centre to a face plane); every hemisphere ray hits (closed surface), hence
    // rho I / R^2 <= E_indirect <= rho I / h_min^2.
    test::owned_scene s;
    const glm::vec3 rho(0.3f, 0.6f, 0.9f), intensity(2.f, 1.f, 0.5f);
    const glm::dvec3 centre(0.1, -0.2, 0.3);
    const double radius = 1.5;
    hand_built::add_icosphere(s, centre, radius, 4, hand_built::add_material(s, rho));
    s.lights.push_back(bounce::point_light{glm::vec3(centre), intensity});
    const accel bvh(s);
    const reference_integrator ri(bvh, s);

    double h_min = radius;
    for (const auto& t : s.triangles) {
        const glm::dvec3 a(s.positions[t.x]), b(s.positions[t.y]), c(s.positions[t.z]);
        h_min = std::min(h_min, std::abs(glm::dot(glm::normalize(glm::cross(b - a, c - a)), a - centre)));
    }
    REQUIRE(h_min > 0.99 * radius);

    const auto i = GENERATE(range(0, 24));
    pcg32 rng(900 + std::uint64_t(i));
    const auto& tri = s.triangles[rng.next_u32() % s.triangles.size()];
    double b1 = rng.next_double(), b2 = rng.next_double();
    if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
    const glm::dvec3 q = (1 - b1 - b2) * glm::dvec3(s.positions[tri.x]) + b1 * glm::dvec3(s.positions[tri.y]) +
                         b2 * glm::dvec3(s.positions[tri.z]);
    const glm::vec3 p(q), n(glm::normalize(centre - q));

    // Direct: the inverse-square law at the point itself (cos = 1), no Monte Carlo.
    const double dq = glm::length(q - centre);
    CHECK(glm::length(glm::dvec3(ri.direct_irradiance(p, n, 1)) - glm::dvec3(intensity) / (dq * dq)) <=
          float_slack * glm::length(glm::dvec3(intensity)) / (dq * dq));

    const auto hs = ri.sample_hemisphere(p, n, hemisphere_grid_for(400), 40 + std::uint64_t(i));
    for (float d : hs.distance) REQUIRE(std::isfinite(d));  // watertight: no ray escapes
    const estimate e = hemisphere_estimate(hs);
    for (int c = 0; c < 3; ++c) {
        const double lo = rho[c] * intensity[c] / (radius * radius), hi = rho[c] * intensity[c] / (h_min * h_min);
        CHECK(e.mean[c] >= lo * (1 - float_slack) - 4 * e.sigma[c]);
        CHECK(e.mean[c] <= hi * (1 + float_slack) + 4 * e.sigma[c]);
    }
}

TEST_CASE("hemisphere samples under a lit ceiling see h / cos(theta) and the ceiling's radiance", "[reference][closed-form][hemisphere]") {
    // A ceiling z = h lit from below by a directional light of irradiance E0 sends
    // L = rho E0 / pi down; rays that miss it bring the environment L_env. So
    // E = rho E0 / pi * Lambert(ceiling) + L_env (pi - Lambert(ceiling)), and each hit lies
    // at distance h / cos(theta).
    test::owned_scene s;
    const float h = 0.7f, half = 2.f;
    const glm::vec3 rho(0.5f, 0.25f, 1.f);
    hand_built::add_square_z(s, h, half, false, hand_built::add_material(s, rho));
    s.lights.push_back(bounce::directional_light{{0.f, 0.f, 1.f}, {3.f, 3.f, 3.f}});
    const accel bvh(s);
    reference_settings settings;
    settings.environment = {0.1f, 0.2f, 0.3f};
    const reference_integrator ri(bvh, s, settings);
    const glm::vec3 p(0.2f, -0.1f, 0.f), n(0, 0, 1);
    const auto hs = ri.sample_hemisphere(p, n, {24, 75}, 5);
    const glm::dvec3 l_ceiling = glm::dvec3(rho) * 3.0 / pi;
    for (std::size_t k = 0; k < hs.direction.size(); ++k) {
        const glm::dvec3 d(hs.direction[k]);
        const glm::dvec3 at = glm::dvec3(p) + d * (double(h) / d.z);
        const double edge = std::max(std::abs(at.x), std::abs(at.y));
        if (edge < half - 1e-3) {
            // Rays leave from p + eps n (eps = ray_epsilon()), so the hit is (h - eps) / cos away.
            CHECK(double(hs.distance[k]) == Approx((h - ri.ray_epsilon()) / d.z).epsilon(1e-5));
            CHECK(glm::length(glm::dvec3(hs.radiance[k]) - l_ceiling) < 1e-5);
        } else if (edge > half + 1e-3) {
            CHECK(std::isinf(hs.distance[k]));
            CHECK(hs.radiance[k] == settings.environment);
        }
    }
    const double covered = hand_built::lambert_polygon(glm::dvec3(p), glm::dvec3(n), square_corners(h, half));
    const estimate e = hemisphere_estimate(hs);
    CHECK(within(e.mean, l_ceiling * covered + glm::dvec3(settings.environment) * (pi - covered), e.sigma));
}

TEST_CASE("hemisphere samples lie one per Ward-Heckbert stratum", "[reference][hemisphere]") {
    const test::owned_scene s = floor_scene();
    const accel bvh(s);
    const reference_integrator ri(bvh, s);
    const glm::vec3 n = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
    const hemisphere_grid grid{7, 22};
    const auto hs = ri.sample_hemisphere({0.f, 0.f, 0.5f}, n, grid, 3);
    REQUIRE(hs.direction.size() == grid.count());
    CHECK(glm::length(glm::cross(hs.tangent, hs.bitangent) - n) < 1e-6f);
    for (std::uint32_t j = 0; j < grid.m; ++j)
        for (std::uint32_t k = 0; k < grid.n; ++k) {
            const std::size_t i = j * grid.n + k;
            const double s2 = std::pow(std::sin(double(hs.theta[i])), 2);
            // sin^2 theta lies in [j / M, (j + 1) / M] and phi in its 1/N-th of the circle.
            CHECK(s2 >= double(j) / grid.m - 1e-6);
            CHECK(s2 <= double(j + 1) / grid.m + 1e-6);
            CHECK(hs.phi[i] >= float(2 * pi * k / grid.n) - 1e-5f);
            CHECK(hs.phi[i] <= float(2 * pi * (k + 1) / grid.n) + 1e-5f);
            const glm::vec3 expected = std::sin(hs.theta[i]) * (std::cos(hs.phi[i]) * hs.tangent + std::sin(hs.phi[i]) * hs.bitangent) +
                                       std::cos(hs.theta[i]) * n;
            CHECK(glm::length(hs.direction[i] - expected) < 1e-5f);
        }
    const auto g = hemisphere_grid_for(1024);
    CHECK(g.m == 18);  // round(sqrt(1024 / pi)) = round(18.05)
    CHECK(g.n == 57);  // round(1024 / 18) = round(56.9)
    CHECK_THROWS_AS(hemisphere_grid_for(0), parameter_error);
}

TEST_CASE("per-pixel images are rho / pi times the irradiance and sum to the combined image", "[reference][images]") {
    test::owned_scene s = floor_scene(3.f, glm::vec3(0.2f, 0.4f, 0.6f));
    s.lights.push_back(bounce::point_light{{0.3f, 0.2f, 1.5f}, glm::vec3(2.f)});
    s.camera.position = {0.f, -2.f, 2.f};
    s.camera.look_at = {0.f, 0.f, 0.f};
    s.camera.up = {0.f, 0.f, 1.f};
    const accel bvh(s);
    auto g = ray_cast_gbuffer(bvh, s, s.camera, 24, 16);
    reference_settings settings;
    settings.hemisphere_samples = 16;
    settings.environment = glm::vec3(0.5f);
    const auto r = render_reference(bvh, s, g.view(), settings);
    const reference_integrator ri(bvh, s, settings);
    std::size_t covered = 0;
    for (std::size_t y = 0; y < 16; ++y)
        for (std::size_t x = 0; x < 24; ++x) {
            CHECK(r.combined(x, y) == r.direct(x, y) + r.indirect(x, y));
            if (!g.view().covered(x, y)) {
                CHECK(r.direct(x, y) == glm::vec3(0.f));
                continue;
            }
            ++covered;
            const glm::vec3 e = ri.direct_irradiance(g.position(x, y), g.normal(x, y), 1);
            CHECK(glm::length(r.direct(x, y) - g.albedo(x, y) / float(pi) * e) <= 1e-6f * glm::length(e));
            // The floor is open to the sky only: E_i = pi L_env exactly.
            CHECK(glm::length(glm::dvec3(r.indirect(x, y)) - glm::dvec3(g.albedo(x, y)) * 0.5) < 1e-6);
        }
    CHECK(covered > 100);
}

TEST_CASE("reference images are bitwise the same with 1 and 2 threads", "[reference][determinism]") {
    // A closed box with a point light and an emissive patch: every random stream is used.
    test::owned_scene s;
    const auto white = hand_built::add_material(s, glm::vec3(0.7f)), red = hand_built::add_material(s, {0.6f, 0.1f, 0.1f});
    const auto lamp = hand_built::add_material(s, glm::vec3(0.f), glm::vec3(5.f));
    hand_built::add_square_z(s, 0.f, 1.f, true, white);
    hand_built::add_square_z(s, 2.f, 1.f, false, white);
    hand_built::add_square_z(s, 1.99f, 0.2f, false, lamp);
    hand_built::add_quad(s, {-1, -1, 0}, {-1, 1, 0}, {-1, 1, 2}, {-1, -1, 2}, {1, 0, 0}, red);
    hand_built::add_quad(s, {1, -1, 0}, {1, -1, 2}, {1, 1, 2}, {1, 1, 0}, {-1, 0, 0}, white);
    hand_built::add_quad(s, {-1, 1, 0}, {1, 1, 0}, {1, 1, 2}, {-1, 1, 2}, {0, -1, 0}, white);
    s.use_emission = true;
    s.lights.push_back(bounce::point_light{{0.3f, 0.f, 1.5f}, glm::vec3(1.f)});
    s.camera.position = {0.f, -3.f, 1.f};
    s.camera.look_at = {0.f, 0.f, 1.f};
    s.camera.up = {0.f, 0.f, 1.f};
    const accel bvh(s);

    reference_settings settings;
    settings.hemisphere_samples = 32;
    settings.area_samples = 4;
    // (done, total) pairs; the callback runs on worker threads (serialized), so the checks
    // wait for the main thread.
    std::vector<std::pair<std::size_t, std::size_t>> reported;
    settings.progress = [&](std::size_t done, std::size_t total) { reported.emplace_back(done, total); };
    auto render = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        auto g = ray_cast_gbuffer(bvh, s, s.camera, 20, 20);
        reported.clear();
        return render_reference(bvh, s, g.view(), settings);
    };
    const auto one = render(1);
    const auto two = render(2);
    // Progress counted every row of both images (direct, then indirect), in increasing order.
    REQUIRE(reported.size() == 40);
    for (std::size_t k = 0; k < 40; ++k) {
        CHECK(reported[k].first == k % 20 + 1);
        CHECK(reported[k].second == 20);
    }
    auto same = [](const image<glm::vec3>& a, const image<glm::vec3>& b) {
        return std::memcmp(a.data(), b.data(), a.width() * a.height() * sizeof(glm::vec3)) == 0;
    };
    CHECK(same(one.direct, two.direct));
    CHECK(same(one.indirect, two.indirect));
    CHECK(same(one.combined, two.combined));
    // And the images are not trivially zero: the box is lit and reflects.
    double total = 0;
    for (std::size_t y = 0; y < 20; ++y)
        for (std::size_t x = 0; x < 20; ++x) total += one.indirect(x, y).x;
    CHECK(total > 0);
}

TEST_CASE("the integrator refuses bad lights, settings and points", "[reference][bad-input]") {
    test::owned_scene s = floor_scene();
    const accel bvh(s);
    SECTION("zero spot direction") {
        s.lights.push_back(bounce::spot_light{{0, 0, 1}, {0, 0, 0}, glm::vec3(1.f), 30.f});
        CHECK_THROWS_WITH(reference_integrator(bvh, s), Catch::Contains("scene.lights[0]"));
    }
    SECTION("zero cone") {
        s.lights.push_back(bounce::spot_light{{0, 0, 1}, {0, 0, -1}, glm::vec3(1.f), 0.f});
        CHECK_THROWS_AS(reference_integrator(bvh, s), parameter_error);
    }
    SECTION("negative intensity") {
        s.lights.push_back(bounce::point_light{{0, 0, 1}, {1.f, -1.f, 1.f}});
        CHECK_THROWS_AS(reference_integrator(bvh, s), parameter_error);
    }
    SECTION("NaN directional light") {
        s.lights.push_back(bounce::directional_light{{0, 0, std::numeric_limits<float>::quiet_NaN()}, glm::vec3(1.f)});
        CHECK_THROWS_AS(reference_integrator(bvh, s), parameter_error);
    }
    SECTION("settings") {
        reference_settings bad;
        bad.hemisphere_samples = 0;
        CHECK_THROWS_WITH(reference_integrator(bvh, s, bad), Catch::Contains("hemisphere_samples"));
        bad = {};
        bad.environment.x = -1.f;
        CHECK_THROWS_WITH(reference_integrator(bvh, s, bad), Catch::Contains("environment"));
    }
    SECTION("points and normals") {
        const reference_integrator ri(bvh, s);
        CHECK_THROWS_WITH(ri.direct_irradiance({0, 0, 0}, {0, 0, 2}, 1), Catch::Contains("'n'"));
        CHECK_THROWS_AS(ri.indirect_irradiance({0, std::numeric_limits<float>::infinity(), 0}, {0, 0, 1}, 16, 1),
                        parameter_error);
        CHECK_THROWS_AS(ri.sample_hemisphere({0, 0, 0}, {0, 0, 1}, {0, 4}, 1), parameter_error);
    }
    SECTION("a G-buffer with a broken pixel") {
        const reference_integrator ri(bvh, s);
        gbuffer<float> g(4, 4);
        g.depth(1, 2) = 1.f;  // covered, but its normal is zero
        CHECK_THROWS_WITH(ri.direct_image(g.view()), Catch::Contains("pixel (1, 2)"));
    }
}
