// gl::progressive_radiosity: the GL backend of progressive refinement radiosity (Cohen et al.
// 1988; Coombe and Harris 2005). See radiosity/kernels.hpp for the steps and docs/radiosity-gl.md.
#include "radiosity_state.hpp"

#include <numbers>

namespace bounce::gl {

void radiosity_options::validate() const {
    shooting.validate();
    require(shooting.shooters_per_step == 1, "radiosity_options.shooters_per_step", "must be 1 on the GL solver");
    require(shooting.light_samples == 1, "radiosity_options.light_samples",
            "must be 1 on the GL solver, which takes lights at element points");
    require(shooting.shooter_groups == 0, "radiosity_options.shooter_groups",
            "must be 0 on the GL solver, whose item buffers render from one point per shot (grouped shooters: CPU, ray casts)");
    require(resolution >= 8 && resolution <= 8192, "radiosity_options.resolution", "must lie in [8, 8192]");
    require(tolerance_px > 0.f && std::isfinite(tolerance_px), "radiosity_options.tolerance_px", "must be positive");
    require(max_tessellation_depth >= 0 && max_tessellation_depth <= 16, "radiosity_options.max_tessellation_depth",
            "must lie in [0, 16]");
    require(parallel_resolution >= 8 && parallel_resolution <= 16384, "radiosity_options.parallel_resolution",
            "must lie in [8, 16384]");
    require(visibility == radiosity_visibility::stereographic || visibility == radiosity_visibility::hemicube ||
                visibility == radiosity_visibility::none,
            "radiosity_options.visibility", "is not a known method");
    require(visibility != radiosity_visibility::hemicube || resolution % 2 == 0, "radiosity_options.resolution",
            "a hemicube needs an even resolution (its side faces keep half the rows)");
}

// ---- the public type --------------------------------------------------------------------

progressive_radiosity::progressive_radiosity(const scene_view& scene, const lightmap_atlas& atlas,
                                             radiosity_options options) {
    options.validate();
    scene.validate();
    require(atlas.chart_of_triangle.size() == scene.triangles.size(), "atlas",
            "was not built from this scene (triangle counts differ)");
    require(atlas.size() > 0 && atlas.block_first.size() == atlas.blocks() + 1 && atlas.blocks() > 0, "atlas",
            "has no elements");
    require(std::all_of(atlas.block_level.begin(), atlas.block_level.end(), [](std::uint8_t l) { return l == 0; }),
            "atlas", "is subdivided; the GL backend takes base atlases only");
    require(atlas.block_texels >= 1 && atlas.block_texels <= 16, "atlas.block_texels",
            "must lie in [1, 16] for the GL backend (its near-field tree is a fixed-size array)");
    require(atlas.width <= 65535 && atlas.height <= 65535, "atlas", "is wider or taller than 65535 texels");
    if (options.visibility == radiosity_visibility::stereographic) {
        const float finest = stereographic_tolerance_floor(scene, atlas.size(), options.resolution);
        if (options.tolerance_px < finest)
            throw parameter_error("radiosity_options.tolerance_px",
                                  bounce::detail::radiosity_number(options.tolerance_px) +
                                      " px is below what the item buffer resolves here (" + bounce::detail::radiosity_number(finest) +
                                      " px: the rasterizer's vertex snap, or float32 positions at this scene's scale), so "
                                      "it would only tessellate deeper for nothing");
    }
    s_ = std::make_unique<state>(scene, atlas, options);
    const auto start = clock_type::now();
    for (const packed_light& l : s_->lights) s_->shoot_light(l);
    finish();
    s_->timings.lights_ms = ms_since(start);
    for (int side = 0; side < sides(); ++side) {
        const auto d = radiosity(side);
        direct_.insert(direct_.end(), d.begin(), d.end());
    }
    s_->upload_direct(direct_);
    s_->reduce();
    check_lights_reach_surfaces(scene, s_->atlas, s_->emitted, two_sided());
}

progressive_radiosity::~progressive_radiosity() = default;
progressive_radiosity::progressive_radiosity(progressive_radiosity&&) noexcept = default;
progressive_radiosity& progressive_radiosity::operator=(progressive_radiosity&&) noexcept = default;

bool progressive_radiosity::step() {
    if (!(s_->next_power > 0)) return false;
    s_->shoot(s_->next);
    ++s_->steps;
    return true;
}

std::size_t progressive_radiosity::solve(double fraction, const std::function<bool(const radiosity_progress&)>& progress) {
    require(fraction >= 0 && fraction < 1, "fraction", "must lie in [0, 1)");
    radiosity_solve_options o;
    o.converge = 1.0 - fraction;
    o.progress = progress;
    return solve(o).steps;
}

radiosity_solve_report progressive_radiosity::solve(const radiosity_solve_options& options) {
    return bounce::detail::run_radiosity_solve(*this, options, [](std::size_t) { return std::size_t(0); });
}

double progressive_radiosity::unshot_fraction() const noexcept {
    const double e = s_->emitted.x + s_->emitted.y + s_->emitted.z;
    return e > 0 ? s_->unshot_total / e : 0.0;
}
radiosity_progress progressive_radiosity::progress() const noexcept {
    return {s_->steps, s_->shots, unshot_fraction(), 0.0, indirect_unshot_fraction()};
}
double progressive_radiosity::indirect_unshot_fraction() const noexcept {
    const glm::dvec3 rho = s_->albedo_area / s_->total_area;
    return bounce::indirect_unshot_fraction(s_->unshot_total, s_->shot_power, (rho.x + rho.y + rho.z) / 3.0);
}
std::uint32_t progressive_radiosity::next_shooter() const noexcept { return s_->next; }
double progressive_radiosity::next_shooter_power() const noexcept { return s_->next_power; }
std::size_t progressive_radiosity::shooters() const noexcept { return s_->blocks() * s_->sides; }
std::uint32_t progressive_radiosity::shooter_first(std::size_t block) const { return s_->first.at(block); }
int progressive_radiosity::sides() const noexcept { return int(s_->sides); }
std::size_t progressive_radiosity::clamped_shots() const noexcept { return s_->clamped_shots; }
glm::dvec3 progressive_radiosity::emitted_power() const noexcept { return s_->emitted; }
glm::dvec3 progressive_radiosity::absorbed_power() const noexcept { return s_->absorbed; }
glm::dvec3 progressive_radiosity::escaped_power() const noexcept { return s_->escaped; }
glm::dvec3 progressive_radiosity::intercepted_power() const noexcept { return s_->intercepted_power; }
glm::dvec3 progressive_radiosity::unshot_power() const {
    glm::dvec3 sum(0.0);
    for (int side = 0; side < sides(); ++side) {
        const auto u = unshot(side);
        for (std::size_t i = 0; i < u.size(); ++i) sum += glm::dvec3(u[i]) * double(s_->atlas.area[i]);
    }
    return sum;
}
std::vector<glm::vec3> progressive_radiosity::radiosity(int side) const { return s_->read_elements(s_->radiosity, side); }
std::vector<glm::vec3> progressive_radiosity::unshot(int side) const { return s_->read_elements(s_->unshot, side); }
glm::dvec3 progressive_radiosity::ambient() const {
    return cohen_ambient(unshot_power(), s_->total_area, s_->albedo_area, int(s_->sides));
}
std::vector<glm::vec3> progressive_radiosity::display_radiosity(int side) const {
    std::vector<glm::vec3> out = radiosity(side);
    const std::vector<glm::vec3> amb = ambient_field(side, out);
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = radiosity_with_ambient<float, glm::vec3>(out[i], s_->atlas.albedo[i], amb[i]);
    return out;
}
std::vector<glm::vec3> progressive_radiosity::output(output_quantity quantity, light_paths paths, int side) const {
    const lightmap_atlas& at = s_->atlas;
    std::vector<glm::vec3> out = radiosity(side);  // checks the side
    const std::size_t o = at.size() * std::size_t(side);
    const bool direct = paths != light_paths::indirect, indirect = paths != light_paths::direct;
    const std::vector<glm::vec3> amb = indirect ? ambient_field(side, out) : std::vector<glm::vec3>(out.size(), glm::vec3(0.f));
    for (std::size_t i = 0; i < out.size(); ++i) {
        // Reflected radiosity of the parts asked for: rho E (the emission on the side that emits).
        const glm::vec3 emission = s_->emits_on(i, side) ? at.emission[i] : glm::vec3(0.f);
        const glm::vec3 reflected = (direct ? direct_[o + i] - emission : glm::vec3(0.f)) +
                                    (indirect ? out[i] - direct_[o + i] + at.albedo[i] * amb[i] : glm::vec3(0.f));
        if (quantity == output_quantity::radiance) {
            out[i] = (reflected + (direct ? emission : glm::vec3(0.f))) * float(1.0 / std::numbers::pi);
            continue;
        }
        for (int c = 0; c < 3; ++c)
            out[i][c] = at.albedo[i][c] > 0.f ? std::max(reflected[c], 0.f) / at.albedo[i][c] : 0.f;
    }
    return out;
}
image<glm::vec3> progressive_radiosity::lightmap(output_quantity quantity, light_paths paths, int level, int side) const {
    const auto values = output(quantity, paths, side);
    return s_->atlas.to_fine_texels(std::span<const glm::vec3>(values), level);
}
image<glm::vec3> progressive_radiosity::radiosity_lightmap(int level, int side) const {
    const auto values = display_radiosity(side);
    return s_->atlas.to_fine_texels(std::span<const glm::vec3>(values), level);
}
texture_ref progressive_radiosity::update_lightmap_texture(int side) {
    state& st = *s_;
    require(side >= 0 && side < sides(), "side", two_sided() ? "must be 0 or 1" : "must be 0 (one-sided)");
    if (!st.lightmap_program) {
        st.lightmap_program = std::make_unique<program>(program::compute(radiosity_glsl::lightmap_compute()));
        st.lightmap_texture = std::make_unique<texture>(texel_format::rgba32f, st.width, st.height);
        std::vector<std::uint32_t> src(std::size_t(st.width) * st.height, 0xffffffffu);
        for (std::uint32_t y = 0; y < st.atlas.height; ++y)
            for (std::uint32_t x = 0; x < st.atlas.width; ++x)
                if (const std::int32_t e = st.atlas.element_at(x, y); e >= 0) {
                    const glm::uvec2 tx = st.atlas.texel[std::size_t(e)];
                    src[std::size_t(y) * st.width + x] = tx.x | (tx.y << 16);
                }
        st.source_texel = std::make_unique<buffer>(src.size() * sizeof(std::uint32_t), src.data());
    }
    const glm::dvec3 unshot_now = unshot_power();
    const auto shaped = st.ambient_terms(unshot_now, nullptr);  // none: Cohen's uniform term
    const glm::vec3 amb = st.options.shooting.ambient && !shaped
                              ? glm::vec3(cohen_ambient(unshot_now, st.total_area, st.albedo_area, int(st.sides)))
                              : glm::vec3(0.f);
    {
        binding_state saved;
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, texels_binding, st.texels.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, radiosity_glsl::source_binding, st.source_texel->id());
        glBindImageTexture(radiosity_unit, st.radiosity.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
        glBindImageTexture(radiosity_glsl::lightmap_unit, st.lightmap_texture->id(), 0, GL_FALSE, 0, GL_WRITE_ONLY,
                           GL_RGBA32F);
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        const program& p = *st.lightmap_program;
        glUseProgram(p.id());
        namespace u = radiosity_glsl::lightmap_uniform;
        p.set(u::atlas_width, int(st.width));
        p.set(u::atlas_height, int(st.height));
        p.set(u::ambient, amb);
        p.set(u::source_row, side * int(st.height));
        p.set(u::shape, shaped ? (shaped->shape == radiosity_ambient::mixed ? 2 : 1) : 0);
        p.set(u::at_least_direct, st.options.shooting.ambient ? 1 : 0);
        glBindImageTexture(radiosity_glsl::direct_unit, st.direct_texture->id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
        if (shaped) {
            glBindImageTexture(radiosity_glsl::window_unit, st.window_irradiance->id(), 0, GL_FALSE, 0, GL_READ_ONLY,
                               GL_RGBA32F);
            p.set(u::factor, glm::vec3(shaped->factor));
            p.set(u::floor, glm::vec3(shaped->floor));
            p.set(u::scale, glm::vec3(shaped->scale));
        }
        glDispatchCompute((st.width + 7) / 8, (st.height + 7) / 8, 1);
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        check_error("progressive_radiosity: the lightmap pass");
    }
    return texture_ref(*st.lightmap_texture);
}

texture_ref progressive_radiosity::update_output_texture(output_quantity quantity, light_paths paths, int side) {
    const lightmap_atlas& at = s_->atlas;
    const image<glm::vec3> values = lightmap(quantity, paths, 0, side);
    // Atlas row y is texture row y, as update_lightmap_texture writes it.
    std::vector<glm::vec4> texels(std::size_t(s_->width) * s_->height, glm::vec4(0.f));
    for (std::uint32_t y = 0; y < at.height; ++y)
        for (std::uint32_t x = 0; x < at.width; ++x)
            if (at.element_at(x, y) >= 0) texels[std::size_t(y) * s_->width + x] = glm::vec4(values(x, y), 1.f);
    if (!output_texture_) output_texture_.emplace(texel_format::rgba32f, s_->width, s_->height);
    const detail::unpack_state unpack;
    glTextureSubImage2D(output_texture_->id(), 0, 0, 0, GLsizei(s_->width), GLsizei(s_->height), GL_RGBA, GL_FLOAT,
                        texels.data());
    check_error("progressive_radiosity: the output texture");
    return texture_ref(*output_texture_);
}

texture_ref progressive_radiosity::radiosity_texture() const noexcept { return texture_ref(s_->radiosity); }
texture_ref progressive_radiosity::unshot_texture() const noexcept { return texture_ref(s_->unshot); }
const radiosity_timings& progressive_radiosity::timings() const noexcept { return s_->timings; }
const lightmap_atlas& progressive_radiosity::atlas() const noexcept { return s_->atlas; }
const radiosity_options& progressive_radiosity::options() const noexcept { return s_->options; }
std::size_t progressive_radiosity::drawn_triangles() const noexcept { return s_->drawn; }

}  // namespace bounce::gl
