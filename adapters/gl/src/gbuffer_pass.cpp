// The raster G-buffer: one indexed draw of the scene into three RGBA32F targets. The
// shaders are plumbing (transform, interpolate, fetch Kd, write); the normal and the depth
// are the surface.hpp kernels, emitted.
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/glsl/emit.hpp>
#include <bounce/surface.hpp>

#include "mesh_draw.hpp"
#include "saved_state.hpp"
#include "vertex_shaders.hpp"

#include <glm/geometric.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace bounce::gl {

namespace {

std::string fragment_shader() {
    glsl::function_set kernels;
    kernels.add("facing_normal", facing_normal<glsl::f32, glsl::vec3>, "n", "p", "eye");
    kernels.add("view_depth", view_depth<glsl::f32, glsl::vec3>, "p", "eye", "forward");
    return "#version 450 core\n" + detail::mesh_albedo_block() + R"(layout(location = 1) uniform vec3 camera_position;
layout(location = 2) uniform vec3 camera_forward;
)" + detail::mesh_varyings + R"(layout(location = 0) out vec4 out_position_depth;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out vec4 out_albedo;

)" + kernels.source() +
           R"(
void main() {
    out_position_depth = vec4(world_position, view_depth(world_position, camera_position, camera_forward));
    out_normal = vec4(facing_normal(world_normal, world_position, camera_position), 0.0);
    out_albedo = vec4(kd[gl_PrimitiveID].rgb, 1.0);
}
)";
}

}  // namespace

// ---- scene_mesh -------------------------------------------------------------------------

scene_mesh::scene_mesh(const scene_view& s)
    : albedo_(std::max<std::size_t>(s.triangles.size(), 1) * sizeof(glm::vec4)), triangles_(s.triangles.size()) {
    s.validate_mesh();
    std::vector<glm::vec4> kd(s.triangles.size());
    for (std::size_t t = 0; t < s.triangles.size(); ++t) kd[t] = glm::vec4(s.materials[s.material_of[t]].albedo, 0.f);
    if (triangles_ == 0) return;
    if (!s.normals.empty()) {
        positions_.emplace(s.positions);
        normals_.emplace(s.normals);
        indices_.emplace(s.triangles);
    } else {
        // Without vertex normals every triangle is shaded with its own plane's normal: three
        // vertices of its own each (a degenerate triangle gets 0, which the kernels treat as
        // "faces nothing" and the rasterizer never covers anyway).
        std::vector<glm::vec3> flat_positions, flat_normals;
        std::vector<glm::uvec3> flat_triangles;
        flat_positions.reserve(3 * triangles_);
        flat_normals.reserve(3 * triangles_);
        flat_triangles.reserve(triangles_);
        for (std::size_t t = 0; t < triangles_; ++t) {
            const glm::uvec3 tri = s.triangles[t];
            const glm::vec3 p0 = s.positions[tri.x], p1 = s.positions[tri.y], p2 = s.positions[tri.z];
            const glm::vec3 c = glm::cross(p1 - p0, p2 - p0);
            const float len = glm::length(c);
            const glm::vec3 n = len > 0.f && std::isfinite(len) ? c / len : glm::vec3(0.f);
            const auto first = std::uint32_t(flat_positions.size());
            for (const glm::vec3& p : {p0, p1, p2}) {
                flat_positions.push_back(p);
                flat_normals.push_back(n);
            }
            flat_triangles.emplace_back(first, first + 1, first + 2);
        }
        positions_.emplace(std::span<const glm::vec3>(flat_positions));
        normals_.emplace(std::span<const glm::vec3>(flat_normals));
        indices_.emplace(std::span<const glm::uvec3>(flat_triangles));
    }
    albedo_.write(0, kd.data(), kd.size() * sizeof(glm::vec4));

    const GLuint vao = vao_.id();
    glVertexArrayVertexBuffer(vao, 0, positions_->id(), 0, sizeof(glm::vec3));
    glVertexArrayVertexBuffer(vao, 1, normals_->id(), 0, sizeof(glm::vec3));
    for (GLuint a = 0; a < 2; ++a) {
        glVertexArrayAttribFormat(vao, a, 3, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribBinding(vao, a, a);
        glEnableVertexArrayAttrib(vao, a);
    }
    glVertexArrayElementBuffer(vao, indices_->id());
    check_error("scene_mesh upload");
}

// ---- gbuffer_pass -----------------------------------------------------------------------

gbuffer_pass::gbuffer_pass()
    : vertex_source_(detail::mesh_vertex), fragment_source_(fragment_shader()), program_(vertex_source_, fragment_source_) {}

void gbuffer_pass::render(const scene_mesh& mesh, const camera& cam, std::size_t width, std::size_t height) {
    require(width > 0 && height > 0, "width/height", "the G-buffer must have a positive size");
    cam.validate();
    GLint max_viewport[2] = {0, 0};
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, max_viewport);
    if (width > std::size_t(max_viewport[0]) || height > std::size_t(max_viewport[1]))
        throw gl_error("bounce::gl: G-buffer of " + std::to_string(width) + " x " + std::to_string(height) +
                       " exceeds GL_MAX_VIEWPORT_DIMS");
    if (!targets_ || width != width_ || height != height_) {
        targets_.reset();
        targets_.emplace(targets{texture(texel_format::rgba32f, width, height), texture(texel_format::rgba32f, width, height),
                                 texture(texel_format::rgba32f, width, height), texture(texel_format::depth32f, width, height),
                                 framebuffer()});
        auto& t = *targets_;
        t.fbo.attach_color(0, t.position_depth);
        t.fbo.attach_color(1, t.normal);
        t.fbo.attach_color(2, t.albedo);
        t.fbo.attach_depth(t.depth);
        t.fbo.set_draw_buffers(3);
        t.fbo.check_complete();
        width_ = width;
        height_ = height;
    }
    const auto& t = *targets_;
    const detail::raster_state raster;
    const detail::program_and_storage_state bindings({0u});

    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, t.fbo.id());
    glViewport(0, 0, GLsizei(width), GLsizei(height));
    const float background_position[4] = {0.f, 0.f, 0.f, std::numeric_limits<float>::infinity()};
    const float zero[4] = {0.f, 0.f, 0.f, 0.f};
    const float far_depth = 1.f;
    glClearNamedFramebufferfv(t.fbo.id(), GL_COLOR, 0, background_position);
    glClearNamedFramebufferfv(t.fbo.id(), GL_COLOR, 1, zero);
    glClearNamedFramebufferfv(t.fbo.id(), GL_COLOR, 2, zero);
    glClearNamedFramebufferfv(t.fbo.id(), GL_DEPTH, 0, &far_depth);

    program_.set(0, cam.projection_matrix(width, height) * cam.view_matrix());
    program_.set(1, cam.position);
    program_.set(2, cam.forward());
    glUseProgram(program_.id());
    detail::draw_mesh(mesh);
    check_error("gbuffer_pass::render");
}

