#pragma once
// The SPIR-V the build compiled (cmake/compile_spirv.cmake writes the definition).
#include <cstdint>
#include <span>
#include <string_view>

namespace bounce::vk::detail {

/// The words of the shader `name` (shader_interface.hpp's names). Throws parameter_error
/// naming "shader" for a name that was not built.
std::span<const std::uint32_t> spirv(std::string_view name);

}  // namespace bounce::vk::detail
