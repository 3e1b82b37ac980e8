// One-bounce indirect irradiance from reflective shadow maps on OpenGL: the interleaved
// split and gather (Segovia et al. 2006), the RSM gather (Dachsbacher and Stamminger 2005)
// as a fragment pass, SII (Dachsbacher and Stamminger 2006) as instanced quads with
// additive blending, the discontinuity buffer and the separable geometry-aware tent. The
// shaders are plumbing (fetches, loops over storage buffers, row flips, writes); the index
// maps, disc centre, pixel-light irradiance, discontinuity test and tent are the emitted
// kernels of indirect/rsm.hpp and indirect/interleaved_sampling.hpp.
#include <bounce/gl/indirect_renderer.hpp>
#include <bounce/glsl/emit.hpp>
#include <bounce/indirect/rsm.hpp>
#include <bounce/indirect/rsm_sampling.hpp>

#include "indirect_shaders.hpp"
#include "saved_state.hpp"
#include "vertex_shaders.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <utility>

#include <glm/glm.hpp>

namespace bounce::gl {

namespace {

using namespace indirect_glsl;
using detail::fullscreen_vertex;


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

// SII's VPLs of one frame: how many were selected, and those whose splat covers a pixel
// with their rectangles in the split buffer, in group order.
struct vpl_splats {
    std::size_t selected = 0;
    std::vector<gpu_vpl> packed;
    std::vector<glm::vec4> rects;
    std::vector<glm::vec4> frames;  // every selected VPL's position and normal, selection order
};

// VPLs from the read-back maps, selected and grouped as the CPU renderer does, each with its
// rectangle in the split buffer (as cpu::splat_vpls: indirect/rsm_sampling.hpp's
// vpl_splat_rect and split_buffer_rect), flux times `scale`; `splatted` gets every one in
// group order.
vpl_splats place_vpl_splats(std::span<const rsm_textures> maps, const camera& cam, std::size_t w, std::size_t h,
                            const indirect_options& o, float scale, std::vector<vpl>& splatted) {
    const interleave_pattern& pattern = o.pattern;
    std::vector<rsm_images> images;
    images.reserve(maps.size());
    for (const auto& m : maps) images.emplace_back(m);
    std::vector<rsm_view> views;
    for (const auto& im : images) views.push_back(im.view());
    const std::vector<vpl> all = select_vpls(views, o);
    std::vector<glm::vec3> positions;
    if (o.assignment == light_assignment::similarity)
        for (const auto& l : all) positions.push_back(l.position);
    const light_groups groups = assign_lights(all.size(), pattern.cells(), o.assignment, positions, o.shift);
    const glm::mat4 view = cam.view_matrix();
    vpl_splats out;
    out.selected = all.size();
    for (const auto& l : all) {
        out.frames.emplace_back(l.position, 0.f);
        out.frames.emplace_back(l.normal, 0.f);
    }
    splatted.clear();
    for (int s = 0; s < pattern.cells(); ++s) {
        const int i = s % pattern.n, j = s / pattern.n;
        const sub_buffer_rect sub = sub_buffer_of(pattern, i, j, w, h);
        for (std::uint32_t k = groups.begin[std::size_t(s)]; k < groups.begin[std::size_t(s) + 1]; ++k) {
            const vpl& l = all[groups.order[k]];
            const vpl scaled{l.position, l.normal, l.flux * scale, l.area * scale};
            splatted.push_back(scaled);
            const pixel_rect q = split_buffer_rect(
                vpl_splat_rect(cam, view, l, all.size(), o.sii_cutoff, o.light.offset, w, h), pattern, i, j, sub);
            if (q.empty()) continue;
            out.packed.push_back(
                {glm::vec4(scaled.position, o.light.min_distance2_for(scaled.area)),
                 glm::vec4(scaled.normal, float(groups.order[k])),
                 glm::vec4(scaled.flux, 0.f)});
            out.rects.emplace_back(float(q.x0), float(q.y0), float(q.x1), float(q.y1));
        }
    }
    return out;
}

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
    // Imperfect shadow maps: the programs (made on the first ism frame), the point set as
    // uploaded (kept while its sampler, size and seed stay), the frame's VPLs and the depth
    // pyramid (every level, finest first).
    std::optional<program> ism_splat, ism_pull, ism_push;
    std::optional<buffer> ism_points, ism_vpls, ism_depth;
    const ism_point_sampler* ism_sampler = nullptr;
    std::size_t ism_point_count = 0;
    std::uint64_t ism_seed = 0;
    ism_atlas_layout ism_layout;
    float ism_spacing = 0.f;
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

