// gl::progressive_radiosity: the GL backend of progressive refinement radiosity (Cohen et al.
// 1988; Coombe and Harris 2005). See radiosity.hpp for the steps and docs/radiosity-gl.md.
#include <bounce/gl/radiosity.hpp>

#include <bounce/glsl/emit.hpp>
#include <bounce/light.hpp>
#include <bounce/lights.hpp>
#include <bounce/radiosity.hpp>
#include <bounce/radiosity_solve.hpp>
#include <bounce/sampling.hpp>
#include <bounce/stereographic_tessellation.hpp>

#include "saved_state.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

namespace bounce::gl {

void radiosity_options::validate() const {
    shooting.validate();
    require(shooting.shooters_per_step == 1, "radiosity_options.shooters_per_step", "must be 1 on the GL solver");
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

namespace {

using clock_type = std::chrono::steady_clock;
double ms_since(clock_type::time_point t) { return std::chrono::duration<double, std::milli>(clock_type::now() - t).count(); }

// Storage-buffer bindings and image units the passes use.
constexpr GLuint texels_binding = 0, nodes_binding = 1, planes_binding = 2, first_binding = 3, element_binding = 4,
                 partial_binding = 5;
constexpr GLuint radiosity_unit = 0, unshot_unit = 1, intercepted_unit = 2, item_unit = 3;
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
    std::array<storage, 6> storage_{};
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

std::string version_header() { return "#version 450 core\n"; }

// Rows of the item buffer: one square, or the hemicube's top face (res rows) above its four
// half side faces (res / 2 rows each).
std::size_t item_rows(const radiosity_options& o) {
    return std::size_t(o.resolution) * (o.visibility == radiosity_visibility::hemicube ? 3 : 1);
}

// The hemicube faces' (right, up, forward) in the shooter's frame: radiosity.hpp's table.
std::array<glm::vec3, 3> face_axes(int face) {
    switch (face) {
        case 1: return {glm::vec3(0, 1, 0), glm::vec3(0, 0, 1), glm::vec3(1, 0, 0)};
        case 2: return {glm::vec3(0, -1, 0), glm::vec3(0, 0, 1), glm::vec3(-1, 0, 0)};
        case 3: return {glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, 1, 0)};
        case 4: return {glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, -1, 0)};
        default: return {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)};
    }
}

}  // namespace

struct progressive_radiosity::state {
    lightmap_atlas atlas;
    radiosity_options options;
    std::uint32_t width = 0, height = 0;
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
    std::unique_ptr<program> item_program, cube_program, parallel_program, distribute_program, light_program, reduce_program, finish_program;

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
    radiosity_timings timings;

    state(const scene_view& scene, const lightmap_atlas& a, const radiosity_options& o);
    void compile();
    struct reduction {
        glm::dvec3 intercepted{0.0}, absorbed{0.0};
    };
    reduction reduce();
    void draw_item_buffer();
    void draw_hemicube();
    void draw_parallel();
    void world_vertices();
    void draw_visibility();
    void set_shot(glm::vec3 position, glm::vec3 axis, float chart);
    void shoot(std::uint32_t k);
    void shoot_light(const packed_light& l);
    std::vector<glm::vec3> read_elements(const texture& t) const;
    void bind_common() const;
};

progressive_radiosity::state::state(const scene_view& scene, const lightmap_atlas& a, const radiosity_options& o)
    : atlas(a),
      options(o),
      width(std::max<std::uint32_t>(a.width, 1)),
      height(std::max<std::uint32_t>(a.height, 1)),
      radiosity(texel_format::rgba32f, width, height),
      unshot(texel_format::rgba32f, width, height),
      intercepted(texel_format::rgba32f, width, height),
      item_color(texel_format::rgba32f, std::size_t(o.resolution), item_rows(o)),
      item_depth(texel_format::depth32f, std::size_t(o.resolution), item_rows(o)),
      texels(std::size_t(width) * height * sizeof(texel_attributes)),
      nodes(std::size_t(1) * sizeof(gpu_node)),
      planes(std::max<std::size_t>(scene.triangles.size(), 1) * sizeof(glm::vec4)),
      first_buffer((a.size() + 1) * sizeof(std::uint32_t)),
      element_texel(std::max<std::size_t>(a.size(), 1) * sizeof(std::uint32_t)),
      partials(sizeof(double)) {
    const std::size_t n = atlas.size();
    // Element attributes per texel, and the initial radiosity and unshot radiosity E.
    std::vector<texel_attributes> attributes(std::size_t(width) * height);
    std::vector<glm::vec4> initial(std::size_t(width) * height, glm::vec4(0.f));
    std::vector<std::uint32_t> packed(std::max<std::size_t>(n, 1), 0u);
    glm::dvec3 emitted_surfaces(0.0);
    for (std::size_t i = 0; i < n; ++i) {
        const glm::uvec2 tx = atlas.texel[i];
        const std::size_t at = std::size_t(tx.y) * width + tx.x;
        attributes[at] = {glm::vec4(atlas.position[i], atlas.area[i]), glm::vec4(atlas.normal[i], float(atlas.chart[i])),
                          glm::vec4(atlas.albedo[i], 0.f)};
        initial[at] = glm::vec4(atlas.emission[i], 0.f);
        packed[i] = tx.x | (tx.y << 16);
        emitted_surfaces += glm::dvec3(atlas.emission[i]) * double(atlas.area[i]);
        total_area += double(atlas.area[i]);
        albedo_area += glm::dvec3(atlas.albedo[i]) * double(atlas.area[i]);
    }
    emitted = emitted_surfaces;
    texels.write(0, attributes.data(), attributes.size() * sizeof(texel_attributes));
    element_texel.write(0, packed.data(), packed.size() * sizeof(std::uint32_t));
    {
        detail::unpack_state unpack;
        for (const texture* tex : {&radiosity, &unshot})
            glTextureSubImage2D(tex->id(), 0, 0, 0, GLsizei(width), GLsizei(height), GL_RGBA, GL_FLOAT, initial.data());
        const glm::vec4 zero(0.f);
        glClearTexImage(intercepted.id(), 0, GL_RGBA, GL_FLOAT, &zero);
        check_error("uploading the radiosity textures");
    }

    // Shooters: blocks or elements, their centres and texel rectangles.
    if (options.shooting.shoot_blocks) first.assign(atlas.block_first.begin(), atlas.block_first.end());
    else {
        first.resize(n + 1);
        std::iota(first.begin(), first.end(), std::uint32_t(0));
    }
    const std::size_t shooters = first.size() - 1;
    centre.resize(shooters);
    rect.resize(shooters);
    for (std::size_t k = 0; k < shooters; ++k) {
        glm::dvec3 c(0.0);
        double area = 0;
        glm::uvec2 mn(std::numeric_limits<std::uint32_t>::max()), mx(0u);
        for (std::uint32_t i = first[k]; i < first[k + 1]; ++i) {
            c += glm::dvec3(atlas.position[i]) * double(atlas.area[i]);
            area += double(atlas.area[i]);
            mn = glm::min(mn, atlas.texel[i]);
            mx = glm::max(mx, atlas.texel[i]);
        }
        centre[k] = glm::vec3(c / area);
        rect[k] = glm::uvec4(mn, mx - mn + 1u);
    }
    std::vector<std::uint32_t> first_padded(first);
    first_buffer = buffer(first_padded.size() * sizeof(std::uint32_t), first_padded.data());
    partials = buffer((shooters + 2) * partial_doubles * sizeof(double));
    // The near-field tree of a block of b x b texels: b^2 + (b/2)^2 + ... nodes at most.
    if (options.shooting.shoot_blocks) {
        int b = atlas.block_texels, count = 0;
        for (;;) {
            count += b * b;
            if (b == 1) break;
            b = (b + 1) / 2;
        }
        max_nodes = count;
        // Depth-first, a stack holds at most 3 siblings waiting per level below the root plus
        // the 4 children just pushed: 3 (levels - 1) + 4 with levels = ceil(log2 b) + 1.
        int levels = 1;
        for (int side = atlas.block_texels; side > 1; side = (side + 1) / 2) ++levels;
        stack_size = 3 * (levels - 1) + 4;
    }
    nodes = buffer(std::size_t(max_nodes) * sizeof(gpu_node));

    // Triangles that have a chart.
    for (std::size_t tri = 0; tri < scene.triangles.size(); ++tri) {
        if (atlas.chart_of_triangle[tri] == lightmap_atlas::none) continue;
        const auto& ix = scene.triangles[tri];
        corners.push_back({scene.positions[ix.x], scene.positions[ix.y], scene.positions[ix.z]});
        triangle_chart.push_back(atlas.chart_of_triangle[tri]);
        const glm::dvec3 p0(corners.back()[0]), p1(corners.back()[1]), p2(corners.back()[2]);
        const glm::dvec3 nn = glm::normalize(glm::cross(p1 - p0, p2 - p0));
        world_plane.emplace_back(glm::vec3(nn), float(glm::dot(nn, p0)));
    }
    const auto [blo, bhi] = scene.bounds();
    lo = blo;
    hi = bhi;
    diagonal = std::max(glm::length(hi - lo), 1e-30f);
    local_plane.assign(std::max<std::size_t>(corners.size(), 1), glm::vec4(0.f, 0.f, 1.f, 0.f));

    item_fbo.attach_color(0, item_color);
    item_fbo.attach_depth(item_depth);
    item_fbo.set_draw_buffers(1);
    item_fbo.check_complete();
    compile();
}

