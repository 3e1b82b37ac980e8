// Emission agreement of the RSM, SII and interleaving kernels: each, printed as GLSL and run
// in a compute shader (llvmpipe through EGL in CI), gives what its CPU float instantiation
// gives, over random inputs and the adversarial ones of each kernel.
//
// Tolerances. A kernel of k float operations, each rounded (GLSL allows 2-3 ulp for
// inversesqrt and division, and fused multiply-adds that round once instead of twice),
// is off by at most about 2 k ulp of the size of its terms, not of its result: a difference
// of two nearly equal terms (a cosine at grazing incidence) keeps the terms' absolute error.
// So each output is compared as |gpu - cpu| <= 1e-5 * scale, where scale is the size of the
// output's terms: Phi / (pi max(d^2, d_min^2)) for the pixel-light irradiance (the value with
// both cosines 1), the largest input for the tent, 1 for weights and cosines. 1e-5 is
// 2 k ulp (ulp = 1.2e-7) for k up to 40 operations, more than any kernel here has.
// Index maps are integers and must agree exactly (indirect/interleaved_sampling.hpp: exact for
// sizes below 2^14 and patterns up to 64 wide).
#include "../gl/agreement_inputs.hpp"
#include "../gl/shared_context.hpp"

#include <bounce/gl/kernel_map.hpp>
#include <bounce/indirect/interleaved_sampling.hpp>
#include <bounce/indirect/rsm.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <tuple>
#include <vector>

using namespace bounce;
using glsl::f32;
using glsl::vec3;

namespace {
using namespace bounce::gl_test;
constexpr double tolerance = 1e-5;
constexpr int random_count = 5000;
}  // namespace

TEST_CASE("pixel_light_irradiance agrees on the GPU and the CPU, hard cases included", "[glsl][rsm]") {
    gl_test::shared_context();
    pcg32 rng(21);
    using args = std::tuple<glm::vec3, glm::vec3, glm::vec3, glm::vec3, glm::vec3, float, float>;
    std::vector<args> in;
    const glm::vec3 up(0, 0, 1), down(0, 0, -1), flux(1.f, 0.5f, 0.25f);
    // Coincident, grazing, behind, shared boundary (floor texel at a wall's foot).
    in.emplace_back(glm::vec3(0.2f), down, glm::vec3(0.2f), up, flux, 0.f, 0.f);
    in.emplace_back(glm::vec3(1, 0, 0), down, glm::vec3(0), up, flux, 0.f, 0.f);
    in.emplace_back(glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::vec3(0), up, flux, 0.f, 0.f);
    in.emplace_back(glm::vec3(0, 0, -1), up, glm::vec3(0), up, flux, 0.f, 0.f);
    in.emplace_back(glm::vec3(0, 0, 1e-3f), glm::vec3(1, 0, 0), glm::vec3(1e-3f, 0, 0), up, flux, 0.01f, 0.f);
    in.emplace_back(glm::vec3(0, 0, 1e-3f), glm::vec3(1, 0, 0), glm::vec3(1e-3f, 0, 0), up, flux, 0.f, 1e-4f);
    for (int k = 0; k < random_count; ++k) {
        const glm::vec3 xp = random_point(rng, 1.f), np = random_unit(rng);
        const glm::vec3 x = xp + random_unit(rng) * (0.01f + 2 * rng.next_float());
        in.emplace_back(x, random_unit(rng), xp, np, flux * rng.next_float(), k % 3 == 0 ? 0.01f : 0.f,
                        k % 5 == 0 ? 1e-4f : 0.f);
    }
    std::vector<glm::vec3> cpu;
    for (const auto& a : in) cpu.push_back(std::apply(pixel_light_irradiance<float, glm::vec3>, a));
    const auto gpu = gl::map_kernel(pixel_light_irradiance<f32, vec3>, in);
    const double worst = worst_scaled(gpu, cpu, [&](std::size_t e) {
        const auto& [x, n, xp, np, f, offset, d2] = in[e];
        const glm::vec3 v = x - (xp - np * offset);
        const double dd = std::max(double(glm::dot(v, v)), double(d2));
        return std::max(1e-30, double(std::max(f.x, std::max(f.y, f.z))) / (std::numbers::pi * std::max(dd, 1e-30)));
    });
    INFO("worst scaled difference " << worst);
    CHECK(worst <= tolerance);
    CHECK(gpu[0] == glm::vec3(0.f));  // coincident: exactly 0 on both
}