    static void additive_blending() {
        glEnable(GL_BLEND);
        glBlendEquation(GL_FUNC_ADD);
        glBlendFunc(GL_ONE, GL_ONE);
    }

    // Interleaved frames: g split into the sub-buffers of `pattern` (split_position_depth,
    // split_normal); returns the G-buffer the shading passes read.
    gbuffer_textures split_gbuffer(const gbuffer_textures& g, std::size_t w, std::size_t h,
                                   const interleave_pattern& pattern) {
        ensure_scratch(w, h);
        target({split_position_depth->id(), split_normal->id()}, w, h);
        textures({g.position_depth.id, g.normal.id});
        frame_uniforms(split, w, h, pattern);
        fullscreen(split);
        gbuffer_textures shaded = g;
        shaded.position_depth = *split_position_depth;
        shaded.normal = *split_normal;
        return shaded;
    }

    // The RSM gather's disc pattern for maps of `texels` texels, grouped by sub-buffer, and
    // the same pattern as one group; made again only when the count or the map size changes.
    void ensure_disc(const indirect_options& o, std::size_t texels) {
        if (disc && disc_count == o.count && disc_texels == texels) return;
        const auto full = rsm_disc_pattern(o.count, o.r_max, texels, o.seed, o.disc);
        const light_groups g = assign_lights(full.size(), o.pattern.cells(), light_assignment::interleaved, {}, o.shift);
        std::vector<glm::vec4> grouped(full.size());
        for (std::size_t k = 0; k < full.size(); ++k) grouped[k] = glm::vec4(full[g.order[k]], 0.f);
        disc.emplace(std::span<const glm::vec4>(grouped));
        groups.emplace(std::span<const std::uint32_t>(g.begin));
        std::vector<glm::vec4> whole(full.size());
        for (std::size_t k = 0; k < full.size(); ++k) whole[k] = glm::vec4(full[k], 0.f);
        const std::uint32_t one_group[2] = {0u, std::uint32_t(full.size())};
        whole_disc.emplace(std::span<const glm::vec4>(whole));
        whole_group.emplace(std::span<const std::uint32_t>(one_group));
        disc_count = o.count;
        disc_texels = texels;
    }

    // The RSM gather of every map into `out`, added; each VPL's flux times `scale`.
    void gather_maps(const gbuffer_textures& shaded, object_id out, std::size_t w, std::size_t h,
                     std::span<const rsm_textures> maps, const indirect_options& o, float scale) {
        ensure_disc(o, maps[0].width() * maps[0].height());
        target({out}, w, h);
        additive_blending();
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, disc->id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, groups->id());
        const program& prog = gather_rsm;
        frame_uniforms(prog, w, h, o.pattern);
        prog.set(loc_weight_scale, scale);
        prog.set(loc_offset, o.light.offset);
        prog.set(loc_min_distance2, o.light.min_distance2);
        for (const auto& m : maps) {
            textures({shaded.position_depth.id, shaded.normal.id, m.position.id, m.normal.id, m.flux.id});
            prog.set(loc_light_view_projection, m.light_view_projection);
            prog.set(loc_map_size, glm::vec2(float(m.width()), float(m.height())));
            fullscreen(prog);
        }
        glDisable(GL_BLEND);
    }

