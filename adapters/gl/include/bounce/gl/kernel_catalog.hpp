#pragma once
/// \file kernel_catalog.hpp
/// Every kernel the GL adapter emits, in every variant its passes compile (each weighting
/// policy, gradients and the in-front test on and off, each blur radius), as a standalone
/// GLSL 4.50 compute shader: the emitted function and a `main` that loads its arguments from
/// a storage buffer, calls it and stores its results (gl::map_kernel_source). For Vulkan
/// the shader is written with `compute_target::vulkan` (set 0, push constants), which
/// glslang compiles to SPIR-V; tests/spirv compiles and validates every entry, and checks
/// that every kernel the GL passes add (`.add("name", kernel<...>, ...)` in adapters/gl/src)
/// is here under the same name and the same kernel function.
///
/// A pass that emits a new kernel adds it to `emitted_kernels` (kernel_catalog.cpp).

#include <bounce/gl/kernel_map.hpp>

#include <string>
#include <vector>

namespace bounce::gl {

/// One emitted kernel: the pass (or shader) that emits it, the name it has there, the C++
/// kernel as written in the catalog (e.g. "disc_form_factor<f32, vec3>"), what variant it is
/// (e.g. "ward-smooth, gradients, front test"; empty when there is one), and the compute
/// shader that calls it.
struct emitted_kernel {
    std::string pass;
    std::string name;
    std::string kernel;
    std::string variant;
    std::string compute_source;
};

/// The catalog, for `target` (no GL context needed: the shaders are only printed).
std::vector<emitted_kernel> emitted_kernels(compute_target target = compute_target::vulkan);

}  // namespace bounce::gl
