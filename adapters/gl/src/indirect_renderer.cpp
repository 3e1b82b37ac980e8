// One-bounce indirect irradiance from reflective shadow maps on OpenGL: the interleaved
// split and gather (Segovia et al. 2006), the RSM gather (Dachsbacher and Stamminger 2005)
// as a fragment pass, SII (Dachsbacher and Stamminger 2006) as instanced quads with
// additive blending, the discontinuity buffer and the separable geometry-aware tent. The
// shaders are plumbing (fetches, loops over storage buffers, row flips, writes); the index
// maps, disc centre, pixel-light irradiance, discontinuity test and tent are the emitted
// kernels of rsm.hpp and interleaved_sampling.hpp.
#include <bounce/gl/indirect_renderer.hpp>
#include <bounce/glsl/emit.hpp>
#include <bounce/rsm.hpp>
#include <bounce/rsm_sampling.hpp>

#include "saved_state.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include <glm/glm.hpp>

namespace bounce::gl {

namespace {

constexpr const char* fullscreen_vertex = R"(#version 450 core
void main() {
    vec2 corner = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1));
    gl_Position = vec4(corner - 1.0, 0.0, 1.0);
}
)";

// Shared declarations: the frame's size and pattern, GL rows to rows from the top, the
// background test (depth +infinity, gbuffer_view::covered).
constexpr const char* common_glsl = R"(layout(location = 0) uniform vec2 frame_size;
layout(location = 1) uniform vec2 frame_pattern;
int top_row(int row) { return int(frame_size.y) - 1 - row; }
ivec2 texel_of(int x, int row_from_top) { return ivec2(x, int(frame_size.y) - 1 - row_from_top); }
bool covered(float depth) { return depth < uintBitsToFloat(0x7f800000u); }
)";

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
    return std::string("#version 450 core\n") + common_glsl + R"(layout(binding = 0) uniform sampler2D gbuffer_position_depth;
layout(binding = 1) uniform sampler2D gbuffer_normal;
layout(binding = 2) uniform sampler2D map_position;
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
constexpr const char* downsample_fragment = R"(#version 450 core
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
    return std::string("#version 450 core\n") + common_glsl + R"(layout(binding = 0) uniform sampler2D gbuffer_position_depth;
layout(binding = 1) uniform sampler2D gbuffer_normal;
layout(binding = 2) uniform sampler2D low_position_depth;
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
constexpr const char* splat_vertex = R"(#version 450 core
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
    return std::string("#version 450 core\n") + R"(struct bounce_vpl {
    vec4 position;
    vec4 normal;
    vec4 flux;
};
layout(std430, binding = 0) readonly buffer bounce_vpls { bounce_vpl vpls[]; };
layout(binding = 0) uniform sampler2D gbuffer_position_depth;
layout(binding = 1) uniform sampler2D gbuffer_normal;
layout(location = 5) uniform float offset;
layout(location = 6) uniform float min_distance2;
flat in int vpl_index;
layout(location = 0) out vec4 irradiance;

)" + k.source() + R"(
void main() {
    ivec2 g = ivec2(gl_FragCoord.xy);
    vec4 position_depth = texelFetch(gbuffer_position_depth, g, 0);
    if (!(position_depth.w < uintBitsToFloat(0x7f800000u))) discard;
    bounce_vpl l = vpls[vpl_index];
    irradiance = vec4(pixel_light_irradiance(position_depth.xyz, texelFetch(gbuffer_normal, g, 0).xyz, l.position.xyz,
                                             l.normal.xyz, l.flux.xyz, offset, min_distance2), 0.0);
}
)";
}

