// The GLSL of gl::indirect_renderer's passes: the interleaved split and gather, the RSM
// gather, SII's splats, the down- and upsampling, the discontinuity buffer and the tent. The
// math in them is emitted from the core's kernels; the rest is fetches, loops and writes.
#include "indirect_shaders.hpp"
#include "gbuffer_samplers.hpp"

#include <bounce/glsl/emit.hpp>
#include <bounce/indirect/imperfect_shadow_maps.hpp>
#include <bounce/indirect/rsm.hpp>
#include <bounce/indirect/rsm_sampling.hpp>

namespace bounce::gl::indirect_glsl {

namespace {

// Shared declarations: the frame's size and pattern, GL rows to rows from the top, the
// background test.
const std::string common_glsl = R"(layout(location = 0) uniform vec2 frame_size;
layout(location = 1) uniform vec2 frame_pattern;
int top_row(int row) { return int(frame_size.y) - 1 - row; }
ivec2 texel_of(int x, int row_from_top) { return ivec2(x, int(frame_size.y) - 1 - row_from_top); }
)" + std::string(detail::gbuffer_covered);

}  // namespace

std::string index_kernels() {
    glsl::function_set k;
    k.add("interleave_gather_coordinate", interleave_gather_coordinate<glsl::f32>, "u", "size", "n", "result");
    k.add("interleave_split_coordinate", interleave_split_coordinate<glsl::f32>, "x", "size", "n");
    return k.source();
}

// Split: split-buffer pixel (u, v) holds image pixel gather_coordinate(u, v) (its inverse
// map is split_coordinate), position-depth and normal into two targets.
std::string split_fragment() {
    return std::string("#version 450 core\n") + common_glsl + R"(layout(binding = 0) uniform sampler2D source_position_depth;
layout(binding = 1) uniform sampler2D source_normal;
layout(location = 0) out vec4 split_position_depth;
layout(location = 1) out vec4 split_normal;

)" + index_kernels() + R"(
void main() {
    ivec2 g = ivec2(gl_FragCoord.xy);
    float gx[2], gy[2];
    interleave_gather_coordinate(float(g.x), frame_size.x, frame_pattern.x, gx);
    interleave_gather_coordinate(float(top_row(g.y)), frame_size.y, frame_pattern.y, gy);
    ivec2 source = texel_of(int(gx[0]), int(gy[0]));
    split_position_depth = texelFetch(source_position_depth, source, 0);
    split_normal = vec4(texelFetch(source_normal, source, 0).xyz, 0.0);
}
)";
}

// Gather: image pixel (x, y) takes split-buffer pixel split_coordinate(x, y).
std::string gather_fragment() {
    return std::string("#version 450 core\n") + common_glsl + R"(layout(binding = 0) uniform sampler2D split_image;
layout(location = 0) out vec4 image;

)" + index_kernels() + R"(
void main() {
    ivec2 g = ivec2(gl_FragCoord.xy);
    float u = interleave_split_coordinate(float(g.x), frame_size.x, frame_pattern.x);
    float v = interleave_split_coordinate(float(top_row(g.y)), frame_size.y, frame_pattern.y);
    image = vec4(texelFetch(split_image, texel_of(int(u), int(v)), 0).rgb, 0.0);
}
)";
}

