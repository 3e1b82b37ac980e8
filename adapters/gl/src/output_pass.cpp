// gl::output_pass: irradiance to radiance on the GPU with the kernel of direct_light.hpp.
#include <bounce/direct_light.hpp>
#include <bounce/gl/output_pass.hpp>
#include <bounce/glsl/emit.hpp>

#include "saved_state.hpp"

namespace bounce::gl {

std::string output_pass::shader_source() {
    glsl::function_set k;
    k.add("lambertian_radiance", lambertian_radiance<glsl::f32, glsl::vec3>, "albedo", "irradiance");
    return "#version 450 core\nlayout(local_size_x = 8, local_size_y = 8) in;\n" + k.source() + R"(
layout(binding = 0) uniform sampler2D albedo_texture;
layout(rgba32f, binding = 0) uniform image2D values;
layout(location = 0) uniform int width;
layout(location = 1) uniform int height;
void main() {
    ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
    if (xy.x >= width || xy.y >= height) return;
    vec4 e = imageLoad(values, xy);
    imageStore(values, xy, vec4(lambertian_radiance(texelFetch(albedo_texture, xy, 0).rgb, e.rgb), e.a));
}
)";
}

output_pass::output_pass() : program_(program::compute(shader_source())) {}

void output_pass::apply(output_quantity quantity, const texture_ref& albedo, const texture_ref& values) const {
    if (quantity == output_quantity::irradiance) return;
    require(values.id != 0 && values.format == texel_format::rgba32f, "values", "must be an RGBA32F texture");
    require(albedo.id != 0 && albedo.width == values.width && albedo.height == values.height, "albedo",
            "must be a texture of the values' size");
    // Image unit 0 as the caller had it (the program, texture unit 0 and its sampler below).
    GLint name = 0, level = 0, layered = 0, layer = 0, access = GL_READ_ONLY, format = GL_R8;
    glGetIntegeri_v(GL_IMAGE_BINDING_NAME, 0, &name);
    glGetIntegeri_v(GL_IMAGE_BINDING_LEVEL, 0, &level);
    glGetIntegeri_v(GL_IMAGE_BINDING_LAYERED, 0, &layered);
    glGetIntegeri_v(GL_IMAGE_BINDING_LAYER, 0, &layer);
    glGetIntegeri_v(GL_IMAGE_BINDING_ACCESS, 0, &access);
    glGetIntegeri_v(GL_IMAGE_BINDING_FORMAT, 0, &format);
    {
        const detail::program_and_storage_state saved({});
        const detail::texture_unit_state units(0, 1);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
        glUseProgram(program_.id());
        glBindTextureUnit(0, albedo.id);
        glBindSampler(0, 0);
        glBindImageTexture(0, values.id, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
        program_.set(0, int(values.width));
        program_.set(1, int(values.height));
        glDispatchCompute(GLuint((values.width + 7) / 8), GLuint((values.height + 7) / 8), 1);
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
    }
    glBindImageTexture(0, GLuint(name), level, GLboolean(layered), layer, GLenum(access), GLenum(format));
    check_error("output_pass::apply");
}

}  // namespace bounce::gl
