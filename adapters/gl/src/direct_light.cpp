// Shadow-mapped direct lighting: depth maps rendered from each light with a slope-scaled
// bias, looked up with a normal offset and 16 hardware-compared PCF taps. The light models
// (direct_light.hpp) and the lookup arithmetic (shadow_mapping.hpp) are emitted kernels; the
// GLSL written here only declares uniforms, transforms by matrices, fetches and loops.
#include <bounce/gl/direct_light.hpp>
#include <bounce/glsl/emit.hpp>
#include <bounce/direct_light.hpp>
#include <bounce/shadow_mapping.hpp>

#include "box_corners.hpp"
#include "color_target.hpp"
#include "gbuffer_samplers.hpp"
#include "saved_state.hpp"
#include "vertex_shaders.hpp"

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <variant>

namespace bounce::gl {

namespace {

constexpr const char* shadow_vertex = R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 0) uniform mat4 light_view_projection;
out vec3 world_position;
void main() {
    world_position = position;
    gl_Position = light_view_projection * vec4(position, 1.0);
}
)";
// 2D maps: the rasterized window depth, biased by glPolygonOffset.
constexpr const char* window_depth_fragment = "#version 450 core\nvoid main() {}\n";

// Cube maps: the radial depth, biased by its own slope (glPolygonOffset does not apply to a
// depth the shader writes).
std::string radial_depth_fragment() {
    glsl::function_set k;
    k.add("radial_shadow_depth", radial_shadow_depth<glsl::f32, glsl::vec3>, "p", "light_position", "inv_far");
    k.add("slope_biased_depth", slope_biased_depth<glsl::f32>, "depth", "ddx", "ddy", "slope_bias", "constant_bias");
    return R"(#version 450 core
layout(location = 1) uniform vec3 light_position;
layout(location = 2) uniform float inv_far;
layout(location = 3) uniform float slope_bias;
layout(location = 4) uniform float constant_bias;
in vec3 world_position;

)" + k.source() + R"(
void main() {
    float depth = radial_shadow_depth(world_position, light_position, inv_far);
    gl_FragDepth = slope_biased_depth(depth, dFdx(depth), dFdy(depth), slope_bias, constant_bias);
}
)";
}

// An up vector not parallel to the unit view direction `d`.
glm::vec3 up_for(const glm::vec3& d) { return std::abs(d.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0); }

// Near and far planes of a map centred at `eye` that holds everything in the bounds: far is
// the farthest corner (with 1% to spare), near 1/1000 of it (float depth keeps about
// 6e-5 far of resolution at the far plane with that ratio).
std::pair<float, float> depth_range(const glm::vec3& eye, const glm::vec3& lo, const glm::vec3& hi) {
    const float far_depth = std::max(detail::farthest_corner_distance(eye, lo, hi) * 1.01f, 1e-3f);
    return {far_depth * 1e-3f, far_depth};
}

// Cube-map faces in GL order (+X, -X, +Y, -Y, +Z, -Z): view direction and the up vector that
// makes a rendered face read back with the orientation of the cube-map lookup (the face's
// s axis is the camera's right, t its up, per the OpenGL 4.5 spec, Table 8.19).
constexpr std::array<std::array<float, 6>, 6> cube_faces = {{{1, 0, 0, 0, -1, 0},
                                                            {-1, 0, 0, 0, -1, 0},
                                                            {0, 1, 0, 0, 0, 1},
                                                            {0, -1, 0, 0, 0, -1},
                                                            {0, 0, 1, 0, -1, 0},
                                                            {0, 0, -1, 0, -1, 0}}};

