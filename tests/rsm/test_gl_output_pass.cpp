// gl::output_pass, output.hpp's radiance on a GL texture (what gl::indirect_renderer's
// render(..., output_quantity) runs), against apply_output on the CPU: the same kernel,
// lambertian_radiance, printed as GLSL.
#include "../gl/shared_context.hpp"

#include <bounce/errors.hpp>
#include <bounce/gl/output_pass.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/output.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>
#include <epoxy/gl.h>

using namespace bounce;

TEST_CASE("the GL output pass makes the CPU's radiance from irradiance and albedo textures, in place",
          "[gl][outputs]") {
    gl_test::shared_context();
    const std::size_t w = 13, h = 7;  // not a multiple of the 8 x 8 work groups
    image<glm::vec4> e(w, h), rho(w, h);
    pcg32 rng(27);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            e(x, y) = glm::vec4(10 * rng.next_float(), 10 * rng.next_float(), 10 * rng.next_float(), rng.next_float());
            rho(x, y) = glm::vec4(rng.next_float(), rng.next_float(), rng.next_float(), 1.f);
        }
    const gl::texture values(gl::texel_format::rgba32f, w, h), albedo(gl::texel_format::rgba32f, w, h);
    gl::write_texture(values, e.view());
    gl::write_texture(albedo, rho.view());

    // The caller's image unit 0 and program survive the pass.
    const gl::texture other(gl::texel_format::rgba32f, 4, 4);
    glBindImageTexture(0, other.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
    const gl::output_pass pass;
    pass.apply(output_quantity::irradiance, albedo, values);  // nothing to do
    pass.apply(output_quantity::radiance, albedo, values);
    GLint bound = 0;
    glGetIntegeri_v(GL_IMAGE_BINDING_NAME, 0, &bound);
    CHECK(GLuint(bound) == other.id());

    image<glm::vec4> got(w, h);
    gl::read_texture(values, got.view());
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            const glm::vec3 expected = lambertian_radiance<float, glm::vec3>(glm::vec3(rho(x, y)), glm::vec3(e(x, y)));
            for (int c = 0; c < 3; ++c) CHECK(got(x, y)[c] == Approx(expected[c]).epsilon(1e-6));
            CHECK(got(x, y).w == e(x, y).w);
        }
    const gl::texture small(gl::texel_format::rgba32f, w - 1, h);
    CHECK_THROWS_AS(pass.apply(output_quantity::radiance, small, values), parameter_error);
}