// The RSM gather over a (split) G-buffer from one map: the pixel's sub-buffer s reads the
// run [group_begin[s], group_begin[s + 1]) of the grouped pattern (cpu::rsm_gather's order).
std::string gather_rsm_fragment() {
    glsl::function_set k;
    k.add("interleave_gather_coordinate", interleave_gather_coordinate<glsl::f32>, "u", "size", "n", "result");
    k.add("rsm_disc_centre", rsm_disc_centre<glsl::f32, glsl::vec2>, "clip_x", "clip_y", "clip_w");
    k.add("pixel_light_irradiance", pixel_light_irradiance<glsl::f32, glsl::vec3>, "x", "n", "xp", "np", "flux",
          "offset", "min_distance2");
    return std::string("#version 450 core\n") + common_glsl + detail::gbuffer_position_normal_samplers() +
           R"(layout(binding = 2) uniform sampler2D map_position;
layout(binding = 3) uniform sampler2D map_normal;
layout(binding = 4) uniform sampler2D map_flux;
layout(std430, binding = 0) readonly buffer bounce_disc { vec4 disc[]; };
layout(std430, binding = 1) readonly buffer bounce_groups { uint group_begin[]; };
layout(location = 2) uniform mat4 light_view_projection;
layout(location = 3) uniform vec2 map_size;
layout(location = 4) uniform float weight_scale;
layout(location = 5) uniform float offset;
layout(location = 6) uniform float min_distance2;
// The upsampling's fallback: only the pixels its mask marks are gathered (the others keep
// the interpolated value below them).
layout(binding = 5) uniform sampler2D fallback_mask;
layout(location = 7) uniform int masked;
layout(location = 0) out vec4 irradiance;

)" + k.source() + R"(
void main() {
    ivec2 g = ivec2(gl_FragCoord.xy);
    if (masked != 0 && texelFetch(fallback_mask, g, 0).r == 0.0) discard;
    vec4 position_depth = texelFetch(gbuffer_position_depth, g, 0);
    if (!covered(position_depth.w)) {
        irradiance = vec4(0.0);
        return;
    }
    float gx[2], gy[2];
    interleave_gather_coordinate(float(g.x), frame_size.x, frame_pattern.x, gx);
    interleave_gather_coordinate(float(top_row(g.y)), frame_size.y, frame_pattern.y, gy);
    int s = int(gy[1]) * int(frame_pattern.x) + int(gx[1]);
    vec3 x = position_depth.xyz;
    vec3 n = texelFetch(gbuffer_normal, g, 0).xyz;
    // The matrix product in glm's order, unfused, so the disc centre rounds as on the CPU.
    precise vec4 clip = (light_view_projection[0] * x.x + light_view_projection[1] * x.y) +
                        (light_view_projection[2] * x.z + light_view_projection[3]);
    vec2 centre = rsm_disc_centre(clip.x, clip.y, clip.w);
    vec3 e = vec3(0.0);
    for (uint k = group_begin[s]; k < group_begin[s + 1]; ++k) {
        vec4 sample_k = disc[k];
        precise float tu = (centre.x + sample_k.x) * map_size.x;
        precise float tv = (centre.y + sample_k.y) * map_size.y;
        if (!(tu >= 0.0 && tu < map_size.x && tv >= 0.0 && tv < map_size.y)) continue;
        ivec2 t = ivec2(int(tu), int(map_size.y) - 1 - int(tv));
        vec3 flux = texelFetch(map_flux, t, 0).rgb;
        if (flux == vec3(0.0)) continue;
        e += pixel_light_irradiance(x, n, texelFetch(map_position, t, 0).xyz, texelFetch(map_normal, t, 0).xyz,
                                    flux * (sample_k.z * weight_scale), offset, min_distance2);
    }
    irradiance = vec4(e, 0.0);
}
)";
}

// Downsampling: low-resolution pixel (x, y) takes the full-resolution pixel
// (min(W - 1, f x + f/2), min(H - 1, f y + f/2)), rows from the top (cpu::downsample_gbuffer).
extern const char* const downsample_fragment = R"(#version 450 core
layout(binding = 0) uniform sampler2D source_position_depth;
layout(binding = 1) uniform sampler2D source_normal;
layout(location = 0) uniform vec2 frame_size;
layout(location = 2) uniform vec2 low_size;
layout(location = 3) uniform int factor;
layout(location = 0) out vec4 low_position_depth;
layout(location = 1) out vec4 low_normal;
void main() {
    ivec2 g = ivec2(gl_FragCoord.xy);
    int y = int(low_size.y) - 1 - g.y;
    int sx = min(int(frame_size.x) - 1, g.x * factor + factor / 2);
    int sy = min(int(frame_size.y) - 1, y * factor + factor / 2);
    ivec2 source = ivec2(sx, int(frame_size.y) - 1 - sy);
    low_position_depth = texelFetch(source_position_depth, source, 0);
    low_normal = vec4(texelFetch(source_normal, source, 0).xyz, 0.0);
}
)";

