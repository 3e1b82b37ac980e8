// gl::progressive_radiosity's steps: the reduction that picks the next shooter, the item
// buffer or hemicube drawn from it, and the shot of an element or a light.
#include "radiosity_state.hpp"

namespace bounce::gl {

namespace {

// Clears an item buffer's framebuffer to "nothing drawn" (no chart, no triangle, the largest
// depth in the colour; the depth attachment to 1) and binds it for drawing.
void clear_and_bind_item_target(GLuint framebuffer_id) {
    const std::array<float, 4> none{-1.f, -1.f, std::numeric_limits<float>::max(), 0.f};
    glClearNamedFramebufferfv(framebuffer_id, GL_COLOR, 0, none.data());
    const float far_depth = 1.f;
    glClearNamedFramebufferfv(framebuffer_id, GL_DEPTH, 0, &far_depth);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer_id);
}

// Points the vertex array `vao` at `vertices`, a stream of item_vertex: attribute 0 the
// position, attribute 1 the (chart, triangle) pair.
void attach_item_vertices(GLuint vao, GLuint vertices) {
    glVertexArrayVertexBuffer(vao, 0, vertices, 0, GLsizei(sizeof(item_vertex)));
    glEnableVertexArrayAttrib(vao, 0);
    glEnableVertexArrayAttrib(vao, 1);
    glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(vao, 1, 2, GL_FLOAT, GL_FALSE, GLuint(offsetof(item_vertex, chart)));
    glVertexArrayAttribBinding(vao, 0, 0);
    glVertexArrayAttribBinding(vao, 1, 0);
}

}  // namespace

