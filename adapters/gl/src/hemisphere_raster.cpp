// The raster hemisphere sampler: an atlas of record planes drawn by one instanced draw per
// batch (or by the caller's callback, once per record), read back through pixel buffer
// objects, or reduced by a compute shader. The
// shaders are plumbing; the per-texel maths are emitted kernels (surface.hpp's
// facing_normal, direct_light.hpp's lambertian_radiance, cache/plane_pixel.hpp's plane_hit_distance and
// plane_pixel_terms) and gl::direct_light's direct_irradiance.
#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/glsl/emit.hpp>
#include <bounce/direct_light.hpp>
#include <bounce/sampling.hpp>
#include <bounce/surface.hpp>

#include "saved_state.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <glm/glm.hpp>

namespace bounce::gl {

namespace {

constexpr std::size_t sums_per_record = 20;  // 17 used: E, rot x, rot y, trans x, trans y (rgb each), wd/r, wd
constexpr unsigned reduce_group = 256;

std::string vertex_shader() {
    return R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
struct bounce_hr_record { mat4 view_projection; vec4 tile; vec4 eye; };
layout(std430, binding = 1) readonly buffer bounce_hr_records { bounce_hr_record records[]; };
out gl_PerVertex { vec4 gl_Position; float gl_ClipDistance[4]; };
out vec3 world_position;
out vec3 world_normal;
flat out vec3 eye;
void main() {
    bounce_hr_record r = records[gl_InstanceID];
    vec4 clip = r.view_projection * vec4(position, 1.0);
    // Keep the primitive inside the record's own frustum, i.e. its own tile.
    gl_ClipDistance[0] = clip.w - clip.x;
    gl_ClipDistance[1] = clip.w + clip.x;
    gl_ClipDistance[2] = clip.w - clip.y;
    gl_ClipDistance[3] = clip.w + clip.y;
    // The tile's place in the atlas: ndc' = ndc * scale + offset.
    gl_Position = vec4(clip.xy * r.tile.xy + r.tile.zw * clip.w, clip.z, clip.w);
    world_position = position;
    world_normal = normal;
    eye = r.eye.xyz;
}
)";
}

std::string fragment_shader(const direct_light& light) {
    glsl::function_set k;
    k.add("facing_normal", facing_normal<glsl::f32, glsl::vec3>, "n", "p", "eye");
    k.add("lambertian_radiance", lambertian_radiance<glsl::f32, glsl::vec3>, "albedo", "irradiance");
    k.add("plane_hit_distance", plane_hit_distance<glsl::f32, glsl::vec3>, "p", "eye");
    return "#version 450 core\n"
           "layout(std430, binding = 0) readonly buffer bounce_hr_albedo { vec4 kd[]; };\n"
           "layout(location = 0) uniform uint triangle_count;\n"
           "in vec3 world_position;\n"
           "in vec3 world_normal;\n"
           "flat in vec3 eye;\n"
           "layout(location = 0) out vec4 radiance_distance;\n\n" +
           light.glsl_source() + "\n" + k.source() +
           R"(
void main() {
    vec3 n = facing_normal(world_normal, world_position, eye);
    // gl_PrimitiveID restarts with each instance; the modulo keeps the lookup right either way.
    vec3 albedo = kd[uint(gl_PrimitiveID) % triangle_count].rgb;
    radiance_distance = vec4(lambertian_radiance(albedo, direct_irradiance(world_position, n)),
                             plane_hit_distance(world_position, eye));
}
)";
}

