#pragma once
/// \file cache/record_std430.hpp
/// An irradiance record as GPU shaders read it: std430, an array of vec4 rows (144 bytes),
/// the layout of the GL splat pass's record buffer and of the Vulkan splat pass's binding 0.
/// In GLSL:
/// ```glsl
/// struct bounce_record {
///     vec4 position_inv_r;  // p_k, 1 / R_k
///     vec4 normal_radius;   // n_k, R_k
///     vec4 irradiance;      // E_k (w unused)
///     vec4 rotation[3];     // grad_r per channel (w unused)
///     vec4 translation[3];  // grad_t per channel (w unused)
/// };
/// ```

#include <bounce/cache/record.hpp>
#include <bounce/errors.hpp>

#include <cmath>
#include <cstddef>
#include <string>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce::inline cache {

struct std430_record {
    glm::vec4 position_inv_r;  ///< p_k, 1 / R_k (computed once here, as the CPU path does)
    glm::vec4 normal_radius;   ///< n_k, R_k
    glm::vec4 irradiance;      ///< E_k
    glm::vec4 rotation[3];     ///< grad_r per channel
    glm::vec4 translation[3];  ///< grad_t per channel
};
static_assert(sizeof(std430_record) == 9 * sizeof(glm::vec4));

/// Record `r` in the GPU layout. Throws parameter_error naming "records[index]" for a
/// non-finite field or a radius that is not positive.
inline std430_record pack_std430(const irradiance_record& r, std::size_t index) {
    const auto finite3 = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    const auto fail = [&](const char* what) { throw parameter_error("records[" + std::to_string(index) + "]", what); };
    if (!finite3(r.position) || !finite3(r.normal) || !finite3(r.irradiance)) fail("position, normal or irradiance is not finite");
    for (int c = 0; c < 3; ++c)
        if (!finite3(r.rotation[std::size_t(c)]) || !finite3(r.translation[std::size_t(c)])) fail("a gradient is not finite");
    if (!(std::isfinite(r.radius) && r.radius > 0.f)) fail("radius must be a positive finite number");
    std430_record g;
    g.position_inv_r = glm::vec4(r.position, 1.f / r.radius);
    g.normal_radius = glm::vec4(r.normal, r.radius);
    g.irradiance = glm::vec4(r.irradiance, 0.f);
    for (int c = 0; c < 3; ++c) {
        g.rotation[c] = glm::vec4(r.rotation[std::size_t(c)], 0.f);
        g.translation[c] = glm::vec4(r.translation[std::size_t(c)], 0.f);
    }
    return g;
}

}  // namespace bounce::cache