// The discontinuity buffer: x = edge towards the right neighbour, y = towards the one below
// (rows from the top); borders and background count as edges (cpu::discontinuity_buffer).
std::string discontinuity_fragment() {
    glsl::function_set k;
    k.add("geometry_discontinuity", geometry_discontinuity<glsl::f32, glsl::vec3>, "depth_a", "n_a", "depth_b", "n_b",
          "relative_depth", "cos_normal");
    return std::string("#version 450 core\n") + common_glsl + R"(layout(binding = 0) uniform sampler2D gbuffer_position_depth;
layout(binding = 1) uniform sampler2D gbuffer_normal;
layout(location = 2) uniform float relative_depth;
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

int tent_radius(const interleave_pattern& p) {
    const int reach = std::max(p.n, p.m) - 1;
    for (int r : {1, 3, 7, 15, 31})
        if (reach <= r) return r;
    return 63;
}

// Uniform locations of common_glsl and the passes.
enum location : int {
    loc_size = 0,
    loc_pattern = 1,
    loc_light_view_projection = 2,
    loc_relative_depth = 2,
    loc_pattern_width = 2,
    loc_map_size = 3,
    loc_cos_normal = 3,
    loc_weight_scale = 4,
    loc_offset = 5,
    loc_min_distance2 = 6,
    loc_masked = 7,
    loc_low_size = 2,
    loc_factor = 3,
    loc_tan_half_fov = 4,
    loc_plane_footprints = 5,
    loc_upsample_cos_normal = 6,
};

// One VPL as the splat shader reads it (std430).
struct gpu_vpl {
    glm::vec4 position, normal, flux;
};

}  // namespace

// ---- the passes -------------------------------------------------------------------------

struct indirect_renderer::passes {
    program split{fullscreen_vertex, split_fragment()};
    program gather{fullscreen_vertex, gather_fragment()};
    program gather_rsm{fullscreen_vertex, gather_rsm_fragment()};
    program splat{splat_vertex, splat_fragment()};
    program discontinuity{fullscreen_vertex, discontinuity_fragment()};
    std::optional<program> downsample, upsample;  // made on the first low-resolution frame
    std::optional<program> tent_x, tent_y;
    int tent_r = 0;
    framebuffer fbo;
    vertex_array empty_vao, rect_vao;
    // Scratch of one size (interleaved frames): split G-buffer, split result, gathered
    // result, horizontal tent, discontinuity buffer.
    std::optional<texture> split_position_depth, split_normal, split_out, gathered, scratch, edges;
    std::size_t width = 0, height = 0;
    // The disc pattern (grouped) and its group starts, kept while unchanged.
    std::optional<buffer> disc, groups;
    // The same pattern in its own order, as one group (the upsampling's fallback gather).
    std::optional<buffer> whole_disc, whole_group;
    std::size_t disc_count = 0, disc_texels = 0;
    std::optional<buffer> vpls, rects;
    // Low-resolution G-buffer and result, the fallback mask, and the query that counts the
    // fallback's pixels.
    std::optional<texture> low_position_depth, low_normal, low_irradiance, fallback_mask;
    std::size_t low_width = 0, low_height = 0;
    object_id query = 0;