std::string reduce_shader() {
    glsl::function_set k;
    k.add("plane_pixel_terms", plane_pixel_terms<glsl::f32, glsl::vec3, glsl::vec2>, "w", "wd", "rot", "left_wall",
          "up_wall", "edge_wall", "L", "L_left", "L_up", "r", "r_left", "r_up", "e", "rot_x", "rot_y", "trans_x",
          "trans_y", "inv_distance", "weight");
    const std::string G = std::to_string(reduce_group), S = std::to_string(sums_per_record);
    return "#version 450 core\n"
           "layout(local_size_x = " + G + ") in;\n"
           "layout(binding = 0) uniform sampler2D atlas;\n"
           "layout(std430, binding = 0) readonly buffer bounce_hr_weights { vec4 weights[]; };\n"
           "layout(std430, binding = 1) writeonly buffer bounce_hr_sums { float sums[]; };\n"
           "layout(location = 0) uniform uint N;\n"
           "layout(location = 1) uniform uint columns;\n"
           "shared float partial[17 * " + G + "];\n\n" +
           k.source() + R"(
void main() {
    uint record = gl_WorkGroupID.x, t = gl_LocalInvocationID.x;
    ivec2 origin = ivec2((record % columns) * N, (record / columns) * N);
    vec3 s_e = vec3(0.0), s_rx = vec3(0.0), s_ry = vec3(0.0), s_tx = vec3(0.0), s_ty = vec3(0.0);
    float s_inv = 0.0, s_w = 0.0;
    for (uint p = t; p < N * N; p += )" + G + R"(u) {
        uint i = p % N, j = p / N;
        vec4 here = texelFetch(atlas, origin + ivec2(i, j), 0);
        vec4 left = texelFetch(atlas, origin + ivec2(i > 0u ? i - 1u : i, j), 0);
        vec4 up = texelFetch(atlas, origin + ivec2(i, j > 0u ? j - 1u : j), 0);
        vec4 w0 = weights[3u * p], w1 = weights[3u * p + 1u], w2 = weights[3u * p + 2u];
        vec3 e, rx, ry, tx, ty;
        float inv_distance, weight;
        plane_pixel_terms(w0.x, w0.y, w0.zw, w1.xy, w1.zw, w2.xy, here.rgb, left.rgb, up.rgb, here.a, left.a, up.a,
                          e, rx, ry, tx, ty, inv_distance, weight);
        s_e += e; s_rx += rx; s_ry += ry; s_tx += tx; s_ty += ty; s_inv += inv_distance; s_w += weight;
    }
    float v[17] = float[17](s_e.x, s_e.y, s_e.z, s_rx.x, s_rx.y, s_rx.z, s_ry.x, s_ry.y, s_ry.z,
                            s_tx.x, s_tx.y, s_tx.z, s_ty.x, s_ty.y, s_ty.z, s_inv, s_w);
    for (uint c = 0u; c < 17u; ++c) partial[c * )" + G + R"(u + t] = v[c];
    barrier();
    for (uint half_size = )" + std::to_string(reduce_group / 2) + R"(u; half_size > 0u; half_size >>= 1u) {
        if (t < half_size)
            for (uint c = 0u; c < 17u; ++c) partial[c * )" + G + R"(u + t] += partial[c * )" + G + R"(u + t + half_size];
        barrier();
    }
    if (t == 0u)
        for (uint c = 0u; c < 17u; ++c) sums[record * )" + S + R"(u + c] = partial[c * )" + G + R"(u];
}
)";
}

// Reversed depth without a far plane (GL_ZERO_TO_ONE): window depth = near / distance along
// the view axis, so precision is even in log-distance and nothing far is clipped. The y axis
// is flipped so that plane row 0 (+y) is texel row 0, the first in memory.
glm::mat4 plane_projection(double half_extent, float near_distance) {
    glm::mat4 p(0.f);
    p[0][0] = float(1.0 / half_extent);
    p[1][1] = float(-1.0 / half_extent);
    p[2][3] = -1.f;
    p[3][2] = near_distance;
    return p;
}

// View matrix of the record's local frame: view x = tangent, y = bitangent, -z = n.
glm::mat4 plane_view(const glm::vec3& eye, const glm::vec3& t, const glm::vec3& b, const glm::vec3& n) {
    glm::mat4 v(1.f);
    for (int c = 0; c < 3; ++c) {
        v[c][0] = t[c];
        v[c][1] = b[c];
        v[c][2] = -n[c];
    }
    v[3][0] = -glm::dot(t, eye);
    v[3][1] = -glm::dot(b, eye);
    v[3][2] = glm::dot(n, eye);
    return v;
}

// Every clip distance's enable (GL_MAX_CLIP_DISTANCES of them), saved and restored
// (raster_state leaves them alone). All of them, not the built-in drawer's four: the
// callback path turns them all off, since a caller's shader that does not write an enabled
// gl_ClipDistance[i] leaves its clipping undefined.
class clip_distance_state {
public:
    clip_distance_state() {
        GLint count = 0;
        glGetIntegerv(GL_MAX_CLIP_DISTANCES, &count);
        enabled_.resize(std::size_t(std::max(count, 0)));
        for (std::size_t i = 0; i < enabled_.size(); ++i) enabled_[i] = glIsEnabled(GLenum(GL_CLIP_DISTANCE0 + i));
    }
    ~clip_distance_state() {
        for (std::size_t i = 0; i < enabled_.size(); ++i)
            if (enabled_[i]) glEnable(GLenum(GL_CLIP_DISTANCE0 + i));
            else glDisable(GLenum(GL_CLIP_DISTANCE0 + i));
    }
    clip_distance_state(const clip_distance_state&) = delete;
    clip_distance_state& operator=(const clip_distance_state&) = delete;

private:
    std::vector<GLboolean> enabled_;
};