void progressive_radiosity::state::compile() {
    using glsl::f32;
    using glsl::vec2;
    using glsl::vec3;
    glsl::function_set fs;
    fs.add("radiosity_item_coords", stereographic_item_coords<f32, vec3, vec2>, "local_position");
    fs.add("radiosity_to_shooter_frame", to_shooter_frame<f32, vec3>, "p", "origin", "t", "b", "n");
    fs.add("radiosity_hemicube_coords", hemicube_face_coords<f32, vec3>, "local_direction");
    fs.add("radiosity_parallel_sees", parallel_item_sees<f32, vec3>, "element", "element_chart", "shown_chart",
           "plane_normal", "plane_offset", "shown_depth", "direction", "diagonal");
    fs.add("radiosity_item_sees", item_buffer_sees<f32, vec3>, "element", "element_chart", "shown_chart",
           "plane_normal", "plane_offset", "shown_depth", "diagonal");
    const std::string lookup_functions = fs.source();

    // Item buffer: the pieces projected by the emitted stereographic map; depth exact at each
    // pixel centre along its direction (stereographic_direction, emitted).
    glsl::function_set vs_fs;
    vs_fs.add("radiosity_item_coords", stereographic_item_coords<f32, vec3, vec2>, "local_position");
    const std::string vertex = version_header() + vs_fs.source() + R"(
layout(location = 0) in vec3 piece_corner;
layout(location = 1) in vec2 ids;
layout(location = 0) noperspective out float radial;
layout(location = 1) flat out vec2 item_ids;
void main() {
    vec2 uv = radiosity_item_coords(piece_corner);
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
    radial = length(piece_corner);
    item_ids = ids;
}
)";
    glsl::function_set fr_fs;
    fr_fs.add("radiosity_pixel_direction", stereographic_direction<f32, vec3, vec2>, "q");
    fr_fs.add("radiosity_plane_depth", item_plane_depth<f32, vec3>, "plane_normal", "plane_offset", "w", "interpolated");
    const std::string fragment = version_header() + fr_fs.source() + R"(
layout(std430, binding = 2) readonly buffer planes_block { vec4 local_plane[]; };
layout(location = 0) uniform float resolution;
layout(location = 1) uniform float depth_scale;
layout(location = 0) noperspective in float radial;
layout(location = 1) flat in vec2 item_ids;
layout(location = 0) out vec4 item;
void main() {
    vec3 w = radiosity_pixel_direction(gl_FragCoord.xy / resolution * 2.0 - 1.0);
    vec4 plane = local_plane[int(item_ids.y)];
    float depth = radiosity_plane_depth(plane.xyz, plane.w, w, radial);
    gl_FragDepth = depth / depth_scale;
    item = vec4(item_ids, depth, 1.0);
}
)";
    item_program = std::make_unique<program>(vertex, fragment);

    // Hemicube faces (Cohen and Greenberg 1985): perspective views of the untessellated
    // triangles, 1/z interpolated by the rasterizer (exact under perspective), depth the
    // distance along the face's forward axis, as cpu::item_buffer_visibility stores it. Side
    // faces keep their upper half: clip y = 2 up - forward maps up / forward in [0, 1] onto
    // the viewport.
    glsl::function_set cube_vs_fs;
    cube_vs_fs.add("radiosity_to_shooter_frame", to_shooter_frame<f32, vec3>, "p", "origin", "t", "b", "n");
    const std::string cube_vertex = version_header() + cube_vs_fs.source() + R"(
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec2 ids;
layout(location = 0) uniform vec3 shot_position;
layout(location = 1) uniform vec3 shot_t;
layout(location = 2) uniform vec3 shot_b;
layout(location = 3) uniform vec3 shot_n;
layout(location = 4) uniform vec3 face_right;
layout(location = 5) uniform vec3 face_up;
layout(location = 6) uniform vec3 face_forward;
layout(location = 7) uniform int side_face;
layout(location = 8) uniform float near_z;
layout(location = 9) uniform float far_z;
layout(location = 0) out float forward_depth;
layout(location = 1) flat out vec2 item_ids;
void main() {
    vec3 l = radiosity_to_shooter_frame(world_position, shot_position, shot_t, shot_b, shot_n);
    vec3 q = vec3(dot(l, face_right), dot(l, face_up), dot(l, face_forward));
    float y = side_face != 0 ? 2.0 * q.y - q.z : q.y;
    float a = (far_z + near_z) / (far_z - near_z), b = -2.0 * far_z * near_z / (far_z - near_z);
    gl_Position = vec4(q.x, y, a * q.z + b, q.z);
    forward_depth = q.z;
    item_ids = ids;
}
)";
    const std::string cube_fragment = version_header() + R"(