// Geometry-aware upsampling (DS05 section 3.3, cpu::upsample_or_gather): interpolate the
// four low-resolution samples around the pixel when at least three are suitable; otherwise
// mark the pixel for the full-resolution gather.
std::string upsample_fragment() {
    glsl::function_set k;
    k.add("geometry_aware_upsample_weights", geometry_aware_upsample_weights<glsl::f32, glsl::vec3>, "x", "n",
          "positions", "normals", "frac_x", "frac_y", "max_plane_distance", "cos_normal", "result");
    return std::string("#version 450 core\n") + common_glsl + detail::gbuffer_position_normal_samplers() +
           R"(layout(binding = 2) uniform sampler2D low_position_depth;
layout(binding = 3) uniform sampler2D low_normal;
layout(binding = 4) uniform sampler2D low_irradiance;
layout(location = 2) uniform vec2 low_size;
layout(location = 3) uniform int factor;
layout(location = 4) uniform float tan_half_fov;
layout(location = 5) uniform float plane_footprints;
layout(location = 6) uniform float cos_normal;
layout(location = 0) out vec4 irradiance;
layout(location = 1) out vec4 fallback;

)" + k.source() + R"(
void main() {
    ivec2 g = ivec2(gl_FragCoord.xy);
    vec4 position_depth = texelFetch(gbuffer_position_depth, g, 0);
    if (!covered(position_depth.w)) {
        irradiance = vec4(0.0);
        fallback = vec4(0.0);
        return;
    }
    float f = float(factor);
    // Low-resolution sample c sits at full-resolution pixel f c + f/2.
    float lx = (float(g.x) - float(factor / 2)) / f, ly = (float(top_row(g.y)) - float(factor / 2)) / f;
    float fx0 = floor(lx), fy0 = floor(ly);
    vec3 ps[4], ns[4], es[4];
    for (int k = 0; k < 4; ++k) {
        int cx = int(clamp(fx0 + float(k & 1), 0.0, low_size.x - 1.0));
        int cy = int(clamp(fy0 + float(k >> 1), 0.0, low_size.y - 1.0));
        ivec2 t = ivec2(cx, int(low_size.y) - 1 - cy);
        vec4 low = texelFetch(low_position_depth, t, 0);
        bool seen = covered(low.w);
        ps[k] = seen ? low.xyz : vec3(1e30);
        ns[k] = seen ? texelFetch(low_normal, t, 0).xyz : vec3(0.0);
        es[k] = texelFetch(low_irradiance, t, 0).rgb;
    }
    // plane_footprints f camera.pixel_footprint(depth, H), in the CPU's order.
    precise float tolerance = plane_footprints * f * (2.0 * position_depth.w * tan_half_fov / frame_size.y);
    float w[5];
    geometry_aware_upsample_weights(position_depth.xyz, texelFetch(gbuffer_normal, g, 0).xyz, ps, ns,
                                    clamp(lx - fx0, 0.0, 1.0), clamp(ly - fy0, 0.0, 1.0), tolerance, cos_normal, w);
    if (w[4] >= 3.0 && w[0] + w[1] + w[2] + w[3] > 0.0) {
        irradiance = vec4(es[0] * w[0] + es[1] * w[1] + es[2] * w[2] + es[3] * w[3], 0.0);
        fallback = vec4(0.0);
    } else {
        irradiance = vec4(0.0);
        fallback = vec4(1.0);
    }
}
)";
}

// SII: one quad per VPL on its split-buffer rectangle (pixel edges, rows from the top).
extern const char* const splat_vertex = R"(#version 450 core
layout(location = 0) in vec4 rect;
layout(location = 0) uniform vec2 frame_size;
flat out int vpl_index;
void main() {
    vpl_index = gl_InstanceID;
    float x = (gl_VertexID & 1) != 0 ? rect.z + 1.0 : rect.x;
    float y = (gl_VertexID & 2) != 0 ? rect.w + 1.0 : rect.y;
    gl_Position = vec4(2.0 * x / frame_size.x - 1.0, 1.0 - 2.0 * y / frame_size.y, 0.0, 1.0);
}
)";