// The state plane_drawer's contract promises before each call (hemisphere_raster.hpp): the
// tile as viewport and scissor box, reversed depth, and every capability that would change
// what a draw writes off. Set in full before every call, so what one record's callback
// changes cannot leak into the next record's tile.
constexpr std::array<GLenum, 11> callback_caps_off = {
    GL_BLEND,       GL_CULL_FACE,          GL_STENCIL_TEST,  GL_RASTERIZER_DISCARD,         GL_DEPTH_CLAMP,
    GL_POLYGON_OFFSET_FILL, GL_SAMPLE_ALPHA_TO_COVERAGE, GL_SAMPLE_COVERAGE, GL_COLOR_LOGIC_OP,
    GL_PRIMITIVE_RESTART,   GL_PRIMITIVE_RESTART_FIXED_INDEX};

void set_plane_draw_state(GLuint fbo, const plane_draw::rect& tile, std::size_t clip_distances) {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
    glViewport(tile.x, tile.y, tile.width, tile.height);
    glScissor(tile.x, tile.y, tile.width, tile.height);
    glEnable(GL_SCISSOR_TEST);
    glEnable(GL_DEPTH_TEST);
    for (const GLenum cap : callback_caps_off) glDisable(cap);
    for (std::size_t i = 0; i < clip_distances; ++i) glDisable(GLenum(GL_CLIP_DISTANCE0 + i));
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glDepthRange(0.0, 1.0);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
}

}  // namespace

void hemisphere_raster_options::validate() const {
    camera.validate();
    require(batch >= 1 && batch <= 4096, "batch", "must lie in [1, 4096]");
    require(std::isfinite(offset) && offset >= 0.f, "offset", "must be finite and >= 0");
    require(std::isfinite(environment.x) && std::isfinite(environment.y) && std::isfinite(environment.z) &&
                environment.x >= 0.f && environment.y >= 0.f && environment.z >= 0.f,
            "environment", "must be finite and >= 0");
}

struct hemisphere_raster::pending_read {
    std::size_t pbo = 0, records = 0;
    GLsync fence = nullptr;
    ~pending_read() {
        if (fence) glDeleteSync(fence);
    }
};

namespace {
std::size_t columns_for(const hemisphere_raster_options& o) {
    o.validate();
    return std::size_t(std::ceil(std::sqrt(double(o.batch))));
}
std::size_t checked_atlas_side(std::size_t tiles, const hemisphere_raster_options& o) {
    const std::size_t side = tiles * o.camera.resolution;
    GLint max_size = 0, max_viewport[2] = {0, 0};
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, max_viewport);
    const auto limit = std::size_t(std::min({max_size, max_viewport[0], max_viewport[1]}));
    if (side > limit)
        throw gl_error("bounce::gl::hemisphere_raster: an atlas of " + std::to_string(o.batch) + " planes of " +
                       std::to_string(o.camera.resolution) + "^2 needs " + std::to_string(side) +
                       " texels per side, beyond GL_MAX_TEXTURE_SIZE / GL_MAX_VIEWPORT_DIMS (" + std::to_string(limit) +
                       "); use a smaller batch");
    return side;
}
}  // namespace

hemisphere_raster::hemisphere_raster(const scene_view& scene, const scene_mesh& mesh, const direct_light& light,
                                     const hemisphere_raster_options& options)
    : hemisphere_raster(scene, &mesh, &light, plane_drawer{}, options) {}

namespace {
plane_drawer checked_drawer(plane_drawer draw) {
    require(bool(draw), "draw", "an empty plane_drawer draws nothing: pass a callable");
    return draw;
}
}  // namespace

hemisphere_raster::hemisphere_raster(const scene_view& scene, plane_drawer draw, const hemisphere_raster_options& options)
    : hemisphere_raster(scene, nullptr, nullptr, checked_drawer(std::move(draw)), options) {}

