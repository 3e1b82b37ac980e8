// Irradiance splatting on OpenGL: instanced quads on the exact screen box of each record's
// sphere of influence, the emitted splat contribution per covered pixel, float blending.
// The shaders are plumbing (buffer and texture fetches, the view transform of the record
// centre, placing the quad corners, discarding, writing); the weighting, the box, the
// extrapolation and the normalization are the kernels of include/bounce/, emitted.
#include <bounce/cache/record_std430.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/glsl/emit.hpp>
#include <bounce/splat_bounds.hpp>

#include "color_target.hpp"
#include "gbuffer_samplers.hpp"
#include "saved_state.hpp"
#include "vertex_shaders.hpp"

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <initializer_list>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace bounce::gl {

namespace {

// One record as the shaders read it (std430: an array of vec4 rows, 144 bytes).
using gpu_record = std430_record;

constexpr const char* record_block = R"(struct bounce_record {
    vec4 position_inv_r;
    vec4 normal_radius;
    vec4 irradiance;
    vec4 rotation[3];
    vec4 translation[3];
};
layout(std430, binding = 0) readonly buffer bounce_records { bounce_record records[]; };
)";

// Uniform locations shared by both stages.
enum location : int {
    loc_view = 0,
    loc_a = 1,
    loc_near = 2,
    loc_tan_half_fov = 3,
    loc_aspect = 4,
    loc_pixel_ndc = 5,
    loc_first = 6,
    loc_max_extrapolation = 7,
    loc_front_tolerance = 8,
};

gpu_record pack(const irradiance_record& r, std::size_t index) { return pack_std430(r, index); }

void require_rgba32f(const texture_ref& t, const char* name) {
    require(t.format == texel_format::rgba32f, name, "must be an RGBA32F texture");
}

// Rows of `image` in GL order (row 0 at the bottom), tightly packed.
std::vector<glm::vec4> flipped(image_view<const glm::vec4> image) {
    std::vector<glm::vec4> rows(image.width() * image.height());
    for (std::size_t y = 0; y < image.height(); ++y) {
        const auto src = image.row(y);
        std::copy(src.begin(), src.end(), rows.begin() + std::ptrdiff_t((image.height() - 1 - y) * image.width()));
    }
    return rows;
}

void upload_rows(const texture& t, const std::vector<glm::vec4>& gl_rows) {
    const detail::unpack_state unpack;
    glTextureSubImage2D(t.id(), 0, 0, 0, GLsizei(t.width()), GLsizei(t.height()), GL_RGBA, GL_FLOAT, gl_rows.data());
    check_error("glTextureSubImage2D");
}

}  // namespace

// ---- G-buffer textures ------------------------------------------------------------------

void gbuffer_textures::validate() const {
    require(position_depth.id != 0 && normal.id != 0 && albedo.id != 0, "gbuffer", "a G-buffer texture is missing");
    const auto is = [](const texture_ref& t, std::initializer_list<texel_format> allowed) {
        return std::find(allowed.begin(), allowed.end(), t.format) != allowed.end();
    };
    require(position_depth.format == texel_format::rgba32f, "gbuffer",
            "position and depth must be an RGBA32F texture (depth in w)");
    require(is(normal, {texel_format::rgba32f, texel_format::rgb32f}), "gbuffer",
            "the normal texture must be RGBA32F or RGB32F");
    require(is(albedo, {texel_format::rgba32f, texel_format::rgb32f, texel_format::rgba8}), "gbuffer",
            "the albedo texture must be RGBA32F, RGB32F or RGBA8");
    require(width() > 0 && height() > 0, "gbuffer", "G-buffer textures have no size");
    require(normal.width == width() && albedo.width == width() && normal.height == height() && albedo.height == height(),
            "gbuffer", "G-buffer textures differ in size");
}

gbuffer_textures textures_of(const gbuffer_pass& pass) {
    return {pass.position_depth(), pass.normal(), pass.albedo()};
}