TEST_CASE("texel-flux, solid-angle, bounding-sphere and disc-sample kernels agree on the GPU and the CPU",
          "[glsl][rsm]") {
    gl_test::shared_context();
    pcg32 rng(22);
    {
        std::vector<std::tuple<float, float, float, float>> in;
        std::vector<std::tuple<float, float, float, float>> mid_in;
        for (int k = 0; k < random_count; ++k) {
            const float x0 = rng.next_float() * 2 - 1, y0 = rng.next_float() * 2 - 1;
            const float t = 0.25f * rng.next_float() + 1e-3f;
            in.emplace_back(x0, y0, std::min(1.f, x0 + t), std::min(1.f, y0 + t));
            mid_in.emplace_back(x0, y0, t, t);
        }
        std::vector<float> cpu, cpu_mid;
        for (const auto& a : in) cpu.push_back(std::apply(rectangle_solid_angle<float>, a));
        for (const auto& a : mid_in) cpu_mid.push_back(std::apply(perspective_texel_solid_angle_midpoint<float>, a));
        // The exact form's four atans are of size <= pi/4: scale 1.
        CHECK(worst_scaled(gl::map_kernel(rectangle_solid_angle<f32>, in), cpu, [](std::size_t) { return 1.0; }) <=
              tolerance);
        CHECK(worst_scaled(gl::map_kernel(perspective_texel_solid_angle_midpoint<f32>, mid_in), cpu_mid,
                           [&](std::size_t e) { return double(cpu_mid[e]); }) <= tolerance);
    }
    {
        std::vector<std::tuple<glm::vec3, glm::vec3, glm::vec3, glm::vec3, glm::vec3, glm::vec3, float, float, float>>
            in;
        for (int k = 0; k < random_count; ++k)
            in.emplace_back(glm::vec3(rng.next_float()), random_point(rng, 2.f), random_unit(rng),
                            random_point(rng, 2.f), random_unit(rng), glm::vec3(5.f), 0.7f, float(k % 2), 1e-3f);
        std::vector<glm::vec3> cpu;
        for (const auto& a : in) cpu.push_back(std::apply(spot_light_texel_flux<float, glm::vec3>, a));
        const auto gpu = gl::map_kernel(spot_light_texel_flux<f32, vec3>, in);
        // A point on the cone's edge may switch sides by rounding; those are excluded.
        double worst = 0;
        for (std::size_t e = 0; e < in.size(); ++e) {
            const auto& [albedo, p, n, l, axis, inten, cc, fo, dw] = in[e];
            const float cos_axis = glm::dot(axis, glm::normalize(p - l));
            if (std::abs(cos_axis - cc) < 1e-5f || std::abs(glm::dot(n, p - l)) < 1e-5f) continue;
            for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::abs(gpu[e][c] - cpu[e][c])) / (5e-3));
        }
        CHECK(worst <= tolerance);
    }
    {
        // Point and directional texel flux: products of inputs behind a facing test; inputs
        // within 1e-5 of grazing (where the test may flip) are left out.
        std::vector<std::tuple<glm::vec3, glm::vec3, glm::vec3, glm::vec3, glm::vec3, float>> point_in;
        std::vector<std::tuple<glm::vec3, glm::vec3, glm::vec3, glm::vec3, float>> dir_in;
        while (point_in.size() < std::size_t(random_count)) {
            const glm::vec3 p = random_point(rng, 2.f), n = random_unit(rng), l = random_point(rng, 2.f),
                            d = random_unit(rng);
            if (std::abs(glm::dot(n, l - p)) < 1e-5f || std::abs(glm::dot(n, d)) < 1e-5f) continue;
            point_in.emplace_back(glm::vec3(rng.next_float()), p, n, l, glm::vec3(3.f), 1e-3f);
            dir_in.emplace_back(glm::vec3(rng.next_float()), n, d, glm::vec3(2.f), 1e-4f);
        }
        std::vector<glm::vec3> cpu_point, cpu_dir;
        for (const auto& a : point_in) cpu_point.push_back(std::apply(point_light_texel_flux<float, glm::vec3>, a));
        for (const auto& a : dir_in) cpu_dir.push_back(std::apply(directional_light_texel_flux<float, glm::vec3>, a));
        CHECK(worst_scaled(gl::map_kernel(point_light_texel_flux<f32, vec3>, point_in), cpu_point,
                           [](std::size_t) { return 3e-3; }) <= tolerance);
        CHECK(worst_scaled(gl::map_kernel(directional_light_texel_flux<f32, vec3>, dir_in), cpu_dir,
                           [](std::size_t) { return 2e-4; }) <= tolerance);
    }
    {
        std::vector<std::tuple<glm::vec3, glm::vec3, float, float, float>> in;
        for (int k = 0; k < random_count; ++k)
            in.emplace_back(random_point(rng, 3.f), random_unit(rng), rng.next_float() * 10, 1e-3f + rng.next_float(),
                            k % 2 ? 0.f : 0.02f);
        std::vector<std::tuple<glm::vec3, float>> cpu;
        for (const auto& a : in) cpu.push_back(std::apply(pixel_light_bounding_sphere<float, glm::vec3>, a));
        const auto gpu = gl::map_kernel(pixel_light_bounding_sphere<f32, vec3>, in);
        double worst = 0;
        for (std::size_t e = 0; e < in.size(); ++e) {
            const double scale = 3.0 + std::get<1>(cpu[e]);  // positions up to 3, radii their own size
            worst = std::max(worst, double(glm::length(std::get<0>(gpu[e]) - std::get<0>(cpu[e]))) / scale);
            worst = std::max(worst, double(std::abs(std::get<1>(gpu[e]) - std::get<1>(cpu[e]))) / scale);
        }
        CHECK(worst <= tolerance);
    }
    {
        std::vector<std::tuple<float, float, float, float, float>> in;
        for (int k = 0; k < random_count; ++k)
            in.emplace_back(rng.next_float(), rng.next_float(), 0.05f + rng.next_float(), 512.f * 512.f, 400.f);
        std::vector<glm::vec3> cpu;
        for (const auto& a : in) cpu.push_back(std::apply(rsm_disc_sample<float, glm::vec3>, a));
        const auto gpu = gl::map_kernel(rsm_disc_sample<f32, vec3>, in);
        std::vector<glm::vec3> cpu_sq;
        for (const auto& a : in) cpu_sq.push_back(std::apply(rsm_disc_sample_xi1_squared<float, glm::vec3>, a));
        const auto gpu_sq = gl::map_kernel(rsm_disc_sample_xi1_squared<f32, vec3>, in);
        for (std::size_t e = 0; e < in.size(); ++e)
            CHECK(std::abs(double(gpu_sq[e].z - cpu_sq[e].z)) <= tolerance * std::max(1e-30, double(cpu_sq[e].z)));
        // Offsets are r_max-sized, the weight its own size.
        double worst = 0;
        for (std::size_t e = 0; e < in.size(); ++e) {
            const double r = std::get<2>(in[e]);
            worst = std::max(worst, std::abs(double(gpu[e].x - cpu[e].x)) / r);
            worst = std::max(worst, std::abs(double(gpu[e].y - cpu[e].y)) / r);
            worst = std::max(worst, std::abs(double(gpu[e].z - cpu[e].z)) / std::max(1e-30, double(cpu[e].z)));
        }
        CHECK(worst <= tolerance);
    }
}