layout(location = 9) uniform float far_z;
layout(location = 10) uniform float shot_chart;
layout(location = 0) in float forward_depth;
layout(location = 1) flat in vec2 item_ids;
layout(location = 0) out vec4 item;
void main() {
    if (item_ids.x == shot_chart) discard;
    gl_FragDepth = forward_depth / far_z;
    item = vec4(item_ids, forward_depth, 1.0);
}
)";
    cube_program = std::make_unique<program>(cube_vertex, cube_fragment);

    // A directional light: an orthographic view along it over the scene's box; the depth is
    // the distance along the light, linear, so the rasterizer's depth is exact.
    const std::string parallel_vertex = version_header() + R"(
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec2 ids;
layout(location = 0) uniform vec3 shot_t;
layout(location = 1) uniform vec3 shot_b;
layout(location = 2) uniform vec3 shot_n;
layout(location = 3) uniform vec2 ortho_lo;
layout(location = 4) uniform float ortho_scale;
layout(location = 5) uniform float parallel_resolution;
layout(location = 6) uniform float depth_lo;
layout(location = 7) uniform float depth_hi;
layout(location = 0) out float along;
layout(location = 1) flat out vec2 item_ids;
void main() {
    vec2 pixel = (vec2(dot(world_position, shot_t), dot(world_position, shot_b)) - ortho_lo) * ortho_scale;
    along = dot(world_position, shot_n);
    gl_Position = vec4(pixel / parallel_resolution * 2.0 - 1.0, (along - depth_lo) / (depth_hi - depth_lo) * 2.0 - 1.0, 1.0);
    item_ids = ids;
}
)";
    const std::string parallel_fragment = version_header() + R"(
layout(location = 0) in float along;
layout(location = 1) flat in vec2 item_ids;
layout(location = 0) out vec4 item;
void main() { item = vec4(item_ids, along, 1.0); }
)";
    parallel_program = std::make_unique<program>(parallel_vertex, parallel_fragment);

    const std::string common = R"(
struct texel_attributes { vec4 position_area; vec4 normal_chart; vec4 albedo; };
layout(std430, binding = 0) readonly buffer texels_block { texel_attributes texel[]; };
layout(std430, binding = 2) readonly buffer planes_block { vec4 local_plane[]; };
layout(std430, binding = 4) readonly buffer element_block { uint element_texel[]; };
layout(location = 21) uniform uint element_count;
layout(rgba32f, binding = 0) uniform image2D radiosity_image;
layout(rgba32f, binding = 1) uniform image2D unshot_image;
layout(rgba32f, binding = 2) uniform writeonly image2D intercepted_image;
layout(rgba32f, binding = 3) uniform readonly image2D item_image;
layout(location = 0) uniform int atlas_width;
layout(location = 1) uniform int atlas_height;
layout(location = 2) uniform vec3 shot_position;
layout(location = 3) uniform vec3 shot_t;
layout(location = 4) uniform vec3 shot_b;
layout(location = 5) uniform vec3 shot_n;
layout(location = 6) uniform float shot_chart;
layout(location = 7) uniform int occlusion;
layout(location = 8) uniform float resolution;
layout(location = 9) uniform float diagonal;
layout(location = 20) uniform int hemicube;
// Visibility of the element at world position p (chart `chart`) from the shot: its pixel in
// the stereographic buffer, or on its hemicube face (top face in rows [0, res), side face f
// in rows res + (f - 1) res / 2 on).
float shot_visibility(vec3 p, float chart) {
    if (occlusion == 0) return 1.0;
    vec3 l = radiosity_to_shooter_frame(p, shot_position, shot_t, shot_b, shot_n);
    int res = int(resolution);
    ivec2 pixel;
    if (hemicube != 0) {
        vec3 f = radiosity_hemicube_coords(l);
        int face = clamp(int(f.x + 0.5), 0, 4);
        int rows = face == 0 ? res : res / 2;
        pixel = ivec2(clamp(int(floor(f.y * resolution)), 0, res - 1),
                      clamp(int(floor(f.z * float(rows))), 0, rows - 1) + (face == 0 ? 0 : res + (face - 1) * (res / 2)));
    } else {
        vec2 uv = radiosity_item_coords(l);
        pixel = clamp(ivec2(floor(uv * resolution)), ivec2(0), ivec2(res - 1));
    }
    vec4 item = imageLoad(item_image, pixel);
    vec4 plane = item.x >= 0.0 ? local_plane[int(item.y)] : vec4(0.0, 0.0, 1.0, 0.0);
    return radiosity_item_sees(l, chart, item.x, plane.xyz, plane.w, item.z, diagonal);
}
void receive(ivec2 xy, vec3 gain, vec3 intercepted) {
    imageStore(radiosity_image, xy, imageLoad(radiosity_image, xy) + vec4(gain, 0.0));
    imageStore(unshot_image, xy, imageLoad(unshot_image, xy) + vec4(gain, 0.0));
    imageStore(intercepted_image, xy, vec4(intercepted, 0.0));
}
)";

    glsl::function_set dist_fs;
    dist_fs.add("radiosity_form_factor", disc_form_factor<f32, vec3>, "receiver_position", "receiver_normal",
                "shooter_position", "shooter_normal", "shooter_area");
    dist_fs.add("radiosity_shot", shot_radiosity<f32, vec3>, "receiver_position", "receiver_normal", "receiver_albedo",
                "shooter_position", "shooter_normal", "shooter_area", "shooter_unshot", "visibility");
    dist_fs.add("radiosity_near_field", near_field_opens<f32, vec3>, "receiver", "node_position", "node_area", "near2");
    const std::string distribute = version_header() + "layout(local_size_x = 64) in;\n" +
                                   lookup_functions + dist_fs.source() + common +
                                   "const int max_nodes = " + std::to_string(max_nodes) + ";\n" +
                                   "const int stack_size = " + std::to_string(stack_size) + ";\n" + R"(