void gbuffer_upload::upload(const gbuffer_view<float>& g) {
    const std::size_t w = g.width(), h = g.height();
    require(w > 0 && h > 0, "g", "the G-buffer is empty");
    const auto same = [&](std::size_t vw, std::size_t vh) { return vw == w && vh == h; };
    require(same(g.position.width(), g.position.height()) && same(g.normal.width(), g.normal.height()) &&
                same(g.albedo.width(), g.albedo.height()),
            "g", "G-buffer views differ in size");
    if (!position_depth_ || position_depth_->width() != w || position_depth_->height() != h) {
        position_depth_.emplace(texel_format::rgba32f, w, h);
        normal_.emplace(texel_format::rgba32f, w, h);
        albedo_.emplace(texel_format::rgba32f, w, h);
    }
    // The layout of gbuffer_pass: background position (0, 0, 0, +inf), normal 0, albedo 0.
    std::vector<glm::vec4> p(w * h), n(w * h), a(w * h);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            const std::size_t i = (h - 1 - y) * w + x;
            const bool covered = g.covered(x, y);
            p[i] = covered ? glm::vec4(g.position(x, y), g.depth(x, y))
                           : glm::vec4(0.f, 0.f, 0.f, std::numeric_limits<float>::infinity());
            n[i] = covered ? glm::vec4(g.normal(x, y), 0.f) : glm::vec4(0.f);
            a[i] = covered ? glm::vec4(g.albedo(x, y), 1.f) : glm::vec4(0.f);
        }
    upload_rows(*position_depth_, p);
    upload_rows(*normal_, n);
    upload_rows(*albedo_, a);
}

gbuffer_textures gbuffer_upload::textures() const {
    require(position_depth_.has_value(), "gbuffer_upload", "nothing uploaded yet");
    return {*position_depth_, *normal_, *albedo_};
}

void read_gbuffer(const gbuffer_textures& g, gbuffer_view<float> out) {
    g.validate();
    const std::size_t w = g.width(), h = g.height();
    const auto sized = [&](std::size_t ow, std::size_t oh) { return ow == w && oh == h; };
    require(sized(out.position.width(), out.position.height()) && sized(out.normal.width(), out.normal.height()) &&
                sized(out.albedo.width(), out.albedo.height()) && sized(out.depth.width(), out.depth.height()),
            "out", "G-buffer views differ in size from the textures");
    image<glm::vec4> position_depth(w, h);
    read_texture(g.position_depth, position_depth.view());
    read_texture(g.normal, out.normal);
    read_texture(g.albedo, out.albedo);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            out.position(x, y) = glm::vec3(position_depth(x, y));
            out.depth(x, y) = position_depth(x, y).w;
        }
}

void write_texture(const texture& t, image_view<const glm::vec4> image) {
    require_rgba32f(t, "t");
    require(image.width() == t.width() && image.height() == t.height(), "image", "size differs from the texture");
    upload_rows(t, flipped(image));
}

namespace {
// RGBA32F texels into the first Pixel::length() channels of `out`, rows flipped to top first.
template <class Pixel>
void read_texels(const texture_ref& t, image_view<Pixel> out) {
    require(t.format == texel_format::rgba32f || t.format == texel_format::rgb32f || t.format == texel_format::rgba8, "t",
            "must be an RGBA32F, RGB32F or RGBA8 texture");
    require(out.width() == t.width && out.height() == t.height, "out", "size differs from the texture");
    const auto f = t.read_floats();
    for (std::size_t y = 0; y < out.height(); ++y)
        for (std::size_t x = 0; x < out.width(); ++x) {
            const std::size_t i = 4 * ((out.height() - 1 - y) * out.width() + x);
            for (int c = 0; c < Pixel::length(); ++c) out(x, y)[c] = f[i + std::size_t(c)];
        }
}
}  // namespace

void read_texture(const texture_ref& t, image_view<glm::vec4> out) { read_texels(t, out); }

void read_texture(const texture_ref& t, image_view<glm::vec3> out) { read_texels(t, out); }