    passes() {
        const GLuint vao = rect_vao.id();
        glVertexArrayAttribFormat(vao, 0, 4, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribBinding(vao, 0, 0);
        glEnableVertexArrayAttrib(vao, 0);
        glVertexArrayBindingDivisor(vao, 0, 1);
        check_error("indirect_renderer vertex array");
    }
    ~passes() {
        if (query != 0) glDeleteQueries(1, &query);
    }
    passes(const passes&) = delete;
    passes& operator=(const passes&) = delete;

    void ensure_low(std::size_t full_w, std::size_t full_h, std::size_t lw, std::size_t lh) {
        if (!downsample) {
            downsample.emplace(fullscreen_vertex, downsample_fragment);
            upsample.emplace(fullscreen_vertex, upsample_fragment());
            glCreateQueries(GL_SAMPLES_PASSED, 1, &query);
        }
        if (!low_position_depth || low_width != lw || low_height != lh) {
            low_position_depth.emplace(texel_format::rgba32f, lw, lh);
            low_normal.emplace(texel_format::rgba32f, lw, lh);
            low_irradiance.emplace(texel_format::rgba32f, lw, lh);
            low_width = lw;
            low_height = lh;
        }
        if (!fallback_mask || fallback_mask->width() != full_w || fallback_mask->height() != full_h)
            fallback_mask.emplace(texel_format::rgba32f, full_w, full_h);
    }

    void ensure_scratch(std::size_t w, std::size_t h) {
        if (split_out && width == w && height == h) return;
        split_position_depth.emplace(texel_format::rgba32f, w, h);
        split_normal.emplace(texel_format::rgba32f, w, h);
        split_out.emplace(texel_format::rgba32f, w, h);
        gathered.emplace(texel_format::rgba32f, w, h);
        scratch.emplace(texel_format::rgba32f, w, h);
        edges.emplace(texel_format::rgba32f, w, h);
        width = w;
        height = h;
    }

    void ensure_tent(int r) {
        if (tent_r == r) return;
        tent_x.emplace(fullscreen_vertex, tent_fragment(r, false));
        tent_y.emplace(fullscreen_vertex, tent_fragment(r, true));
        tent_r = r;
    }

    // Binds `targets` as the colour attachments, the viewport to their size.
    void target(std::initializer_list<object_id> targets, std::size_t w, std::size_t h) {
        GLenum buffers[4];
        GLuint i = 0;
        for (object_id t : targets) {
            glNamedFramebufferTexture(fbo.id(), GL_COLOR_ATTACHMENT0 + i, t, 0);
            buffers[i] = GL_COLOR_ATTACHMENT0 + i;
            ++i;
        }
        for (GLuint j = i; j < 4; ++j) glNamedFramebufferTexture(fbo.id(), GL_COLOR_ATTACHMENT0 + j, 0, 0);
        glNamedFramebufferDrawBuffers(fbo.id(), GLsizei(i), buffers);
        fbo.check_complete();
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo.id());
        glViewport(0, 0, GLsizei(w), GLsizei(h));
    }

    void release_targets() {
        for (GLuint j = 0; j < 4; ++j) glNamedFramebufferTexture(fbo.id(), GL_COLOR_ATTACHMENT0 + j, 0, 0);
    }

    static void textures(std::initializer_list<object_id> ids) {
        GLuint unit = 0;
        for (object_id t : ids) {
            glBindTextureUnit(unit, t);
            glBindSampler(unit, 0);
            ++unit;
        }
    }

    static void frame_uniforms(const program& p, std::size_t w, std::size_t h, const interleave_pattern& pattern) {
        p.set(loc_size, glm::vec2(float(w), float(h)));
        p.set(loc_pattern, glm::vec2(float(pattern.n), float(pattern.m)));
    }

    void fullscreen(const program& p) {
        glUseProgram(p.id());
        glBindVertexArray(empty_vao.id());
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
};

indirect_renderer::indirect_renderer(const indirect_options& options, bool time_stages)
    : options_(options), time_stages_(time_stages) {
    options_.validate();
    passes_ = std::make_unique<passes>();
}

indirect_renderer::~indirect_renderer() = default;

double indirect_renderer::lap(clock::time_point& t) const {
    if (time_stages_) finish();
    const auto now = clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - t).count();
    t = now;
    return ms;
}