    // SII: the VPLs as instanced quads over their rectangles, added into `out`.
    void draw_splats(const gbuffer_textures& shaded, object_id out, std::size_t w, std::size_t h,
                     const std::vector<gpu_vpl>& packed, const std::vector<glm::vec4>& rect_list,
                     const indirect_options& o) {
        vpls.emplace(std::span<const gpu_vpl>(packed));
        rects.emplace(std::span<const glm::vec4>(rect_list));
        target({out}, w, h);
        additive_blending();
        textures({shaded.position_depth.id, shaded.normal.id});
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, vpls->id());
        const program& prog = splat;
        prog.set(loc_size, glm::vec2(float(w), float(h)));
        prog.set(loc_offset, o.light.offset);
        const bool ism = o.visibility == indirect_visibility::ism;
        prog.set(6, ism ? 1 : 0);
        if (ism) {
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, ism_depth->id());
            prog.set(7, float(ism_layout.map_size));
            prog.set(8, int(ism_layout.columns));
            prog.set(9, int(ism_layout.width()));
            prog.set(10, ism_spacing);
            prog.set(11, o.ism.bias_scale);
        }
        glUseProgram(prog.id());
        glVertexArrayVertexBuffer(rect_vao.id(), 0, rects->id(), 0, sizeof(glm::vec4));
        glBindVertexArray(rect_vao.id());
        glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, GLsizei(packed.size()));
        glDisable(GL_BLEND);
    }

    // The frame's imperfect shadow maps of the VPLs `frames` (selection order) in ism_depth:
    // the point set (made and uploaded when it changes), cleared atlas, splat, pull-push.
    void build_ism(const ism_point_sampler& sampler, const indirect_options& o, const std::vector<glm::vec4>& frames) {
        const ism_params& ip = o.ism;
        if (!ism_splat) {
            ism_splat.emplace(program::compute(ism_splat_compute()));
            ism_pull.emplace(program::compute(ism_pull_compute()));
            ism_push.emplace(program::compute(ism_push_compute()));
        }
        const std::size_t total = o.count * std::size_t(ip.points_per_vpl);
        if (!ism_points || ism_sampler != &sampler || ism_point_count != total || ism_seed != ip.seed) {
            const std::vector<glm::vec3> pts = sampler.points(total, ip.seed);
            std::vector<glm::vec4> packed(std::max<std::size_t>(pts.size(), 1), glm::vec4(0.f));
            for (std::size_t i = 0; i < pts.size(); ++i) packed[i] = glm::vec4(pts[i], 0.f);
            ism_points.emplace(std::span<const glm::vec4>(packed));
            ism_sampler = &sampler;
            ism_point_count = pts.size();
            ism_seed = ip.seed;
        }
        const std::size_t v = frames.size() / 2;
        ism_layout = ism_atlas_layout(ip.map_size, v);
        ism_spacing = ism_point_spacing(sampler.area(), ip.points_per_vpl);
        std::size_t texels = 0;
        for (int l = 0; l <= ism_layout.levels(); ++l) texels += (ism_layout.width() >> l) * (ism_layout.height() >> l);
        if (!ism_depth || ism_depth->size() != texels * sizeof(float)) ism_depth.emplace(texels * sizeof(float));
        const std::uint32_t empty_bits = std::bit_cast<std::uint32_t>(ism_empty);
        glClearNamedBufferData(ism_depth->id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &empty_bits);
        if (v == 0) return;
        ism_vpls.emplace(std::span<const glm::vec4>(frames));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, ism_points->id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, ism_vpls->id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, ism_depth->id());
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        const program& sp = *ism_splat;
        sp.set(0, unsigned(ism_point_count));
        sp.set(1, unsigned(v));
        sp.set(2, float(ip.map_size));
        sp.set(3, unsigned(ism_layout.columns));
        sp.set(4, unsigned(ism_layout.width()));
        glUseProgram(sp.id());
        const std::size_t groups = (ism_point_count + 255) / 256, gx = std::min<std::size_t>(groups, 4096);
        if (groups > 0) glDispatchCompute(GLuint(gx), GLuint((groups + gx - 1) / gx), 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        if (!ip.pull_push) return;
        std::vector<std::size_t> offset(1, 0);
        for (int l = 1; l <= ism_layout.levels(); ++l)
            offset.push_back(offset.back() + (ism_layout.width() >> (l - 1)) * (ism_layout.height() >> (l - 1)));
        const auto level_pass = [&](const program& p, int coarse, std::size_t dispatch_w, std::size_t dispatch_h) {
            p.set(0, unsigned(offset[std::size_t(coarse - 1)]));
            p.set(1, unsigned(offset[std::size_t(coarse)]));
            glProgramUniform2ui(p.id(), 2, GLuint(ism_layout.width() >> coarse), GLuint(ism_layout.height() >> coarse));
            glUseProgram(p.id());
            glDispatchCompute(GLuint((dispatch_w + 7) / 8), GLuint((dispatch_h + 7) / 8), 1);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        };
        for (int l = 1; l <= ism_layout.levels(); ++l)
            level_pass(*ism_pull, l, ism_layout.width() >> l, ism_layout.height() >> l);
        for (int l = ism_layout.levels(); l >= 1; --l)
            level_pass(*ism_push, l, ism_layout.width() >> (l - 1), ism_layout.height() >> (l - 1));
    }

    // The geometry-aware blur of `gathered` into `out`: the discontinuity buffer of g, then
    // the separable tent across and along.
    void blur(const gbuffer_textures& g, object_id out, std::size_t w, std::size_t h, const indirect_options& o) {
        const interleave_pattern& pattern = o.pattern;
        target({edges->id()}, w, h);
        textures({g.position_depth.id, g.normal.id});
        frame_uniforms(discontinuity, w, h, pattern);
        discontinuity.set(loc_relative_depth, o.discontinuity.relative_depth);
        discontinuity.set(loc_cos_normal, o.discontinuity.cos_normal);
        fullscreen(discontinuity);

        ensure_tent(tent_radius(pattern));
        target({scratch->id()}, w, h);
        textures({gathered->id(), edges->id(), g.position_depth.id});
        frame_uniforms(*tent_x, w, h, pattern);
        tent_x->set(loc_pattern_width, float(pattern.n));
        fullscreen(*tent_x);

        target({out}, w, h);
        textures({scratch->id(), edges->id(), g.position_depth.id});
        frame_uniforms(*tent_y, w, h, pattern);
        tent_y->set(loc_pattern_width, float(pattern.m));
        fullscreen(*tent_y);
    }
};