// ---- splat_pass -------------------------------------------------------------------------

std::string splat_pass::vertex_source(weighting_kind weighting) {
    glsl::function_set kernels;
    with_weighting(weighting, [&](auto policy) {
        using W = decltype(policy);
        kernels.add("influence_radius", &W::template influence_radius<glsl::f32>, "r", "a");
    });
    kernels.add("sphere_ndc_bounds", sphere_ndc_bounds<glsl::f32, glsl::vec3>, "c", "r", "near_depth", "tan_half_fov_y",
                "aspect", "box");
    // The record's centre and radius arrive as per-instance attributes (Gautron 2008's vertex
    // attributes; storage buffers in vertex shaders are optional in OpenGL 4.5), read from
    // the same buffer the fragment stage indexes.
    return std::string("#version 450 core\n") + R"(layout(location = 0) in vec4 record_position_inv_r;
layout(location = 1) in float record_radius;
layout(location = 0) uniform mat4 view;
layout(location = 1) uniform float a;
layout(location = 2) uniform float near_depth;
layout(location = 3) uniform float tan_half_fov_y;
layout(location = 4) uniform float aspect;
layout(location = 5) uniform vec2 pixel_ndc;
layout(location = 6) uniform uint first;
flat out uint record_index;

)" + kernels.source() +
           R"(
void main() {
    // gl_InstanceID does not count the base instance.
    record_index = first + uint(gl_InstanceID);
    vec3 centre = (view * vec4(record_position_inv_r.xyz, 1.0)).xyz;
    float box[4];
    sphere_ndc_bounds(centre, influence_radius(record_radius, a), near_depth, tan_half_fov_y, aspect, box);
    // One pixel of margin on each side (sphere_pixel_rect needs only 1/8), so that no pixel
    // centre on the box edge is lost to rounding (outside the sphere every weight is 0), then
    // clipped to the screen: the invisible sphere's zero-area box at x = y = 2 stays empty.
    vec2 lo = clamp(vec2(box[0], box[1]) - pixel_ndc, vec2(-1.0), vec2(1.0));
    vec2 hi = clamp(vec2(box[2], box[3]) + pixel_ndc, vec2(-1.0), vec2(1.0));
    // Triangle-strip corners (lo, lo), (hi, lo), (lo, hi), (hi, hi).
    gl_Position = vec4((gl_VertexID & 1) != 0 ? hi.x : lo.x, (gl_VertexID & 2) != 0 ? hi.y : lo.y, 0.0, 1.0);
}
)";
}

std::string splat_pass::fragment_source(weighting_kind weighting, bool gradients, bool front_test) {
    glsl::function_set kernels;
    with_weighting(weighting, [&](auto policy) {
        with_kernel_flags(gradients, front_test, [&](auto g, auto f) {
            kernels.add("splat_contribution",
                        splat_contribution<decltype(policy), decltype(g)::value, decltype(f)::value, glsl::f32, glsl::vec3>,
                        "p", "n", "albedo", "pk", "nk", "inv_r", "a", "e", "rot_r", "rot_g", "rot_b", "tr_r", "tr_g",
                        "tr_b", "max_extrapolation", "front_tolerance", "c");
        });
    });
    return std::string("#version 450 core\n") + record_block + detail::gbuffer_position_normal_samplers() +
           detail::gbuffer_albedo_sampler() + R"(layout(location = 1) uniform float a;
layout(location = 7) uniform float max_extrapolation;
layout(location = 8) uniform float front_tolerance;
flat in uint record_index;
layout(location = 0) out vec4 splat;

)" + kernels.source() + detail::gbuffer_covered +
           R"(
