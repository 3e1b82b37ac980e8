// Running a generated compute shader over a batch of packed float inputs.
#include <bounce/gl/kernel_map.hpp>

#include "saved_state.hpp"

#include <algorithm>

namespace bounce::gl::detail {

std::vector<float> run_map(const std::string& source, std::span<const float> inputs, std::size_t count,
                           std::size_t out_floats_per_element) {
    // The shader indexes floats with 32-bit unsigned integers.
    require(inputs.size() < 0xffffffffu && count * out_floats_per_element < 0xffffffffu, "inputs",
            "too many elements for one map_kernel batch (32-bit indices)");
    const program prog = program::compute(source);
    const std::size_t out_bytes = std::max<std::size_t>(count * out_floats_per_element, 1) * sizeof(float);
    GLint64 max_block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
    if (std::max(inputs.size_bytes(), out_bytes) > std::size_t(max_block))
        throw gl_error("bounce::gl: map_kernel batch of " + std::to_string(count) +
                       " elements exceeds GL_MAX_SHADER_STORAGE_BLOCK_SIZE = " + std::to_string(max_block) + " bytes");
    const buffer in(inputs.size_bytes(), inputs.data());
    buffer out(out_bytes);

    const program_and_storage_state saved({0u, 1u});
    glUseProgram(prog.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
    prog.set(1, unsigned(count));
    // At most 65535 work groups per dispatch is what every 4.5 implementation allows.
    constexpr std::size_t local = 64, per_dispatch = 65535 * local;
    for (std::size_t first = 0; first < count; first += per_dispatch) {
        prog.set(0, unsigned(first));
        const std::size_t n = std::min(per_dispatch, count - first);
        glDispatchCompute(GLuint((n + local - 1) / local), 1, 1);
    }
    check_error("glDispatchCompute");
    std::vector<float> result(count * out_floats_per_element);
    out.read(0, result.data(), result.size() * sizeof(float));
    return result;
}

}  // namespace bounce::gl::detail