indirect_timings indirect_renderer::render(const gbuffer_textures& g, const camera& cam,
                                           std::span<const rsm_textures> maps, const texture_ref& irradiance) {
    g.validate();
    cam.validate();
    require(irradiance.id != 0 && irradiance.format == texel_format::rgba32f, "irradiance",
            "must be an RGBA32F texture");
    require(irradiance.width == g.width() && irradiance.height == g.height(), "irradiance",
            "size differs from the G-buffer");
    for (const auto& m : maps) m.validate("maps");
    if (options_.technique == indirect_technique::rsm_gather)
        for (const auto& m : maps)
            require(m.width() == maps[0].width() && m.height() == maps[0].height(), "maps",
                    "must all have one size (the disc pattern's weights hold its texel count)");

    passes& p = *passes_;
    const std::size_t w = g.width(), h = g.height();
    indirect_timings t;
    const detail::raster_state raster;
    const detail::blend_offset_state blend;
    const detail::program_and_storage_state bindings({0u, 1u});
    const detail::texture_unit_state units(0, 6);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glDisable(GL_DITHER);
    auto start = clock::now();

    const int f = options_.low_resolution;
    if (f == 1) {
        frame(g, w, h, cam, maps, irradiance.id, t, start);
    } else {
        const std::size_t lw = (w + std::size_t(f) - 1) / std::size_t(f), lh = (h + std::size_t(f) - 1) / std::size_t(f);
        p.ensure_low(w, h, lw, lh);
        p.target({p.low_position_depth->id(), p.low_normal->id()}, lw, lh);
        passes::textures({g.position_depth.id, g.normal.id});
        p.downsample->set(loc_size, glm::vec2(float(w), float(h)));
        p.downsample->set(loc_low_size, glm::vec2(float(lw), float(lh)));
        p.downsample->set(loc_factor, f);
        p.fullscreen(*p.downsample);
        check_error("indirect_renderer downsample");
        t.split_ms += lap(start);
        const gbuffer_textures low{*p.low_position_depth, *p.low_normal, *p.low_normal};
        frame(low, lw, lh, cam, maps, p.low_irradiance->id(), t, start);

        // Interpolate where three low-resolution samples suit the pixel, mark the others,
        // then gather the marked pixels at full resolution with the whole pattern (weight 1).
        p.target({irradiance.id, p.fallback_mask->id()}, w, h);
        passes::textures({g.position_depth.id, g.normal.id, p.low_position_depth->id(), p.low_normal->id(),
                          p.low_irradiance->id()});
        const program& up = *p.upsample;
        up.set(loc_size, glm::vec2(float(w), float(h)));
        up.set(loc_low_size, glm::vec2(float(lw), float(lh)));
        up.set(loc_factor, f);
        up.set(loc_tan_half_fov, cam.tan_half_fov());
        up.set(loc_plane_footprints, options_.upsample.plane_footprints);
        up.set(loc_upsample_cos_normal, options_.upsample.cos_normal);
        p.fullscreen(up);
        if (!maps.empty()) {
            p.target({irradiance.id}, w, h);
            glEnable(GL_BLEND);
            glBlendEquation(GL_FUNC_ADD);
            glBlendFunc(GL_ONE, GL_ONE);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, p.whole_disc->id());
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, p.whole_group->id());
            const program& prog = p.gather_rsm;
            passes::frame_uniforms(prog, w, h, interleave_pattern{1, 1});
            prog.set(loc_weight_scale, 1.f);
            prog.set(loc_offset, options_.light.offset);
            prog.set(loc_min_distance2, options_.light.min_distance2);
            prog.set(loc_masked, 1);
            for (std::size_t k = 0; k < maps.size(); ++k) {
                const auto& m = maps[k];
                passes::textures({g.position_depth.id, g.normal.id, m.position.id, m.normal.id, m.flux.id,
                                  p.fallback_mask->id()});
                prog.set(loc_light_view_projection, m.light_view_projection);
                prog.set(loc_map_size, glm::vec2(float(m.width()), float(m.height())));
                // Every fallback pixel draws once per map: count them on the first.
                if (k == 0) glBeginQuery(GL_SAMPLES_PASSED, p.query);
                p.fullscreen(prog);
                if (k == 0) glEndQuery(GL_SAMPLES_PASSED);
            }
            prog.set(loc_masked, 0);
            glDisable(GL_BLEND);
            GLuint64 samples = 0;
            glGetQueryObjectui64v(p.query, GL_QUERY_RESULT, &samples);
            t.fallback_pixels = std::size_t(samples);
        }
        check_error("indirect_renderer upsample");
        t.upsample_ms = lap(start);
    }
    p.release_targets();
    check_error("indirect_renderer::render");
    return t;
}

