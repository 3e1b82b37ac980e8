// The ray-cast plane sampler (sample_plane over the Embree reference integrator's
// incoming_radiance): the same planes as the analytic ceiling away from its edge, and
// irradiance and its translation gradient close to the closed forms of the half-lit ceiling.
#include "../core/half_lit_ceiling.hpp"
#include "half_lit_ceiling_scene.hpp"

#include <bounce/embree/accel.hpp>
#include <bounce/embree/plane_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/cpu/plane_estimate.hpp>
#include <bounce/cache/plane_camera.hpp>
#include <bounce/cache/plane_weights.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <utility>

using namespace bounce;

namespace {

constexpr double pi = std::numbers::pi;

}  // namespace

TEST_CASE("ray-cast planes of a half-lit ceiling give the closed-form irradiance and gradient", "[hemisphere][embree]") {
    const float H = 1.5f, x_edge = 0.25f, kd = 0.6f, E_perp = 3.f;
    const double L = double(kd) * E_perp / pi;
    const test::owned_scene s = hemisphere_test::half_lit_ceiling_scene(H, x_edge, kd, E_perp);
    const embree::accel bvh(s);
    const embree::reference_integrator ref(bvh, s);
    // Planes in orthonormal_basis(n), turned by a fixed angle, or each by its own.
    const auto [turn, hashed] = GENERATE(std::pair{0.0, false}, std::pair{30.0, false}, std::pair{0.0, true});
    const plane_camera cam{64, 126.0, turn, hashed};
    const auto stretch = make_plane_weights(cam, plane_weighting::stretch);
    const glm::vec3 n(0, 1, 0);
    pcg32 rng(8);
    for (int c = 0; c < 12; ++c) {
        const glm::vec3 p(float(2 * rng.next_double() - 1), 0.f, float(2 * rng.next_double() - 1));
        image<glm::vec3> radiance(cam.resolution, cam.resolution);
        image<float> distance(cam.resolution, cam.resolution);
        embree::sample_plane(ref, cam, p, n, radiance.view(), distance.view());
        const auto e = cpu::estimate_plane(stretch, {radiance.view(), distance.view()});
        // The record at p sees the lit side where world x > x_edge: the core test's ceiling
        // (ceiling_seen_from), its rigorous bound on E (mixed cells) and its translation
        // budget for N = 64.
        const auto hc = hemisphere_test::ceiling_seen_from(cam, p, H, ref.ray_epsilon(), x_edge, L);
        const auto bound = ceiling_test::mixed_cells(cam, hc, true);
        CAPTURE(turn, hashed, p.x, p.z, e.irradiance.x, hc.E(), bound.E);
        // Float radiance (relative 1e-7 of E) on top of the bound.
        CHECK(std::abs(e.irradiance.x - hc.E()) <= L * bound.E + 1e-6 * hc.E());
        CHECK(glm::length(e.rotation[0] - hc.rot_y() * hc.across()) <= L * bound.rotation + 1e-6 * hc.E());
        CHECK(glm::length(e.translation[0] - hc.dE_dx() * hc.along()) < 0.044 * pi * L / (2 * hc.h));
        const double E = hc.E();
        // And the full-hemisphere reference integrator agrees with the same closed form
        // (its stratified estimate of a step: ~1/M of the scale with M = 18 at 1024 rays).
        const glm::vec3 Eref = ref.indirect_irradiance(p, n, 1024, 1000 + c);
        CHECK(std::abs(double(Eref.x) - E) < 1.0 / 18 * pi * L / 2);
    }
}
