#pragma once
// What gl::progressive_radiosity keeps between steps (its state) and the GL plumbing its
// passes share: private to adapters/gl/src, included by radiosity.cpp (the public type),
// radiosity_passes.cpp (the programs) and radiosity_shooting.cpp (a shot's passes).
#include <bounce/gl/radiosity.hpp>

#include <bounce/glsl/emit.hpp>
#include <bounce/light.hpp>
#include <bounce/direct_light.hpp>
#include <bounce/radiosity/ambient_window.hpp>
#include <bounce/radiosity/kernels.hpp>
#include <bounce/radiosity/rebake.hpp>
#include <bounce/radiosity/shooters.hpp>
#include <bounce/radiosity/sides.hpp>
#include <bounce/radiosity/solve.hpp>
#include <bounce/sampling.hpp>
#include <bounce/radiosity/stereographic_tessellation.hpp>

#include "radiosity_shaders.hpp"
#include "saved_state.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <tuple>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

namespace bounce::gl {

namespace radiosity_detail {

using clock_type = std::chrono::steady_clock;
inline double ms_since(clock_type::time_point t) { return std::chrono::duration<double, std::milli>(clock_type::now() - t).count(); }

// Storage-buffer bindings and image units the passes use (named with their shaders).
using radiosity_glsl::texels_binding, radiosity_glsl::nodes_binding, radiosity_glsl::planes_binding,
    radiosity_glsl::first_binding, radiosity_glsl::element_binding, radiosity_glsl::partial_binding;
using radiosity_glsl::radiosity_unit, radiosity_glsl::unshot_unit, radiosity_glsl::intercepted_unit,
    radiosity_glsl::item_unit;
constexpr unsigned reduce_group = 64;
// The reduction's buffer: the result (best power, best index, total unshot, intercepted rgb,
// absorbed rgb) in the first 9 doubles, then from double 16 on 8 per shooter (power, intercepted rgb, absorbed rgb).
constexpr std::size_t partial_doubles = 8;

// The bindings the passes change beyond raster_state: program, the storage buffers and image
// units above; restored on destruction.
class binding_state {
public:
    binding_state() {
        glGetIntegerv(GL_CURRENT_PROGRAM, &program_);
        glGetIntegerv(GL_SHADER_STORAGE_BUFFER_BINDING, &generic_);
        for (GLuint i = 0; i < storage_.size(); ++i) {
            glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, i, &storage_[i].buffer);
            glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_START, i, &storage_[i].start);
            glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_SIZE, i, &storage_[i].size);
        }
        for (GLuint i = 0; i < images_.size(); ++i) {
            image& m = images_[i];
            glGetIntegeri_v(GL_IMAGE_BINDING_NAME, i, &m.name);
            glGetIntegeri_v(GL_IMAGE_BINDING_LEVEL, i, &m.level);
            glGetIntegeri_v(GL_IMAGE_BINDING_LAYERED, i, &m.layered);
            glGetIntegeri_v(GL_IMAGE_BINDING_LAYER, i, &m.layer);
            glGetIntegeri_v(GL_IMAGE_BINDING_ACCESS, i, &m.access);
            glGetIntegeri_v(GL_IMAGE_BINDING_FORMAT, i, &m.format);
        }
    }
    ~binding_state() {
        for (GLuint i = 0; i < images_.size(); ++i) {
            const image& m = images_[i];
            glBindImageTexture(i, GLuint(m.name), m.level, GLboolean(m.layered), m.layer, GLenum(m.access),
                               GLenum(m.format));
        }
        for (GLuint i = 0; i < storage_.size(); ++i) {
            const auto& b = storage_[i];
            if (b.size > 0) glBindBufferRange(GL_SHADER_STORAGE_BUFFER, i, GLuint(b.buffer), b.start, b.size);
            else glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, GLuint(b.buffer));
        }
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, GLuint(generic_));
        glUseProgram(GLuint(program_));
    }
    binding_state(const binding_state&) = delete;
    binding_state& operator=(const binding_state&) = delete;

private:
    struct storage {
        GLint buffer = 0;
        GLint64 start = 0, size = 0;
    };
    struct image {
        GLint name = 0, level = 0, layered = 0, layer = 0, access = GL_READ_ONLY, format = GL_RGBA32F;
    };
    GLint program_ = 0, generic_ = 0;
    std::array<storage, 7> storage_{};
    std::array<image, 4> images_{};
};

// One vertex of the item buffer's vertex stream: shooter-frame position, chart, triangle.
struct item_vertex {
    glm::vec3 local;
    float chart, triangle;
};

// std430 layouts shared with the shaders.
struct texel_attributes {
    glm::vec4 position_area{0.f};  // world position, area (0: not an element's texel)
    glm::vec4 normal_chart{0.f};   // unit normal, chart
    glm::vec4 albedo{0.f};         // rho, unused
};
struct gpu_node {
    glm::vec4 position_area;
    glm::vec4 unshot;
    std::array<std::int32_t, 4> meta;  // first child, child count (0: a leaf)
};

