// The GPU lookups of an irradiance volume (gl/irradiance_volume.hpp: the kernels of
// volume/kernels.hpp emitted to GLSL, run by a compute pass on llvmpipe in CI)
// agree with the CPU's (volume/probe_octree.hpp) on an adaptive octree with gradients and
// inside probes.
//
// Tolerance 1e-5 relative to the largest irradiance of the volume: both sides add the same
// nonzero terms in the same order (the GPU also adds the zero-weight terms the CPU skips,
// which change nothing); each term is a 9-coefficient SH evaluation (about 40 float
// operations, ~2 ulp each in the worst case on either side: 40 * 2 * 6e-8 = 5e-6 of the
// term's size) times a weight whose pow() llvmpipe evaluates to a few ulp; the average is a
// convex combination, so the error stays below ~5e-6 of the largest term: 1e-5 of the
// largest irradiance covers it.
#include "../gl/shared_context.hpp"
#include "../owned_scene.hpp"

#include <bounce/gl/irradiance_volume.hpp>
#include <bounce/volume/probe_octree.hpp>
#include <bounce/volume/probe_visibility.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace bounce;

namespace {

// One triangle across the volume (the scene a build needs; the probes come from fields).
test::owned_scene one_triangle() {
    test::owned_scene scene;
    scene.materials = {material{glm::vec3(0.5f), glm::vec3(0.f)}};
    scene.positions = {{0.3f, -0.9f, -0.9f}, {0.3f, 0.9f, -0.9f}, {0.3f, -0.9f, 0.9f}};
    scene.triangles = {{0, 1, 2}};
    scene.material_of = {0};
    return scene;
}

}  // namespace

