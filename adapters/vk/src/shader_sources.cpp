// The Vulkan passes' compute shaders: bindings, push constants and loops are plumbing here;
// the math is the one-source kernels (cache/record.hpp's splat_contribution and
// normalization, the weighting's influence_radius, sh/basis.hpp's sh_basis and
// rectangle_solid_angle.hpp's texel solid angle), emitted by glsl::emit as the GL adapter
// emits them.
#include "shader_sources.hpp"

#include "shader_interface.hpp"

#include <bounce/cache/record.hpp>
#include <bounce/cache/weighting.hpp>
#include <bounce/glsl/emit.hpp>
#include <bounce/rectangle_solid_angle.hpp>
#include <bounce/sh/basis.hpp>

#include <numbers>

namespace bounce::vk::detail {

namespace {

using glsl::f32;
using glsl::vec3;

std::string header(std::uint32_t group_x, std::uint32_t group_y) {
    return "#version 450 core\nlayout(local_size_x = " + std::to_string(group_x) + ", local_size_y = " +
           std::to_string(group_y) + ") in;\n";
}

std::string splat_shader(weighting_kind weighting, bool gradients, bool front_test) {
    glsl::function_set k;
    with_weighting(weighting, [&](auto policy) {
        using W = decltype(policy);
        k.add("influence_radius", &W::template influence_radius<f32>, "r", "a");
        with_kernel_flags(gradients, front_test, [&](auto g, auto f) {
            k.add("splat_contribution", splat_contribution<W, decltype(g)::value, decltype(f)::value, f32, vec3>, "p", "n",
                  "albedo", "pk", "nk", "inv_r", "a", "e", "rot_r", "rot_g", "rot_b", "tr_r", "tr_g", "tr_b",
                  "max_extrapolation", "front_tolerance", "c");
        });
    });
    // The CPU's culling radius (cpu::splatting's culling_radius2): the zone widened by a
    // relative 1e-5, so rounding never culls a point the weight keeps.
    const std::string widen = glsl::float_literal(1.f + 1e-5f), pi = glsl::float_literal(float(std::numbers::pi));
    return header(splat_group, splat_group) + R"(struct bounce_record {
    vec4 position_inv_r;
    vec4 normal_radius;
    vec4 irradiance;
    vec4 rotation[3];
    vec4 translation[3];
};
layout(std430, set = 0, binding = 0) readonly buffer bounce_records { bounce_record records[]; };
layout(std430, set = 0, binding = 1) readonly buffer bounce_position_depth { vec4 position_depth[]; };
layout(std430, set = 0, binding = 2) readonly buffer bounce_normal { vec4 normal[]; };
layout(std430, set = 0, binding = 3) readonly buffer bounce_albedo { vec4 albedo[]; };
layout(std430, set = 0, binding = 4) buffer bounce_splat { vec4 splat[]; };
layout(push_constant) uniform bounce_splat_constants {
    uint width;
    uint height;
    uint first;
    uint count;
    float a;
    float max_extrapolation;
    float front_tolerance;
    uint irradiance;
};

)" + k.source() + R"(
void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x >= width || pixel.y >= height) return;
    uint i = pixel.y * width + pixel.x;
    vec4 pd = position_depth[i];
    // No geometry here (depth +infinity).
    if (!(pd.w < uintBitsToFloat(0x7f800000u))) return;
    vec3 p = pd.xyz;
    vec3 n = normal[i].xyz;
    vec3 rho = irradiance != 0u ? vec3()" + pi + R"() : albedo[i].rgb;
    // Records in order, added one by one to what the pixel holds: the CPU's summation order.
    vec4 sum = splat[i];
    for (uint k = first; k < first + count; ++k) {
        bounce_record r = records[k];
        vec3 d = p - r.position_inv_r.xyz;
        float zone = influence_radius(r.normal_radius.w, a);
        if (!(dot(d, d) <= zone * zone * )" + widen + R"()) continue;
        float c[4];
        splat_contribution(p, n, rho, r.position_inv_r.xyz, r.normal_radius.xyz, r.position_inv_r.w, a,
                           r.irradiance.xyz, r.rotation[0].xyz, r.rotation[1].xyz, r.rotation[2].xyz,
                           r.translation[0].xyz, r.translation[1].xyz, r.translation[2].xyz, max_extrapolation,
                           front_tolerance, c);
        if (c[3] > 0.0) sum += vec4(c[0], c[1], c[2], c[3]);
    }
    splat[i] = sum;
}
)";
}

