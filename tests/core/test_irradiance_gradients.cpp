// The hemisphere estimator against closed forms: a point under an infinite plane at height
// h whose radiance is L0 for world x > 0 and 0 elsewhere (a "half-lit ceiling").
//   E(x0)           = (pi L0 / 2) (1 + x0 / sqrt(x0^2 + h^2))
//   dE/dx0          = (pi L0 / 2) h^2 / (x0^2 + h^2)^(3/2),   dE/dy0 = 0
//   grad_r          = int L (n x w) dw = (0, (pi L0 / 2) h / sqrt(x0^2 + h^2), 0)
// (derivations in docs/irradiance-splatting.md). The hemisphere is rotated about z by a
// random angle so the edge does not line up with the strata.
#include <bounce/irradiance_gradients.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace bounce;

namespace {
struct half_lit_ceiling {
    double h, x0, L0, rot;  // height, point offset, radiance, rotation of the edge about z

    // Samples seen from the origin with normal +z; the lit half-plane is {x cos(rot) + y sin(rot) > -x0}.
    hemisphere_samples sample(std::uint32_t M, std::uint32_t N, std::uint64_t seed) const {
        hemisphere_samples s;
        s.rings = M;
        s.wedges = N;
        s.direction = stratified_cosine_directions(M, N, stratified2(N, M, seed));
        for (const auto& d : s.direction) {
            const double t = h / double(d.z);
            const double along = t * (d.x * std::cos(rot) + d.y * std::sin(rot));
            const bool lit = along > -x0;
            s.radiance.emplace_back(float(lit ? L0 : 0.0));
            s.distance.push_back(float(t));
        }
        return s;
    }
    double E() const { return std::numbers::pi * L0 / 2 * (1 + x0 / std::hypot(x0, h)); }
    double dE_dx() const { return std::numbers::pi * L0 / 2 * h * h / std::pow(x0 * x0 + h * h, 1.5); }
    double rot_y() const { return std::numbers::pi * L0 / 2 * h / std::hypot(x0, h); }
    glm::dvec3 along() const { return {std::cos(rot), std::sin(rot), 0}; }
    glm::dvec3 across() const { return {-std::sin(rot), std::cos(rot), 0}; }
};
}  // namespace

TEST_CASE("the estimator recovers irradiance and both gradients of a half-lit ceiling", "[gradients]") {
    pcg32 rng(2024);
    const int cases = 200;
    double worst_E = 0, worst_t_k = 0, worst_t_w = 0, worst_r = 0;
    double sum_t_k = 0, sum_t_w = 0;
    for (int i = 0; i < cases; ++i) {
        const half_lit_ceiling c{0.5 + 2 * rng.next_double(), 4 * rng.next_double() - 2, 1 + rng.next_double(),
                                 2 * std::numbers::pi * rng.next_double()};
        const auto s = c.sample(32, 128, std::uint64_t(i));
        const auto ek = estimate_hemisphere(s, translation_gradient_kind::krivanek_2005);
        const auto ew = estimate_hemisphere(s, translation_gradient_kind::ward_heckbert_1992);
        const double scale = std::numbers::pi * c.L0 / 2;  // the size of every quantity here
        worst_E = std::max(worst_E, std::abs(ek.irradiance.x - c.E()) / scale);
        const double tk = glm::length(ek.translation[0] - c.dE_dx() * c.along()) * c.h / scale;
        const double tw = glm::length(ew.translation[0] - c.dE_dx() * c.along()) * c.h / scale;
        worst_t_k = std::max(worst_t_k, tk);
        worst_t_w = std::max(worst_t_w, tw);
        sum_t_k += tk;
        sum_t_w += tw;
        worst_r = std::max(worst_r, glm::length(ek.rotation[0] - c.rot_y() * c.across()) / scale);
        // Grey radiance: every channel must agree.
        CHECK(ek.irradiance.x == ek.irradiance.z);
    }
    // Error budget: the edge crosses each of the N wedges in one ring cell whose value is a
    // point sample of a step, so the irradiance error is at most one cell weight per wedge,
    // N * pi L0 / (M N) = pi L0 / M, i.e. 2/M of the scale pi L0 / 2. The gradients are sums
    // of differences across walls located to within one stratum, ~1/M in sin^2(theta): we
    // allow 1.5/M of the natural scale pi L0 / (2 h) for Krivanek's form. The rotation gradient
    // is a plain cell sum like E, with weights bounded by E's: the same 2/M budget.
    CAPTURE(worst_E, worst_t_k, worst_t_w, worst_r, sum_t_k / cases, sum_t_w / cases);
    CHECK(worst_E < 2.0 / 32);
    CHECK(worst_t_k < 1.5 / 32);
    CHECK(worst_r < 2.0 / 32);
    // Krivanek's azimuthal walls carry the cosine Ward-Heckbert's omit: on average better.
    CHECK(sum_t_k < sum_t_w);
}

TEST_CASE("a uniform environment has zero gradients and irradiance pi L", "[gradients]") {
    const auto M = GENERATE(1u, 2u, 7u, 16u);
    const auto N = GENERATE(1u, 3u, 32u);
    hemisphere_samples s;
    s.rings = M;
    s.wedges = N;
    s.direction = stratified_cosine_directions(M, N, stratified2(N, M, 9));
    s.radiance.assign(s.size(), glm::vec3(0.25f, 1.f, 2.f));
    s.distance.assign(s.size(), 3.f);
    const auto e = estimate_hemisphere(s);
    // Cell weights sum to pi exactly up to rounding of M*N additions.
    CHECK(e.irradiance.x == Approx(std::numbers::pi * 0.25).epsilon(1e-12));
    CHECK(e.irradiance.z == Approx(std::numbers::pi * 2.0).epsilon(1e-12));
    for (int c = 0; c < 3; ++c) {
        CHECK(glm::length(e.translation[c]) < 1e-12);
        CHECK(glm::length(e.rotation[c]) < 1e-12);
    }
    CHECK(e.harmonic_mean_distance == Approx(3.0).epsilon(1e-6));
}

TEST_CASE("escaped rays do not shorten the harmonic mean distance and bad samples are refused", "[gradients][bad-input]") {
    hemisphere_samples s;
    s.rings = 2;
    s.wedges = 2;
    s.direction = stratified_cosine_directions(2, 2, stratified2(2, 2, 1));
    s.radiance.assign(4, glm::vec3(1.f));
    s.distance = {2.f, std::numeric_limits<float>::infinity(), 2.f, std::numeric_limits<float>::infinity()};
    CHECK(estimate_hemisphere(s).harmonic_mean_distance == Approx(4.0));  // 4 / (1/2 + 1/2)
    s.distance.assign(4, std::numeric_limits<float>::infinity());
    CHECK(std::isinf(estimate_hemisphere(s).harmonic_mean_distance));
    s.distance[0] = 0.f;
    CHECK_THROWS_AS(estimate_hemisphere(s), parameter_error);
    s.distance[0] = 1.f;
    s.radiance[2].y = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_AS(estimate_hemisphere(s), parameter_error);
    s.radiance.pop_back();
    CHECK_THROWS_AS(estimate_hemisphere(s), parameter_error);
}