struct near_node { vec4 position_area; vec4 unshot; ivec4 meta; };
layout(std430, binding = 1) readonly buffer nodes_block { near_node node[]; };
layout(location = 10) uniform int node_count;
layout(location = 11) uniform float near2;
void main() {
    // One invocation per element, at its texel (the atlas's padding and empty texels cost nothing).
    if (gl_GlobalInvocationID.x >= element_count) return;
    uint code = element_texel[gl_GlobalInvocationID.x];
    ivec2 xy = ivec2(int(code & 0xffffu), int(code >> 16u));
    texel_attributes a = texel[xy.y * atlas_width + xy.x];
    if (!(a.position_area.w > 0.0)) return;
    if (a.normal_chart.w == shot_chart) { imageStore(intercepted_image, xy, vec4(0.0)); return; }
    vec3 pr = a.position_area.xyz, nr = a.normal_chart.xyz, rho = a.albedo.rgb;
    vec3 gain = vec3(0.0), incident = vec3(0.0);
    // The block as one disc where the receiver is farther than near_field times its side,
    // else as its four quadrants, recursively, down to elements: the CPU solver's traversal
    // (a stack, children pushed in order, so terms are summed in its order). Each node is
    // visited at most once, so max_nodes bounds the loop.
    // Most receivers are far from the whole block: one disc, no stack.
    near_node root = node[node_count - 1];
    if (root.meta.y == 0 || !(radiosity_near_field(pr, root.position_area.xyz, root.position_area.w, near2) > 0.5)) {
        float f = radiosity_form_factor(pr, nr, root.position_area.xyz, shot_n, root.position_area.w);
        if (f > 0.0) {
            incident = root.unshot.xyz * f;
            gain = radiosity_shot(pr, nr, rho, root.position_area.xyz, shot_n, root.position_area.w, root.unshot.xyz, 1.0);
        }
    } else {
        int stack[stack_size];
        int top = 0;
        for (int c = 0; c < root.meta.y; ++c) stack[top++] = root.meta.x + c;
        for (int visit = 0; visit < max_nodes && top > 0; ++visit) {
            near_node nd = node[stack[--top]];
            bool near_node_ = radiosity_near_field(pr, nd.position_area.xyz, nd.position_area.w, near2) > 0.5;
            if (nd.meta.y == 0 || !near_node_) {
                float f = radiosity_form_factor(pr, nr, nd.position_area.xyz, shot_n, nd.position_area.w);
                if (f > 0.0) {
                    incident += nd.unshot.xyz * f;
                    gain += radiosity_shot(pr, nr, rho, nd.position_area.xyz, shot_n, nd.position_area.w, nd.unshot.xyz, 1.0);
                }
            } else {
                for (int c = 0; c < nd.meta.y && top < stack_size; ++c) stack[top++] = nd.meta.x + c;
            }
        }
    }
    if (!(incident.x > 0.0 || incident.y > 0.0 || incident.z > 0.0)) { imageStore(intercepted_image, xy, vec4(0.0)); return; }
    float v = shot_visibility(pr, a.normal_chart.w);
    if (!(v > 0.0)) { imageStore(intercepted_image, xy, vec4(0.0)); return; }
    receive(xy, gain * v, incident * (v * a.position_area.w));
}
)";
    distribute_program = std::make_unique<program>(program::compute(distribute));

    glsl::function_set light_fs;
    light_fs.add("radiosity_point_irradiance", point_light_irradiance<f32, vec3>, "p", "n", "light_position",
                 "intensity");
    light_fs.add("radiosity_directional_irradiance", directional_light_irradiance<f32, vec3>, "n", "direction",
                 "irradiance");
    light_fs.add("radiosity_spot_irradiance", spot_light_irradiance<f32, vec3>, "p", "n", "light_position", "axis",
                 "intensity", "cos_cone", "cosine_falloff");
    const std::string light = version_header() + "layout(local_size_x = 64) in;\n" +
                              lookup_functions + light_fs.source() + common + R"(
layout(location = 10) uniform int spot;
layout(location = 11) uniform vec3 light_axis;
layout(location = 12) uniform vec3 intensity;
layout(location = 13) uniform float cos_cone;
layout(location = 14) uniform float cosine_falloff;
layout(location = 15) uniform int strict_side;
layout(location = 16) uniform int parallel;
layout(location = 17) uniform vec2 ortho_lo;
layout(location = 18) uniform float ortho_scale;
layout(location = 19) uniform float parallel_resolution;
// Visibility along a directional light: the element's pixel in the orthographic buffer,
// whose planes are the triangles' world planes.
float parallel_visibility(vec3 p, float chart) {
    if (occlusion == 0) return 1.0;
    vec3 l = radiosity_to_shooter_frame(p, vec3(0.0), shot_t, shot_b, shot_n);
    int res = int(parallel_resolution);
    ivec2 pixel = clamp(ivec2(floor((l.xy - ortho_lo) * ortho_scale)), ivec2(0), ivec2(res - 1));
    vec4 item = imageLoad(item_image, pixel);
    vec4 plane = item.x >= 0.0 ? local_plane[int(item.y)] : vec4(0.0, 0.0, 1.0, 0.0);
    return radiosity_parallel_sees(p, chart, item.x, plane.xyz, plane.w, item.z, shot_n, diagonal);
}
void main() {
    // One invocation per element, at its texel (the atlas's padding and empty texels cost nothing).
    if (gl_GlobalInvocationID.x >= element_count) return;
    uint code = element_texel[gl_GlobalInvocationID.x];
    ivec2 xy = ivec2(int(code & 0xffffu), int(code >> 16u));
    texel_attributes a = texel[xy.y * atlas_width + xy.x];
    if (!(a.position_area.w > 0.0)) return;
    if (a.normal_chart.w == shot_chart) { imageStore(intercepted_image, xy, vec4(0.0)); return; }
    vec3 p = a.position_area.xyz, n = a.normal_chart.xyz;
    // Each element belongs to one hemisphere of the light: z >= 0 of the first, z > 0 of the second.
    float z = dot(p - shot_position, shot_n);
    bool side = parallel != 0 || (strict_side != 0 ? z > 0.0 : z >= 0.0);
    vec3 e = parallel != 0 ? radiosity_directional_irradiance(n, light_axis, intensity)
           : spot != 0     ? radiosity_spot_irradiance(p, n, shot_position, light_axis, intensity, cos_cone, cosine_falloff)
                           : radiosity_point_irradiance(p, n, shot_position, intensity);
    if (!side || !(e.x > 0.0 || e.y > 0.0 || e.z > 0.0)) { imageStore(intercepted_image, xy, vec4(0.0)); return; }
    float v = parallel != 0 ? parallel_visibility(p, a.normal_chart.w) : shot_visibility(p, a.normal_chart.w);
    if (!(v > 0.0)) { imageStore(intercepted_image, xy, vec4(0.0)); return; }
    receive(xy, a.albedo.rgb * (e * v), e * (v * a.position_area.w));
}
)";
    light_program = std::make_unique<program>(program::compute(light));

    // Reduction, in two passes with few barriers (llvmpipe runs a barrier as a switch of
    // every invocation): per shooter (one invocation each) its unshot power, the channel sums
    // times area in double and in element order (the CPU solver's sum), with its elements'
    // intercepted and absorbed power; then one work group of 64 striding over the shooters
    // (ties to the lowest index) and a shared-memory tree over its 64 partial results.
    const std::string reduce = version_header() + R"(
