#pragma once
// The GLSL of every Vulkan pass, with the kernels of include/bounce emitted into it: what
// bounce_vk_emit writes at build time for glslangValidator (not part of the library).

#include <string>
#include <vector>

namespace bounce::vk::detail {

struct shader_source {
    std::string name;  ///< file stem and the name the adapter looks the SPIR-V up by
    std::string glsl;  ///< GLSL 4.50 compute shader for Vulkan
};

std::vector<shader_source> shader_sources();

}  // namespace bounce::vk::detail