TEST_CASE("the gather disc's centre agrees on the GPU and the CPU, behind the projection included", "[glsl][rsm]") {
    gl_test::shared_context();
    pcg32 rng(25);
    std::vector<std::tuple<float, float, float>> in = {{0.f, 0.f, 0.f}, {1.f, -1.f, -2.f}, {3.f, 0.2f, 1.f}};
    for (int k = 0; k < random_count; ++k)
        in.emplace_back(rng.next_float() * 4 - 2, rng.next_float() * 4 - 2, rng.next_float() * 4 - 1);
    std::vector<glm::vec2> cpu;
    for (const auto& a : in) cpu.push_back(std::apply(rsm_disc_centre<float, glm::vec2>, a));
    const auto gpu = gl::map_kernel(rsm_disc_centre<f32, glsl::vec2>, in);
    // Map coordinates lie in [0, 1]: scale 1.
    CHECK(worst_scaled(gpu, cpu, [](std::size_t) { return 1.0; }) <= tolerance);
    CHECK(gpu[0] == glm::vec2(0.5f));
}

TEST_CASE("the interleave index maps agree exactly on the GPU and the CPU", "[glsl][interleave]") {
    gl_test::shared_context();
    pcg32 rng(23);
    std::vector<std::tuple<float, float, float>> in;
    for (int n : {1, 2, 3, 4, 7, 8, 64})
        for (int size : {1, 5, 63, 64, 65, 767, 1280, 16383})
            for (int k = 0; k < 40; ++k)
                in.emplace_back(float(k == 0 ? size - 1 : rng.next_u32() % std::uint32_t(size)), float(size), float(n));
    std::vector<float> cpu_split;
    std::vector<std::array<float, 2>> cpu_gather;
    for (const auto& [x, size, n] : in) {
        cpu_split.push_back(interleave_split_coordinate<float>(x, size, n));
        cpu_gather.push_back(interleave_gather_coordinate<float>(x, size, n));
    }
    std::vector<std::tuple<float, float, float>> cells;
    std::vector<float> cpu_origin, cpu_extent;
    for (const auto& [x, size, n] : in) {
        cells.emplace_back(std::min(x, n - 1), size, n);
        cpu_origin.push_back(interleave_sub_buffer_origin<float>(std::min(x, n - 1), size, n));
        cpu_extent.push_back(interleave_sub_buffer_extent<float>(std::min(x, n - 1), size, n));
    }
    const auto gpu_origin = gl::map_kernel(interleave_sub_buffer_origin<f32>, cells);
    const auto gpu_extent = gl::map_kernel(interleave_sub_buffer_extent<f32>, cells);
    for (std::size_t e = 0; e < cells.size(); ++e) {
        REQUIRE(gpu_origin[e] == cpu_origin[e]);
        REQUIRE(gpu_extent[e] == cpu_extent[e]);
    }
    const auto gpu_split = gl::map_kernel(interleave_split_coordinate<f32>, in);
    const auto gpu_gather = gl::map_kernel(interleave_gather_coordinate<f32>, in);
    for (std::size_t e = 0; e < in.size(); ++e) {
        INFO("x " << std::get<0>(in[e]) << " size " << std::get<1>(in[e]) << " n " << std::get<2>(in[e]));
        REQUIRE(gpu_split[e] == cpu_split[e]);
        REQUIRE(gpu_gather[e] == cpu_gather[e]);
    }
}