void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 position_depth = texelFetch(gbuffer_position_depth, pixel, 0);
    // No geometry here.
    if (!covered(position_depth.w)) discard;
    bounce_record r = records[record_index];
    float c[4];
    splat_contribution(position_depth.xyz, texelFetch(gbuffer_normal, pixel, 0).xyz,
                       texelFetch(gbuffer_albedo, pixel, 0).rgb, r.position_inv_r.xyz, r.normal_radius.xyz,
                       r.position_inv_r.w, a, r.irradiance.xyz, r.rotation[0].xyz, r.rotation[1].xyz,
                       r.rotation[2].xyz, r.translation[0].xyz, r.translation[1].xyz, r.translation[2].xyz,
                       max_extrapolation, front_tolerance, c);
    // The record does not reach this pixel (cpu::splat_records adds only w > 0).
    if (!(c[3] > 0.0)) discard;
    splat = vec4(c[0], c[1], c[2], c[3]);
}
)";
}

splat_pass::splat_pass() {
    // Per-instance attributes from the record buffer (bound in splat(): it may be
    // reallocated as it grows): 0 = (p_k, 1/R_k), 1 = R_k.
    const GLuint vao = record_vao_.id();
    glVertexArrayAttribFormat(vao, 0, 4, GL_FLOAT, GL_FALSE, GLuint(offsetof(gpu_record, position_inv_r)));
    glVertexArrayAttribFormat(vao, 1, 1, GL_FLOAT, GL_FALSE, GLuint(offsetof(gpu_record, normal_radius) + 3 * sizeof(float)));
    for (GLuint a = 0; a < 2; ++a) {
        glVertexArrayAttribBinding(vao, a, 0);
        glEnableVertexArrayAttrib(vao, a);
    }
    glVertexArrayBindingDivisor(vao, 0, 1);
    check_error("splat_pass vertex array");
}

const program& splat_pass::variant(weighting_kind weighting, bool gradients, bool front_test) {
    const auto key = std::make_tuple(int(weighting), gradients, front_test);
    auto it = programs_.find(key);
    if (it == programs_.end())
        it = programs_
                 .emplace(key, program(vertex_source(weighting), fragment_source(weighting, gradients, front_test)))
                 .first;
    return it->second;
}

void splat_pass::write_records(std::size_t at, std::span<const irradiance_record> records) {
    std::vector<gpu_record> packed(records.size());
    for (std::size_t i = 0; i < records.size(); ++i) packed[i] = pack(records[i], at + i);
    const std::size_t needed = at + records.size();
    if (needed > capacity_) {
        GLint64 max_block = 0;
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
        std::size_t capacity = std::max<std::size_t>({needed, 2 * capacity_, 256});
        const std::size_t max_records = std::size_t(max_block) / sizeof(gpu_record);
        if (needed > max_records)
            throw gl_error("bounce::gl: " + std::to_string(needed) + " records exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE = " +
                           std::to_string(max_block) + " bytes");
        capacity = std::min(capacity, max_records);
        buffer grown(capacity * sizeof(gpu_record));
        if (records_ && at > 0)
            glCopyNamedBufferSubData(records_->id(), grown.id(), 0, 0, GLsizeiptr(at * sizeof(gpu_record)));
        records_.emplace(std::move(grown));
        capacity_ = capacity;
    }
    if (!packed.empty()) records_->write(at * sizeof(gpu_record), packed.data(), packed.size() * sizeof(gpu_record));
    count_ = needed;
    check_error("splat_pass record upload");
}

void splat_pass::upload(std::span<const irradiance_record> records) {
    // Validate everything before the old contents are dropped.
    for (std::size_t i = 0; i < records.size(); ++i) (void)pack(records[i], i);
    count_ = 0;
    write_records(0, records);
}

void splat_pass::append(std::span<const irradiance_record> records) { write_records(count_, records); }

void splat_pass::ensure_target(std::size_t width, std::size_t height) {
    require(width > 0 && height > 0, "width/height", "the splat buffer must have a positive size");
    detail::ensure_color_target(splat_, fbo_, width, height);
    width_ = width;
    height_ = height;
}

void splat_pass::clear(std::size_t width, std::size_t height) {
    ensure_target(width, height);
    const float zero[4] = {0.f, 0.f, 0.f, 0.f};
    glClearTexImage(splat_->id(), 0, GL_RGBA, GL_FLOAT, zero);
    check_error("splat_pass::clear");
}

