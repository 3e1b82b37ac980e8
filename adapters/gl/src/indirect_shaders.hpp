#pragma once
// The GLSL texts of gl::indirect_renderer's passes (private to adapters/gl/src): plumbing
// around the kernels emitted from indirect/rsm.hpp and indirect/interleaved_sampling.hpp.
// The full-screen passes draw with vertex_shaders.hpp's full-screen triangle.
#include <string>

namespace bounce::gl::indirect_glsl {

extern const char* const downsample_fragment;
extern const char* const splat_vertex;
std::string index_kernels();
std::string split_fragment();
std::string gather_fragment();
std::string gather_rsm_fragment();
std::string upsample_fragment();
std::string splat_fragment();
std::string discontinuity_fragment();
std::string tent_fragment(int radius, bool vertical);
std::string ism_splat_compute();
std::string ism_pull_compute();
std::string ism_push_compute();

}  // namespace bounce::gl::indirect_glsl
