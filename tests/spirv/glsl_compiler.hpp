#pragma once
// GLSL to SPIR-V with libglslang in the test's process, and SPIR-V validation with
// SPIRV-Tools (what glslangValidator and spirv-val do, without a process per shader: the
// catalog has about a hundred shaders, and the test must stay quick).

#include <cstdint>
#include <string>
#include <vector>

namespace bounce::spirv_test {

enum class stage { vertex, fragment, compute };

struct compiled {
    bool ok = false;
    std::string log;                ///< the compiler's messages (errors when !ok)
    std::vector<std::uint32_t> spirv;  ///< Vulkan only
};

/// Compiles `source` as GLSL for Vulkan 1.2 (SPIR-V 1.5), as
/// `glslangValidator -V --target-env vulkan1.2` does.
compiled compile_for_vulkan(const std::string& source, stage s);
/// Compiles `source` as OpenGL GLSL (what a GL driver is given), as `glslangValidator` with
/// no target does: parse and link, no SPIR-V.
compiled compile_for_opengl(const std::string& source, stage s);
/// spirv-val's verdict for Vulkan 1.2: empty when valid, else its messages.
std::string validate_for_vulkan(const std::vector<std::uint32_t>& spirv);

}  // namespace bounce::spirv_test