layout(local_size_x = 64) in;
struct texel_attributes { vec4 position_area; vec4 normal_chart; vec4 albedo; };
layout(std430, binding = 0) readonly buffer texels_block { texel_attributes texel[]; };
layout(std430, binding = 3) readonly buffer first_block { uint shooter_first[]; };
layout(std430, binding = 4) readonly buffer element_block { uint element_texel[]; };
layout(std430, binding = 5) buffer partial_block { double partial[]; };
layout(rgba32f, binding = 1) uniform readonly image2D unshot_image;
layout(rgba32f, binding = 2) uniform readonly image2D intercepted_image;
layout(location = 0) uniform int atlas_width;
layout(location = 1) uniform uint shooter_count;
void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= shooter_count) return;
    double power = 0.0;
    dvec3 ic = dvec3(0.0), ab = dvec3(0.0);
    for (uint e = shooter_first[k]; e < shooter_first[k + 1u]; ++e) {
        uint code = element_texel[e];
        ivec2 xy = ivec2(int(code & 0xffffu), int(code >> 16u));
        texel_attributes a = texel[xy.y * atlas_width + xy.x];
        vec4 u = imageLoad(unshot_image, xy);
        power += (double(u.r) + double(u.g) + double(u.b)) * double(a.position_area.w);
        dvec3 got = dvec3(imageLoad(intercepted_image, xy).rgb);
        ic += got;
        ab += (dvec3(1.0) - dvec3(a.albedo.rgb)) * got;
    }
    uint at = (k + 2u) * 8u;
    partial[at] = power;
    partial[at + 1u] = ic.x; partial[at + 2u] = ic.y; partial[at + 3u] = ic.z;
    partial[at + 4u] = ab.x; partial[at + 5u] = ab.y; partial[at + 6u] = ab.z;
}
)";
    reduce_program = std::make_unique<program>(program::compute(reduce));
    const std::string finish = version_header() + R"(
layout(local_size_x = 64) in;
layout(std430, binding = 5) buffer partial_block { double partial[]; };
layout(location = 0) uniform uint shooter_count;
shared double s[64 * 9];
void main() {
    uint i = gl_LocalInvocationID.x;
    double best = -1.0, index = 4294967295.0, total = 0.0;
    dvec3 ic = dvec3(0.0), ab = dvec3(0.0);
    for (uint k = i; k < shooter_count; k += 64u) {
        uint at = (k + 2u) * 8u;
        double p = partial[at];
        if (p > best) { best = p; index = double(k); }
        total += p;
        ic += dvec3(partial[at + 1u], partial[at + 2u], partial[at + 3u]);
        ab += dvec3(partial[at + 4u], partial[at + 5u], partial[at + 6u]);
    }
    s[i * 9u] = best; s[i * 9u + 1u] = index; s[i * 9u + 2u] = total;
    s[i * 9u + 3u] = ic.x; s[i * 9u + 4u] = ic.y; s[i * 9u + 5u] = ic.z;
    s[i * 9u + 6u] = ab.x; s[i * 9u + 7u] = ab.y; s[i * 9u + 8u] = ab.z;
    for (uint stride = 32u; stride > 0u; stride >>= 1u) {
        barrier();
        if (i < stride) {
            uint j = i + stride;
            bool take = s[j * 9u] > s[i * 9u] || (s[j * 9u] == s[i * 9u] && s[j * 9u + 1u] < s[i * 9u + 1u]);
            if (take) { s[i * 9u] = s[j * 9u]; s[i * 9u + 1u] = s[j * 9u + 1u]; }
            for (uint c = 2u; c < 9u; ++c) s[i * 9u + c] += s[j * 9u + c];
        }
    }
    barrier();
    if (i == 0u)
        for (uint c = 0u; c < 9u; ++c) partial[c] = s[c];
}
)";
    finish_program = std::make_unique<program>(program::compute(finish));
}

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
        reduce_program->set(0, int(width));
        reduce_program->set(1, unsigned(first.size() - 1));
        glDispatchCompute(GLuint((first.size() - 1 + reduce_group - 1) / reduce_group), 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        glUseProgram(finish_program->id());
        finish_program->set(0, unsigned(first.size() - 1));
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        check_error("progressive_radiosity: the shooter reduction");
    }
    std::array<double, 9> r{};
    partials.read(0, r.data(), sizeof(double) * 9);
    next_power = std::max(0.0, r[0]);
    next = std::uint32_t(std::clamp(r[1], 0.0, double(first.size() - 2)));
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
        const glm::vec3 nl(glm::dot(glm::vec3(world_plane[k]), t), glm::dot(glm::vec3(world_plane[k]), b),
                           glm::dot(glm::vec3(world_plane[k]), shot_axis));
        const float d = glm::dot(nl, l[0]);
        local_plane[k] = d >= 0.f ? glm::vec4(nl, d) : glm::vec4(-nl, -d);
        const float chart = float(triangle_chart[k]), id = float(k);
        // The CPU's pieces in the CPU's order (stereographic_tessellation.hpp).
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
        glVertexArrayVertexBuffer(item_vao.id(), 0, vertices->id(), 0, GLsizei(sizeof(item_vertex)));
        glEnableVertexArrayAttrib(item_vao.id(), 0);
        glEnableVertexArrayAttrib(item_vao.id(), 1);
        glVertexArrayAttribFormat(item_vao.id(), 0, 3, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribFormat(item_vao.id(), 1, 2, GL_FLOAT, GL_FALSE, GLuint(offsetof(item_vertex, chart)));
        glVertexArrayAttribBinding(item_vao.id(), 0, 0);
        glVertexArrayAttribBinding(item_vao.id(), 1, 0);
    }
    if (!pieces.empty()) vertices->write(0, pieces.data(), pieces.size() * sizeof(item_vertex));

    // The farthest the scene can be from the shooter: the depth attachment's scale.
    float far_distance = 0.f;
    for (int m = 0; m < 8; ++m) {
        const glm::vec3 corner((m & 1) ? hi.x : lo.x, (m & 2) ? hi.y : lo.y, (m & 4) ? hi.z : lo.z);
        far_distance = std::max(far_distance, glm::length(corner - shot_position));
    }
    detail::raster_state raster;
    binding_state saved;
    const std::array<float, 4> none{-1.f, -1.f, std::numeric_limits<float>::max(), 0.f};
    glClearNamedFramebufferfv(item_fbo.id(), GL_COLOR, 0, none.data());
    const float far_depth = 1.f;
    glClearNamedFramebufferfv(item_fbo.id(), GL_DEPTH, 0, &far_depth);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, item_fbo.id());
    glViewport(0, 0, options.resolution, options.resolution);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, planes_binding, planes.id());
    glUseProgram(item_program->id());
    item_program->set(0, res);
    item_program->set(1, far_distance * 1.01f + 1e-6f * diagonal);
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
    glVertexArrayVertexBuffer(cube_vao.id(), 0, cube_vertices->id(), 0, GLsizei(sizeof(item_vertex)));
    glEnableVertexArrayAttrib(cube_vao.id(), 0);
    glEnableVertexArrayAttrib(cube_vao.id(), 1);
    glVertexArrayAttribFormat(cube_vao.id(), 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(cube_vao.id(), 1, 2, GL_FLOAT, GL_FALSE, GLuint(offsetof(item_vertex, chart)));
    glVertexArrayAttribBinding(cube_vao.id(), 0, 0);
    glVertexArrayAttribBinding(cube_vao.id(), 1, 0);
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
    // (cpu::item_buffer_visibility's parallel buffer); its extent along the light.
    glm::vec2 mn(std::numeric_limits<float>::max()), mx(-std::numeric_limits<float>::max());
    float d0 = std::numeric_limits<float>::max(), d1 = -std::numeric_limits<float>::max();
    for (int m = 0; m < 8; ++m) {
        const glm::vec3 corner((m & 1) ? hi.x : lo.x, (m & 2) ? hi.y : lo.y, (m & 4) ? hi.z : lo.z);
        const glm::vec2 q(glm::dot(corner, t), glm::dot(corner, b));
        mn = glm::min(mn, q);
        mx = glm::max(mx, q);
        d0 = std::min(d0, glm::dot(corner, shot_axis));
        d1 = std::max(d1, glm::dot(corner, shot_axis));
    }
    const float side = std::max(std::max(mx.x - mn.x, mx.y - mn.y), 1e-30f) * (1.f + 2.f / float(res));
    ortho_lo = 0.5f * (mn + mx) - glm::vec2(0.5f * side);
    ortho_scale = float(res) / side;
    const float margin = 0.01f * diagonal;
    detail::raster_state raster;
    binding_state saved;
    const std::array<float, 4> none{-1.f, -1.f, std::numeric_limits<float>::max(), 0.f};
    glClearNamedFramebufferfv(parallel_fbo->id(), GL_COLOR, 0, none.data());
    const float far_depth = 1.f;
    glClearNamedFramebufferfv(parallel_fbo->id(), GL_DEPTH, 0, &far_depth);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, parallel_fbo->id());
    glViewport(0, 0, res, res);
    const program& p = *parallel_program;
    glUseProgram(p.id());
    p.set(0, t);
    p.set(1, b);
    p.set(2, shot_axis);
    p.set(3, ortho_lo);
    p.set(4, ortho_scale);
    p.set(5, float(res));
    p.set(6, d0 - margin);
    p.set(7, d1 + margin);
    glBindVertexArray(cube_vao.id());
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(cube_vertex_count));
    drawn = cube_vertex_count / 3;
    check_error("progressive_radiosity: drawing the directional light's buffer");
}

