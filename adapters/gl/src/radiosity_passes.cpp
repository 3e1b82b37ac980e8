// gl::progressive_radiosity's state: its buffers and textures, and the programs of its passes
// (item buffer, visibility, shot, light shot, reduction), compiled from emitted kernels.
#include "radiosity_state.hpp"

namespace bounce::gl {

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

}  // namespace bounce::gl
