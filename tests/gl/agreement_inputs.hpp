#pragma once
// What the GLSL agreement tests of every family share: random inputs of the shapes kernels
// take, and the largest GPU-CPU difference over a batch in units of a per-element scale.
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::gl_test {

/// A direction uniform on the unit sphere.
inline glm::vec3 random_unit(pcg32& rng) {
    const float z = 2 * rng.next_float() - 1, phi = 6.2831853f * rng.next_float();
    const float r = std::sqrt(std::max(0.f, 1 - z * z));
    return glm::normalize(glm::vec3(r * std::cos(phi), r * std::sin(phi), z));
}
/// A direction uniform on the upper (z >= 0) hemisphere.
inline glm::vec3 random_upper(pcg32& rng) {
    glm::vec3 v = random_unit(rng);
    v.z = std::abs(v.z);
    return v;
}
/// A point uniform in the cube [-extent, extent]^3.
inline glm::vec3 random_point(pcg32& rng, float extent) {
    return glm::vec3(rng.next_float() * 2 - 1, rng.next_float() * 2 - 1, rng.next_float() * 2 - 1) * extent;
}

/// Largest |gpu - cpu| / scale(e) over all elements e and their components (float or glm
/// vectors); every value must be finite.
template <class R, class Scale>
double worst_scaled(const std::vector<R>& gpu, const std::vector<R>& cpu, Scale scale) {
    REQUIRE(gpu.size() == cpu.size());
    double worst = 0;
    for (std::size_t e = 0; e < cpu.size(); ++e) {
        const auto diff = [&](double g, double c) {
            REQUIRE(std::isfinite(g));
            REQUIRE(std::isfinite(c));
            worst = std::max(worst, std::abs(g - c) / scale(e));
        };
        if constexpr (std::is_same_v<R, float>)
            diff(gpu[e], cpu[e]);
        else
            for (int c = 0; c < R::length(); ++c) diff(gpu[e][c], cpu[e][c]);
    }
    return worst;
}

}  // namespace bounce::gl_test
