#pragma once
/// \file output_pass.hpp
/// output.hpp's choice on GL textures: `gl::output_pass` turns an RGBA32F texture of
/// irradiance into radiance rho/pi E in place, with the albedo of a G-buffer texture, by the
/// one kernel lambertian_radiance (direct_light.hpp) emitted as GLSL. What apply_output does
/// on the CPU, for the families whose GL output is a texture (gl::indirect_renderer).

#include <bounce/gl/objects.hpp>
#include <bounce/output.hpp>

#include <string>

namespace bounce::gl {

class output_pass {
public:
    /// Compiles the pass (a context must be current; it must outlive the pass). Throws
    /// shader_error when it does not compile.
    output_pass();

    /// The compute shader's source: the emitted kernel and the plumbing around it.
    static std::string shader_source();

    /// Nothing for irradiance; for radiance, every texel of `values` (RGBA32F) becomes
    /// lambertian_radiance(albedo.rgb, values.rgb), alpha kept. `albedo` is a texture of
    /// values' size in any format gbuffer_textures takes (read with texelFetch, GL row
    /// order as `values`). Restores the program, texture unit 0 and image unit 0. Throws
    /// parameter_error naming "albedo" or "values" on sizes or formats it cannot use.
    void apply(output_quantity quantity, const texture_ref& albedo, const texture_ref& values) const;

private:
    program program_;
};

}  // namespace bounce::gl