std::string splat_fragment() {
    glsl::function_set k;
    k.add("pixel_light_irradiance", pixel_light_irradiance<glsl::f32, glsl::vec3>, "x", "n", "xp", "np", "flux",
          "offset", "min_distance2");
    k.add("ism_map_texel", ism_map_texel<glsl::f32, glsl::vec3, glsl::vec2>, "p", "origin", "n", "res");
    k.add("ism_visible", ism_visible<glsl::f32, glsl::vec3>, "receiver", "receiver_normal", "origin", "stored_depth",
          "res", "spacing", "scale");
    // position.w: the VPL's own d^2 clamp (pixel_light_params::min_distance2_for); normal.w:
    // its index in the frame's selection, its map in the imperfect shadow maps' atlas.
    return std::string("#version 450 core\n") + R"(struct bounce_vpl {
    vec4 position;
    vec4 normal;
    vec4 flux;
};
layout(std430, binding = 0) readonly buffer bounce_vpls { bounce_vpl vpls[]; };
layout(std430, binding = 2) readonly buffer bounce_ism_depth { float ism_depth[]; };
)" + detail::gbuffer_position_normal_samplers() + R"(layout(location = 5) uniform float offset;
layout(location = 6) uniform int ism_on;
layout(location = 7) uniform float ism_map_size;
layout(location = 8) uniform int ism_columns;
layout(location = 9) uniform int ism_atlas_width;
layout(location = 10) uniform float ism_spacing;
layout(location = 11) uniform float ism_bias_scale;
flat in int vpl_index;
layout(location = 0) out vec4 irradiance;

)" + k.source() + detail::gbuffer_covered + R"(
void main() {
    ivec2 g = ivec2(gl_FragCoord.xy);
    vec4 position_depth = texelFetch(gbuffer_position_depth, g, 0);
    if (!covered(position_depth.w)) discard;
    bounce_vpl l = vpls[vpl_index];
    vec3 x = position_depth.xyz;
    vec3 n = texelFetch(gbuffer_normal, g, 0).xyz;
    vec3 e = pixel_light_irradiance(x, n, l.position.xyz, l.normal.xyz, l.flux.xyz, offset, l.position.w);
    if (ism_on != 0) {
        // The texel of the VPL's map in the atlas (ism_atlas_layout::index), its depth test.
        int j = int(l.normal.w), s = int(ism_map_size);
        vec3 t = ism_map_texel(x, l.position.xyz, l.normal.xyz, ism_map_size);
        int at = ((j / ism_columns) * s + int(t.y)) * ism_atlas_width + (j % ism_columns) * s + int(t.x);
        e = e * ism_visible(x, n, l.position.xyz, ism_depth[at], ism_map_size, ism_spacing, ism_bias_scale);
    }
    irradiance = vec4(e, 0.0);
}
)";
}

// Imperfect shadow maps, 1: point i of the set (VPL i % V's subset) into its VPL's map in
// the atlas, the nearest depth kept by atomicMin on the float's bits (non-negative floats
// order as their bits). 2D dispatch: i = y * (groups in x) * 256 + x.
std::string ism_splat_compute() {
    glsl::function_set k;
    k.add("ism_splat_texel", ism_splat_texel<glsl::f32, glsl::vec3, glsl::vec2>, "p", "origin", "n", "res");
    return std::string("#version 450 core\nlayout(local_size_x = 256) in;\n") +
           R"(layout(std430, binding = 0) readonly buffer bounce_ism_points { vec4 points[]; };
layout(std430, binding = 1) readonly buffer bounce_ism_vpls { vec4 vpl_frames[]; };
layout(std430, binding = 2) buffer bounce_ism_depth { uint depth_bits[]; };
layout(location = 0) uniform uint point_count;
layout(location = 1) uniform uint vpl_count;
layout(location = 2) uniform float map_size;
layout(location = 3) uniform uint columns;
layout(location = 4) uniform uint atlas_width;

)" + k.source() + R"(
void main() {
    uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 256u + gl_GlobalInvocationID.x;
    if (i >= point_count) return;
    uint j = i % vpl_count;
    vec3 t = ism_splat_texel(points[i].xyz, vpl_frames[2u * j].xyz, vpl_frames[2u * j + 1u].xyz, map_size);
    if (!(t.z < )" + glsl::float_literal(ism_empty) + R"()) return;
    uint s = uint(map_size);
    uint at = ((j / columns) * s + uint(t.y)) * atlas_width + (j % columns) * s + uint(t.x);
    atomicMin(depth_bits[at], floatBitsToUint(t.z));
}
)";
}

// What the pull and the push share: the depth pyramid (levels stored one after another,
// finest first), the two levels' offsets and the coarser one's size.
const std::string ism_level_glsl = R"(#version 450 core
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 2) buffer bounce_ism_depth { float depth[]; };
layout(location = 0) uniform uint fine_offset;
layout(location = 1) uniform uint coarse_offset;
layout(location = 2) uniform uvec2 coarse_size;

)";

// 2: the pull, one coarse texel of 2 x 2 finer ones.
std::string ism_pull_compute() {
    glsl::function_set k;
    k.add("ism_pull", ism_pull<glsl::f32>, "a", "b", "c", "d");
    return ism_level_glsl + k.source() + R"(
void main() {
    uvec2 c = gl_GlobalInvocationID.xy;
    if (c.x >= coarse_size.x || c.y >= coarse_size.y) return;
    uint fw = 2u * coarse_size.x;
    uint f = fine_offset + 2u * c.y * fw + 2u * c.x;
    depth[coarse_offset + c.y * coarse_size.x + c.x] = ism_pull(depth[f], depth[f + 1u], depth[f + fw], depth[f + fw + 1u]);
}
)";
}

