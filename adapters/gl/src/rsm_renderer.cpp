// Reflective shadow maps by rasterization (Dachsbacher and Stamminger 2005, section 3.1):
// the scene drawn once per map into three RGBA32F targets, by the caller's rsm_drawer or
// by the built-in one (one indexed draw of a scene_mesh). The shaders are
// plumbing (transform, interpolate, fetch Kd and the texel's solid angle, write); the
// facing normal and the reflected flux are the kernels of surface.hpp and indirect/rsm.hpp, emitted.
#include <bounce/gl/rsm_renderer.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/glsl/emit.hpp>
#include <bounce/camera.hpp>
#include <bounce/indirect/rsm.hpp>
#include <bounce/indirect/rsm_layout.hpp>
#include <bounce/surface.hpp>

#include "box_corners.hpp"
#include "mesh_draw.hpp"
#include "saved_state.hpp"
#include "vertex_shaders.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <variant>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace bounce::gl {

// ---- rsm_renderer -----------------------------------------------------------------------

namespace {

std::string fragment_source() {
    glsl::function_set k;
    k.add("facing_normal", facing_normal<glsl::f32, glsl::vec3>, "n", "p", "eye");
    k.add("point_light_texel_flux", point_light_texel_flux<glsl::f32, glsl::vec3>, "albedo", "p", "n",
          "light_position", "intensity", "solid_angle");
    k.add("spot_light_texel_flux", spot_light_texel_flux<glsl::f32, glsl::vec3>, "albedo", "p", "n", "light_position",
          "axis", "intensity", "cos_cone", "cosine_falloff", "solid_angle");
    k.add("directional_light_texel_flux", directional_light_texel_flux<glsl::f32, glsl::vec3>, "albedo", "n",
          "direction", "irradiance", "texel_area");
    return "#version 450 core\n" + detail::mesh_albedo_block() + R"(layout(binding = 0) uniform sampler2D texel_solid_angle;
layout(location = 1) uniform vec3 light_position;
layout(location = 2) uniform vec3 light_direction;
layout(location = 3) uniform vec3 light_intensity;
layout(location = 4) uniform float cos_cone;
layout(location = 5) uniform float cosine_falloff;
layout(location = 6) uniform int kind;
layout(location = 7) uniform float texel_area;
layout(location = 8) uniform uint first_triangle;
)" + detail::mesh_varyings + R"(layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out vec4 out_flux;

)" + k.source() + R"(
void main() {
    vec3 albedo = kd[first_triangle + uint(gl_PrimitiveID)].rgb;
    // The normal faces the light: its position, or for a distant light a point up the beam.
    vec3 eye = kind == 2 ? world_position - light_direction : light_position;
    vec3 n = facing_normal(world_normal, world_position, eye);
    vec3 flux;
    if (kind == 0) {
        flux = point_light_texel_flux(albedo, world_position, n, light_position, light_intensity,
                                      texelFetch(texel_solid_angle, ivec2(gl_FragCoord.xy), 0).r);
    } else if (kind == 1) {
        flux = spot_light_texel_flux(albedo, world_position, n, light_position, light_direction, light_intensity,
                                     cos_cone, cosine_falloff, texelFetch(texel_solid_angle, ivec2(gl_FragCoord.xy), 0).r);
    } else {
        flux = directional_light_texel_flux(albedo, n, light_direction, light_intensity, texel_area);
    }
    out_position = vec4(world_position, 0.0);
    out_normal = vec4(n, 0.0);
    out_flux = vec4(flux, 0.0);
}
)";
}

enum location : int {
    loc_view_projection = 0,
    loc_light_position = 1,
    loc_light_direction = 2,
    loc_light_intensity = 3,
    loc_cos_cone = 4,
    loc_cosine_falloff = 5,
    loc_kind = 6,
    loc_texel_area = 7,
    loc_first_triangle = 8,
};


// The built-in drawer: the mesh's vertex array and per-triangle albedo, one indexed draw.
rsm_drawer mesh_drawer(const scene_mesh& mesh) {
    return [&mesh](const rsm_draw&) { detail::draw_mesh(mesh); };
}

rsm_drawer checked_drawer(rsm_drawer draw) {
    require(bool(draw), "draw", "an empty rsm_drawer draws nothing: pass a callable");
    return draw;
}

}  // namespace

void rsm_draw::set_first_triangle(std::uint32_t first) const {
    glProgramUniform1ui(program, loc_first_triangle, first);
}

rsm_renderer::rsm_renderer(const scene_view& scene, const scene_mesh& mesh, const rsm_render_options& options)
    : rsm_renderer(scene, mesh_drawer(mesh), options) {}

rsm_renderer::rsm_renderer(const scene_view& scene, rsm_drawer draw, const rsm_render_options& options)
    : scene_(scene), draw_(checked_drawer(std::move(draw))), options_(options), program_(detail::mesh_vertex, fragment_source()) {
    options_.validate();
}

std::vector<rsm_map_layout> rsm_renderer::layout(std::span<const light> lights) const {
    const auto [lo, hi] = scene_.bounds();
    return rsm_layout(lights, lo, hi, options_);
}