void splat_pass::upload_splat(image_view<const glm::vec4> splat) {
    require(!splat.empty(), "splat", "the splat buffer is empty");
    ensure_target(splat.width(), splat.height());
    write_texture(*splat_, splat);
}

void splat_pass::splat(const gbuffer_textures& g, const camera& cam, const splat_params& params, weighting_kind weighting,
                       std::size_t first, std::size_t count) {
    params.validate();
    cam.validate();
    g.validate();
    require(splat_.has_value(), "splat_pass", "no splat buffer: call clear or upload_splat first");
    require(g.width() == width_ && g.height() == height_, "gbuffer", "G-buffer and splat buffer sizes differ");
    require(first <= count_, "first", "past the last record");
    count = std::min(count, count_ - first);
    if (count == 0) return;
    require(count <= std::size_t(std::numeric_limits<GLsizei>::max()), "count", "too many records for one draw");
    const program& prog = variant(weighting, params.gradients, params.front_test());

    prog.set(loc_view, cam.view_matrix());
    prog.set(loc_a, params.a);
    prog.set(loc_near, cam.near_plane);
    prog.set(loc_tan_half_fov, cam.tan_half_fov());
    prog.set(loc_aspect, float(width_) / float(height_));
    prog.set(loc_pixel_ndc, glm::vec2(2.f / float(width_), 2.f / float(height_)));
    prog.set(loc_first, unsigned(first));
    prog.set(loc_max_extrapolation, params.max_extrapolation);
    prog.set(loc_front_tolerance, params.front_tolerance);

    const detail::raster_state raster;
    const detail::blend_offset_state blend;
    const detail::program_and_storage_state bindings({0u});
    const detail::texture_unit_state units(0, 3);

    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, GLsizei(width_), GLsizei(height_));
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glDisable(GL_DITHER);
    // Float blending adds each fragment to the buffer in primitive (= record) order.
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glUseProgram(prog.id());
    glVertexArrayVertexBuffer(record_vao_.id(), 0, records_->id(), 0, sizeof(gpu_record));
    glBindVertexArray(record_vao_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, records_->id());
    detail::bind_gbuffer_textures(g);
    glDrawArraysInstancedBaseInstance(GL_TRIANGLE_STRIP, 0, 4, GLsizei(count), GLuint(first));
    check_error("splat_pass::splat");
}

void splat_pass::read_splat(image_view<glm::vec4> out) const { read_texture(splat_texture(), out); }

image<glm::vec4> splat_pass::read_splat() const {
    image<glm::vec4> out(splat_texture().width(), splat_texture().height());
    read_splat(out.view());
    return out;
}

const texture& splat_pass::splat_texture() const {
    require(splat_.has_value(), "splat_pass", "no splat buffer: call clear or upload_splat first");
    return *splat_;
}

// ---- compose_pass -----------------------------------------------------------------------

namespace {
constexpr GLint loc_lambda = 0;

// with_wide: hole filling (hole_filled_splat) from a second splat buffer at a wider a.
std::string compose_fragment(bool with_direct, bool with_wide) {
    glsl::function_set kernels;
    kernels.add("normalized_splat", normalized_splat<glsl::f32, glsl::vec3>, "sum", "weight");
    if (with_wide)
        kernels.add("hole_filled_splat", hole_filled_splat<glsl::f32, glsl::vec3>, "sum", "weight", "wide_sum",
                    "wide_weight", "lambda");
    return std::string("#version 450 core\n") + "layout(binding = 0) uniform sampler2D splat_buffer;\n" +
           (with_direct ? "layout(binding = 1) uniform sampler2D direct_radiance;\n" : "") +
           (with_wide ? "layout(binding = 2) uniform sampler2D wide_buffer;\nlayout(location = 0) uniform float lambda;\n"
                      : "") +
           "layout(location = 0) out vec4 radiance;\n\n" + kernels.source() +
           "\nvoid main() {\n"
           "    ivec2 pixel = ivec2(gl_FragCoord.xy);\n"
           "    vec4 s = texelFetch(splat_buffer, pixel, 0);\n" +
           (with_wide ? "    vec4 w = texelFetch(wide_buffer, pixel, 0);\n"
                        "    vec3 indirect = hole_filled_splat(s.rgb, s.a, w.rgb, w.a, lambda);\n"
                      : "    vec3 indirect = normalized_splat(s.rgb, s.a);\n") +
           (with_direct ? "    radiance = vec4(texelFetch(direct_radiance, pixel, 0).rgb + indirect, 1.0);\n"
                        : "    radiance = vec4(indirect, 1.0);\n") +
           "}\n";
}
}  // namespace