const texture& gbuffer_pass::position_depth() const {
    require(targets_.has_value(), "gbuffer_pass", "nothing rendered yet");
    return targets_->position_depth;
}
const texture& gbuffer_pass::normal() const {
    require(targets_.has_value(), "gbuffer_pass", "nothing rendered yet");
    return targets_->normal;
}
const texture& gbuffer_pass::albedo() const {
    require(targets_.has_value(), "gbuffer_pass", "nothing rendered yet");
    return targets_->albedo;
}

void gbuffer_pass::read(gbuffer_view<float> out) const {
    require(targets_.has_value(), "gbuffer_pass", "nothing rendered yet");
    const auto same_size = [&](std::size_t w, std::size_t h) { return w == width_ && h == height_; };
    require(same_size(out.position.width(), out.position.height()) && same_size(out.normal.width(), out.normal.height()) &&
                same_size(out.albedo.width(), out.albedo.height()) && same_size(out.depth.width(), out.depth.height()),
            "out", "G-buffer views differ in size from the rendering");
    const auto p = targets_->position_depth.read_floats(), n = targets_->normal.read_floats(),
               a = targets_->albedo.read_floats();
    for (std::size_t y = 0; y < height_; ++y) {
        const std::size_t gl_row = height_ - 1 - y;  // GL's row 0 is the bottom
        for (std::size_t x = 0; x < width_; ++x) {
            const std::size_t i = 4 * (gl_row * width_ + x);
            out.position(x, y) = {p[i], p[i + 1], p[i + 2]};
            out.depth(x, y) = p[i + 3];
            out.normal(x, y) = {n[i], n[i + 1], n[i + 2]};
            out.albedo(x, y) = {a[i], a[i + 1], a[i + 2]};
        }
    }
}

gbuffer<float> gbuffer_pass::read() const {
    require(targets_.has_value(), "gbuffer_pass", "nothing rendered yet");
    gbuffer<float> g(width_, height_);
    read(g.view());
    return g;
}

}  // namespace bounce::gl