indirect_renderer::indirect_renderer(const indirect_options& options, bool time_stages)
    : options_(options), time_stages_(time_stages) {
    validate_options(options_);
    passes_ = std::make_unique<passes>();
}

void indirect_renderer::validate_options(const indirect_options& options) {
    options.validate();
    require(options.visibility != indirect_visibility::rays, "visibility",
            "rays run on the CPU only (cpu::indirect_renderer with embree::occlusion_rays); GL offers ism");
    require(options.discontinuity.complete_below == 0.f, "discontinuity.complete_below",
            "completing isolated pixels runs on the CPU only (cpu::indirect_renderer)");
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
    require(options_.visibility != indirect_visibility::ism || points_, "visibility",
            "ism needs the scene's ism_point_sampler (set_point_sampler)");
    const detail::program_and_storage_state bindings({0u, 1u, 2u});
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
            passes::additive_blending();
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
    const gbuffer_textures shaded = interleaved ? p.split_gbuffer(g, w, h, pattern) : g;
    const object_id shaded_out = interleaved ? p.split_out->id() : out;
    check_error("indirect_renderer split");
    t.split_ms += lap(start);

    // Shade the sub-buffers.
    const float zero[4] = {0.f, 0.f, 0.f, 0.f};
    glClearTexImage(shaded_out, 0, GL_RGBA, GL_FLOAT, zero);
    const float scale =
        options_.energy_correct ? interleaved_weight_scale<float>(float(pattern.n), float(pattern.m)) : 1.f;
    if (options_.technique == indirect_technique::rsm_gather) {
        t.vpls = options_.count;
        if (!maps.empty()) p.gather_maps(shaded, shaded_out, w, h, maps, options_, scale);
    } else {
        const vpl_splats splats = place_vpl_splats(maps, cam, w, h, options_, scale, splatted_);
        t.vpls = splats.selected;
        if (options_.visibility == indirect_visibility::ism) p.build_ism(*points_, options_, splats.frames);
        if (!splats.packed.empty()) p.draw_splats(shaded, shaded_out, w, h, splats.packed, splats.rects, options_);
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
            p.blur(g, out, w, h, options_);
            check_error("indirect_renderer blur");
            t.blur_ms += lap(start);
        }
    }
}

}  // namespace bounce::gl
