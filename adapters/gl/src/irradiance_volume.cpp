#include <bounce/gl/irradiance_volume.hpp>

#include "saved_state.hpp"

#include <bounce/gl/errors.hpp>
#include <bounce/glsl/emit.hpp>
#include <bounce/volume/kernels.hpp>
#include <bounce/volume/visibility_kernels.hpp>

#include <algorithm>
#include <cmath>

#include <glm/vec4.hpp>

namespace bounce::gl {

namespace {

constexpr int L = irradiance_volume_bands;
using glsl::f32;
using glsl::vec3;

std::size_t max_block_bytes() {
    GLint64 max_block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
    return std::size_t(max_block);
}

template <class T>
buffer upload(const std::vector<T>& v, const char* what) {
    const std::size_t bytes = std::max<std::size_t>(v.size() * sizeof(T), 16);
    if (bytes > max_block_bytes())
        throw gl_error(std::string("bounce::gl: irradiance volume ") + what + " of " + std::to_string(bytes) +
                       " bytes exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE");
    return buffer(bytes, v.empty() ? nullptr : v.data());
}

}  // namespace

irradiance_volume_buffers::irradiance_volume_buffers(const irradiance_volume& volume, const probe_visibility* visibility)
    : nodes_(1), probes_(1), owners_(1), moments_(16), positions_(16), reference_reach_(volume.reference_reach()) {
    require(!visibility || visibility->probe_count() == volume.probes().size(), "visibility",
            "one distance map per probe of the volume");
    const auto flat = volume.flatten();
    nodes_ = upload(flat.nodes, "nodes");
    probes_ = upload(flat.probes, "probes");
    owners_ = upload(volume.probe_owners(), "owners");
    if (visibility) {
        moments_ = upload(visibility->moments(), "distance moments");
        std::vector<glm::vec4> at;  // where each probe was baked (relocated or on its lattice point)
        for (std::size_t j = 0; j < volume.probes().size(); ++j)
            at.emplace_back(visibility->position(j, volume.probes()[j].position), 0.f);
        positions_ = upload(at, "probe positions");
        visibility_resolution_ = visibility->resolution();
    }
}

/// What one dispatch's uniforms say.
struct irradiance_volume_lookup::dispatch {
    int weighted = 0;
    weighted_lookup how{};
    float ref = 1.f;
    int visible = 0;
    float resolution = 0.f, bias = 0.f;
    glm::vec3 eye{0.f};
};

std::string irradiance_volume_lookup::shader_source() {
    glsl::function_set fns;
    fns.add("iv_clamp", volume_clamp<f32, vec3>, "p", "lo", "size");
    fns.add("iv_octant", octree_octant<f32, vec3>, "p", "lo", "size");
    fns.add("iv_reaches", octree_node_reaches<f32, vec3>, "p", "lo", "size", "support");
    fns.add("iv_trilinear_weights", trilinear_weights<f32, vec3>, "p", "lo", "size", "w");
    fns.add("iv_trilinear_add", trilinear_probe_accumulate<L, f32, vec3>, "sum", "wsum", "n", "weight", "valid", "c",
            "sum_out", "wsum_out");
    fns.add("iv_weighted_add", weighted_probe_accumulate<L, f32, vec3>, "sum", "wsum", "p", "n", "s", "reach", "ref", "b",
            "min_distance", "gradient_scale", "c", "gx", "gy", "gz", "sum_out", "wsum_out");
    fns.add("iv_average", probe_average<f32, vec3>, "sum", "wsum");
    fns.add("iv_oct_encode", octahedral_encode<f32, vec3>, "d", "u", "v");
    fns.add("iv_oct_bilinear", octahedral_bilinear<f32>, "u", "v", "n", "b");
    fns.add("iv_oct_texel", octahedral_texel_index<f32>, "x", "y", "n");
    fns.add("iv_bilinear_moments", bilinear_moments<f32>, "mean", "mean_square", "fx", "fy", "m", "m2");
    fns.add("iv_view", view_direction<f32, vec3>, "p", "n", "eye");
    fns.add("iv_spacing", cell_spacing<f32, vec3>, "size");
    fns.add("iv_bias", self_shadow_biased<f32, vec3>, "p", "n", "view", "spacing", "bias");
    fns.add("iv_probe_to_point", probe_to_point<f32, vec3>, "s", "biased", "dir", "distance");
    fns.add("iv_visibility_weight", visibility_probe_weight<f32, vec3>, "p", "n", "s", "distance", "mean", "mean_square",
            "trilinear");
    // Plumbing: the std430 structs of irradiance_volume_gpu_node / _probe, loads, loops.
    return "#version 450 core\n"
           "layout(local_size_x = 64) in;\n"
           "struct iv_node { vec4 lo; vec4 size; int first_child; int pad0; int pad1; int pad2; uint corner[8]; };\n"
           "struct iv_probe { vec4 position; vec4 radiance[9]; vec4 gradient[27]; };\n"
           "layout(std430, binding = 0) readonly buffer iv_nodes { iv_node nodes[]; };\n"
           "layout(std430, binding = 1) readonly buffer iv_probes { iv_probe probes[]; };\n"
           "layout(std430, binding = 2) readonly buffer iv_owners { uint owners[]; };\n"
           "layout(std430, binding = 3) readonly buffer iv_points { vec4 points[]; };\n"
           "layout(std430, binding = 4) writeonly buffer iv_results { vec4 results[]; };\n"
           "layout(std430, binding = 5) readonly buffer iv_moments { float moments[]; };\n"
           "layout(std430, binding = 6) readonly buffer iv_positions { vec4 positions[]; };\n"
           "layout(location = 0) uniform uint count;\n"
           "layout(location = 1) uniform int weighted;\n"
           "layout(location = 2) uniform float b;\n"
           "layout(location = 3) uniform float support;\n"
           "layout(location = 4) uniform float gradient_scale;\n"
           "layout(location = 5) uniform float ref;\n"
           "layout(location = 6) uniform float min_distance;\n"
           "layout(location = 7) uniform int visible;\n"
           "layout(location = 8) uniform float resolution;\n"
           "layout(location = 9) uniform float bias;\n"
           "layout(location = 10) uniform vec3 eye;\n\n" +
           fns.source() +
           "\nvoid load_probe(uint j, out vec3 c[9], out vec3 gx[9], out vec3 gy[9], out vec3 gz[9]) {\n"
           "    for (int i = 0; i < 9; ++i) {\n"
           "        c[i] = probes[j].radiance[i].xyz;\n"
           "        gx[i] = probes[j].gradient[i].xyz;\n"
           "        gy[i] = probes[j].gradient[9 + i].xyz;\n"
           "        gz[i] = probes[j].gradient[18 + i].xyz;\n"
           "    }\n"
           "}\n"
           "void load_moments(uint j, vec3 dir, out float mean, out float square) {\n"
           "    float u, v, b[4], m[4], m2[4];\n"
           "    iv_oct_encode(dir, u, v);\n"
           "    iv_oct_bilinear(u, v, resolution, b);\n"
           "    uint base = j * 2u * uint(resolution) * uint(resolution);\n"
           "    for (int k = 0; k < 4; ++k) {\n"
           "        uint t = uint(iv_oct_texel(b[0] + float(k & 1), b[1] + float(k >> 1), resolution));\n"
           "        m[k] = moments[base + 2u * t];\n"
           "        m2[k] = moments[base + 2u * t + 1u];\n"
           "    }\n"
           "    iv_bilinear_moments(m, m2, b[2], b[3], mean, square);\n"
           "}\n"
           "void main() {\n"
           "    uint e = gl_GlobalInvocationID.x;\n"
           "    if (e >= count) return;\n"
           "    vec3 p = points[2u * e].xyz, n = points[2u * e + 1u].xyz;\n"
           "    vec3 sum = vec3(0.0);\n"
           "    float wsum = 0.0;\n"
           "    vec3 c[9], gx[9], gy[9], gz[9];\n"
           "    if (weighted == 0) {\n"
           "        vec3 pc = iv_clamp(p, nodes[0].lo.xyz, nodes[0].size.xyz);\n"
           "        uint i = 0u;\n"
           "        for (int level = 0; level < 64 && nodes[i].first_child >= 0; ++level)\n"
           "            i = uint(nodes[i].first_child) + uint(iv_octant(pc, nodes[i].lo.xyz, nodes[i].size.xyz));\n"
           "        float w[8];\n"
           "        iv_trilinear_weights(p, nodes[i].lo.xyz, nodes[i].size.xyz, w);\n"
           "        vec3 biased = iv_bias(p, n, iv_view(p, n, eye), iv_spacing(nodes[i].size.xyz), bias);\n"
           "        for (int k = 0; k < 8; ++k) {\n"
           "            uint j = nodes[i].corner[k];\n"
           "            load_probe(j, c, gx, gy, gz);\n"
           "            float weight = w[k];\n"
           "            if (visible != 0) {\n"
           "                vec3 dir;\n"
           "                float distance, mean, square;\n"
           "                iv_probe_to_point(positions[j].xyz, biased, dir, distance);\n"
           "                load_moments(j, dir, mean, square);\n"
           "                weight = iv_visibility_weight(p, n, positions[j].xyz, distance, mean, square, w[k]);\n"
           "            }\n"
           "            iv_trilinear_add(sum, wsum, n, weight, probes[j].position.w > 0.0 ? 1.0 : 0.0, c, sum, wsum);\n"
           "        }\n"
           "    } else {\n"
           "        uint stack[96];\n"
           "        int top = 0;\n"
           "        stack[top++] = 0u;\n"
           "        while (top > 0) {\n"
           "            uint i = stack[--top];\n"
           "            if (iv_reaches(p, nodes[i].lo.xyz, nodes[i].size.xyz, support) == 0.0) continue;\n"
           "            if (nodes[i].first_child >= 0) {\n"
           "                for (int k = 7; k >= 0; --k) stack[top++] = uint(nodes[i].first_child + k);\n"
           "                continue;\n"
           "            }\n"
           "            for (int k = 0; k < 8; ++k) {\n"
           "                uint j = nodes[i].corner[k];\n"
           "                if (owners[j] != i || probes[j].position.w <= 0.0) continue;\n"
           "                load_probe(j, c, gx, gy, gz);\n"
           "                iv_weighted_add(sum, wsum, p, n, probes[j].position.xyz, support * probes[j].position.w, ref, b,\n"
           "                                min_distance, gradient_scale, c, gx, gy, gz, sum, wsum);\n"
           "            }\n"
           "        }\n"
           "    }\n"
           "    results[e] = vec4(iv_average(sum, wsum), 0.0);\n"
           "}\n";
}

irradiance_volume_lookup::irradiance_volume_lookup() : program_(program::compute(shader_source())) {}

std::vector<glm::vec3> irradiance_volume_lookup::light_points(const irradiance_volume_buffers& volume,
                                                               std::span<const glm::vec3> points,
                                                               std::span<const glm::vec3> normals,
                                                               volume_interpolation interpolation,
                                                               const weighted_lookup& how, output_quantity quantity,
                                                               std::span<const glm::vec3> albedo) const {
    require(how.b > 0 && how.b <= 4, "b", "the distance exponent must lie in (0, 4]");
    require(how.support > 1 && std::isfinite(how.support), "support", "must be finite and > 1");
    dispatch d;
    d.weighted = interpolation == volume_interpolation::weighted ? 1 : 0;
    d.how = how;
    d.ref = how.support * volume.reference_reach();
    return run(volume, points, normals, d, quantity, albedo);
}

std::vector<glm::vec3> irradiance_volume_lookup::light_points(const irradiance_volume_buffers& volume,
                                                               std::span<const glm::vec3> points,
                                                               std::span<const glm::vec3> normals, glm::vec3 eye,
                                                               const visibility_lookup& how, output_quantity quantity,
                                                               std::span<const glm::vec3> albedo) const {
    require(std::isfinite(how.self_shadow_bias) && how.self_shadow_bias >= 0, "self_shadow_bias", "must be finite and >= 0");
    require(std::isfinite(eye.x) && std::isfinite(eye.y) && std::isfinite(eye.z), "eye", "must be finite");
    dispatch d;
    d.visible = how.mode == volume_visibility::chebyshev ? 1 : 0;
    require(!d.visible || volume.visibility_resolution() > 0, "visibility",
            "the buffers hold no distance moments (irradiance_volume_buffers with a probe_visibility)");
    d.ref = d.how.support * volume.reference_reach();
    d.resolution = float(volume.visibility_resolution());
    d.bias = how.self_shadow_bias;
    d.eye = eye;
    return run(volume, points, normals, d, quantity, albedo);
}

std::vector<glm::vec3> irradiance_volume_lookup::run(const irradiance_volume_buffers& volume,
                                                     std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                                                     const dispatch& d, output_quantity quantity,
                                                     std::span<const glm::vec3> albedo) const {
    require(normals.size() == points.size(), "normals", "one normal per point");
    require(quantity == output_quantity::irradiance || albedo.size() == points.size(), "albedo",
            "one albedo per point is needed for radiance");
    require(points.size() < 0x7fffffffu / 2, "points", "too many points for one dispatch (32-bit indices)");
    std::vector<glm::vec3> out(points.size());
    if (points.empty()) return out;
    std::vector<float> packed(points.size() * 8);
    for (std::size_t i = 0; i < points.size(); ++i)
        for (int k = 0; k < 3; ++k) packed[8 * i + std::size_t(k)] = points[i][k], packed[8 * i + 4 + std::size_t(k)] = normals[i][k];
    const buffer in(packed.size() * sizeof(float), packed.data());
    buffer result(points.size() * 4 * sizeof(float));

    const detail::program_and_storage_state saved({0u, 1u, 2u, 3u, 4u, 5u, 6u});
    glUseProgram(program_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, volume.nodes().id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, volume.probes().id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, volume.owners().id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, in.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, result.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, volume.moments().id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, volume.positions().id());
    program_.set(0, unsigned(points.size()));
    program_.set(1, d.weighted);
    program_.set(2, d.how.b);
    program_.set(3, d.how.support);
    program_.set(4, d.how.gradients ? 1.f : 0.f);
    program_.set(5, d.ref);
    program_.set(6, irradiance_volume::min_relative_distance);
    program_.set(7, d.visible);
    program_.set(8, d.resolution);
    program_.set(9, d.bias);
    program_.set(10, d.eye);
    constexpr std::size_t local = 64;
    require((points.size() + local - 1) / local <= 65535, "points", "at most 65535 * 64 points per call");
    glDispatchCompute(GLuint((points.size() + local - 1) / local), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    check_error("glDispatchCompute (irradiance volume lookup)");
    std::vector<float> raw(points.size() * 4);
    result.read(0, raw.data(), raw.size() * sizeof(float));
    for (std::size_t i = 0; i < points.size(); ++i) out[i] = glm::vec3(raw[4 * i], raw[4 * i + 1], raw[4 * i + 2]);
    apply_output(quantity, albedo, std::span<glm::vec3>(out));
    return out;
}

}  // namespace bounce::gl