TEST_CASE("GPU and CPU irradiance-volume lookups agree to 1e-5", "[irradiance_volume][gl]") {
    gl_test::shared_context();
    const test::owned_scene scene = one_triangle();
    // A smooth non-linear field with analytic gradients; probes with z < -0.8 are inside.
    const auto source = [](std::span<const glm::vec3> p, std::span<irradiance_probe> out) {
        for (std::size_t j = 0; j < p.size(); ++j) {
            const glm::vec3 x = p[j];
            out[j] = {};
            out[j].position = x;
            out[j].inside = x.z < -0.8f;
            for (std::size_t i = 0; i < 9; ++i) {
                const float a = 0.3f * float(i + 1);
                out[j].radiance[i] = glm::vec3(std::sin(a * x.x) + 1.5f, std::cos(a * x.y) + x.z, 0.5f * x.x * x.y + 1.f) /
                                     float(i + 1);
                out[j].gradient[0][i] = glm::vec3(a * std::cos(a * x.x), 0.f, 0.5f * x.y) / float(i + 1);
                out[j].gradient[1][i] = glm::vec3(0.f, -a * std::sin(a * x.y), 0.5f * x.x) / float(i + 1);
                out[j].gradient[2][i] = glm::vec3(0.f, 1.f, 0.f) / float(i + 1);
            }
            out[j].harmonic_mean_distance = 1;
        }
    };
    irradiance_volume_settings s;
    s.min_depth = 1;
    s.max_depth = 3;
    s.distance_ratio = s.neighbour_change = s.gradient_ratio = s.cull_tolerance = 0;
    s.prediction_tolerance = 0;  // Oat's heuristics shape this octree
    s.geometry_triangles = 1;
    const auto volume = irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), s, source);
    REQUIRE(volume.depth() == 3);

    std::vector<glm::vec3> points, normals;
    pcg32 rng(5);
    for (int i = 0; i < 1500; ++i) {
        // Inside the volume, a little outside it, and on its splitting planes.
        glm::vec3 p(2.2f * rng.next_float() - 1.1f, 2.2f * rng.next_float() - 1.1f, 2.2f * rng.next_float() - 1.1f);
        if (i % 7 == 0) p.x = 0.f;
        if (i % 11 == 0) p.y = 0.25f;
        const float z = 2 * rng.next_float() - 1, phi = 6.2831853f * rng.next_float(), r = std::sqrt(std::max(0.f, 1 - z * z));
        points.push_back(p);
        normals.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    const gl::irradiance_volume_buffers buffers(volume);
    const gl::irradiance_volume_lookup lookup;
    struct variant {
        gl::volume_interpolation interpolation;
        weighted_lookup how;
    };
    for (const variant v : {variant{gl::volume_interpolation::trilinear, {}}, variant{gl::volume_interpolation::weighted, {}},
                            variant{gl::volume_interpolation::weighted, {1.f, false, 2.5f}},
                            variant{gl::volume_interpolation::weighted, {4.f, true, 1.2f}}}) {
        const auto gpu = lookup.light_points(buffers, points, normals, v.interpolation, v.how);
        std::vector<glm::vec3> cpu(points.size());
        float largest = 0;
        for (std::size_t i = 0; i < points.size(); ++i) {
            cpu[i] = v.interpolation == gl::volume_interpolation::trilinear ? volume.trilinear(points[i], normals[i])
                                                                            : volume.weighted(points[i], normals[i], v.how);
            for (int k = 0; k < 3; ++k) largest = std::max(largest, std::abs(cpu[i][k]));
        }
        REQUIRE(largest > 0.1f);
        for (std::size_t i = 0; i < points.size(); ++i)
            for (int k = 0; k < 3; ++k) {
                INFO("point " << i << " channel " << k << " interpolation " << int(v.interpolation) << " b " << v.how.b);
                REQUIRE(gpu[i][k] == Approx(cpu[i][k]).margin(1e-5 * largest));
            }
    }
    // Radiance with the caller's albedo (output.hpp): rho/pi times the irradiance, per point.
    const std::vector<glm::vec3> albedo(points.size(), glm::vec3(0.2f, 0.5f, 0.9f));
    const auto e = lookup.light_points(buffers, points, normals, gl::volume_interpolation::weighted);
    const auto l = lookup.light_points(buffers, points, normals, gl::volume_interpolation::weighted, {},
                                       output_quantity::radiance, albedo);
    for (std::size_t i = 0; i < points.size(); ++i) REQUIRE(l[i] == lambertian_radiance<float, glm::vec3>(albedo[i], e[i]));
    CHECK_THROWS_AS(lookup.light_points(buffers, points, normals, gl::volume_interpolation::weighted, {},
                                        output_quantity::radiance),
                    parameter_error);

    // Visibility (DDGI, volume/probe_visibility.hpp): random distance moments in 8 x 8 maps
    // and relocated probe positions, points at probes too, the eye inside the volume; the
    // same tolerance.
    std::vector<float> moments;
    for (std::size_t j = 0; j < volume.probes().size() * 64; ++j) {
        const float mean = 1.2f * rng.next_float(), variance = 0.05f * rng.next_float() * rng.next_float();
        moments.push_back(mean);
        moments.push_back(mean * mean + variance);
    }
    std::vector<glm::vec3> baked_at;  // relocated probes: a few hundredths off their lattice points
    for (const auto& pr : volume.probes())
        baked_at.push_back(pr.position + 0.04f * glm::vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f));
    const probe_visibility vis(8, moments, baked_at);
    for (std::size_t j = 0; j < volume.probes().size(); j += 17) points[j] = baked_at[j];  // distance 0 from the probe
    const glm::vec3 eye(0.1f, 0.2f, -0.3f);
    const gl::irradiance_volume_buffers with_moments(volume, &vis);
    CHECK_THROWS_AS(lookup.light_points(buffers, points, normals, eye, visibility_lookup{}), parameter_error);
    for (const float bias : {0.f, 0.3f, 1.f}) {
        const visibility_lookup how{volume_visibility::chebyshev, bias};
        const auto gpu = lookup.light_points(with_moments, points, normals, eye, how);
        float largest = 0;
        std::vector<glm::vec3> cpu(points.size());
        for (std::size_t i = 0; i < points.size(); ++i) {
            cpu[i] = trilinear_visible(volume, vis, points[i], normals[i],
                                       view_direction<float, glm::vec3>(points[i], normals[i], eye), how);
            for (int k = 0; k < 3; ++k) largest = std::max(largest, std::abs(cpu[i][k]));
        }
        REQUIRE(largest > 0.1f);
        for (std::size_t i = 0; i < points.size(); ++i)
            for (int k = 0; k < 3; ++k) {
                INFO("visibility: point " << i << " channel " << k << " bias " << bias);
                REQUIRE(std::isfinite(gpu[i][k]));
                REQUIRE(gpu[i][k] == Approx(cpu[i][k]).margin(1e-5 * largest));
            }
    }
    // Mode none is the plain trilinear lookup.
    const auto none = lookup.light_points(with_moments, points, normals, eye, visibility_lookup{volume_visibility::none, 0.3f});
    for (std::size_t i = 0; i < points.size(); ++i)
        for (int k = 0; k < 3; ++k) REQUIRE(none[i][k] == Approx(volume.trilinear(points[i], normals[i])[k]).margin(1e-5));
}

TEST_CASE("the GPU lookup refuses a volume whose hanging corners the CPU lookup computes", "[irradiance_volume][gl]") {
    gl_test::shared_context();
    const test::owned_scene scene = one_triangle();
    // Light with a step at x = 0.5: merged octrees keep depth 3 there, coarser elsewhere.
    const auto source = [](std::span<const glm::vec3> p, std::span<irradiance_probe> out) {
        for (std::size_t j = 0; j < p.size(); ++j) {
            out[j] = {};
            out[j].position = p[j];
            out[j].radiance[0] = glm::vec3(2 + 3 / (1 + std::exp(-(p[j].x - 0.5f) / 0.02f)));
            out[j].noise = 1e-4f;
            out[j].harmonic_mean_distance = 1;
        }
    };
    irradiance_volume_settings s;
    s.min_depth = 1;
    s.max_depth = 3;
    s.calibrate_noise = false;
    s.bias_tolerance = 0.01f;
    s.hanging_corners = hanging_corner_storage::computed;
    const auto computed = irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), s, source);
    REQUIRE(!computed.hanging_corners().empty());
    try {
        const gl::irradiance_volume_buffers buffers(computed);
        FAIL("the GPU buffers of a volume without probes at its hanging corners were made");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "volume");
    }
    s.hanging_corners = hanging_corner_storage::stored;  // the same octree with its corners stored
    CHECK_NOTHROW(gl::irradiance_volume_buffers(irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), s, source)));
}