TEST_CASE("the geometry-aware tent, the discontinuity test and the upsampling weights agree on the GPU and the CPU",
          "[glsl][interleave]") {
    gl_test::shared_context();
    pcg32 rng(24);
    {
        constexpr int R = 7;
        std::vector<std::tuple<std::array<glm::vec3, 2 * R + 1>, std::array<float, 2 * R>, float>> in;
        for (int k = 0; k < random_count; ++k) {
            std::array<glm::vec3, 2 * R + 1> v;
            std::array<float, 2 * R> edges;
            for (auto& x : v) x = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 10.f;
            for (auto& x : edges) x = rng.next_float() < 0.1f ? 1.f : 0.f;
            in.emplace_back(v, edges, float(1 + k % 8));
        }
        std::vector<glm::vec3> cpu;
        for (const auto& a : in) cpu.push_back(std::apply(geometry_aware_tent<R, float, glm::vec3>, a));
        CHECK(worst_scaled(gl::map_kernel(geometry_aware_tent<R, f32, vec3>, in), cpu,
                           [](std::size_t) { return 10.0; }) <= tolerance);
    }
    {
        std::vector<std::tuple<float, glm::vec3, float, glm::vec3, float, float>> in;
        while (in.size() < std::size_t(random_count)) {
            const float da = 0.1f + 10 * rng.next_float(), db = da * (0.8f + 0.4f * rng.next_float());
            const glm::vec3 na = random_unit(rng), nb = glm::normalize(na + random_unit(rng) * rng.next_float());
            // Away from the thresholds, where a rounding difference would flip the answer.
            if (std::abs(std::abs(da - db) - 0.05f * std::min(da, db)) < 1e-4f * da ||
                std::abs(glm::dot(na, nb) - 0.9f) < 1e-4f)
                continue;
            in.emplace_back(da, na, db, nb, 0.05f, 0.9f);
        }
        std::vector<float> cpu;
        for (const auto& a : in) cpu.push_back(std::apply(geometry_discontinuity<float, glm::vec3>, a));
        const auto gpu = gl::map_kernel(geometry_discontinuity<f32, vec3>, in);
        for (std::size_t e = 0; e < in.size(); ++e) REQUIRE(gpu[e] == cpu[e]);
    }
    {
        // The blur's visibility edges: sums of n terms of random brightness, a random share
        // of them visible, some pixels unlit; away from the threshold.
        std::vector<std::tuple<float, float, float, float, float, float, float>> in;
        while (in.size() < std::size_t(random_count)) {
            float sums[2][3];
            for (auto& s : sums) {
                const int n = int(1 + 60 * rng.next_float());
                s[0] = s[1] = s[2] = 0.f;
                if (rng.next_float() < 0.1f) continue;  // unlit
                const float share = rng.next_float();
                for (int k = 0; k < n; ++k) {
                    const float b = 0.01f + rng.next_float();
                    s[0] += b;
                    s[1] += rng.next_float() < share ? b : 0.f;
                    s[2] += b * b;
                }
            }
            const float sigmas = 3.f * rng.next_float();
            if (sums[0][0] > 0.f && sums[1][0] > 0.f) {
                const float d = sums[0][1] / sums[0][0] - sums[1][1] / sums[1][0];
                const float t = sigmas * sigmas * (sums[0][2] / (sums[0][0] * sums[0][0]) +
                                                   sums[1][2] / (sums[1][0] * sums[1][0]));
                if (std::abs(4.f * d * d - t) < 1e-3f * (t + 1e-3f)) continue;
            }
            in.emplace_back(sums[0][0], sums[0][1], sums[0][2], sums[1][0], sums[1][1], sums[1][2], sigmas);
        }
        std::vector<float> cpu;
        for (const auto& a : in) cpu.push_back(std::apply(visibility_discontinuity<float>, a));
        const auto gpu = gl::map_kernel(visibility_discontinuity<f32>, in);
        for (std::size_t e = 0; e < in.size(); ++e) REQUIRE(gpu[e] == cpu[e]);
    }
    {
        using args = std::tuple<glm::vec3, glm::vec3, std::array<glm::vec3, 4>, std::array<glm::vec3, 4>, float, float,
                                float, float>;
        std::vector<args> in;
        while (in.size() < std::size_t(random_count)) {
            const glm::vec3 x = random_point(rng, 1.f), n = random_unit(rng);
            std::array<glm::vec3, 4> ps, ns;
            bool near_threshold = false;
            for (int k = 0; k < 4; ++k) {
                ps[std::size_t(k)] = x + random_point(rng, 0.05f);
                ns[std::size_t(k)] = glm::normalize(n + random_unit(rng) * 0.5f * rng.next_float());
                near_threshold = near_threshold || std::abs(glm::dot(n, ns[std::size_t(k)]) - 0.9f) < 1e-4f ||
                                 std::abs(std::abs(glm::dot(n, ps[std::size_t(k)] - x)) - 0.02f) < 1e-5f;
            }
            if (!near_threshold) in.emplace_back(x, n, ps, ns, rng.next_float(), rng.next_float(), 0.02f, 0.9f);
        }
        std::vector<std::array<float, 5>> cpu;
        for (const auto& a : in) cpu.push_back(std::apply(geometry_aware_upsample_weights<float, glm::vec3>, a));
        const auto gpu = gl::map_kernel(geometry_aware_upsample_weights<f32, vec3>, in);
        double worst = 0;
        for (std::size_t e = 0; e < in.size(); ++e) {
            REQUIRE(gpu[e][4] == cpu[e][4]);  // the same samples count
            for (int k = 0; k < 4; ++k)
                worst = std::max(worst, double(std::abs(gpu[e][std::size_t(k)] - cpu[e][std::size_t(k)])));
        }
        CHECK(worst <= tolerance);
    }
}
