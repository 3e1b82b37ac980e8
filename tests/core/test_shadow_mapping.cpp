// CPU properties of the shadow-mapping kernels the GL direct-light pass prints as GLSL.
#include <bounce/sampling.hpp>
#include <bounce/shadow_mapping.hpp>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

using namespace bounce;

TEST_CASE("the PCF taps form a 4x4 grid of texel steps centred on the lookup", "[shadow]") {
    double su = 0, sv = 0;
    for (int i = 0; i < pcf_tap_count; ++i) {
        su += pcf_tap_offset(i, 0);
        sv += pcf_tap_offset(i, 1);
        CHECK(std::abs(pcf_tap_offset(i, 0)) <= 1.5);
        CHECK(std::abs(pcf_tap_offset(i, 1)) <= 1.5);
    }
    CHECK(su == 0.0);
    CHECK(sv == 0.0);
    pcg32 rng(17);
    for (int k = 0; k < 300; ++k) {
        const glm::dvec3 clip(4 * rng.next_double() - 2, 4 * rng.next_double() - 2, 4 * rng.next_double() - 2);
        const double w = 0.1 + 3 * rng.next_double(), inv_res = 1.0 / 1024;
        const auto taps = shadow_map_taps<double, glm::dvec3>(clip, w, inv_res);
        glm::dvec3 mean(0);
        for (const auto& t : taps) mean += t / double(pcf_tap_count);
        // The taps average to the projected point (the offsets sum to zero) and share its depth.
        CHECK(mean.x == Approx(clip.x / w * 0.5 + 0.5).margin(1e-12));
        CHECK(mean.y == Approx(clip.y / w * 0.5 + 0.5).margin(1e-12));
        for (const auto& t : taps) CHECK(t.z == Approx(clip.z / w * 0.5 + 0.5).margin(1e-12));
        // Neighbouring taps are one texel apart.
        CHECK(taps[1].x - taps[0].x == Approx(inv_res).margin(1e-12));
        CHECK(taps[4].y - taps[0].y == Approx(inv_res).margin(1e-12));
    }
}

TEST_CASE("cube-map taps stay on the face of the lookup direction and carry radial depths", "[shadow]") {
    pcg32 rng(23);
    for (int k = 0; k < 500; ++k) {
        const glm::dvec3 d = glm::dvec3(2 * rng.next_double() - 1, 2 * rng.next_double() - 1, 2 * rng.next_double() - 1) *
                             (0.1 + 10 * rng.next_double());
        const double inv_far = 1.0 / 50, inv_res = 1.0 / 512;
        const auto [dirs, refs] = cube_shadow_taps<double, glm::dvec3>(d, inv_far, inv_res);
        const double major = cube_major_axis<double, glm::dvec3>(d);
        const int axis = std::abs(d.x) >= std::abs(d.y) && std::abs(d.x) >= std::abs(d.z) ? 0
                         : std::abs(d.y) >= std::abs(d.z)                               ? 1
                                                                                        : 2;
        glm::dvec3 mean(0);
        for (int i = 0; i < pcf_tap_count; ++i) {
            // Offsets lie in the face plane: the major-axis component does not move.
            CHECK(dirs[std::size_t(i)][axis] == d[axis]);
            CHECK(refs[std::size_t(i)] == Approx(glm::length(dirs[std::size_t(i)]) * inv_far).epsilon(1e-12));
            mean += dirs[std::size_t(i)] / double(pcf_tap_count);
        }
        CHECK(glm::length(mean - d) <= 1e-12 * (1 + major));
        // The outermost taps are 1.5 face texels out on each face axis: 1.5 * 2 major / res.
        CHECK(glm::length(dirs[0] - d) == Approx(std::sqrt(2.0) * 1.5 * 2 * major * inv_res).epsilon(1e-9));
    }
}

TEST_CASE("PCF visibility is the fraction of passing taps", "[shadow]") {
    for (int lit = 0; lit <= pcf_tap_count; ++lit) {
        std::array<float, pcf_tap_count> tests{};
        for (int i = 0; i < lit; ++i) tests[std::size_t(i)] = 1.f;
        CHECK(pcf_visibility<float>(tests) == Approx(float(lit) / pcf_tap_count));
    }
}

TEST_CASE("texel sizes and offsets follow the map geometry", "[shadow]") {
    const glm::dvec3 light(1, 2, 3), axis = glm::normalize(glm::dvec3(0.3, -1, 0.2));
    for (double D : {0.5, 2.0, 40.0}) {
        const glm::dvec3 p = light + axis * D;
        CHECK(perspective_shadow_texel<double, glm::dvec3>(p, light, axis, 0.5, 1.0 / 256) == Approx(2 * D * 0.5 / 256));
        CHECK(radial_shadow_depth<double, glm::dvec3>(p, light, 1.0 / 100) == Approx(D / 100));
        CHECK(cube_shadow_texel<double, glm::dvec3>(p, light, 1.0 / 256) ==
              Approx(2 * cube_major_axis<double, glm::dvec3>(p - light) / 256));
    }
    const glm::dvec3 n = glm::normalize(glm::dvec3(1, 1, 0));
    const auto q = normal_offset_point<double, glm::dvec3>({0, 0, 0}, n, 0.01, 1.5);
    CHECK(glm::length(q - n * 0.015) < 1e-15);
    // The slope bias grows with the larger derivative and never pulls a depth toward the light.
    CHECK(slope_biased_depth<double>(0.5, 0.001, -0.004, 2.0, 4.0) == Approx(0.5 + 2 * 0.004 + 4 * 0.5 / 8388608.0));
    CHECK(slope_biased_depth<double>(0.5, 0, 0, 2.0, 0.0) == 0.5);
}