hemisphere_raster::hemisphere_raster(const scene_view& scene, const scene_mesh* mesh, const direct_light* light,
                                     plane_drawer draw, const hemisphere_raster_options& options)
    : mesh_(mesh), light_(light), draw_(std::move(draw)), options_(options), columns_(columns_for(options)),
      rows_((options.batch + columns_ - 1) / columns_), vertex_source_(mesh ? vertex_shader() : std::string()),
      fragment_source_(light ? fragment_shader(*light) : std::string()), reduce_source_(reduce_shader()),
      reduce_program_(program::compute(reduce_source_)),
      atlas_(texel_format::rgba32f, checked_atlas_side(columns_, options), rows_ * options.camera.resolution),
      depth_(texel_format::depth32f, columns_ * options.camera.resolution, rows_ * options.camera.resolution),
      records_(options.batch * (16 + 8) * sizeof(float)), sums_(options.batch * sums_per_record * sizeof(float)) {
    (void)checked_atlas_side(rows_, options);
    if (options_.offset > 0.f) offset_ = options_.offset;
    else {
        const auto [lo, hi] = scene.bounds();
        offset_ = std::max(1e-4f * glm::length(hi - lo), 1e-6f);
    }
    fbo_.attach_color(0, atlas_);
    fbo_.attach_depth(depth_);
    fbo_.set_draw_buffers(1);
    fbo_.check_complete();
    const std::size_t bytes = atlas_.width() * atlas_.height() * 4 * sizeof(float);
    for (auto& p : pbo_) p.emplace(bytes);
    if (mesh_) {
        raster_program_.emplace(vertex_source_, fragment_source_);
        raster_program_->set(0, unsigned(std::max<std::size_t>(mesh_->triangle_count(), 1)));
    }
    reduce_program_.set(0, unsigned(options_.camera.resolution));
    reduce_program_.set(1, unsigned(columns_));
}

hemisphere_raster::~hemisphere_raster() = default;

void hemisphere_raster::render(std::span<const glm::vec3> positions, std::span<const glm::vec3> normals) {
    require(positions.size() == normals.size(), "normals", "one normal per position");
    require(!positions.empty() && positions.size() <= capacity(), "positions", "between 1 and capacity() records");
    const std::uint32_t N = options_.camera.resolution;
    const glm::mat4 projection = plane_projection(options_.camera.half_extent(), offset_ / 100.f);
    std::vector<plane_draw> draws(positions.size());
    for (std::size_t k = 0; k < positions.size(); ++k) {
        const glm::vec3 p = positions[k], n = normals[k];
        require(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), "positions", "non-finite position");
        require(std::abs(glm::length(n) - 1.f) <= 1e-3f, "normals", "normal is not unit length");
        const auto tb = options_.camera.frame(p, n);
        plane_draw& d = draws[k];
        d.record = k;
        d.position = p;
        d.normal = n;
        d.eye = p + offset_ * n;
        d.view = plane_view(d.eye, tb[0], tb[1], n);
        d.projection = projection;
        d.view_projection = projection * d.view;
        // Tile (c, r) spans texels [c N, (c + 1) N) x [r N, (r + 1) N) of the atlas.
        d.tile = {std::int32_t((k % columns_) * N), std::int32_t((k / columns_) * N), std::int32_t(N), std::int32_t(N)};
    }

    const detail::raster_state raster;  // scissor test off: the clears below reach every tile
    const detail::blend_offset_state blend;
    const detail::scissor_box_state scissor;
    const clip_distance_state clips;
    const detail::program_and_storage_state bindings({0u, 1u});
    rendered_ = 0;  // the atlas is about to change: nothing to read until this batch is drawn
    const float background[4] = {options_.environment.x, options_.environment.y, options_.environment.z,
                                 std::numeric_limits<float>::infinity()};
    const float far_depth = 0.f;  // reversed depth: 0 is infinitely far
    glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, 0, background);
    glClearNamedFramebufferfv(fbo_.id(), GL_DEPTH, 0, &far_depth);
    if (draw_) draw_callback(draws);
    else {
        std::vector<float> packed(draws.size() * 24);
        const float W = float(atlas_.width()), H = float(atlas_.height());
        for (const plane_draw& d : draws) {
            float* r = &packed[d.record * 24];
            std::memcpy(r, &d.view_projection[0][0], 16 * sizeof(float));
            // The tile's place in the atlas as an affine map of NDC: ndc' = ndc * scale + offset.
            r[16] = float(N) / W;
            r[17] = float(N) / H;
            r[18] = (2.f * float(d.tile.x) + float(N)) / W - 1.f;
            r[19] = (2.f * float(d.tile.y) + float(N)) / H - 1.f;
            r[20] = d.eye.x;
            r[21] = d.eye.y;
            r[22] = d.eye.z;
            r[23] = 0.f;
        }
        records_.write(0, packed.data(), packed.size() * sizeof(float));
        draw_built_in(draws.size());
    }
    check_error("hemisphere_raster::render");
    rendered_ = positions.size();
}