void progressive_radiosity::state::bind_common() const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, texels_binding, texels.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, nodes_binding, nodes.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, planes_binding, planes.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, first_binding, first_buffer.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, element_binding, element_texel.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, partial_binding, partials.id());
    glBindImageTexture(radiosity_unit, radiosity.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(unshot_unit, unshot.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(intercepted_unit, intercepted.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(item_unit, item_color.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
}

progressive_radiosity::state::reduction progressive_radiosity::state::reduce() {
    const auto start = clock_type::now();
    {
        binding_state saved;
        bind_common();
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        glUseProgram(reduce_program->id());
        namespace u = radiosity_glsl::reduce_uniform;
        reduce_program->set(u::atlas_width, int(width));
        reduce_program->set(u::atlas_height, int(height));
        reduce_program->set(u::shooter_count, unsigned(blocks() * sides));
        reduce_program->set(u::blocks, unsigned(blocks()));
        glDispatchCompute(GLuint((blocks() * sides + reduce_group - 1) / reduce_group), 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        glUseProgram(finish_program->id());
        finish_program->set(radiosity_glsl::finish_uniform::shooter_count, unsigned(blocks() * sides));
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        check_error("progressive_radiosity: the shooter reduction");
    }
    std::array<double, 9> r{};
    partials.read(0, r.data(), sizeof(double) * 9);
    next_power = std::max(0.0, r[0]);
    next = std::uint32_t(std::clamp(r[1], 0.0, double(blocks() * sides - 1)));
    unshot_total = r[2];
    timings.choice_ms += ms_since(start);
    return {{r[3], r[4], r[5]}, {r[6], r[7], r[8]}};
}

void progressive_radiosity::state::set_shot(glm::vec3 position, glm::vec3 axis, float chart) {
    shot_position = position;
    shot_axis = axis;
    shot_chart = chart;
    const auto tb = orthonormal_basis<float, glm::vec3>(axis);
    t = tb[0];
    b = tb[1];
}

void progressive_radiosity::state::set_frame_uniforms(const program& p, int t_location, int b_location,
                                                      int n_location) const {
    p.set(t_location, t);
    p.set(b_location, b);
    p.set(n_location, shot_axis);
}

float progressive_radiosity::state::farthest_from_shot() const {
    float far_distance = 0.f;
    for (int m = 0; m < 8; ++m) {
        const glm::vec3 corner((m & 1) ? hi.x : lo.x, (m & 2) ? hi.y : lo.y, (m & 4) ? hi.z : lo.z);
        far_distance = std::max(far_distance, glm::length(corner - shot_position));
    }
    return far_distance;
}

void progressive_radiosity::state::draw_item_buffer() {
    // The triangles in the shooter's frame, clipped above its plane and tessellated until no
    // projected edge bends more than tolerance_px from its chord (cpu::item_buffer_visibility).
    pieces.clear();
    const float res = float(options.resolution);
    const float z_min = 1e-6f * diagonal;
    const stereographic_tessellation how{res, options.tolerance_px, options.max_tessellation_depth};
    std::vector<glm::vec3> poly, scratch;
    for (std::size_t k = 0; k < corners.size(); ++k) {
        if (float(triangle_chart[k]) == shot_chart) continue;
        std::array<glm::vec3, 3> l;
        for (int m = 0; m < 3; ++m)
            l[std::size_t(m)] = to_shooter_frame<float, glm::vec3>(corners[k][std::size_t(m)], shot_position, t, b, shot_axis);
        if (l[0].z < z_min && l[1].z < z_min && l[2].z < z_min) continue;
        local_plane[k] = shooter_plane<float, glm::vec3, glm::vec4>(glm::vec3(world_plane[k]), l[0], t, b, shot_axis);
        const float chart = float(triangle_chart[k]), id = float(k);
        // The CPU's pieces in the CPU's order (radiosity/stereographic_tessellation.hpp).
        clip_and_tessellate_stereographic(l, z_min, how, poly, scratch,
                                          [&](const std::array<glm::vec3, 3>& piece, const std::array<glm::vec2, 3>&) {
                                              for (const glm::vec3& v : piece) pieces.push_back({v, chart, id});
                                          });
    }
    drawn = pieces.size() / 3;
    planes.write(0, local_plane.data(), local_plane.size() * sizeof(glm::vec4));
    if (pieces.size() > vertex_capacity) {
        vertex_capacity = std::max<std::size_t>(pieces.size() * 2, 1024);
        vertices = std::make_unique<buffer>(vertex_capacity * sizeof(item_vertex));
        attach_item_vertices(item_vao.id(), vertices->id());
    }
    if (!pieces.empty()) vertices->write(0, pieces.data(), pieces.size() * sizeof(item_vertex));

    // The farthest the scene can be from the shooter: the depth attachment's scale.
    const float far_distance = farthest_from_shot();
    detail::raster_state raster;
    binding_state saved;
    clear_and_bind_item_target(item_fbo.id());
    glViewport(0, 0, options.resolution, options.resolution);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, planes_binding, planes.id());
    glUseProgram(item_program->id());
    item_program->set(radiosity_glsl::item_uniform::resolution, res);
    item_program->set(radiosity_glsl::item_uniform::depth_scale, far_distance * 1.01f + 1e-6f * diagonal);
    glBindVertexArray(item_vao.id());
    if (!pieces.empty()) glDrawArrays(GL_TRIANGLES, 0, GLsizei(pieces.size()));
    check_error("progressive_radiosity: drawing the item buffer");
}

void progressive_radiosity::state::draw_visibility() {
    if (options.visibility == radiosity_visibility::stereographic) draw_item_buffer();
    else if (options.visibility == radiosity_visibility::hemicube) draw_hemicube();
}

void progressive_radiosity::state::world_vertices() {
    if (cube_vertices) return;
    std::vector<item_vertex> v;
    for (std::size_t k = 0; k < corners.size(); ++k)
        for (int m = 0; m < 3; ++m) v.push_back({corners[k][std::size_t(m)], float(triangle_chart[k]), float(k)});
    cube_vertex_count = v.size();
    cube_vertices = std::make_unique<buffer>(std::max<std::size_t>(v.size(), 1) * sizeof(item_vertex), v.data());
    attach_item_vertices(cube_vao.id(), cube_vertices->id());
}

void progressive_radiosity::state::draw_parallel() {
    const int res = options.parallel_resolution;
    if (!parallel_fbo) {
        parallel_color = std::make_unique<texture>(texel_format::rgba32f, std::size_t(res), std::size_t(res));
        parallel_depth = std::make_unique<texture>(texel_format::depth32f, std::size_t(res), std::size_t(res));
        parallel_fbo = std::make_unique<framebuffer>();
        parallel_fbo->attach_color(0, *parallel_color);
        parallel_fbo->attach_depth(*parallel_depth);
        parallel_fbo->set_draw_buffers(1);
        parallel_fbo->check_complete();
    }
    world_vertices();
    // The planes the lookup reads are the world planes here.
    std::vector<glm::vec4> wp(world_plane);
    wp.resize(local_plane.size(), glm::vec4(0.f, 0.f, 1.f, 0.f));
    planes.write(0, wp.data(), wp.size() * sizeof(glm::vec4));
    // The scene's box projected across the light, widened by a pixel each side
    // (radiosity/kernels.hpp, cpu::item_buffer_visibility's parallel buffer); its extent
    // along the light.
    std::tie(ortho_lo, ortho_scale) = parallel_item_window<float, glm::vec3, glm::vec2>(lo, hi, t, b, float(res));
    float d0 = std::numeric_limits<float>::max(), d1 = -std::numeric_limits<float>::max();
    for (int m = 0; m < 8; ++m) {
        const glm::vec3 corner((m & 1) ? hi.x : lo.x, (m & 2) ? hi.y : lo.y, (m & 4) ? hi.z : lo.z);
        d0 = std::min(d0, glm::dot(corner, shot_axis));
        d1 = std::max(d1, glm::dot(corner, shot_axis));
    }
    const float margin = 0.01f * diagonal;
    detail::raster_state raster;
    binding_state saved;
    clear_and_bind_item_target(parallel_fbo->id());
    glViewport(0, 0, res, res);
    const program& p = *parallel_program;
    glUseProgram(p.id());
    namespace u = radiosity_glsl::parallel_uniform;
    set_frame_uniforms(p, u::shot_t, u::shot_b, u::shot_n);
    p.set(u::ortho_lo, ortho_lo);
    p.set(u::ortho_scale, ortho_scale);
    p.set(u::parallel_resolution, float(res));
    p.set(u::depth_lo, d0 - margin);
    p.set(u::depth_hi, d1 + margin);
    glBindVertexArray(cube_vao.id());
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(cube_vertex_count));
    drawn = cube_vertex_count / 3;
    check_error("progressive_radiosity: drawing the directional light's buffer");
}

void progressive_radiosity::state::draw_hemicube() {
    // Each triangle's plane in the shooter's frame, facing away from it, for the lookup.
    for (std::size_t k = 0; k < corners.size(); ++k)
        local_plane[k] = shooter_plane<float, glm::vec3, glm::vec4>(
            glm::vec3(world_plane[k]), to_shooter_frame<float, glm::vec3>(corners[k][0], shot_position, t, b, shot_axis), t,
            b, shot_axis);
    planes.write(0, local_plane.data(), local_plane.size() * sizeof(glm::vec4));
    world_vertices();
    const float far_z = farthest_from_shot() * 1.01f + 1e-6f * diagonal, near_z = 1e-6f * diagonal;
    detail::raster_state raster;
    binding_state saved;
    clear_and_bind_item_target(item_fbo.id());
    const program& p = *cube_program;
    glUseProgram(p.id());
    namespace u = radiosity_glsl::hemicube_uniform;
    p.set(u::shot_position, shot_position);
    set_frame_uniforms(p, u::shot_t, u::shot_b, u::shot_n);
    p.set(u::near_z, near_z);
    p.set(u::far_z, far_z);
    p.set(u::shot_chart, shot_chart);
    glBindVertexArray(cube_vao.id());
    const float res = float(options.resolution);
    for (int face = 0; face < 5; ++face) {
        // The face's axes and number, drawn into its rows of the buffer (radiosity/kernels.hpp).
        const auto axes = hemicube_face_axes<glm::vec3>(face);
        p.set(u::face_right, axes[0]);
        p.set(u::face_up, axes[1]);
        p.set(u::face_forward, axes[2]);
        p.set(u::face, float(face));
        glViewport(0, GLint(hemicube_face_first_row(float(face), res)), GLsizei(res),
                   GLsizei(hemicube_face_rows(float(face), res)));
        glDrawArrays(GL_TRIANGLES, 0, GLsizei(cube_vertex_count));
    }
    drawn = 5 * cube_vertex_count / 3;
    check_error("progressive_radiosity: drawing the hemicube");
}

std::vector<glm::vec3> progressive_radiosity::state::read_elements(const texture& tex, int side) const {
    require(side >= 0 && std::uint32_t(side) < sides, "side", sides == 2 ? "must be 0 or 1" : "must be 0 (one-sided)");
    const std::vector<float> all = tex.read_floats();
    std::vector<glm::vec3> out(atlas.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const std::size_t row = std::size_t(atlas.texel[i].y) + std::size_t(side) * height;
        const std::size_t at = 4 * (row * width + atlas.texel[i].x);
        out[i] = glm::vec3(all[at], all[at + 1], all[at + 2]);
    }
    return out;
}

void progressive_radiosity::state::shoot(std::uint32_t k) {
    auto start = clock_type::now();
    // Block `block`'s elements on `side` (their rows of the textures): they shoot into the
    // hemisphere of that side's normal.
    const std::uint32_t block = std::uint32_t(k % blocks()), side = std::uint32_t(k / blocks());
    const std::uint32_t i0 = first[block], i1 = first[block + 1];
    // The shooter's texels, read back: its power and its near-field tree (the CPU solver's
    // build_near_tree: elements, then 2 x 2 groups of its grid cells, ..., the block last);
    // then cleared.
    const glm::uvec4 r = rect[block] + glm::uvec4(0u, side * height, 0u, 0u);
    std::vector<glm::vec4> texels_back(std::size_t(r.z) * r.w);
    {
        detail::pack_state pack;
        glGetTextureSubImage(unshot.id(), 0, GLint(r.x), GLint(r.y), 0, GLsizei(r.z), GLsizei(r.w), 1, GL_RGBA, GL_FLOAT,
                             GLsizei(texels_back.size() * sizeof(glm::vec4)), texels_back.data());
        const glm::vec4 zero(0.f);
        glClearTexSubImage(unshot.id(), 0, GLint(r.x), GLint(r.y), 0, GLsizei(r.z), GLsizei(r.w), 1, GL_RGBA, GL_FLOAT,
                           &zero);
        check_error("progressive_radiosity: reading the shooter back");
    }
    // The shooter's unshot radiosity per element, from the texels read back.
    const auto unshot_of = [&](std::uint32_t i) {
        const glm::uvec2 tx = atlas.texel[i] + glm::uvec2(0u, side * height) - glm::uvec2(r.x, r.y);
        return glm::dvec3(glm::vec3(texels_back[std::size_t(tx.y) * r.z + tx.x]));
    };
    glm::dvec3 power(0.0);
    for (std::uint32_t i = i0; i < i1; ++i) power += unshot_of(i) * double(atlas.area[i]);
    upload_near_tree(block, unshot_of);
    set_block_shot(block, side);
    draw_visibility();
    if (options.timed_stages) finish();
    timings.visibility_ms += ms_since(start);

    start = clock_type::now();
    distribute(shot_chart, false);
    if (options.timed_stages) finish();
    timings.distribution_ms += ms_since(start);
    reduction got = reduce();
    // At most its own power (shot_scale, as the CPU solver scales it).
    const glm::dvec3 scale = shot_scale(power, got.intercepted);
    if (scale != glm::dvec3(1.0)) {
        rescale(glm::vec3(scale));
        got = reduce();
        ++clamped_shots;
    }
    for (std::uint32_t i = i0; i < i1; ++i) effective_shot[side * atlas.size() + i] += glm::vec3(unshot_of(i) * scale);
    absorbed += got.absorbed;
    escaped += power - got.intercepted;
    intercepted_power += got.intercepted;
    record_ambient(power, got);
    shot_power += power.x + power.y + power.z;
    ++shots;
}

void progressive_radiosity::state::set_block_shot(std::uint32_t block, std::uint32_t side) {
    const std::uint32_t i0 = first[block];
    set_shot(centre[block], side_normal<float, glm::vec3>(atlas.normal[i0], float(side)), float(atlas.chart[i0]));
}

void progressive_radiosity::state::distribute(float chart, bool masked) {
    binding_state saved;
    bind_common();
    if (masked) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, radiosity_glsl::keep_binding, keep->id());
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    const program& p = *distribute_program;
    glUseProgram(p.id());
    set_shot_uniforms(p, chart, options.visibility == radiosity_visibility::hemicube);
    namespace u = radiosity_glsl::distribute_uniform;
    p.set(u::node_count, int(near.size()));
    p.set(u::near2, float(options.shooting.near_field * options.shooting.near_field));
    p.set(u::masked, masked ? 1 : 0);
    glDispatchCompute(GLuint((atlas.size() + 63) / 64), 1, 1);
    check_error("progressive_radiosity: the distribution pass");
}

void progressive_radiosity::state::rescale(glm::vec3 scale) {
    const auto start = clock_type::now();
    {
        binding_state saved;
        bind_common();
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        const program& p = *rescale_program;
        glUseProgram(p.id());
        p.set(radiosity_glsl::rescale_uniform::atlas_width, int(width));
        p.set(radiosity_glsl::rescale_uniform::atlas_height, int(height));
        p.set(radiosity_glsl::rescale_uniform::sides, int(sides));
        p.set(radiosity_glsl::rescale_uniform::element_count, unsigned(atlas.size()));
        p.set(radiosity_glsl::rescale_uniform::scale, scale);
        glDispatchCompute(GLuint((atlas.size() + 63) / 64), 1, 1);
        check_error("progressive_radiosity: scaling a shot to its power");
    }
    if (options.timed_stages) finish();
    timings.distribution_ms += ms_since(start);
}

void progressive_radiosity::state::set_shot_uniforms(const program& p, float chart, bool hemicube) const {
    namespace u = radiosity_glsl::shot_uniform;
    p.set(u::atlas_width, int(width));
    p.set(u::atlas_height, int(height));
    p.set(u::shot_position, shot_position);
    set_frame_uniforms(p, u::shot_t, u::shot_b, u::shot_n);
    p.set(u::shot_chart, chart);
    p.set(u::occlusion, options.visibility != radiosity_visibility::none ? 1 : 0);
    p.set(u::resolution, float(options.resolution));
    p.set(u::diagonal, diagonal);
    p.set(u::hemicube, hemicube ? 1 : 0);
    p.set(u::element_count, unsigned(atlas.size()));
    p.set(u::two_sided, sides == 2 ? 1 : 0);
}

void progressive_radiosity::state::set_light_uniforms(const program& p, const packed_light& l, bool spot,
                                                      bool strict_side, bool parallel, float sign) const {
    namespace u = radiosity_glsl::light_uniform;
    p.set(u::spot, spot ? 1 : 0);
    p.set(u::light_axis, l.direction());
    p.set(u::intensity, sign * l.intensity());
    p.set(u::cos_cone, l.cos_cone());
    p.set(u::cosine_falloff, l.cosine_falloff());
    p.set(u::strict_side, strict_side ? 1 : 0);
    p.set(u::parallel, parallel ? 1 : 0);
    p.set(u::ortho_lo, ortho_lo);
    p.set(u::ortho_scale, ortho_scale);
    p.set(u::parallel_resolution, float(options.parallel_resolution));
}

void progressive_radiosity::state::light_pass(const packed_light& l, bool spot, bool strict_side, bool parallel, float sign) {
    {
        binding_state saved;
        bind_common();
        // A directional light looks its elements up in its own orthographic buffer.
        if (parallel && parallel_color)
            glBindImageTexture(item_unit, parallel_color->id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        const program& p = *light_program;
        glUseProgram(p.id());
        set_shot_uniforms(p, -2.f, !parallel && options.visibility == radiosity_visibility::hemicube);
        set_light_uniforms(p, l, spot, strict_side, parallel, sign);
        glDispatchCompute(GLuint((atlas.size() + 63) / 64), 1, 1);
        check_error(parallel ? "progressive_radiosity: shooting a directional light" : "progressive_radiosity: shooting a light");
    }
    const reduction got = reduce();
    emitted += got.intercepted;
    intercepted_power += got.intercepted;
    absorbed += got.absorbed;
}

void progressive_radiosity::state::shoot_light(const packed_light& l, float sign) {
    const light_kind kind = l.kind();
    if (kind == light_kind::directional) {
        set_shot(glm::vec3(0.f), l.direction(), -2.f);
        if (options.visibility != radiosity_visibility::none) draw_parallel();
        light_pass(l, false, false, true, sign);
        return;
    }
    const glm::vec3 axis = kind == light_kind::spot ? l.direction() : glm::vec3(0, 0, 1);
    std::vector<glm::vec3> axes{axis};
    // A point light, or a spot wider than a hemisphere, needs the other half too.
    if (kind == light_kind::point || l.cos_cone() < 0.f) axes.push_back(-axis);
    for (std::size_t h = 0; h < axes.size(); ++h) {
        set_shot(l.position(), axes[h], -2.f);
        draw_visibility();
        light_pass(l, kind == light_kind::spot, h != 0, false, sign);
    }
}

}  // namespace bounce::gl