void progressive_radiosity::state::draw_hemicube() {
    // Each triangle's plane in the shooter's frame, facing away from it, for the lookup.
    for (std::size_t k = 0; k < corners.size(); ++k) {
        const glm::vec3 nl(glm::dot(glm::vec3(world_plane[k]), t), glm::dot(glm::vec3(world_plane[k]), b),
                           glm::dot(glm::vec3(world_plane[k]), shot_axis));
        const float d = glm::dot(nl, to_shooter_frame<float, glm::vec3>(corners[k][0], shot_position, t, b, shot_axis));
        local_plane[k] = d >= 0.f ? glm::vec4(nl, d) : glm::vec4(-nl, -d);
    }
    planes.write(0, local_plane.data(), local_plane.size() * sizeof(glm::vec4));
    world_vertices();
    float far_distance = 0.f;
    for (int m = 0; m < 8; ++m) {
        const glm::vec3 corner((m & 1) ? hi.x : lo.x, (m & 2) ? hi.y : lo.y, (m & 4) ? hi.z : lo.z);
        far_distance = std::max(far_distance, glm::length(corner - shot_position));
    }
    const float far_z = far_distance * 1.01f + 1e-6f * diagonal, near_z = 1e-6f * diagonal;
    detail::raster_state raster;
    binding_state saved;
    const std::array<float, 4> none{-1.f, -1.f, std::numeric_limits<float>::max(), 0.f};
    glClearNamedFramebufferfv(item_fbo.id(), GL_COLOR, 0, none.data());
    const float far_depth = 1.f;
    glClearNamedFramebufferfv(item_fbo.id(), GL_DEPTH, 0, &far_depth);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, item_fbo.id());
    const program& p = *cube_program;
    glUseProgram(p.id());
    p.set(0, shot_position);
    p.set(1, t);
    p.set(2, b);
    p.set(3, shot_axis);
    p.set(8, near_z);
    p.set(9, far_z);
    p.set(10, shot_chart);
    glBindVertexArray(cube_vao.id());
    const int res = options.resolution;
    for (int face = 0; face < 5; ++face) {
        const auto axes = face_axes(face);
        p.set(4, axes[0]);
        p.set(5, axes[1]);
        p.set(6, axes[2]);
        p.set(7, face == 0 ? 0 : 1);
        if (face == 0) glViewport(0, 0, res, res);
        else glViewport(0, res + (face - 1) * (res / 2), res, res / 2);
        glDrawArrays(GL_TRIANGLES, 0, GLsizei(cube_vertex_count));
    }
    drawn = 5 * cube_vertex_count / 3;
    check_error("progressive_radiosity: drawing the hemicube");
}

std::vector<glm::vec3> progressive_radiosity::state::read_elements(const texture& tex) const {
    const std::vector<float> all = tex.read_floats();
    std::vector<glm::vec3> out(atlas.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const std::size_t at = 4 * (std::size_t(atlas.texel[i].y) * width + atlas.texel[i].x);
        out[i] = glm::vec3(all[at], all[at + 1], all[at + 2]);
    }
    return out;
}