void indirect_renderer::frame(const gbuffer_textures& g, std::size_t w, std::size_t h, const camera& cam,
                              std::span<const rsm_textures> maps, object_id out, indirect_timings& t,
                              clock::time_point& start) {
    passes& p = *passes_;
    const interleave_pattern& pattern = options_.pattern;
    const bool interleaved = pattern.cells() > 1;
    gbuffer_textures shaded = g;
    object_id shaded_out = out;
    if (interleaved) {
        p.ensure_scratch(w, h);
        p.target({p.split_position_depth->id(), p.split_normal->id()}, w, h);
        passes::textures({g.position_depth.id, g.normal.id});
        passes::frame_uniforms(p.split, w, h, pattern);
        p.fullscreen(p.split);
        shaded.position_depth = *p.split_position_depth;
        shaded.normal = *p.split_normal;
        shaded_out = p.split_out->id();
    }
    check_error("indirect_renderer split");
    t.split_ms += lap(start);

    // Shade the sub-buffers.
    const float zero[4] = {0.f, 0.f, 0.f, 0.f};
    glClearTexImage(shaded_out, 0, GL_RGBA, GL_FLOAT, zero);
    const float scale =
        options_.energy_correct ? interleaved_weight_scale<float>(float(pattern.n), float(pattern.m)) : 1.f;
    if (options_.technique == indirect_technique::rsm_gather) {
        t.vpls = options_.count;
        if (!maps.empty()) {
            const std::size_t texels = maps[0].width() * maps[0].height();
            if (!p.disc || p.disc_count != options_.count || p.disc_texels != texels) {
                const auto full =
                    rsm_disc_pattern(options_.count, options_.r_max, texels, options_.seed, options_.disc);
                const light_groups groups =
                    assign_lights(full.size(), pattern.cells(), light_assignment::interleaved, {}, options_.shift);
                std::vector<glm::vec4> grouped(full.size());
                for (std::size_t k = 0; k < full.size(); ++k) grouped[k] = glm::vec4(full[groups.order[k]], 0.f);
                p.disc.emplace(std::span<const glm::vec4>(grouped));
                p.groups.emplace(std::span<const std::uint32_t>(groups.begin));
                std::vector<glm::vec4> whole(full.size());
                for (std::size_t k = 0; k < full.size(); ++k) whole[k] = glm::vec4(full[k], 0.f);
                const std::uint32_t one_group[2] = {0u, std::uint32_t(full.size())};
                p.whole_disc.emplace(std::span<const glm::vec4>(whole));
                p.whole_group.emplace(std::span<const std::uint32_t>(one_group));
                p.disc_count = options_.count;
                p.disc_texels = texels;
            }
            p.target({shaded_out}, w, h);
            glEnable(GL_BLEND);
            glBlendEquation(GL_FUNC_ADD);
            glBlendFunc(GL_ONE, GL_ONE);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, p.disc->id());
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, p.groups->id());
            const program& prog = p.gather_rsm;
            passes::frame_uniforms(prog, w, h, pattern);
            prog.set(loc_weight_scale, scale);
            prog.set(loc_offset, options_.light.offset);
            prog.set(loc_min_distance2, options_.light.min_distance2);
            for (const auto& m : maps) {
                passes::textures({shaded.position_depth.id, shaded.normal.id, m.position.id, m.normal.id, m.flux.id});
                prog.set(loc_light_view_projection, m.light_view_projection);
                prog.set(loc_map_size, glm::vec2(float(m.width()), float(m.height())));
                p.fullscreen(prog);
            }
            glDisable(GL_BLEND);
        }
    } else {
        // VPLs from the read-back maps, selected as the CPU renderer selects them.
        std::vector<rsm_images> images;
        images.reserve(maps.size());
        for (const auto& m : maps) images.emplace_back(m);
        std::vector<rsm_view> views;
        for (const auto& im : images) views.push_back(im.view());
        const std::vector<vpl> all = select_vpls(views, options_);
        t.vpls = all.size();
        std::vector<glm::vec3> positions;
        if (options_.assignment == light_assignment::similarity)
            for (const auto& l : all) positions.push_back(l.position);
        const light_groups groups =
            assign_lights(all.size(), pattern.cells(), options_.assignment, positions, options_.shift);
        // Each VPL's rectangle in the split buffer (as cpu::splat_vpls: rsm_sampling.hpp's
        // vpl_splat_rect and split_buffer_rect), in group order.
        const glm::mat4 view = cam.view_matrix();
        splatted_.clear();
        std::vector<gpu_vpl> packed;
        std::vector<glm::vec4> rects;
        for (int s = 0; s < pattern.cells(); ++s) {
            const int i = s % pattern.n, j = s / pattern.n;
            const sub_buffer_rect sub = sub_buffer_of(pattern, i, j, w, h);
            for (std::uint32_t k = groups.begin[std::size_t(s)]; k < groups.begin[std::size_t(s) + 1]; ++k) {
                const vpl& l = all[groups.order[k]];
                const vpl scaled{l.position, l.normal, l.flux * scale};
                splatted_.push_back(scaled);
                const pixel_rect q = split_buffer_rect(
                    vpl_splat_rect(cam, view, l, all.size(), options_.sii_cutoff, options_.light.offset, w, h), pattern,
                    i, j, sub);
                if (q.empty()) continue;
                packed.push_back({glm::vec4(scaled.position, 0.f), glm::vec4(scaled.normal, 0.f),
                                  glm::vec4(scaled.flux, 0.f)});
                rects.emplace_back(float(q.x0), float(q.y0), float(q.x1), float(q.y1));
            }
        }
        if (!packed.empty()) {
            p.vpls.emplace(std::span<const gpu_vpl>(packed));
            p.rects.emplace(std::span<const glm::vec4>(rects));
            p.target({shaded_out}, w, h);
            glEnable(GL_BLEND);
            glBlendEquation(GL_FUNC_ADD);
            glBlendFunc(GL_ONE, GL_ONE);
            passes::textures({shaded.position_depth.id, shaded.normal.id});
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, p.vpls->id());
            const program& prog = p.splat;
            prog.set(loc_size, glm::vec2(float(w), float(h)));
            prog.set(loc_offset, options_.light.offset);
            prog.set(loc_min_distance2, options_.light.min_distance2);
            glUseProgram(prog.id());
            glVertexArrayVertexBuffer(p.rect_vao.id(), 0, p.rects->id(), 0, sizeof(glm::vec4));
            glBindVertexArray(p.rect_vao.id());
            glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, GLsizei(packed.size()));
            glDisable(GL_BLEND);
        }
    }
    check_error("indirect_renderer shade");
    t.shade_ms += lap(start);

    if (interleaved) {
        const object_id gathered = options_.blur ? p.gathered->id() : out;
        p.target({gathered}, w, h);
        passes::textures({p.split_out->id()});
        passes::frame_uniforms(p.gather, w, h, pattern);
        p.fullscreen(p.gather);
        check_error("indirect_renderer gather");
        t.gather_ms += lap(start);
        if (options_.blur) {
            p.target({p.edges->id()}, w, h);
            passes::textures({g.position_depth.id, g.normal.id});
            passes::frame_uniforms(p.discontinuity, w, h, pattern);
            p.discontinuity.set(loc_relative_depth, options_.discontinuity.relative_depth);
            p.discontinuity.set(loc_cos_normal, options_.discontinuity.cos_normal);
            p.fullscreen(p.discontinuity);

            p.ensure_tent(tent_radius(pattern));
            p.target({p.scratch->id()}, w, h);
            passes::textures({p.gathered->id(), p.edges->id(), g.position_depth.id});
            passes::frame_uniforms(*p.tent_x, w, h, pattern);
            p.tent_x->set(loc_pattern_width, float(pattern.n));
            p.fullscreen(*p.tent_x);

            p.target({out}, w, h);
            passes::textures({p.scratch->id(), p.edges->id(), g.position_depth.id});
            passes::frame_uniforms(*p.tent_y, w, h, pattern);
            p.tent_y->set(loc_pattern_width, float(pattern.m));
            p.fullscreen(*p.tent_y);
            check_error("indirect_renderer blur");
            t.blur_ms += lap(start);
        }
    }
}

}  // namespace bounce::gl
