#pragma once
// The G-buffer textures (gbuffer_textures) as the passes that shade its pixels read them:
// bound to texture units 0, 1 and 2, declared in GLSL at the same bindings, and the GLSL test
// of a covered pixel. Plumbing only.
#include <bounce/gl/splat_pass.hpp>

#include <epoxy/gl.h>

#include <string>
#include <utility>

namespace bounce::gl::detail {

/// The texture units of position and depth, of the normal and of the albedo.
inline constexpr GLuint gbuffer_position_depth_unit = 0, gbuffer_normal_unit = 1, gbuffer_albedo_unit = 2;

/// "layout(binding = UNIT) uniform sampler2D NAME;"
inline std::string sampler_declaration(GLuint unit, const char* name) {
    return "layout(binding = " + std::to_string(unit) + ") uniform sampler2D " + name + ";\n";
}

/// The samplers gbuffer_position_depth and gbuffer_normal, at their units.
inline std::string gbuffer_position_normal_samplers() {
    return sampler_declaration(gbuffer_position_depth_unit, "gbuffer_position_depth") +
           sampler_declaration(gbuffer_normal_unit, "gbuffer_normal");
}

/// The sampler gbuffer_albedo, at its unit.
inline std::string gbuffer_albedo_sampler() { return sampler_declaration(gbuffer_albedo_unit, "gbuffer_albedo"); }

/// GLSL `bool covered(float depth)`: whether a pixel whose position_depth.w is `depth` sees
/// geometry, i.e. whether its depth is below +infinity (gbuffer_view::covered).
inline constexpr const char* gbuffer_covered = "bool covered(float depth) { return depth < uintBitsToFloat(0x7f800000u); }\n";

/// Binds all three textures of `g` to their units, without sampler objects (the passes
/// fetch texels). The caller saves and restores the units.
inline void bind_gbuffer_textures(const gbuffer_textures& g) {
    const std::pair<GLuint, object_id> bindings[3] = {
        {gbuffer_position_depth_unit, g.position_depth.id}, {gbuffer_normal_unit, g.normal.id}, {gbuffer_albedo_unit, g.albedo.id}};
    for (const auto& [unit, texture] : bindings) {
        glBindTextureUnit(unit, texture);
        glBindSampler(unit, 0);
    }
}

}  // namespace bounce::gl::detail