// 3: the push, one finer texel from its (already pushed) parent.
std::string ism_push_compute() {
    glsl::function_set k;
    k.add("ism_push", ism_push<glsl::f32>, "fine", "coarse");
    return ism_level_glsl + k.source() + R"(
void main() {
    uvec2 f = gl_GlobalInvocationID.xy;
    uint fw = 2u * coarse_size.x;
    if (f.x >= fw || f.y >= 2u * coarse_size.y) return;
    uint at = fine_offset + f.y * fw + f.x;
    depth[at] = ism_push(depth[at], depth[coarse_offset + (f.y / 2u) * coarse_size.x + f.x / 2u]);
}
)";
}

// The discontinuity buffer: x = edge towards the right neighbour, y = towards the one below
// (rows from the top); borders and background count as edges (cpu::discontinuity_buffer).
std::string discontinuity_fragment() {
    glsl::function_set k;
    k.add("geometry_discontinuity", geometry_discontinuity<glsl::f32, glsl::vec3>, "depth_a", "n_a", "depth_b", "n_b",
          "relative_depth", "cos_normal");
    return std::string("#version 450 core\n") + common_glsl + detail::gbuffer_position_normal_samplers() +
           R"(layout(location = 2) uniform float relative_depth;
layout(location = 3) uniform float cos_normal;
layout(location = 0) out vec4 edges;

)" + k.source() + R"(
float edge(ivec2 a, ivec2 b) {
    float da = texelFetch(gbuffer_position_depth, a, 0).w, db = texelFetch(gbuffer_position_depth, b, 0).w;
    if (!covered(da) || !covered(db)) return 1.0;
    return geometry_discontinuity(da, texelFetch(gbuffer_normal, a, 0).xyz, db, texelFetch(gbuffer_normal, b, 0).xyz,
                                  relative_depth, cos_normal);
}
void main() {
    ivec2 g = ivec2(gl_FragCoord.xy);
    int y = top_row(g.y);
    float right = g.x + 1 < int(frame_size.x) ? edge(g, ivec2(g.x + 1, g.y)) : 1.0;
    float below = y + 1 < int(frame_size.y) ? edge(g, ivec2(g.x, g.y - 1)) : 1.0;
    edges = vec4(right, below, 0.0, 0.0);
}
)";
}

// One pass of the geometry-aware tent with compile-time radius R along x or y (rows from
// the top), clamped at the borders as cpu::geometry_aware_blur.
std::string tent_fragment(int radius, bool vertical) {
    glsl::function_set k;
    const auto add = [&]<int R>() {
        k.add("geometry_aware_tent", geometry_aware_tent<R, glsl::f32, glsl::vec3>, "values", "edges", "n");
    };
    switch (radius) {
        case 1: add.operator()<1>(); break;
        case 3: add.operator()<3>(); break;
        case 7: add.operator()<7>(); break;
        case 15: add.operator()<15>(); break;
        case 31: add.operator()<31>(); break;
        default: add.operator()<63>(); break;
    }
    const std::string r = std::to_string(radius);
    return std::string("#version 450 core\n") + common_glsl + "const int R = " + r + ";\nconst bool vertical = " +
           (vertical ? "true" : "false") + R"(;
layout(binding = 0) uniform sampler2D blur_input;
layout(binding = 1) uniform sampler2D edge_buffer;
layout(binding = 2) uniform sampler2D gbuffer_position_depth;
layout(location = 2) uniform float pattern_width;
layout(location = 0) out vec4 blurred;

)" + k.source() + R"(
void main() {
    ivec2 g = ivec2(gl_FragCoord.xy);
    if (!covered(texelFetch(gbuffer_position_depth, g, 0).w)) {
        blurred = vec4(texelFetch(blur_input, g, 0).rgb, 0.0);
        return;
    }
    int x = g.x, y = top_row(g.y);
    int along = vertical ? y : x;
    int size = vertical ? int(frame_size.y) : int(frame_size.x);
    vec3 values[2 * R + 1];
    float cuts[2 * R];
    for (int k = 0; k <= 2 * R; ++k) {
        int t = along - R + k;
        bool inside = t >= 0 && t < size;
        int at = inside ? t : along;
        ivec2 texel = vertical ? texel_of(x, at) : texel_of(at, y);
        values[k] = texelFetch(blur_input, texel, 0).rgb;
        if (k < 2 * R) {
            vec2 e = texelFetch(edge_buffer, texel, 0).xy;
            cuts[k] = inside && t + 1 < size ? (vertical ? e.y : e.x) : 1.0;
        }
    }
    blurred = vec4(geometry_aware_tent(values, cuts, pattern_width), 0.0);
}
)";
}

}  // namespace bounce::gl::indirect_glsl
