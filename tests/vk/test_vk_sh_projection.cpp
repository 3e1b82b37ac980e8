// vk::sh_projector against sh_project_cube_map (sh/projection.hpp, double precision) on
// lavapipe: random RGB cube maps of sizes 1, 7 and 16, two and three maps a batch, 2, 3 and
// 4 bands; and the float texel solid angle the shader uses against the double one.
//
// Tolerance: 1e-5 relative to the magnitude of each coefficient's terms,
// |gpu_i - cpu_i| <= 1e-5 sum over texels |f| |Y_i| dw (per channel): the GPU sums the same
// terms in float (each texel's basis, solid angle and product to a few ulps; a strided share
// of at most 6 * 16^2 / 256 = 6 terms per invocation, then a tree of 8 levels), so its
// rounding is a few dozen ulps of that magnitude at most. For a coefficient whose terms do
// not cancel (c_00 of a positive map) the bound is 1e-5 of the coefficient itself.
#include "../skip.hpp"
#include "vulkan_device.hpp"

#include <bounce/rectangle_solid_angle.hpp>
#include <bounce/sampling.hpp>
#include <bounce/sh/projection.hpp>
#include <bounce/vk/sh_projection.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace bounce;

namespace {

// Every term's magnitude summed: sum over texels |f| |Y_i| dw, per channel.
template <int L>
sh_coefficients<L, glm::dvec3> term_magnitudes(const cube_map_view<const glm::vec3>& cube) {
    const std::size_t n = cube.size();
    sh_coefficients<L, glm::dvec3> m{};
    for (int f = 0; f < 6; ++f)
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x) {
                const auto basis = sh_basis<L, double, glm::dvec3>(cube_texel_direction(cube_face(f), n, x, y));
                const glm::dvec3 v = glm::abs(glm::dvec3(cube.faces[std::size_t(f)](x, y))) * cube_texel_solid_angle(n, x, y);
                for (std::size_t i = 0; i < sh_count(L); ++i) m[i] += v * std::abs(basis[i]);
            }
    return m;
}

template <int L>
void check_projection(vk_test::test_device& dev, std::size_t size, std::size_t maps, std::uint64_t seed) {
    INFO("L = " << L << ", size " << size << ", " << maps << " maps");
    pcg32 rng(seed);
    std::vector<glm::vec3> texels(maps * 6 * size * size);
    for (auto& t : texels) t = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 4.f - glm::vec3(1.f);
    constexpr std::size_t n = sh_count(L);
    auto in = dev.buffer<glm::vec3>(texels.size(), texels);
    auto out = dev.buffer<glm::vec4>(maps * n);
    vk::sh_projector projector(dev.ref(), L);
    REQUIRE(projector.coefficients() == n);
    // Two calls, the second for the maps after the first: the map index places the results.
    projector.project(in->range(), out->range(), size, 0, 1);
    if (maps > 1) projector.project(in->range(), out->range(), size, 1, maps - 1);
    const auto gpu = out->read<glm::vec4>(maps * n);
    double worst = 0;
    for (std::size_t m = 0; m < maps; ++m) {
        cube_map_view<const glm::vec3> cube;
        for (std::size_t f = 0; f < 6; ++f)
            cube.faces[f] = image_view<const glm::vec3>(texels.data() + (m * 6 + f) * size * size, size, size);
        const auto cpu = sh_project_cube_map<L>(cube);
        const auto scale = term_magnitudes<L>(cube);
        for (std::size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c) {
                const double d = std::abs(double(gpu[m * n + i][c]) - cpu[i][c]);
                worst = std::max(worst, d / scale[i][c]);
                INFO("map " << m << " coefficient " << i << " channel " << c << ": gpu " << gpu[m * n + i][c] << ", cpu "
                            << cpu[i][c]);
                CHECK(d <= 1e-5 * scale[i][c]);
            }
    }
    WARN("L = " << L << ", size " << size << ": worst |gpu - cpu| / sum of |terms| = " << worst);
}

}  // namespace

TEST_CASE("the Vulkan SH projection of cube maps agrees with sh_project_cube_map to 1e-5", "[vk][sh]") {
    const auto dev = vk_test::test_device::create();
    if (!dev) {
        test::skip("no Vulkan 1.2 device with a compute queue (Debian: mesa-vulkan-drivers gives lavapipe)");
        return;
    }
    check_projection<3>(*dev, 16, 3, 1);
    check_projection<3>(*dev, 7, 2, 2);
    check_projection<3>(*dev, 1, 2, 3);
    check_projection<2>(*dev, 16, 2, 4);
    check_projection<4>(*dev, 16, 2, 5);
    CHECK_THROWS_WITH(vk::sh_projector(dev->ref(), 5), Catch::Contains("bands"));
}

TEST_CASE("rectangle_solid_angle_triangles keeps a cube-map texel's solid angle to float precision", "[vk][sh]") {
    // The corner differences of rectangle_solid_angle lose digits on small texels in float;
    // the two triangles do not (relative 1e-6 at 4096 texels a side, where the corner form
    // in float is off by more than 1e-2).
    for (const std::size_t size : {1u, 2u, 7u, 64u, 512u, 4096u}) {
        double worst = 0, worst_corners = 0;
        for (const std::size_t x : {std::size_t(0), size / 3, size - 1})
            for (const std::size_t y : {std::size_t(0), size / 2, size - 1}) {
                const double exact = cube_texel_solid_angle(size, x, y);
                const float s = float(size);
                const float u0 = float(2 * x) / s - 1.f, u1 = float(2 * x + 2) / s - 1.f;
                const float v0 = float(2 * y) / s - 1.f, v1 = float(2 * y + 2) / s - 1.f;
                const double triangles = rectangle_solid_angle_triangles<float, glm::vec3>(u0, v0, u1, v1);
                const double corners = rectangle_solid_angle<float>(u0, v0, u1, v1);
                worst = std::max(worst, std::abs(triangles - exact) / exact);
                worst_corners = std::max(worst_corners, std::abs(corners - exact) / exact);
            }
        INFO("size " << size << ": triangles " << worst << ", corners " << worst_corners);
        CHECK(worst <= 1e-6);
        if (size == 4096) CHECK(worst_corners > 1e-2);
    }
}