const texture& rsm_renderer::solid_angles(float fov_deg) {
    auto it = solid_angles_.find(fov_deg);
    if (it != solid_angles_.end()) return it->second;
    const std::size_t r = options_.resolution;
    const double t = std::tan(glm::radians(double(fov_deg)) * 0.5);
    // Texel (x, y), row y from the top, as embree::rsm_ray_caster computes it (the shared
    // rsm_texel_solid_angle); stored in GL row order.
    std::vector<float> dw(r * r);
    for (std::size_t y = 0; y < r; ++y)
        for (std::size_t x = 0; x < r; ++x) dw[(r - 1 - y) * r + x] = float(rsm_texel_solid_angle(t, r, x, y));
    texture table(texel_format::r32f, r, r);
    {
        const detail::unpack_state unpack;
        glTextureSubImage2D(table.id(), 0, 0, 0, GLsizei(r), GLsizei(r), GL_RED, GL_FLOAT, dw.data());
        check_error("rsm_renderer solid-angle table");
    }
    return solid_angles_.emplace(fov_deg, std::move(table)).first->second;
}

void rsm_renderer::render(std::span<const light> lights, std::span<rsm_textures> targets) {
    const auto maps = layout(lights);
    if (targets.size() != maps.size())
        throw parameter_error("targets", "must hold one map per entry of layout(lights) (" +
                                             std::to_string(maps.size()) + ")");
    const std::size_t r = options_.resolution;
    for (const auto& t : targets) {
        t.validate("targets");
        require(t.width() == r && t.height() == r, "targets", "maps must be resolution x resolution texels");
    }
    if (!depth_ || depth_->width() != r) {
        depth_.emplace(texel_format::depth32f, r, r);
        fbo_.attach_depth(*depth_);
    }
    for (std::size_t k = 0; k < maps.size(); ++k) {
        targets[k].light_view_projection = maps[k].light_view_projection;
        render_map(maps[k], pack(lights[maps[k].light]), targets[k]);
    }
}

void rsm_renderer::render(std::span<const light> lights) {
    const std::size_t count = layout(lights).size();
    const std::size_t r = options_.resolution;
    if (owned_.size() != count || (!owned_.empty() && owned_[0].flux.width() != r)) {
        owned_.clear();
        for (std::size_t k = 0; k < count; ++k)
            owned_.push_back({texture(texel_format::rgba32f, r, r), texture(texel_format::rgba32f, r, r),
                              texture(texel_format::rgba32f, r, r)});
    }
    refs_.clear();
    for (const auto& o : owned_) refs_.push_back({o.position, o.normal, o.flux, glm::mat4(1.f)});
    render(lights, std::span<rsm_textures>(refs_));
}

void rsm_renderer::render_map(const rsm_map_layout& m, const packed_light& l, const rsm_textures& target) {
    const std::size_t r = options_.resolution;
    glm::mat4 raster = m.light_view_projection;
    if (!m.orthographic) {
        // Same x, y and w rows as the map's matrix (they do not depend on the depth range);
        // near and far from the scene bounds, so no geometry beyond the camera's default far
        // plane is lost.
        auto [lo, hi] = scene_.bounds();
        // No absolute floor beyond what keeps the planes apart in float (a scene within a
        // millimetre of the light had its depth range stretched to 1e-3 units before).
        const float far_depth = std::max(detail::farthest_corner_distance(m.position, lo, hi) * 1.01f, 1e-15f);
        raster = glm::perspective(glm::radians(m.fov_deg), 1.f, far_depth * 1e-4f, far_depth) * m.view;
    }
    const float texel_area = m.orthographic ? m.texel_size * m.texel_size : 0.f;

    const detail::raster_state raster_saved;
    const detail::blend_offset_state blend;
    const detail::program_and_storage_state bindings({0u});
    const detail::texture_unit_state units(0, 1);
    glNamedFramebufferTexture(fbo_.id(), GL_COLOR_ATTACHMENT0, target.position.id, 0);
    glNamedFramebufferTexture(fbo_.id(), GL_COLOR_ATTACHMENT1, target.normal.id, 0);
    glNamedFramebufferTexture(fbo_.id(), GL_COLOR_ATTACHMENT2, target.flux.id, 0);
    fbo_.set_draw_buffers(3);
    fbo_.check_complete();
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, GLsizei(r), GLsizei(r));
    const float zero[4] = {0.f, 0.f, 0.f, 0.f};
    const float away[4] = {-m.forward.x, -m.forward.y, -m.forward.z, 0.f};
    const float far_depth = 1.f;
    glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, 0, zero);
    glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, 1, away);
    glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, 2, zero);
    glClearNamedFramebufferfv(fbo_.id(), GL_DEPTH, 0, &far_depth);
    program_.set(loc_view_projection, raster);
    program_.set(loc_light_position, l.position());
    program_.set(loc_light_direction, l.direction());
    program_.set(loc_light_intensity, l.intensity());
    program_.set(loc_cos_cone, l.cos_cone());
    program_.set(loc_cosine_falloff, l.cosine_falloff());
    program_.set(loc_kind, int(l.kind()));
    program_.set(loc_texel_area, texel_area);
    const rsm_draw d{m, raster, program_.id()};
    d.set_first_triangle(0);
    glUseProgram(program_.id());
    glBindTextureUnit(0, m.orthographic ? 0 : solid_angles(m.fov_deg).id());
    glBindSampler(0, 0);
    // The targets are detached again however the callback leaves (an exception included).
    struct detach {
        GLuint fbo;
        ~detach() {
            for (GLenum a : {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2})
                glNamedFramebufferTexture(fbo, a, 0, 0);
        }
    } const detached{fbo_.id()};
    draw_(d);
    check_error("rsm_renderer::render");
}

}  // namespace bounce::gl