// One instanced draw for the whole batch: instance k reads record k and clips itself to its
// tile, so the atlas is one viewport and the scene's state is set once.
void hemisphere_raster::draw_built_in(std::size_t records) {
    if (mesh_->triangle_count() == 0) return;
    const detail::texture_unit_state units(1, GLuint(std::max<std::size_t>(light_->texture_units(), 1)));
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, GLsizei(atlas_.width()), GLsizei(atlas_.height()));
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glDepthFunc(GL_GREATER);
    for (int i = 0; i < 4; ++i) glEnable(GLenum(GL_CLIP_DISTANCE0 + i));
    glUseProgram(raster_program_->id());
    light_->bind(*raster_program_, 1);
    glBindVertexArray(mesh_->vertices().id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, mesh_->albedo_per_triangle().id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, records_.id());
    glDrawElementsInstanced(GL_TRIANGLES, GLsizei(3 * mesh_->triangle_count()), GL_UNSIGNED_INT, nullptr,
                            GLsizei(records));
}

// One call per record, as lightmapper.h renders its user's scene once per hemisphere view:
// the viewport and the scissor box keep each call in its tile (the caller's shader has no
// clip distances to do it), and the state is set again before every call.
void hemisphere_raster::draw_callback(std::span<const plane_draw> draws) {
    GLint clip_count = 0;
    glGetIntegerv(GL_MAX_CLIP_DISTANCES, &clip_count);
    for (const plane_draw& d : draws) {
        set_plane_draw_state(fbo_.id(), d.tile, std::size_t(std::max(clip_count, 0)));
        draw_(d);
    }
}

void hemisphere_raster::start_read() {
    require(rendered_ > 0, "hemisphere_raster", "nothing rendered yet");
    // Both buffers in flight: the oldest must be collected first (reads come back in order).
    require(pending_.size() < pbo_.size(), "hemisphere_raster", "two reads are pending: call finish_read() first");
    auto read = std::make_unique<pending_read>();
    read->pbo = next_pbo_;
    read->records = rendered_;
    next_pbo_ = (next_pbo_ + 1) % pbo_.size();
    const detail::pack_state pack;  // tightly packed, no pack buffer bound; restored after
    glBindBuffer(GL_PIXEL_PACK_BUFFER, pbo_[read->pbo]->id());
    // Into the bound pack buffer at offset 0: returns once queued.
    glGetTextureImage(atlas_.id(), 0, GL_RGBA, GL_FLOAT, GLsizei(pbo_[read->pbo]->size()), nullptr);
    read->fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
    check_error("hemisphere_raster::start_read");
    pending_.push_back(std::move(read));
}

plane_batch hemisphere_raster::finish_read() {
    require(!pending_.empty(), "hemisphere_raster", "no read pending: call start_read() first");
    auto read = std::move(pending_.front());
    pending_.pop_front();
    // Wait in steps of 1 s so a lost context does not hang forever without a message.
    for (int tries = 0;; ++tries) {
        const GLenum status = glClientWaitSync(read->fence, GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000ull);
        if (status == GL_ALREADY_SIGNALED || status == GL_CONDITION_SATISFIED) break;
        if (status == GL_WAIT_FAILED || tries >= 600)
            throw gl_error("bounce::gl::hemisphere_raster: the read-back fence never signalled");
    }
    const std::uint32_t N = options_.camera.resolution;
    const std::size_t W = atlas_.width();
    std::vector<float> texels(pbo_[read->pbo]->size() / sizeof(float));
    pbo_[read->pbo]->read(0, texels.data(), texels.size() * sizeof(float));
    plane_batch out;
    out.camera = options_.camera;
    for (std::size_t k = 0; k < read->records; ++k) {
        image<glm::vec3> radiance(N, N);
        image<float> distance(N, N);
        const std::size_t x0 = (k % columns_) * N, y0 = (k / columns_) * N;
        for (std::uint32_t j = 0; j < N; ++j)
            for (std::uint32_t i = 0; i < N; ++i) {
                const float* t = &texels[4 * ((y0 + j) * W + x0 + i)];
                radiance(i, j) = {t[0], t[1], t[2]};
                distance(i, j) = t[3];
            }
        out.radiance.push_back(std::move(radiance));
        out.distance.push_back(std::move(distance));
    }
    return out;
}

