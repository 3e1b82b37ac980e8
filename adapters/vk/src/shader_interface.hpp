#pragma once
// What the Vulkan passes' shaders and the adapter agree on: the shaders' names, their
// push-constant blocks (C++ structs here, GLSL blocks in shader_sources.cpp, checked by the
// sizes) and workgroup sizes. docs/vulkan.md lists the bindings.

#include <bounce/cache/weighting.hpp>

#include <cstdint>
#include <string>

namespace bounce::vk::detail {

/// The splat shader of a weighting and the kernel's flags: "splat_<weighting>[_gradients][_front]".
inline std::string splat_shader_name(weighting_kind weighting, bool gradients, bool front_test) {
    return "splat_" + std::string(weighting_name(weighting)) + (gradients ? "_gradients" : "") + (front_test ? "_front" : "");
}
/// The SH projection shader of L bands: "sh_project_l<L>".
inline std::string sh_shader_name(int bands) { return "sh_project_l" + std::to_string(bands); }

/// The band counts the SH projection is built for.
inline constexpr int sh_bands[] = {2, 3, 4};

inline constexpr std::uint32_t splat_group = 8;       ///< splat: 8 x 8 pixels per workgroup
inline constexpr std::uint32_t normalize_group = 64;  ///< normalize: 64 pixels per workgroup
inline constexpr std::uint32_t sh_group = 256;        ///< SH projection: one workgroup per map

struct splat_constants {
    std::uint32_t width, height, first, count;
    float a, max_extrapolation, front_tolerance;
    std::uint32_t irradiance;  ///< 1: the albedo binding is ignored and pi used (irradiance out)
};
static_assert(sizeof(splat_constants) == 32);

struct normalize_constants {
    std::uint32_t count;
    float lambda;
};
static_assert(sizeof(normalize_constants) == 8);

struct sh_constants {
    std::uint32_t size, first_map;
};
static_assert(sizeof(sh_constants) == 8);

}  // namespace bounce::vk::detail