// Rows of the item buffer: one square, or the hemicube's top face (res rows) above its four
// half side faces (res / 2 rows each).
inline std::size_t item_rows(const radiosity_options& o) {
    return std::size_t(o.resolution) * (o.visibility == radiosity_visibility::hemicube ? 3 : 1);
}


}  // namespace radiosity_detail

using namespace radiosity_detail;

struct progressive_radiosity::state {
    lightmap_atlas atlas;
    radiosity_options options;
    std::uint32_t width = 0, height = 0;
    // Two-sided (options.shooting.two_sided): the radiosity, unshot and intercepted textures
    // hold the fronts in rows [0, height) and the backs in rows [height, 2 height); shooter k
    // is block k % blocks on side k / blocks, as on the CPU.
    std::uint32_t sides = 1;
    std::vector<std::uint8_t> emits_back;  // per chart, 1 when it emits from its back (emission_sides)
    std::vector<packed_light> lights;      // the scene's point, spot and directional lights (re-bakes change them)
    // Per element-side (side-major), what its shots delivered from: each shot's unshot
    // radiosity times its scale (shot_scale), summed, as cpu::progressive_radiosity keeps it
    // (its effective_shot_): B = E + rho F S holds for it, and a re-bake re-shoots it.
    std::vector<glm::vec3> effective_shot;
    // Shooters.
    std::vector<std::uint32_t> first;
    std::vector<glm::vec3> centre;
    std::vector<glm::uvec4> rect;  // texel bounding box of each shooter's elements: x, y, w, h
    // Scene triangles with a chart: corners, chart, world plane (unit n, n . x).
    std::vector<std::array<glm::vec3, 3>> corners;
    std::vector<std::uint32_t> triangle_chart;
    std::vector<glm::vec4> world_plane;
    float diagonal = 1.f;
    glm::vec3 lo{0.f}, hi{0.f};
    int max_nodes = 1, stack_size = 4;
    double total_area = 0;
    glm::dvec3 albedo_area{0.0};

    // GL objects.
    texture radiosity, unshot, intercepted, item_color, item_depth;
    framebuffer item_fbo;
    vertex_array item_vao;
    buffer texels, nodes, planes, first_buffer, element_texel, partials;
    std::unique_ptr<buffer> keep;  // a re-bake's receiver mask, one bit per element (keep_binding)
    // B once the lights were shot, per element-side (the radiosity's rows): the display lightmap
    // shows at least it with the ambient term (radiosity_with_ambient_at_least_direct).
    std::unique_ptr<texture> direct_texture;
    std::unique_ptr<buffer> vertices;
    std::size_t vertex_capacity = 0;
    vertex_array cube_vao;
    std::unique_ptr<buffer> cube_vertices;
    std::size_t cube_vertex_count = 0;
    // A directional light's orthographic buffer, made when the scene has one.
    std::unique_ptr<texture> parallel_color, parallel_depth;
    std::unique_ptr<framebuffer> parallel_fbo;
    glm::vec2 ortho_lo{0.f};
    float ortho_scale = 1.f;
    // The display lightmap: element_at as packed source texels (0xffffffff: no chart).
    std::unique_ptr<texture> lightmap_texture;
    std::unique_ptr<buffer> source_texel;
    std::unique_ptr<program> lightmap_program;
    std::unique_ptr<program> item_program, cube_program, parallel_program, distribute_program, light_program, reduce_program, finish_program,
        rescale_program;

    // Per shot, CPU side.
    glm::vec3 shot_position{0.f}, shot_axis{0.f, 0.f, 1.f}, t{1, 0, 0}, b{0, 1, 0};
    float shot_chart = -2.f;
    std::vector<glm::vec4> local_plane;
    std::vector<item_vertex> pieces;
    std::vector<gpu_node> near;
    std::size_t drawn = 0;

    // Bookkeeping (double, per channel), from the reductions.
    glm::dvec3 emitted{0.0}, absorbed{0.0}, escaped{0.0}, intercepted_power{0.0};
    double unshot_total = 0;
    std::uint32_t next = 0;
    double next_power = 0;
    std::size_t steps = 0, shots = 0;
    std::size_t clamped_shots = 0;  // shots scaled down to their power (shot_scale)
    double shot_power = 0;          // power shot by surfaces so far, channels summed (W)
    radiosity_timings timings;

    // The shaped ambient terms (radiosity_ambient.cpp, radiosity/ambient_window.hpp): the window
    // of recent surface shots; its irradiance h per element-side in a texture with the
    // radiosity's rows, made with its passes at the first shot recorded.
    shot_ambient_window ambient_window;
    std::unique_ptr<texture> window_irradiance;
    std::unique_ptr<program> window_record_program, window_deficit_program;
    std::unique_ptr<buffer> window_deficit;