detail::object make_depth_texture(GLenum target, int resolution) {
    GLuint name = 0;
    glCreateTextures(target, 1, &name);
    detail::object owner(detail::object_kind::texture, name);
    glTextureStorage2D(name, 1, GL_DEPTH_COMPONENT32F, resolution, resolution);
    // Hardware comparison: texture() returns the bilinearly weighted fraction of the 2x2
    // texels whose depth passes ref <= stored (lit).
    glTextureParameteri(name, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(name, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(name, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(name, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTextureParameteri(name, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    glTextureParameteri(name, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTextureParameteri(name, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    check_error("shadow map allocation");
    return owner;
}

std::string indexed(const char* name, std::size_t i) { return std::string(name) + "[" + std::to_string(i) + "]"; }

}  // namespace

void direct_light_options::validate() const {
    require(shadow_resolution >= 16, "shadow_resolution", "must be at least 16 texels");
    require(std::isfinite(slope_bias) && slope_bias >= 0.f, "slope_bias", "must be a non-negative number");
    require(std::isfinite(constant_bias) && constant_bias >= 0.f, "constant_bias", "must be a non-negative number");
    require(std::isfinite(normal_offset_texels) && normal_offset_texels >= 0.f, "normal_offset_texels",
            "must be a non-negative number");
    require(std::isfinite(max_spot_map_cone_deg) && max_spot_map_cone_deg > 0.f && max_spot_map_cone_deg <= 80.f,
            "max_spot_map_cone_deg", "must lie in (0, 80]");
}

std::vector<direct_light::light_entry> direct_light::prepare(const scene_view& scene, const direct_light_options& options) {
    options.validate();
    GLint max_2d = 0, max_cube = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_2d);
    glGetIntegerv(GL_MAX_CUBE_MAP_TEXTURE_SIZE, &max_cube);
    const int res = options.shadow_resolution;
    auto [lo, hi] = scene.bounds();
    if (scene.positions.empty()) lo = hi = glm::vec3(0.f);
    validate_lights(scene.lights);
    std::vector<light_entry> lights;
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const std::string name = "scene.lights[" + std::to_string(i) + "]";
        const auto fail = [&](const char* what) { throw parameter_error(name, what); };
        light_entry l;
        l.light = pack(scene.lights[i]);
        const glm::vec3 position = l.light.position(), vector = l.light.direction();
        bool cube = false;
        if (l.light.kind() == light_kind::point) {
            cube = true;
        } else if (const auto* sl = std::get_if<spot_light>(&scene.lights[i])) {
            cube = sl->cone_deg > options.max_spot_map_cone_deg;
            if (!cube) {
                // The map covers the cone plus 3 texels for the PCF footprint (taps reach
                // 1.5 texels out, each bilinear over one more): tan' = tan(cone) + 3 * 2 tan' / res.
                l.map = map_kind::perspective;
                l.tan_half_fov = float(std::tan(glm::radians(double(sl->cone_deg))) / (1.0 - 6.0 / res));
                const auto [n, f] = depth_range(position, lo, hi);
                l.near_depth = n;
                l.far_depth = f;
                l.view_projection = glm::perspective(2.f * std::atan(l.tan_half_fov), 1.f, n, f) *
                                    glm::lookAt(position, position + vector, up_for(vector));
            }
        } else {
            l.map = map_kind::orthographic;
            // Seen from outside the scene's bounding sphere, the map spans the rectangle the
            // box's corners project to across the light (1% to spare, and 3 texels for the
            // PCF footprint as for spot maps). For a sun that is not along a diagonal this is
            // well inside the sphere's disc, so the texels are smaller (docs/hemisphere-sampling.md
            // measures it).
            const glm::vec3 centre = 0.5f * (lo + hi);
            const float r = std::max(0.505f * glm::length(hi - lo), 1e-3f);
            const glm::mat4 view = glm::lookAt(centre - 2.f * r * vector, centre, up_for(vector));
            glm::vec2 half_extent(0.f);  // of the corners in the view's x and y, around the centre's
            const glm::vec2 middle(view * glm::vec4(centre, 1.f));
            for (int c = 0; c < 8; ++c)
                half_extent = glm::max(half_extent,
                                       glm::abs(glm::vec2(view * glm::vec4(detail::box_corner(lo, hi, c), 1.f)) - middle));
            half_extent = glm::max(1.01f * half_extent, glm::vec2(1e-3f)) / (1.f - 6.f / float(res));
            l.near_depth = 0.5f * r;
            l.far_depth = 3.5f * r;
            l.texel_world = 2.f * std::max(half_extent.x, half_extent.y) / float(res);  // the longer side
            l.view_projection = glm::ortho(middle.x - half_extent.x, middle.x + half_extent.x, middle.y - half_extent.y,
                                           middle.y + half_extent.y, l.near_depth, l.far_depth) *
                                view;
        }
        if (cube) {
            if (res > max_cube) fail("shadow_resolution exceeds GL_MAX_CUBE_MAP_TEXTURE_SIZE");
            l.map = map_kind::cube;
            const auto [n, f] = depth_range(position, lo, hi);
            l.near_depth = n;
            l.far_depth = f;
            const glm::mat4 projection = glm::perspective(glm::radians(90.f), 1.f, n, f);
            for (std::size_t face = 0; face < 6; ++face) {
                const auto& c = cube_faces[face];
                l.face_view_projection[face] =
                    projection * glm::lookAt(position, position + glm::vec3(c[0], c[1], c[2]), glm::vec3(c[3], c[4], c[5]));
            }
            l.depth = make_depth_texture(GL_TEXTURE_CUBE_MAP, res);
        } else {
            if (res > max_2d) fail("shadow_resolution exceeds GL_MAX_TEXTURE_SIZE");
            l.depth = make_depth_texture(GL_TEXTURE_2D, res);
        }
        lights.push_back(std::move(l));
    }
    return lights;
}

direct_light::direct_light(const scene_view& scene, const scene_mesh& mesh, int shadow_resolution)
    : direct_light(scene, mesh, [&] {
          direct_light_options o;
          o.shadow_resolution = shadow_resolution;
          return o;
      }()) {}

namespace {

// The built-in drawer: the mesh's vertex array, one indexed draw.
shadow_drawer mesh_drawer(const scene_mesh& mesh) {
    return [&mesh](const shadow_draw&) {
        if (mesh.triangle_count() == 0) return;
        glBindVertexArray(mesh.vertices().id());
        glDrawElements(GL_TRIANGLES, GLsizei(3 * mesh.triangle_count()), GL_UNSIGNED_INT, nullptr);
    };
}

shadow_drawer checked_drawer(shadow_drawer draw) {
    require(bool(draw), "draw", "an empty shadow_drawer draws nothing: pass a callable");
    return draw;
}

}  // namespace

direct_light::direct_light(const scene_view& scene, const scene_mesh& mesh, const direct_light_options& options)
    : direct_light(scene, mesh_drawer(mesh), options) {}

direct_light::direct_light(const scene_view& scene, shadow_drawer draw, const direct_light_options& options)
    : draw_(checked_drawer(std::move(draw))), options_(options), lights_(prepare(scene, options)),
      window_depth_program_(shadow_vertex, window_depth_fragment), radial_depth_program_(shadow_vertex, radial_depth_fragment()),
      radiance_program_(detail::fullscreen_vertex, radiance_fragment_source()) {
    glNamedFramebufferDrawBuffer(shadow_fbo_.id(), GL_NONE);
    glNamedFramebufferReadBuffer(shadow_fbo_.id(), GL_NONE);
    render_shadow_maps();
}

void direct_light::render_shadow_maps() {
    const detail::raster_state raster;
    const detail::blend_offset_state offset;
    const detail::program_and_storage_state bindings({});
    const GLsizei res = options_.shadow_resolution;
    // Slope-scaled depth bias: each stored depth is pushed away from the light by
    // slope_bias x its depth slope plus constant_bias x the smallest depth step (2D maps by
    // glPolygonOffset, cube maps by the radial-depth shader itself).
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(options_.slope_bias, options_.constant_bias);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, shadow_fbo_.id());
    glViewport(0, 0, res, res);
    const float far_depth = 1.f;
    // The depth attachment is detached again however the callback leaves (an exception included).
    struct detach {
        GLuint fbo;
        ~detach() { glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, 0, 0); }
    } const detached{shadow_fbo_.id()};
    const auto draw = [&](const program& prog, const shadow_draw& d) {
        const GLenum status = glCheckNamedFramebufferStatus(shadow_fbo_.id(), GL_DRAW_FRAMEBUFFER);
        if (status != GL_FRAMEBUFFER_COMPLETE) throw gl_error("bounce::gl: shadow-map framebuffer is not complete");
        glClearNamedFramebufferfv(shadow_fbo_.id(), GL_DEPTH, 0, &far_depth);
        glUseProgram(prog.id());
        prog.set(0, d.view_projection);
        draw_(d);
    };
    for (std::size_t i = 0; i < lights_.size(); ++i) {
        const light_entry& l = lights_[i];
        if (l.map == map_kind::cube) {
            radial_depth_program_.set(1, l.light.position());
            radial_depth_program_.set(2, 1.f / l.far_depth);
            radial_depth_program_.set(3, options_.slope_bias);
            radial_depth_program_.set(4, options_.constant_bias);
            for (GLint face = 0; face < 6; ++face) {
                glNamedFramebufferTextureLayer(shadow_fbo_.id(), GL_DEPTH_ATTACHMENT, l.depth.id(), 0, face);
                draw(radial_depth_program_, {i, face, l.face_view_projection[std::size_t(face)]});
            }
        } else {
            glNamedFramebufferTexture(shadow_fbo_.id(), GL_DEPTH_ATTACHMENT, l.depth.id(), 0);
            draw(window_depth_program_, {i, -1, l.view_projection});
        }
    }
    check_error("direct_light::render_shadow_maps");
}

std::string direct_light::glsl_source() const {
    const std::size_t n = lights_.size();
    std::string s = "// bounce::gl::direct_light: shadowed direct irradiance of " + std::to_string(n) + " light(s)\n";
    if (n == 0) return s + "vec3 direct_irradiance(vec3 p, vec3 n) { return vec3(0.0); }\n";
    const std::string N = std::to_string(n);
    s += "uniform float bounce_dl_inv_resolution;\n"
         "uniform float bounce_dl_normal_offset;\n"
         "uniform vec3 bounce_dl_position[" + N + "];\n"
         "uniform vec3 bounce_dl_vector[" + N + "];\n"
         "uniform vec3 bounce_dl_intensity[" + N + "];\n"
         "uniform float bounce_dl_cos_cone[" + N + "];\n"
         "uniform float bounce_dl_falloff[" + N + "];\n"
         "uniform mat4 bounce_dl_matrix[" + N + "];\n"
         "uniform float bounce_dl_tan_half_fov[" + N + "];\n"
         "uniform float bounce_dl_texel[" + N + "];\n"
         "uniform float bounce_dl_inv_far[" + N + "];\n";
    for (std::size_t i = 0; i < n; ++i)
        s += std::string("uniform ") + (lights_[i].map == map_kind::cube ? "samplerCubeShadow" : "sampler2DShadow") +
             " bounce_dl_map_" + std::to_string(i) + ";\n";

    glsl::function_set k;
    k.add("bounce_dl_point_light_irradiance", point_light_irradiance<glsl::f32, glsl::vec3>, "p", "n", "light_position",
          "intensity");
    k.add("bounce_dl_spot_light_irradiance", spot_light_irradiance<glsl::f32, glsl::vec3>, "p", "n", "light_position",
          "axis", "intensity", "cos_cone", "cosine_falloff");
    k.add("bounce_dl_directional_light_irradiance", directional_light_irradiance<glsl::f32, glsl::vec3>, "n", "direction",
          "irradiance");
    k.add("bounce_dl_normal_offset_point", normal_offset_point<glsl::f32, glsl::vec3>, "p", "n", "texel",
          "offset_texels");
    k.add("bounce_dl_perspective_shadow_texel", perspective_shadow_texel<glsl::f32, glsl::vec3>, "p", "light_position",
          "axis", "tan_half_fov", "inv_resolution");
    k.add("bounce_dl_cube_shadow_texel", cube_shadow_texel<glsl::f32, glsl::vec3>, "p", "light_position",
          "inv_resolution");
    k.add("bounce_dl_shadow_map_taps", shadow_map_taps<glsl::f32, glsl::vec3>, "clip", "clip_w", "inv_resolution", "taps");
    k.add("bounce_dl_cube_shadow_taps", cube_shadow_taps<glsl::f32, glsl::vec3>, "d", "inv_far", "inv_resolution",
          "directions", "depths");
    k.add("bounce_dl_pcf_visibility", pcf_visibility<glsl::f32>, "lit");
    s += "\n" + k.source() + "\n";

    std::string sum = "vec3(0.0)";
    for (std::size_t i = 0; i < n; ++i) {
        const auto& l = lights_[i];
        const std::string I = std::to_string(i), at = "[" + I + "]";
        std::string e;
        if (l.light.kind() == light_kind::point)
            e = "bounce_dl_point_light_irradiance(p, n, bounce_dl_position" + at + ", bounce_dl_intensity" + at + ")";
        else if (l.light.kind() == light_kind::spot)
            e = "bounce_dl_spot_light_irradiance(p, n, bounce_dl_position" + at + ", bounce_dl_vector" + at +
                ", bounce_dl_intensity" + at + ", bounce_dl_cos_cone" + at + ", bounce_dl_falloff" + at + ")";
        else
            e = "bounce_dl_directional_light_irradiance(n, bounce_dl_vector" + at + ", bounce_dl_intensity" + at + ")";
        s += "vec3 bounce_dl_light_" + I + "(vec3 p, vec3 n) {\n    vec3 e = " + e + ";\n";
        if (l.map == map_kind::cube) {
            s += "    vec3 q = bounce_dl_normal_offset_point(p, n, bounce_dl_cube_shadow_texel(p, bounce_dl_position" + at +
                 ", bounce_dl_inv_resolution), bounce_dl_normal_offset);\n"
                 "    vec3 directions[16];\n    float depths[16];\n"
                 "    bounce_dl_cube_shadow_taps(q - bounce_dl_position" + at + ", bounce_dl_inv_far" + at +
                 ", bounce_dl_inv_resolution, directions, depths);\n"
                 "    float lit[16];\n"
                 "    for (int t = 0; t < 16; ++t) lit[t] = texture(bounce_dl_map_" + I + ", vec4(directions[t], depths[t]));\n";
        } else {
            const std::string texel =
                l.map == map_kind::perspective
                    ? "bounce_dl_perspective_shadow_texel(p, bounce_dl_position" + at + ", bounce_dl_vector" + at +
                          ", bounce_dl_tan_half_fov" + at + ", bounce_dl_inv_resolution)"
                    : "bounce_dl_texel" + at;
            s += "    vec3 q = bounce_dl_normal_offset_point(p, n, " + texel + ", bounce_dl_normal_offset);\n"
                 "    vec4 clip = bounce_dl_matrix" + at + " * vec4(q, 1.0);\n"
                 "    vec3 taps[16];\n"
                 "    bounce_dl_shadow_map_taps(clip.xyz, clip.w, bounce_dl_inv_resolution, taps);\n"
                 "    float lit[16];\n"
                 "    for (int t = 0; t < 16; ++t) lit[t] = texture(bounce_dl_map_" + I + ", taps[t]);\n";
        }
        s += "    return e * bounce_dl_pcf_visibility(lit);\n}\n\n";
        sum += " + bounce_dl_light_" + I + "(p, n)";
    }
    s += "vec3 direct_irradiance(vec3 p, vec3 n) {\n    return " + sum + ";\n}\n";
    return s;
}

void direct_light::bind(const program& p, unsigned first_texture_unit) const {
    GLint max_units = 0;
    glGetIntegerv(GL_MAX_COMBINED_TEXTURE_IMAGE_UNITS, &max_units);
    if (std::size_t(first_texture_unit) + lights_.size() > std::size_t(max_units))
        throw gl_error("bounce::gl: direct_light needs texture units " + std::to_string(first_texture_unit) + " to " +
                       std::to_string(first_texture_unit + lights_.size()) +
                       ", beyond GL_MAX_COMBINED_TEXTURE_IMAGE_UNITS = " + std::to_string(max_units));
    const GLuint id = p.id();
    const auto loc = [&](const std::string& name) { return glGetUniformLocation(id, name.c_str()); };
    // Inactive uniforms (the program does not call direct_irradiance) have location -1,
    // which glProgramUniform ignores.
    glProgramUniform1f(id, loc("bounce_dl_inv_resolution"), 1.f / float(options_.shadow_resolution));
    glProgramUniform1f(id, loc("bounce_dl_normal_offset"), options_.normal_offset_texels);
    for (std::size_t i = 0; i < lights_.size(); ++i) {
        const auto& l = lights_[i];
        const glm::vec3 position = l.light.position(), vector = l.light.direction(), intensity = l.light.intensity();
        glProgramUniform3fv(id, loc(indexed("bounce_dl_position", i)), 1, glm::value_ptr(position));
        glProgramUniform3fv(id, loc(indexed("bounce_dl_vector", i)), 1, glm::value_ptr(vector));
        glProgramUniform3fv(id, loc(indexed("bounce_dl_intensity", i)), 1, glm::value_ptr(intensity));
        glProgramUniform1f(id, loc(indexed("bounce_dl_cos_cone", i)), l.light.cos_cone());
        glProgramUniform1f(id, loc(indexed("bounce_dl_falloff", i)), l.light.cosine_falloff());
        glProgramUniformMatrix4fv(id, loc(indexed("bounce_dl_matrix", i)), 1, GL_FALSE, glm::value_ptr(l.view_projection));
        glProgramUniform1f(id, loc(indexed("bounce_dl_tan_half_fov", i)), l.tan_half_fov);
        glProgramUniform1f(id, loc(indexed("bounce_dl_texel", i)), l.texel_world);
        glProgramUniform1f(id, loc(indexed("bounce_dl_inv_far", i)), 1.f / l.far_depth);
        const GLuint unit = first_texture_unit + GLuint(i);
        glProgramUniform1i(id, loc("bounce_dl_map_" + std::to_string(i)), GLint(unit));
        glBindTextureUnit(unit, l.depth.id());
        glBindSampler(unit, 0);
    }
    check_error("direct_light::bind");
}

std::string direct_light::radiance_fragment_source() const {
    glsl::function_set k;
    k.add("lambertian_radiance", lambertian_radiance<glsl::f32, glsl::vec3>, "albedo", "irradiance");
    return "#version 450 core\n" + detail::gbuffer_position_normal_samplers() + detail::gbuffer_albedo_sampler() +
           "layout(location = 0) out vec4 radiance;\n\n" + glsl_source() + "\n" + k.source() + detail::gbuffer_covered +
           R"(
void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 position_depth = texelFetch(gbuffer_position_depth, pixel, 0);
    // No geometry here, no light either.
    if (!covered(position_depth.w)) {
        radiance = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    vec3 e = direct_irradiance(position_depth.xyz, texelFetch(gbuffer_normal, pixel, 0).xyz);
    radiance = vec4(lambertian_radiance(texelFetch(gbuffer_albedo, pixel, 0).rgb, e), 1.0);
}
)";
}

void direct_light::render(const gbuffer_textures& g) {
    g.validate();
    const std::size_t w = g.width(), h = g.height();
    detail::ensure_color_target(radiance_, radiance_fbo_, w, h);
    const detail::raster_state raster;
    const detail::blend_offset_state blend;
    const detail::program_and_storage_state bindings({});
    const detail::texture_unit_state units(0, GLuint(3 + lights_.size()));
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, radiance_fbo_.id());
    glViewport(0, 0, GLsizei(w), GLsizei(h));
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    // PCF taps near a cube face edge filter across it.
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    glUseProgram(radiance_program_.id());
    glBindVertexArray(empty_vao_.id());
    detail::bind_gbuffer_textures(g);
    bind(radiance_program_, 3);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    check_error("direct_light::render");
}

const texture& direct_light::radiance() const {
    require(radiance_.has_value(), "direct_light", "nothing rendered yet");
    return *radiance_;
}

void direct_light::read(image_view<glm::vec3> out) const { read_texture(radiance(), out); }

}  // namespace bounce::gl