compose_pass::compose_pass()
    : with_direct_(detail::fullscreen_vertex, compose_fragment(true, false)),
      without_direct_(detail::fullscreen_vertex, compose_fragment(false, false)),
      with_direct_wide_(detail::fullscreen_vertex, compose_fragment(true, true)),
      without_direct_wide_(detail::fullscreen_vertex, compose_fragment(false, true)) {}

void compose_pass::compose(const texture& splat, const texture* direct) { compose(splat, direct, nullptr, 0.f); }

void compose_pass::compose(const texture& splat, const texture* direct, const texture* wide, float lambda) {
    require_rgba32f(splat, "splat");
    if (direct) {
        require_rgba32f(*direct, "direct");
        require(direct->width() == splat.width() && direct->height() == splat.height(), "direct",
                "size differs from the splat buffer");
    }
    if (wide) {
        require_rgba32f(*wide, "wide");
        require(wide->width() == splat.width() && wide->height() == splat.height(), "wide",
                "size differs from the splat buffer");
        require(std::isfinite(lambda) && lambda > 0.f, "lambda", "must be a positive number");
    }
    detail::ensure_color_target(result_, fbo_, splat.width(), splat.height());
    const program& prog = wide ? (direct ? with_direct_wide_ : without_direct_wide_) : (direct ? with_direct_ : without_direct_);
    const detail::raster_state raster;
    const detail::program_and_storage_state bindings({});
    const detail::texture_unit_state units(0, 3);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, GLsizei(splat.width()), GLsizei(splat.height()));
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glUseProgram(prog.id());
    glBindVertexArray(empty_vao_.id());
    glBindTextureUnit(0, splat.id());
    glBindSampler(0, 0);
    if (direct) {
        glBindTextureUnit(1, direct->id());
        glBindSampler(1, 0);
    }
    if (wide) {
        glBindTextureUnit(2, wide->id());
        glBindSampler(2, 0);
        glProgramUniform1f(prog.id(), loc_lambda, lambda);
    }
    glDrawArrays(GL_TRIANGLES, 0, 3);
    check_error("compose_pass::compose");
}

void compose_pass::compose(const texture& splat, image_view<const glm::vec3> direct) {
    require(direct.width() == splat.width() && direct.height() == splat.height(), "direct",
            "size differs from the splat buffer");
    if (!uploaded_direct_ || uploaded_direct_->width() != direct.width() || uploaded_direct_->height() != direct.height())
        uploaded_direct_.emplace(texel_format::rgba32f, direct.width(), direct.height());
    image<glm::vec4> padded(direct.width(), direct.height());
    for (std::size_t y = 0; y < direct.height(); ++y)
        for (std::size_t x = 0; x < direct.width(); ++x) padded(x, y) = glm::vec4(direct(x, y), 1.f);
    write_texture(*uploaded_direct_, padded.view());
    compose(splat, &*uploaded_direct_);
}

void compose_pass::read(image_view<glm::vec3> out) const { read_texture(result(), out); }

const texture& compose_pass::result() const {
    require(result_.has_value(), "compose_pass", "nothing composed yet");
    return *result_;
}

}  // namespace bounce::gl