void progressive_radiosity::state::shoot(std::uint32_t k) {
    auto start = clock_type::now();
    const std::uint32_t i0 = first[k], i1 = first[k + 1];
    // The shooter's texels, read back: its power and its near-field tree (the CPU solver's
    // build_near_tree: elements, then 2 x 2 groups of its grid cells, ..., the block last);
    // then cleared.
    const glm::uvec4 r = rect[k];
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
    glm::dvec3 power(0.0);
    struct node_sum {
        glm::uvec2 cell;
        glm::dvec3 moment, power;
        double area;
        std::int32_t first_child, child_count;
    };
    std::vector<node_sum> level, up;
    glm::vec4 block_rect(0.f, 0.f, 1.f, 1.f);
    glm::uvec2 grid(1u);
    if (options.shooting.shoot_blocks) {
        block_rect = atlas.block_rect[k];
        grid = atlas.block_grid[k];
    }
    const lightmap_chart& ch = atlas.charts[atlas.chart[i0]];
    for (std::uint32_t i = i0; i < i1; ++i) {
        const glm::uvec2 tx = atlas.texel[i] - glm::uvec2(r.x, r.y);
        const glm::vec3 u(texels_back[std::size_t(tx.y) * r.z + tx.x]);
        const double a = double(atlas.area[i]);
        power += glm::dvec3(u) * a;
        const glm::vec3 d = atlas.position[i] - ch.origin;
        const glm::vec2 g((glm::dot(d, ch.axis_u) / glm::dot(ch.axis_u, ch.axis_u) - block_rect.x) /
                              (block_rect.z / float(grid.x)),
                          (glm::dot(d, ch.axis_v) / glm::dot(ch.axis_v, ch.axis_v) - block_rect.y) /
                              (block_rect.w / float(grid.y)));
        const glm::uvec2 cell(std::uint32_t(std::clamp(int(std::floor(g.x)), 0, int(grid.x) - 1)),
                              std::uint32_t(std::clamp(int(std::floor(g.y)), 0, int(grid.y) - 1)));
        level.push_back({cell, glm::dvec3(atlas.position[i]) * a, glm::dvec3(u) * a, a, 0, 0});
    }
    near.clear();
    const auto key = [](glm::uvec2 c) { return std::uint64_t(c.y) << 32 | c.x; };
    for (;;) {
        std::stable_sort(level.begin(), level.end(),
                         [&](const node_sum& x, const node_sum& y) { return key(x.cell / 2u) < key(y.cell / 2u); });
        const std::int32_t base = std::int32_t(near.size());
        for (const node_sum& p : level) {
            near.push_back({glm::vec4(glm::vec3(p.moment / p.area), float(p.area)), glm::vec4(glm::vec3(p.power / p.area), 0.f),
                            {p.first_child, p.child_count, 0, 0}});
        }
        if (level.size() == 1) break;
        up.clear();
        for (std::size_t j = 0; j < level.size(); ++j) {
            const glm::uvec2 pc = level[j].cell / 2u;
            if (up.empty() || key(up.back().cell) != key(pc))
                up.push_back({pc, glm::dvec3(0.0), glm::dvec3(0.0), 0.0, base + std::int32_t(j), 0});
            node_sum& q = up.back();
            q.moment += level[j].moment;
            q.power += level[j].power;
            q.area += level[j].area;
            ++q.child_count;
        }
        level.swap(up);
    }
    require(near.size() <= std::size_t(max_nodes), "atlas", "a shooter's near-field tree outgrew its bound");
    nodes.write(0, near.data(), near.size() * sizeof(gpu_node));

    const float chart = float(atlas.chart[i0]);
    set_shot(centre[k], atlas.normal[i0], chart);
    draw_visibility();
    if (options.timed_stages) finish();
    timings.visibility_ms += ms_since(start);

    start = clock_type::now();
    {
        binding_state saved;
        bind_common();
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        const program& p = *distribute_program;
        glUseProgram(p.id());
        p.set(0, int(width));
        p.set(1, int(height));
        p.set(2, shot_position);
        p.set(3, t);
        p.set(4, b);
        p.set(5, shot_axis);
        p.set(6, chart);
        p.set(7, options.visibility != radiosity_visibility::none ? 1 : 0);
        p.set(8, float(options.resolution));
        p.set(20, options.visibility == radiosity_visibility::hemicube ? 1 : 0);
        p.set(21, unsigned(atlas.size()));
        p.set(9, diagonal);
        p.set(10, int(near.size()));
        p.set(11, float(options.shooting.near_field * options.shooting.near_field));
        glDispatchCompute(GLuint((atlas.size() + 63) / 64), 1, 1);
        check_error("progressive_radiosity: the distribution pass");
    }
    if (options.timed_stages) finish();
    timings.distribution_ms += ms_since(start);
    const reduction got = reduce();
    absorbed += got.absorbed;
    escaped += power - got.intercepted;
    intercepted_power += got.intercepted;
    ++shots;
}