std::string normalize_shader(bool wide) {
    glsl::function_set k;
    k.add("normalized_splat", normalized_splat<f32, vec3>, "sum", "weight");
    if (wide) k.add("hole_filled_splat", hole_filled_splat<f32, vec3>, "sum", "weight", "wide_sum", "wide_weight", "lambda");
    return header(normalize_group, 1) +
           "layout(std430, set = 0, binding = 0) readonly buffer bounce_splat { vec4 splat[]; };\n" +
           (wide ? "layout(std430, set = 0, binding = 1) readonly buffer bounce_wide { vec4 wide[]; };\n"
                   "layout(std430, set = 0, binding = 2) writeonly buffer bounce_indirect { vec4 indirect[]; };\n"
                 : "layout(std430, set = 0, binding = 1) writeonly buffer bounce_indirect { vec4 indirect[]; };\n") +
           "layout(push_constant) uniform bounce_normalize_constants {\n    uint count;\n    float lambda;\n};\n\n" +
           k.source() +
           "\nvoid main() {\n"
           "    uint i = gl_GlobalInvocationID.x;\n"
           "    if (i >= count) return;\n"
           "    vec4 s = splat[i];\n" +
           (wide ? "    vec4 w = wide[i];\n    indirect[i] = vec4(hole_filled_splat(s.rgb, s.a, w.rgb, w.a, lambda), 1.0);\n"
                 : "    indirect[i] = vec4(normalized_splat(s.rgb, s.a), 1.0);\n") +
           "}\n";
}

template <int L>
std::string sh_shader() {
    constexpr int n = int(sh_count(L));
    glsl::function_set k;
    k.add("sh_basis", sh_basis<L, f32, vec3>, "d", "y");
    k.add("texel_solid_angle", rectangle_solid_angle_triangles<f32, vec3>, "u0", "v0", "u1", "v1");
    const std::string N = std::to_string(n), G = std::to_string(sh_group);
    return header(sh_group, 1) + R"(layout(std430, set = 0, binding = 0) readonly buffer bounce_texels { float texels[]; };
layout(std430, set = 0, binding = 1) writeonly buffer bounce_coefficients { vec4 coefficients[]; };
layout(push_constant) uniform bounce_sh_constants {
    uint size;
    uint first_map;
};
shared vec3 partial[)" + G + R"(];

)" + k.source() + R"(
// The direction of face coordinates (u, v) on a face, in OpenGL's cube-map layout
// (sh/projection.hpp's cube_face_direction).
vec3 face_direction(uint face, float u, float v) {
    if (face == 0u) return vec3(1.0, -v, -u);
    if (face == 1u) return vec3(-1.0, -v, u);
    if (face == 2u) return vec3(u, 1.0, v);
    if (face == 3u) return vec3(u, -1.0, -v);
    if (face == 4u) return vec3(u, -v, 1.0);
    return vec3(-u, -v, -1.0);
}

void main() {
    uint map = first_map + gl_WorkGroupID.x;
    uint lid = gl_LocalInvocationID.x;
    uint per_face = size * size;
    uint per_map = 6u * per_face;
    float s = float(size);
    vec3 sum[)" + N + R"(];
    for (int i = 0; i < )" + N + R"(; ++i) sum[i] = vec3(0.0);
    for (uint t = lid; t < per_map; t += )" + G + R"(u) {
        uint face = t / per_face;
        uint y = (t - face * per_face) / size;
        uint x = t - face * per_face - y * size;
        float u0 = float(2u * x) / s - 1.0, u1 = float(2u * x + 2u) / s - 1.0;
        float v0 = float(2u * y) / s - 1.0, v1 = float(2u * y + 2u) / s - 1.0;
        vec3 d = normalize(face_direction(face, float(2u * x + 1u) / s - 1.0, float(2u * y + 1u) / s - 1.0));
        float y_d[)" + N + R"(];
        sh_basis(d, y_d);
        uint at = 3u * (map * per_map + t);
        vec3 f = vec3(texels[at], texels[at + 1u], texels[at + 2u]) * texel_solid_angle(u0, v0, u1, v1);
        for (int i = 0; i < )" + N + R"(; ++i) sum[i] += f * y_d[i];
    }
    // Tree reduction of the workgroup's partial sums, one coefficient at a time. Each
    // barrier() comes with memoryBarrierShared(): without it lavapipe let some reads see
    // stale partial sums (c_00 off by 2e-5 relative).
    for (int i = 0; i < )" + N + R"(; ++i) {
        partial[lid] = sum[i];
        memoryBarrierShared();
        barrier();
        for (uint stride = )" + std::to_string(sh_group / 2) + R"(u; stride > 0u; stride >>= 1u) {
            if (lid < stride) partial[lid] += partial[lid + stride];
            memoryBarrierShared();
            barrier();
        }
        if (lid == 0u) coefficients[map * )" + N + R"(u + uint(i)] = vec4(partial[0], 0.0);
        memoryBarrierShared();
        barrier();
    }
}
)";
}

}  // namespace

std::vector<shader_source> shader_sources() {
    std::vector<shader_source> out;
    for (const weighting_kind w : weighting_kinds)
        for (const bool gradients : {false, true})
            for (const bool front : {false, true})
                out.push_back({splat_shader_name(w, gradients, front), splat_shader(w, gradients, front)});
    out.push_back({"normalize", normalize_shader(false)});
    out.push_back({"normalize_wide", normalize_shader(true)});
    out.push_back({sh_shader_name(2), sh_shader<2>()});
    out.push_back({sh_shader_name(3), sh_shader<3>()});
    out.push_back({sh_shader_name(4), sh_shader<4>()});
    return out;
}

}  // namespace bounce::vk::detail
