// gl::progressive_radiosity's ambient term shaped by its shots (radiosity/ambient.hpp,
// radiosity_ambient::shots and ::mixed), as cpu::shot_ambient_state keeps it: the window's sums
// and weights are radiosity/ambient_window.hpp's; its irradiance h per element-side stays on
// the GPU, in a texture with the radiosity's rows, raised after each surface shot by a compute
// pass from the intercepted power the distribution wrote (lights are not recorded, as on the
// CPU). The mixed term's deficit is summed on the GPU for the lightmap pass, or from h read
// back where the caller reads the radiosity back anyway (display_radiosity, output).
#include "radiosity_state.hpp"

namespace bounce::gl {

void progressive_radiosity::state::record_ambient(const glm::dvec3& power, const reduction& got) {
    if (!shot_ambient_window::shaped(options.shooting)) return;
    if (!window_irradiance) {
        window_irradiance = std::make_unique<texture>(texel_format::rgba32f, width, std::size_t(height) * sides);
        const glm::vec4 zero(0.f);
        glClearTexImage(window_irradiance->id(), 0, GL_RGBA, GL_FLOAT, &zero);
        window_record_program = std::make_unique<program>(program::compute(radiosity_glsl::window_record_compute()));
        window_deficit_program = std::make_unique<program>(program::compute(radiosity_glsl::window_deficit_compute()));
        window_deficit = std::make_unique<buffer>(3 * sizeof(double));
    }
    // h = (h + received scale w) k: the shot at the weight before record(), then the rescale.
    const double w = ambient_window.weight();
    const double k = ambient_window.record(power, got.intercepted, got.absorbed, unshot_total);
    const auto start = clock_type::now();
    {
        binding_state saved;
        glBindImageTexture(intercepted_unit, intercepted.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
        const program& p = *window_record_program;
        use_window_pass(p, GL_READ_WRITE);
        namespace u = radiosity_glsl::window_uniform;
        p.set(u::keep, float(k));
        p.set(u::weight, float(w * k));
        glDispatchCompute(GLuint((atlas.size() + 63) / 64), 1, 1);
        check_error("progressive_radiosity: recording a shot for the ambient term");
    }
    timings.distribution_ms += ms_since(start);
}

void progressive_radiosity::state::use_window_pass(const program& p, GLenum access) const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, texels_binding, texels.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, element_binding, element_texel.id());
    glBindImageTexture(radiosity_glsl::window_unit, window_irradiance->id(), 0, GL_FALSE, 0, access, GL_RGBA32F);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    glUseProgram(p.id());
    namespace u = radiosity_glsl::window_uniform;
    p.set(u::atlas_width, int(width));
    p.set(u::atlas_height, int(height));
    p.set(u::element_count, unsigned(atlas.size()));
    p.set(u::sides, int(sides));
}

std::optional<shot_ambient_terms> progressive_radiosity::state::ambient_terms(const glm::dvec3& unshot,
                                                                              std::vector<glm::vec3>* h) const {
    if (!shot_ambient_window::shaped(options.shooting) || !window_irradiance || ambient_window.empty()) return std::nullopt;
    shot_ambient_terms t = ambient_window.terms(options.shooting.ambient_shape, unshot, total_area * double(sides));
    if (h) {
        const std::vector<float> all = window_irradiance->read_floats();
        const std::size_t n = atlas.size();
        h->resize(n * sides);
        for (std::size_t side = 0; side < sides; ++side)
            for (std::size_t i = 0; i < n; ++i) {
                const std::size_t at = 4 * ((std::size_t(atlas.texel[i].y) + side * height) * width + atlas.texel[i].x);
                (*h)[side * n + i] = glm::vec3(all[at], all[at + 1], all[at + 2]);
            }
        if (t.shape == radiosity_ambient::mixed) t.with_deficit(t.deficit(std::span<const glm::vec3>(*h), atlas.area));
        return t;
    }
    if (t.shape != radiosity_ambient::mixed) return t;
    {
        binding_state saved;
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, partial_binding, window_deficit->id());
        const program& p = *window_deficit_program;
        use_window_pass(p, GL_READ_ONLY);
        namespace u = radiosity_glsl::window_uniform;
        p.set(u::factor, glm::vec3(t.factor));
        p.set(u::floor, glm::vec3(t.floor));
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        check_error("progressive_radiosity: the mixed ambient term's deficit");
    }
    glm::dvec3 deficit(0.0);
    window_deficit->read(0, &deficit[0], 3 * sizeof(double));
    t.with_deficit(deficit);
    return t;
}

std::vector<glm::vec3> progressive_radiosity::ambient_field(int side) const {
    require(side >= 0 && side < sides(), "side", two_sided() ? "must be 0 or 1" : "must be 0 (one-sided)");
    return ambient_field(side, radiosity(side));
}

std::vector<glm::vec3> progressive_radiosity::ambient_field(int side, const std::vector<glm::vec3>& b) const {
    const state& st = *s_;
    const std::size_t n = st.atlas.size();
    if (!st.options.shooting.ambient) return std::vector<glm::vec3>(n, glm::vec3(0.f));
    const glm::dvec3 u = unshot_power();
    std::vector<glm::vec3> h;
    const auto t = st.ambient_terms(u, &h);
    std::vector<glm::vec3> out(n, glm::vec3(cohen_ambient(u, st.total_area, st.albedo_area, int(st.sides))));
    if (t)
        for (std::size_t i = 0; i < n; ++i) out[i] = t->at(h[std::size_t(side) * n + i]);
    // At least minus what the shots delivered, (B - direct) / rho, as the CPU solver clamps it at
    // its gathered irradiance: negative after a re-bake dims a light (radiosity/rebake.hpp).
    const std::size_t o = std::size_t(side) * n;
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            if (const float rho = st.atlas.albedo[i][c]; rho > 0.f) out[i][c] = std::max(out[i][c], (direct_[o + i][c] - b[i][c]) / rho);
    return out;
}

const shot_ambient_window& progressive_radiosity::ambient_window() const noexcept { return s_->ambient_window; }

}  // namespace bounce::gl