void progressive_radiosity::state::shoot_light(const packed_light& l) {
    const light_kind kind = l.kind();
    if (kind == light_kind::directional) {
        set_shot(glm::vec3(0.f), l.direction(), -2.f);
        if (options.visibility != radiosity_visibility::none) draw_parallel();
        {
            binding_state saved;
            bind_common();
            if (parallel_color)
                glBindImageTexture(item_unit, parallel_color->id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
            glMemoryBarrier(GL_ALL_BARRIER_BITS);
            const program& p = *light_program;
            glUseProgram(p.id());
            p.set(0, int(width));
            p.set(1, int(height));
            p.set(2, shot_position);
            p.set(3, t);
            p.set(4, b);
            p.set(5, shot_axis);
            p.set(6, -2.f);
            p.set(7, options.visibility != radiosity_visibility::none ? 1 : 0);
            p.set(8, float(options.resolution));
            p.set(9, diagonal);
            p.set(10, 0);
            p.set(11, l.direction());
            p.set(12, l.intensity());
            p.set(13, l.cos_cone());
            p.set(14, l.cosine_falloff());
            p.set(15, 0);
            p.set(16, 1);
            p.set(17, ortho_lo);
            p.set(18, ortho_scale);
            p.set(19, float(options.parallel_resolution));
            p.set(20, 0);
            p.set(21, unsigned(atlas.size()));
            glDispatchCompute(GLuint((atlas.size() + 63) / 64), 1, 1);
            check_error("progressive_radiosity: shooting a directional light");
        }
        const reduction got = reduce();
        emitted += got.intercepted;
        intercepted_power += got.intercepted;
        absorbed += got.absorbed;
        return;
    }
    const glm::vec3 axis = kind == light_kind::spot ? l.direction() : glm::vec3(0, 0, 1);
    std::vector<glm::vec3> axes{axis};
    // A point light, or a spot wider than a hemisphere, needs the other half too.
    if (kind == light_kind::point || l.cos_cone() < 0.f) axes.push_back(-axis);
    for (std::size_t h = 0; h < axes.size(); ++h) {
        set_shot(l.position(), axes[h], -2.f);
        draw_visibility();
        {
            binding_state saved;
            bind_common();
            glMemoryBarrier(GL_ALL_BARRIER_BITS);
            const program& p = *light_program;
            glUseProgram(p.id());
            p.set(0, int(width));
            p.set(1, int(height));
            p.set(2, shot_position);
            p.set(3, t);
            p.set(4, b);
            p.set(5, shot_axis);
            p.set(6, -2.f);
            p.set(7, options.visibility != radiosity_visibility::none ? 1 : 0);
            p.set(8, float(options.resolution));
            p.set(20, options.visibility == radiosity_visibility::hemicube ? 1 : 0);
            p.set(21, unsigned(atlas.size()));
        p.set(21, unsigned(atlas.size()));
            p.set(9, diagonal);
            p.set(10, kind == light_kind::spot ? 1 : 0);
            p.set(11, l.direction());
            p.set(12, l.intensity());
            p.set(13, l.cos_cone());
            p.set(14, l.cosine_falloff());
            p.set(15, h == 0 ? 0 : 1);
            p.set(16, 0);
            p.set(17, ortho_lo);
            p.set(18, ortho_scale);
            p.set(19, float(options.parallel_resolution));
            glDispatchCompute(GLuint((atlas.size() + 63) / 64), 1, 1);
            check_error("progressive_radiosity: shooting a light");
        }
        const reduction got = reduce();
        emitted += got.intercepted;
        intercepted_power += got.intercepted;
        absorbed += got.absorbed;
    }
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
    for (const light& l : scene.lights) s_->shoot_light(pack(l));
    finish();
    s_->timings.lights_ms = ms_since(start);
    s_->reduce();
    check_lights_reach_surfaces(scene, s_->atlas, s_->emitted);
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
    return {s_->steps, s_->shots, unshot_fraction(), 0.0};
}
std::uint32_t progressive_radiosity::next_shooter() const noexcept { return s_->next; }
double progressive_radiosity::next_shooter_power() const noexcept { return s_->next_power; }
std::size_t progressive_radiosity::shooters() const noexcept { return s_->first.size() - 1; }
std::uint32_t progressive_radiosity::shooter_first(std::size_t k) const { return s_->first.at(k); }
glm::dvec3 progressive_radiosity::emitted_power() const noexcept { return s_->emitted; }
glm::dvec3 progressive_radiosity::absorbed_power() const noexcept { return s_->absorbed; }
glm::dvec3 progressive_radiosity::escaped_power() const noexcept { return s_->escaped; }
glm::dvec3 progressive_radiosity::intercepted_power() const noexcept { return s_->intercepted_power; }
glm::dvec3 progressive_radiosity::unshot_power() const {
    const auto u = unshot();
    glm::dvec3 sum(0.0);
    for (std::size_t i = 0; i < u.size(); ++i) sum += glm::dvec3(u[i]) * double(s_->atlas.area[i]);
    return sum;
}
std::vector<glm::vec3> progressive_radiosity::radiosity() const { return s_->read_elements(s_->radiosity); }
std::vector<glm::vec3> progressive_radiosity::unshot() const { return s_->read_elements(s_->unshot); }
glm::dvec3 progressive_radiosity::ambient() const {
    const glm::dvec3 rho_avg = s_->albedo_area / s_->total_area;
    return unshot_power() / s_->total_area / (glm::dvec3(1.0) - glm::min(rho_avg, glm::dvec3(0.999)));
}
std::vector<glm::vec3> progressive_radiosity::display_radiosity() const {
    std::vector<glm::vec3> out = radiosity();
    const glm::vec3 amb = s_->options.shooting.ambient ? glm::vec3(ambient()) : glm::vec3(0.f);
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = radiosity_with_ambient<float, glm::vec3>(out[i], s_->atlas.albedo[i], amb);
    return out;
}
image<glm::vec3> progressive_radiosity::lightmap(int level) const {
    const auto values = display_radiosity();
    return s_->atlas.to_fine_texels(std::span<const glm::vec3>(values), level);
}
texture_ref progressive_radiosity::update_lightmap_texture() {
    state& st = *s_;
    if (!st.lightmap_program) {
        using glsl::f32;
        using glsl::vec3;
        glsl::function_set fs;
        fs.add("radiosity_display", radiosity_with_ambient<f32, vec3>, "radiosity", "albedo", "ambient");
        st.lightmap_program = std::make_unique<program>(program::compute(version_header() + R"(
layout(local_size_x = 8, local_size_y = 8) in;
)" + fs.source() + R"(
struct texel_attributes { vec4 position_area; vec4 normal_chart; vec4 albedo; };
layout(std430, binding = 0) readonly buffer texels_block { texel_attributes texel[]; };
layout(std430, binding = 4) readonly buffer source_block { uint source_texel[]; };
layout(rgba32f, binding = 0) uniform readonly image2D radiosity_image;
layout(rgba32f, binding = 2) uniform writeonly image2D lightmap_image;
layout(location = 0) uniform int atlas_width;
layout(location = 1) uniform int atlas_height;
layout(location = 2) uniform vec3 ambient;
void main() {
    ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
    if (xy.x >= atlas_width || xy.y >= atlas_height) return;
    uint code = source_texel[xy.y * atlas_width + xy.x];
    if (code == 0xffffffffu) { imageStore(lightmap_image, xy, vec4(0.0)); return; }
    ivec2 from = ivec2(int(code & 0xffffu), int(code >> 16u));
    vec3 b = imageLoad(radiosity_image, from).rgb;
    vec3 rho = texel[from.y * atlas_width + from.x].albedo.rgb;
    imageStore(lightmap_image, xy, vec4(radiosity_display(b, rho, ambient), 1.0));
}
)"));
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
    const glm::vec3 amb = st.options.shooting.ambient ? glm::vec3(ambient()) : glm::vec3(0.f);
    {
        binding_state saved;
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, texels_binding, st.texels.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, element_binding, st.source_texel->id());
        glBindImageTexture(radiosity_unit, st.radiosity.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
        glBindImageTexture(intercepted_unit, st.lightmap_texture->id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        const program& p = *st.lightmap_program;
        glUseProgram(p.id());
        p.set(0, int(st.width));
        p.set(1, int(st.height));
        p.set(2, amb);
        glDispatchCompute((st.width + 7) / 8, (st.height + 7) / 8, 1);
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        check_error("progressive_radiosity: the lightmap pass");
    }
    return texture_ref(*st.lightmap_texture);
}

texture_ref progressive_radiosity::radiosity_texture() const noexcept { return texture_ref(s_->radiosity); }
texture_ref progressive_radiosity::unshot_texture() const noexcept { return texture_ref(s_->unshot); }
const radiosity_timings& progressive_radiosity::timings() const noexcept { return s_->timings; }
const lightmap_atlas& progressive_radiosity::atlas() const noexcept { return s_->atlas; }
const radiosity_options& progressive_radiosity::options() const noexcept { return s_->options; }
std::size_t progressive_radiosity::drawn_triangles() const noexcept { return s_->drawn; }

}  // namespace bounce::gl