void hemisphere_raster::read_planes(std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                                    const plane_batch_consumer& consume) {
    require(normals.size() == positions.size(), "normals", "must have one entry per position");
    require(bool(consume), "consume", "must be a callable");
    require(pending_.empty(), "hemisphere_raster", "has reads pending; read_planes would collect them");
    try {
        std::optional<std::size_t> previous;  // the first record of the batch being copied
        for (std::size_t first = 0; first < positions.size(); first += capacity()) {
            const std::size_t count = std::min(capacity(), positions.size() - first);
            render(positions.subspan(first, count), normals.subspan(first, count));
            start_read();
            if (previous) consume(*previous, finish_read());
            previous = first;
        }
        if (previous) consume(*previous, finish_read());
    } catch (...) {
        pending_.clear();  // the fences and buffers are reused; nothing waits on them
        throw;
    }
}

void hemisphere_raster::set_weights(const plane_weights& weights) {
    require(weights.camera.resolution == options_.camera.resolution &&
                weights.camera.aperture_deg == options_.camera.aperture_deg,
            "weights", "table of another plane camera");
    const std::size_t n = options_.camera.pixel_count();
    require(weights.irradiance.size() == n && weights.distance.size() == n && weights.rotation.size() == n &&
                weights.left_wall.size() == n && weights.up_wall.size() == n && weights.edge_wall.size() == n,
            "weights", "table size does not match its camera");
    std::vector<glm::vec4> packed(3 * n);
    for (std::size_t p = 0; p < n; ++p) {
        packed[3 * p] = glm::vec4(float(weights.irradiance[p]), float(weights.distance[p]), float(weights.rotation[p].x),
                                  float(weights.rotation[p].y));
        packed[3 * p + 1] = glm::vec4(glm::vec2(weights.left_wall[p]), glm::vec2(weights.up_wall[p]));
        packed[3 * p + 2] = glm::vec4(glm::vec2(weights.edge_wall[p]), 0.f, 0.f);
    }
    if (!weights_) weights_.emplace(packed.size() * sizeof(glm::vec4));
    weights_->write(0, packed.data(), packed.size() * sizeof(glm::vec4));
    table_ = weights;
}

std::vector<hemisphere_estimate> hemisphere_raster::reduce() {
    require(rendered_ > 0, "hemisphere_raster", "nothing rendered yet");
    require(weights_.has_value(), "hemisphere_raster", "no weights: call set_weights() first");
    {
        const detail::program_and_storage_state bindings({0u, 1u});
        const detail::texture_unit_state units(0, 1);
        glUseProgram(reduce_program_.id());
        glBindTextureUnit(0, atlas_.id());
        glBindSampler(0, 0);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, weights_->id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, sums_.id());
        glDispatchCompute(GLuint(rendered_), 1, 1);
        check_error("hemisphere_raster::reduce");
    }
    std::vector<float> sums(rendered_ * sums_per_record);
    sums_.read(0, sums.data(), sums.size() * sizeof(float));
    std::vector<hemisphere_estimate> out(rendered_);
    const double s = table_.scale;
    for (std::size_t k = 0; k < rendered_; ++k) {
        const float* v = &sums[k * sums_per_record];
        auto& e = out[k];
        e.irradiance = glm::dvec3(v[0], v[1], v[2]) * s;
        for (int c = 0; c < 3; ++c) {
            e.rotation[std::size_t(c)] = glm::dvec3(v[3 + c], v[6 + c], 0) * s;
            e.translation[std::size_t(c)] = glm::dvec3(v[9 + c], v[12 + c], 0) * s;
        }
        if (v[15] > 0.f) e.harmonic_mean_distance = double(v[16]) / double(v[15]);
    }
    return out;
}

}  // namespace bounce::gl