    state(const scene_view& scene, const lightmap_atlas& a, const radiosity_options& o);
    void compile();
    // The element attributes per texel (texel_attributes) from the atlas, uploaded.
    void upload_texel_attributes();
    // The shooters' centres from the atlas's element positions.
    void place_shooters();
    // The triangles the item buffers draw, the scene's box and diagonal, from `scene`.
    void place_triangles(const scene_view& scene);
    // A re-bake's re-shot of block-side k (k % blocks on side k / blocks): its radiosity
    // `shot` (per element-side) times `sign`, unscaled, to the receivers whose bit is set in
    // `keep_bits`, with the geometry as it is; the balance's sums corrected (what it delivers
    // is intercepted, not escaped).
    void reshoot(std::uint32_t k, float sign, const std::vector<glm::vec3>& shot, const std::vector<std::uint32_t>& keep_bits);
    // Every side's element values of t (side-major), read back; and written into t.
    std::vector<glm::vec3> read_sides(const texture& t) const;
    void write_sides(const texture& t, const std::vector<glm::vec3>& values);
    // `direct` (per element-side, side-major) into direct_texture.
    void upload_direct(const std::vector<glm::vec3>& direct);
    struct reduction {
        glm::dvec3 intercepted{0.0}, absorbed{0.0};
    };
    reduction reduce();
    // Adds the surface shot just distributed, of `power`, whose reduction after its scale is
    // `got`, to the window when the options ask for a shaped ambient term.
    void record_ambient(const glm::dvec3& power, const reduction& got);
    // The shaped ambient's terms for the unshot power `unshot`, or none for Cohen's uniform term
    // (not asked for, or no shot recorded yet). With `h`, the window read back into it (per
    // element-side, side-major) and the mixed deficit summed from it; else summed on the GPU.
    std::optional<shot_ambient_terms> ambient_terms(const glm::dvec3& unshot, std::vector<glm::vec3>* h) const;
    // Binds what both window passes read (the window with `access`), uses `p`, sets their uniforms.
    void use_window_pass(const program& p, GLenum access) const;
    void draw_item_buffer();
    void draw_hemicube();
    void draw_parallel();
    void world_vertices();
    void draw_visibility();
    void set_shot(glm::vec3 position, glm::vec3 axis, float chart);
    void shoot(std::uint32_t k);
    // The near-field tree of block `block` (the CPU solver's build_near_tree) from its
    // elements' radiosity_of(i) (glm::dvec3), uploaded for the distribution.
    template <class Radiosity>
    void upload_near_tree(std::uint32_t block, const Radiosity& radiosity_of) {
        near.clear();
        build_near_field_tree(atlas, first[block], first[block + 1], options.shooting.shoot_blocks, block, radiosity_of,
                              [&](glm::dvec3 position, double area, glm::dvec3 mean, std::uint32_t first_child,
                                  std::uint32_t children) {
                                  near.push_back({glm::vec4(glm::vec3(position), float(area)), glm::vec4(glm::vec3(mean), 0.f),
                                                  {std::int32_t(first_child), std::int32_t(children), 0, 0}});
                              });
        require(near.size() <= std::size_t(max_nodes), "atlas", "a shooter's near-field tree outgrew its bound");
        nodes.write(0, near.data(), near.size() * sizeof(gpu_node));
    }
    // The distribution pass of the shot set (set_shot) from chart `chart` with the tree
    // uploaded; `masked`: only the receivers whose bit is set in `keep`.
    void distribute(float chart, bool masked);
    // Side `side` of block `block` as the shot's position, axis and chart.
    void set_block_shot(std::uint32_t block, std::uint32_t side);
    // The last distribution's deliveries times `scale` (per channel, each at most 1).
    void rescale(glm::vec3 scale);
    // The shot of light l; `sign` -1 takes away exactly what it delivered (the same passes,
    // linear in the intensity): a re-bake's old light.
    void shoot_light(const packed_light& l, float sign = 1.f);
    // The light pass for the current shot of light l (the uniforms of set_light_uniforms),
    // then the reduction, whose intercepted power the light emitted.
    void light_pass(const packed_light& l, bool spot, bool strict_side, bool parallel, float sign);
    // The uniforms of shot_uniform on the distribution or light program p, for a shot from
    // chart `chart` (-2: a light) whose visibility is looked up on the hemicube or not.
    void set_shot_uniforms(const program& p, float chart, bool hemicube) const;
    // light_uniform: the light l, its kind flags and the directional light's buffer.
    void set_light_uniforms(const program& p, const packed_light& l, bool spot, bool strict_side, bool parallel,
                            float sign) const;
    // The shooter's frame (t, b, shot_axis) at p's locations for shot_t, shot_b, shot_n.
    void set_frame_uniforms(const program& p, int t_location, int b_location, int n_location) const;
    // The farthest corner of the scene's box from the shot's position.
    float farthest_from_shot() const;
    // Whether element i's emission leaves from side `side` (its front when one-sided).
    bool emits_on(std::size_t i, int side) const {
        const bool back = !emits_back.empty() && emits_back[atlas.chart[i]];
        return back == (side == 1);
    }
    std::size_t blocks() const noexcept { return first.size() - 1; }
    // Element values of side `side` read back from t (one of the textures with a row band per side).
    std::vector<glm::vec3> read_elements(const texture& t, int side) const;
    void bind_common() const;
};


}  // namespace bounce::gl
