// The GLSL of gl::progressive_radiosity's passes: the item buffer (stereographic map), the
// hemicube faces, a directional light's orthographic buffer, the distribution of a shot,
// the shot of a light, and the two-pass reduction that picks the next shooter. The
// projections, form factors, visibility tests and light irradiances are emitted from the
// kernels of radiosity/kernels.hpp and direct_light.hpp; the rest is fetches, loops and writes.
#include "radiosity_shaders.hpp"

#include <bounce/direct_light.hpp>
#include <bounce/glsl/emit.hpp>
#include <bounce/radiosity/ambient.hpp>
#include <bounce/radiosity/kernels.hpp>
#include <bounce/radiosity/sides.hpp>

#include <initializer_list>
#include <utility>

namespace bounce::gl::radiosity_glsl {

namespace {

using glsl::f32;
using glsl::vec2;
using glsl::vec3;

const std::string version_line = "#version 450 core\n";

// One "layout(location = L) uniform DECLARATION;" line per (L, declaration).
std::string uniforms(std::initializer_list<std::pair<int, const char*>> declarations) {
    std::string out;
    for (const auto& [location, declaration] : declarations)
        out += "layout(location = " + std::to_string(location) + ") uniform " + declaration + ";\n";
    return out;
}

// The shooter's frame (shot_t, shot_b, shot_n) at a pass's locations for them.
std::string frame_uniforms(int t, int b, int n) {
    return uniforms({{t, "vec3 shot_t"}, {b, "vec3 shot_b"}, {n, "vec3 shot_n"}});
}

// A std430 storage block at `binding`: "layout(std430, binding = B) DECLARATION;".
std::string storage_block(unsigned binding, const char* declaration) {
    return "layout(std430, binding = " + std::to_string(binding) + ") " + declaration + ";\n";
}

// An RGBA32F image at `unit`: "layout(rgba32f, binding = U) uniform DECLARATION;".
std::string image(unsigned unit, const char* declaration) {
    return "layout(rgba32f, binding = " + std::to_string(unit) + ") uniform " + declaration + ";\n";
}

// The item passes' stage interfaces: the vertex stream (item_vertex, as the state attaches
// it: attribute 0 a position named `position`, attribute 1 the (chart, triangle) ids), the
// ids handed on flat, and what every item fragment shader reads and writes (the item:
// chart, triangle, depth, 1).
std::string item_vertex_inputs(const char* position) {
    return std::string("layout(location = 0) in vec3 ") + position + ";\nlayout(location = 1) in vec2 ids;\n";
}
const char* const item_ids_out = "layout(location = 1) flat out vec2 item_ids;\n";
const char* const item_fragment_interface =
    "layout(location = 1) flat in vec2 item_ids;\nlayout(location = 0) out vec4 item;\n";

const char* const texel_attributes_struct =
    "struct texel_attributes { vec4 position_area; vec4 normal_chart; vec4 albedo; };\n";

// The kernels the visibility lookups of the distribution and light passes call: where an
// element is looked up (its texel) and whether the surface shown there hides it.
std::string lookup_functions() {
    glsl::function_set fs;
    fs.add("radiosity_to_shooter_frame", to_shooter_frame<f32, vec3>, "p", "origin", "t", "b", "n");
    fs.add("radiosity_stereographic_texel", stereographic_item_texel<f32, vec3, vec2>, "local_position", "res");
    fs.add("radiosity_hemicube_texel", hemicube_item_texel<f32, vec3>, "local_position", "res");
    fs.add("radiosity_hemicube_first_row", hemicube_face_first_row<f32>, "face", "res");
    fs.add("radiosity_parallel_texel", parallel_item_texel<f32, vec3, vec2>, "p", "t", "b", "lo", "scale", "res");
    fs.add("radiosity_parallel_sees", parallel_item_sees<f32, vec3>, "element", "element_chart", "shown_chart",
           "plane_normal", "plane_offset", "shown_depth", "direction", "diagonal");
    fs.add("radiosity_item_sees", item_buffer_sees<f32, vec3>, "element", "element_chart", "shown_chart",
           "plane_normal", "plane_offset", "shown_depth", "diagonal");
    fs.add("radiosity_side_normal", side_normal<f32, vec3>, "normal", "side");
    return fs.source();
}

// The distribution and light passes' uniforms (shot_uniform).
std::string shot_uniforms() {
    using namespace shot_uniform;
    return uniforms({{element_count, "uint element_count"},
                     {atlas_width, "int atlas_width"},
                     {atlas_height, "int atlas_height"},
                     {shot_position, "vec3 shot_position"}}) +
           frame_uniforms(shot_t, shot_b, shot_n) +
           uniforms({{shot_chart, "float shot_chart"},
                     {occlusion, "int occlusion"},
                     {resolution, "float resolution"},
                     {diagonal, "float diagonal"},
                     {hemicube, "int hemicube"},
                     {two_sided, "int two_sided"}});
}

// What the distribution and light passes share: the element texels, the images, the
// visibility of an element from the shot, and an element's receiving of it.
std::string shot_common() {
    return std::string("\n") + texel_attributes_struct +
           storage_block(texels_binding, "readonly buffer texels_block { texel_attributes texel[]; }") +
           storage_block(planes_binding, "readonly buffer planes_block { vec4 local_plane[]; }") +
           storage_block(element_binding, "readonly buffer element_block { uint element_texel[]; }") +
           image(radiosity_unit, "image2D radiosity_image") + image(unshot_unit, "image2D unshot_image") +
           image(intercepted_unit, "writeonly image2D intercepted_image") +
           image(item_unit, "readonly image2D item_image") + R"(
// Visibility of the element at world position p (chart `chart`) from the shot: its texel in
// the stereographic buffer, or on its hemicube face, whose texels start at the face's first
// row of the buffer.
float shot_visibility(vec3 p, float chart) {
    if (occlusion == 0) return 1.0;
    vec3 l = radiosity_to_shooter_frame(p, shot_position, shot_t, shot_b, shot_n);
    ivec2 pixel;
    if (hemicube != 0) {
        vec3 h = radiosity_hemicube_texel(l, resolution);
        pixel = ivec2(h.yz) + ivec2(0, int(radiosity_hemicube_first_row(h.x, resolution)));
    } else {
        pixel = ivec2(radiosity_stereographic_texel(l, resolution));
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
// The element at texel xy of the fronts' rows on side `side` (the backs' rows follow them).
ivec2 side_texel(ivec2 xy, int side) { return xy + ivec2(0, side * atlas_height); }
// Nothing intercepted on either side (the reduction reads both).
void intercept_nothing(ivec2 xy) {
    imageStore(intercepted_image, xy, vec4(0.0));
    if (two_sided != 0) imageStore(intercepted_image, side_texel(xy, 1), vec4(0.0));
}
)";
}

}  // namespace

// Item buffer: the pieces projected by the emitted stereographic map; depth exact at each
// pixel centre along its direction (stereographic_direction, emitted).
std::string item_buffer_vertex() {
    glsl::function_set fs;
    fs.add("radiosity_item_coords", stereographic_item_coords<f32, vec3, vec2>, "local_position");
    return version_line + fs.source() + "\n" + item_vertex_inputs("piece_corner") +
           "layout(location = 0) noperspective out float radial;\n" + item_ids_out + R"(void main() {
    vec2 uv = radiosity_item_coords(piece_corner);
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
    radial = length(piece_corner);
    item_ids = ids;
}
)";
}

std::string item_buffer_fragment() {
    glsl::function_set fs;
    fs.add("radiosity_texel_direction", stereographic_texel_direction<f32, vec3, vec2>, "centre", "res");
    fs.add("radiosity_plane_depth", item_plane_depth<f32, vec3>, "plane_normal", "plane_offset", "w", "interpolated");
    return version_line + fs.source() +
           uniforms({{item_uniform::resolution, "float resolution"}, {item_uniform::depth_scale, "float depth_scale"}}) +
           "\n" + storage_block(planes_binding, "readonly buffer planes_block { vec4 local_plane[]; }") +
           "layout(location = 0) noperspective in float radial;\n" + item_fragment_interface + R"(void main() {
    vec3 w = radiosity_texel_direction(gl_FragCoord.xy, resolution);
    vec4 plane = local_plane[int(item_ids.y)];
    float depth = radiosity_plane_depth(plane.xyz, plane.w, w, radial);
    gl_FragDepth = depth / depth_scale;
    item = vec4(item_ids, depth, 1.0);
}
)";
}

// Hemicube faces (Cohen and Greenberg 1985): perspective views of the untessellated
// triangles, 1/z interpolated by the rasterizer (exact under perspective), depth the
// distance along the face's forward axis, as cpu::item_buffer_visibility stores it. Side
// faces keep their upper half; hemicube_face_clip puts each corner where the face's (u, v)
// (the lookup's) lands in the face's viewport.
std::string hemicube_vertex() {
    using namespace hemicube_uniform;
    glsl::function_set fs;
    fs.add("radiosity_to_shooter_frame", to_shooter_frame<f32, vec3>, "p", "origin", "t", "b", "n");
    fs.add("radiosity_frame_coords", frame_coords<f32, vec3>, "d", "t", "b", "n");
    fs.add("radiosity_face_clip", hemicube_face_clip<f32, vec3, glsl::vec4>, "q", "face", "near_z", "far_z");
    return version_line + fs.source() + uniforms({{shot_position, "vec3 shot_position"}}) +
           frame_uniforms(shot_t, shot_b, shot_n) +
           uniforms({{face_right, "vec3 face_right"},
                     {face_up, "vec3 face_up"},
                     {face_forward, "vec3 face_forward"},
                     {face, "float face"},
                     {near_z, "float near_z"},
                     {far_z, "float far_z"}}) +
           "\n" + item_vertex_inputs("world_position") + "layout(location = 0) out float forward_depth;\n" +
           item_ids_out + R"(void main() {
    vec3 l = radiosity_to_shooter_frame(world_position, shot_position, shot_t, shot_b, shot_n);
    vec3 q = radiosity_frame_coords(l, face_right, face_up, face_forward);
    gl_Position = radiosity_face_clip(q, face, near_z, far_z);
    forward_depth = q.z;
    item_ids = ids;
}
)";
}

std::string hemicube_fragment() {
    using namespace hemicube_uniform;
    return version_line + uniforms({{far_z, "float far_z"}, {shot_chart, "float shot_chart"}}) +
           "\nlayout(location = 0) in float forward_depth;\n" + item_fragment_interface + R"(void main() {
    if (item_ids.x == shot_chart) discard;
    gl_FragDepth = forward_depth / far_z;
    item = vec4(item_ids, forward_depth, 1.0);
}
)";
}

// A directional light: an orthographic view along it over the scene's box, each corner at
// its texel coordinates (parallel_item_coords, as the lookup finds them); the depth is the
// distance along the light, linear, so the rasterizer's depth is exact.
std::string parallel_vertex() {
    using namespace parallel_uniform;
    glsl::function_set fs;
    fs.add("radiosity_parallel_coords", parallel_item_coords<f32, vec3, vec2>, "p", "t", "b", "lo", "scale");
    return version_line + fs.source() + frame_uniforms(shot_t, shot_b, shot_n) +
           uniforms({{ortho_lo, "vec2 ortho_lo"},
                     {ortho_scale, "float ortho_scale"},
                     {parallel_resolution, "float parallel_resolution"},
                     {depth_lo, "float depth_lo"},
                     {depth_hi, "float depth_hi"}}) +
           "\n" + item_vertex_inputs("world_position") + "layout(location = 0) out float along;\n" + item_ids_out +
           R"(void main() {
    vec2 pixel = radiosity_parallel_coords(world_position, shot_t, shot_b, ortho_lo, ortho_scale);
    along = dot(world_position, shot_n);
    gl_Position = vec4(pixel / parallel_resolution * 2.0 - 1.0, (along - depth_lo) / (depth_hi - depth_lo) * 2.0 - 1.0, 1.0);
    item_ids = ids;
}
)";
}

std::string parallel_fragment() {
    return version_line + "\nlayout(location = 0) in float along;\n" + item_fragment_interface +
           R"(void main() { item = vec4(item_ids, along, 1.0); }
)";
}

// The distribution of a shot: every element receives from the shooter's near-field tree
// (disc form factors), times its visibility.
std::string distribute_compute(int max_nodes, int stack_size) {
    glsl::function_set fs;
    fs.add("radiosity_form_factor", element_form_factor<f32, vec3>, "receiver_position", "receiver_normal",
           "receiver_area", "shooter_position", "shooter_normal", "shooter_area");
    fs.add("radiosity_near_field", near_field_opens<f32, vec3>, "receiver", "node_position", "node_area", "near2");
    fs.add("radiosity_receiving_side", receiving_side<f32, vec3>, "receiver", "receiver_normal", "source", "two_sided");
    return version_line + "layout(local_size_x = 64) in;\n" + shot_uniforms() +
           uniforms({{distribute_uniform::node_count, "int node_count"},
                     {distribute_uniform::near2, "float near2"},
                     {distribute_uniform::masked, "int masked"}}) +
           lookup_functions() + fs.source() + shot_common() + "const int max_nodes = " + std::to_string(max_nodes) +
           ";\n" + "const int stack_size = " + std::to_string(stack_size) + ";\n" + R"(
struct near_node { vec4 position_area; vec4 unshot; ivec4 meta; };
)" + storage_block(nodes_binding, "readonly buffer nodes_block { near_node node[]; }") +
           storage_block(keep_binding, "readonly buffer keep_block { uint keep_bits[]; }") + R"(
void main() {
    // One invocation per element, at its texel (the atlas's padding and empty texels cost nothing).
    uint e = gl_GlobalInvocationID.x;
    if (e >= element_count) return;
    uint code = element_texel[e];
    ivec2 xy = ivec2(int(code & 0xffffu), int(code >> 16u));
    texel_attributes a = texel[xy.y * atlas_width + xy.x];
    if (!(a.position_area.w > 0.0)) return;
    if (a.normal_chart.w == shot_chart) { intercept_nothing(xy); return; }
    // A re-bake's re-shot reaches only the receivers whose bit is set (keep_bits, element order).
    if (masked != 0 && (keep_bits[e >> 5u] & (1u << (e & 31u))) == 0u) { intercept_nothing(xy); return; }
    vec3 pr = a.position_area.xyz, nr = a.normal_chart.xyz, rho = a.albedo.rgb;
    float ar = a.position_area.w;
    // precise: no fused multiply-add in the sums, so they round as the CPU's do (a shooter's
    // power decides the next shot, and equal powers in a symmetric scene must stay equal).
    precise vec3 incident = vec3(0.0), incident_back = vec3(0.0);
    // The block as one disc where the receiver is farther than near_field times its side,
    // else as its four quadrants, recursively, down to elements: the CPU solver's traversal
    // (a stack, children pushed in order, so terms are summed in its order), each node
    // lighting the receiver's side that faces it (receiving_side, radiosity/sides.hpp: the
    // back only when two-sided). Each node is visited at most once, so max_nodes bounds the
    // loop; most receivers are far from the whole block and visit the root alone.
    int stack[stack_size];
    int top = 0, current = node_count - 1;
    for (int visit = 0; visit < max_nodes; ++visit) {
        near_node nd = node[current];
        if (nd.meta.y == 0 || !(radiosity_near_field(pr, nd.position_area.xyz, nd.position_area.w, near2) > 0.5)) {
            float side = radiosity_receiving_side(pr, nr, nd.position_area.xyz, float(two_sided));
            float f = radiosity_form_factor(pr, radiosity_side_normal(nr, side), ar, nd.position_area.xyz, shot_n,
                                            nd.position_area.w);
            if (f > 0.0) {
                if (side > 0.5) incident_back += nd.unshot.xyz * f;
                else incident += nd.unshot.xyz * f;
            }
        } else {
            for (int c = 0; c < nd.meta.y && top < stack_size; ++c) stack[top++] = nd.meta.x + c;
        }
        if (top == 0) break;
        current = stack[--top];
    }
    // Either sign: a re-bake shoots negative unshot radiosity (radiosity/rebake.hpp).
    if (incident == vec3(0.0) && incident_back == vec3(0.0)) { intercept_nothing(xy); return; }
    float v = shot_visibility(pr, a.normal_chart.w);
    if (!(v > 0.0)) { intercept_nothing(xy); return; }
    vec3 received = incident * v;
    receive(xy, rho * received, received * ar);
    if (two_sided != 0) {
        vec3 received_back = incident_back * v;
        receive(side_texel(xy, 1), rho * received_back, received_back * ar);
    }
}
)";
}

// A shot that would deliver more than its power, scaled down after its distribution
// (shot_scale, radiosity/shooters.hpp): each element's received radiosity, its intercepted
// power over its area, times (scale - 1) is taken back from its radiosity and unshot
// radiosity (times rho), and its intercepted power scaled, for the reduction that follows.
std::string rescale_compute() {
    using namespace rescale_uniform;
    return version_line + "layout(local_size_x = 64) in;\n" +
           uniforms({{atlas_width, "int atlas_width"},
                     {element_count, "uint element_count"},
                     {scale, "vec3 scale"},
                     {atlas_height, "int atlas_height"},
                     {sides, "int sides"}}) +
           "\n" + texel_attributes_struct +
           storage_block(texels_binding, "readonly buffer texels_block { texel_attributes texel[]; }") +
           storage_block(element_binding, "readonly buffer element_block { uint element_texel[]; }") +
           image(radiosity_unit, "image2D radiosity_image") + image(unshot_unit, "image2D unshot_image") +
           image(intercepted_unit, "image2D intercepted_image") + R"(
void main() {
    if (gl_GlobalInvocationID.x >= element_count) return;
    uint code = element_texel[gl_GlobalInvocationID.x];
    ivec2 xy = ivec2(int(code & 0xffffu), int(code >> 16u));
    texel_attributes a = texel[xy.y * atlas_width + xy.x];
    if (!(a.position_area.w > 0.0)) return;
    // Each side's rows (the backs' follow the fronts').
    for (int side = 0; side < sides; ++side) {
        ivec2 at = xy + ivec2(0, side * atlas_height);
        vec3 got = imageLoad(intercepted_image, at).rgb;
        if (got == vec3(0.0)) continue;
        vec3 change = a.albedo.rgb * (got / a.position_area.w * (scale - vec3(1.0)));
        imageStore(radiosity_image, at, imageLoad(radiosity_image, at) + vec4(change, 0.0));
        imageStore(unshot_image, at, imageLoad(unshot_image, at) + vec4(change, 0.0));
        imageStore(intercepted_image, at, vec4(got * scale, 0.0));
    }
}
)";
}

// The shot of a point, spot or directional light: every element's irradiance from it,
// times its visibility (the item buffer, or the directional light's orthographic buffer).
std::string light_compute() {
    using namespace light_uniform;
    glsl::function_set fs;
    fs.add("radiosity_light_side", light_hemisphere_side<f32, vec3>, "p", "light_position", "axis", "strict");
    fs.add("radiosity_point_irradiance", point_light_irradiance<f32, vec3>, "p", "n", "light_position", "intensity");
    fs.add("radiosity_directional_irradiance", directional_light_irradiance<f32, vec3>, "n", "direction", "irradiance");
    fs.add("radiosity_spot_irradiance", spot_light_irradiance<f32, vec3>, "p", "n", "light_position", "axis",
           "intensity", "cos_cone", "cosine_falloff");
    return version_line + "layout(local_size_x = 64) in;\n" + shot_uniforms() +
           uniforms({{spot, "int spot"},
                     {light_axis, "vec3 light_axis"},
                     {intensity, "vec3 intensity"},
                     {cos_cone, "float cos_cone"},
                     {cosine_falloff, "float cosine_falloff"},
                     {strict_side, "int strict_side"},
                     {parallel, "int parallel"},
                     {ortho_lo, "vec2 ortho_lo"},
                     {ortho_scale, "float ortho_scale"},
                     {parallel_resolution, "float parallel_resolution"}}) +
           lookup_functions() + fs.source() + shot_common() + R"(
// Visibility along a directional light: the element's pixel in the orthographic buffer,
// whose planes are the triangles' world planes.
float parallel_visibility(vec3 p, float chart) {
    if (occlusion == 0) return 1.0;
    ivec2 pixel = ivec2(radiosity_parallel_texel(p, shot_t, shot_b, ortho_lo, ortho_scale, parallel_resolution));
    vec4 item = imageLoad(item_image, pixel);
    vec4 plane = item.x >= 0.0 ? local_plane[int(item.y)] : vec4(0.0, 0.0, 1.0, 0.0);
    return radiosity_parallel_sees(p, chart, item.x, plane.xyz, plane.w, item.z, shot_n, diagonal);
}
// The light's irradiance at p on the side of normal n (emitted from direct_light.hpp).
vec3 light_irradiance(vec3 p, vec3 n) {
    return parallel != 0 ? radiosity_directional_irradiance(n, light_axis, intensity)
         : spot != 0     ? radiosity_spot_irradiance(p, n, shot_position, light_axis, intensity, cos_cone, cosine_falloff)
                         : radiosity_point_irradiance(p, n, shot_position, intensity);
}
void main() {
    // One invocation per element, at its texel (the atlas's padding and empty texels cost nothing).
    if (gl_GlobalInvocationID.x >= element_count) return;
    uint code = element_texel[gl_GlobalInvocationID.x];
    ivec2 xy = ivec2(int(code & 0xffffu), int(code >> 16u));
    texel_attributes a = texel[xy.y * atlas_width + xy.x];
    if (!(a.position_area.w > 0.0)) return;
    intercept_nothing(xy);
    if (a.normal_chart.w == shot_chart) return;
    vec3 p = a.position_area.xyz, n = a.normal_chart.xyz;
    // Each element belongs to one hemisphere of the light: z >= 0 of the first, z > 0 of the second.
    bool hemisphere = parallel != 0 || radiosity_light_side(p, shot_position, shot_n, float(strict_side)) > 0.5;
    if (!hemisphere) return;
    // The side facing the light: the front, or (two-sided) the back, as the CPU solver takes it.
    vec3 e = light_irradiance(p, n);
    int side = 0;
    if (two_sided != 0 && e == vec3(0.0)) {
        side = 1;
        e = light_irradiance(p, radiosity_side_normal(n, 1.0));
    }
    if (e == vec3(0.0)) return;  // either sign: a re-bake takes a light's old light away with -intensity
    float v = parallel != 0 ? parallel_visibility(p, a.normal_chart.w) : shot_visibility(p, a.normal_chart.w);
    if (!(v > 0.0)) return;
    receive(side_texel(xy, side), a.albedo.rgb * (e * v), e * (v * a.position_area.w));
}
)";
}

// Reduction, in two passes with few barriers (llvmpipe runs a barrier as a switch of
// every invocation): per shooter (one invocation each) its unshot power, the channel sums
// times area in double and in element order (the CPU solver's sum), with its elements'
// intercepted and absorbed power; then one work group of 64 striding over the shooters
// (ties to the lowest index) and a shared-memory tree over its 64 partial results.
std::string reduce_compute() {
    using namespace reduce_uniform;
    return version_line +
           uniforms({{atlas_width, "int atlas_width"},
                     {shooter_count, "uint shooter_count"},
                     {blocks, "uint blocks"},
                     {atlas_height, "int atlas_height"}}) +
           "\nlayout(local_size_x = 64) in;\n" + texel_attributes_struct +
           storage_block(texels_binding, "readonly buffer texels_block { texel_attributes texel[]; }") +
           storage_block(first_binding, "readonly buffer first_block { uint shooter_first[]; }") +
           storage_block(element_binding, "readonly buffer element_block { uint element_texel[]; }") +
           storage_block(partial_binding, "buffer partial_block { double partial[]; }") +
           image(unshot_unit, "readonly image2D unshot_image") +
           image(intercepted_unit, "readonly image2D intercepted_image") + R"(
void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= shooter_count) return;
    // Shooter k: block k % blocks on side k / blocks (that side's rows), as on the CPU.
    uint block = k % blocks;
    ivec2 rows = ivec2(0, int(k / blocks) * atlas_height);
    double power = 0.0;
    dvec3 ic = dvec3(0.0), ab = dvec3(0.0);
    for (uint e = shooter_first[block]; e < shooter_first[block + 1u]; ++e) {
        uint code = element_texel[e];
        ivec2 xy = ivec2(int(code & 0xffffu), int(code >> 16u));
        texel_attributes a = texel[xy.y * atlas_width + xy.x];
        vec4 u = imageLoad(unshot_image, xy + rows);
        // In magnitude, as the CPU solver counts it: a re-bake's unshot radiosity may be negative.
        power += (abs(double(u.r)) + abs(double(u.g)) + abs(double(u.b))) * double(a.position_area.w);
        dvec3 got = dvec3(imageLoad(intercepted_image, xy + rows).rgb);
        ic += got;
        ab += (dvec3(1.0) - dvec3(a.albedo.rgb)) * got;
    }
    uint at = (k + 2u) * 8u;
    partial[at] = power;
    partial[at + 1u] = ic.x; partial[at + 2u] = ic.y; partial[at + 3u] = ic.z;
    partial[at + 4u] = ab.x; partial[at + 5u] = ab.y; partial[at + 6u] = ab.z;
}
)";
}

std::string finish_compute() {
    return version_line + uniforms({{finish_uniform::shooter_count, "uint shooter_count"}}) +
           "\nlayout(local_size_x = 64) in;\n" + storage_block(partial_binding, "buffer partial_block { double partial[]; }") +
           R"(
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
}

// The display lightmap: each lightmap texel shows its element's radiosity with the ambient
// term (radiosity_with_ambient, emitted), on the side whose rows start at source_row;
// source_texel holds the element's atlas texel packed as x | y << 16, or 0xffffffff where the
// texel shows no element. The ambient: uniform, or shaped from the window's irradiance h
// (h factor; mixed: mixed_ambient, emitted).
std::string lightmap_compute() {
    using namespace lightmap_uniform;
    glsl::function_set fs;
    fs.add("radiosity_display", radiosity_with_ambient<f32, vec3>, "radiosity", "albedo", "ambient");
    fs.add("radiosity_display_at_least", radiosity_with_ambient_at_least_direct<f32, vec3>, "radiosity", "albedo",
           "ambient", "direct");
    fs.add("radiosity_mixed_ambient", mixed_ambient<f32, vec3>, "shaped", "floor_level", "scale");
    return version_line + "layout(local_size_x = 8, local_size_y = 8) in;\n" + fs.source() + texel_attributes_struct +
           storage_block(texels_binding, "readonly buffer texels_block { texel_attributes texel[]; }") +
           storage_block(source_binding, "readonly buffer source_block { uint source_texel[]; }") +
           image(radiosity_unit, "readonly image2D radiosity_image") +
           image(lightmap_unit, "writeonly image2D lightmap_image") + image(window_unit, "readonly image2D window_image") +
           image(direct_unit, "readonly image2D direct_image") +
           uniforms({{atlas_width, "int atlas_width"},
                     {atlas_height, "int atlas_height"},
                     {ambient, "vec3 ambient"},
                     {source_row, "int source_row"},
                     {shape, "int shape"},
                     {factor, "vec3 factor"},
                     {floor, "vec3 floor_level"},
                     {scale, "vec3 scale"},
                     {at_least_direct, "int at_least_direct"}}) +
           R"(
void main() {
    ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
    if (xy.x >= atlas_width || xy.y >= atlas_height) return;
    uint code = source_texel[xy.y * atlas_width + xy.x];
    if (code == 0xffffffffu) { imageStore(lightmap_image, xy, vec4(0.0)); return; }
    ivec2 from = ivec2(int(code & 0xffffu), int(code >> 16u));
    vec3 b = imageLoad(radiosity_image, from + ivec2(0, source_row)).rgb;
    vec3 rho = texel[from.y * atlas_width + from.x].albedo.rgb;
    vec3 a = ambient;
    if (shape != 0) {
        vec3 shaped = imageLoad(window_image, from + ivec2(0, source_row)).rgb * factor;
        a = shape == 2 ? radiosity_mixed_ambient(shaped, floor_level, scale) : shaped;
    }
    vec3 shown = at_least_direct != 0
        ? radiosity_display_at_least(b, rho, a, imageLoad(direct_image, from + ivec2(0, source_row)).rgb)
        : radiosity_display(b, rho, a);
    imageStore(lightmap_image, xy, vec4(shown, 1.0));
}
)";
}

// The window passes' common head: their uniforms, the element texels and the window's image.
std::string window_head() {
    using namespace window_uniform;
    return version_line + "layout(local_size_x = 64) in;\n" +
           uniforms({{atlas_width, "int atlas_width"},
                     {atlas_height, "int atlas_height"},
                     {element_count, "uint element_count"},
                     {sides, "int sides"}}) +
           "\n" + texel_attributes_struct +
           storage_block(texels_binding, "readonly buffer texels_block { texel_attributes texel[]; }") +
           storage_block(element_binding, "readonly buffer element_block { uint element_texel[]; }") + R"(
// Element e's texel in the fronts' rows, and its area (0: not an element's texel).
ivec2 element_xy(uint e) { uint code = element_texel[e]; return ivec2(int(code & 0xffffu), int(code >> 16u)); }
float element_area(ivec2 xy) { return texel[xy.y * atlas_width + xy.x].position_area.w; }
)";
}

// A surface shot added to the window (shot_ambient_window): each element-side's received
// irradiance, its intercepted power (the shot's scale applied) over its area, times the weight;
// keep < 1 rescales the older sum.
std::string window_record_compute() {
    using namespace window_uniform;
    return window_head() + uniforms({{keep, "float keep"}, {weight, "float weight"}}) +
           image(window_unit, "image2D window_image") + image(intercepted_unit, "readonly image2D intercepted_image") +
           R"(
void main() {
    if (gl_GlobalInvocationID.x >= element_count) return;
    ivec2 xy = element_xy(gl_GlobalInvocationID.x);
    float area = element_area(xy);
    if (!(area > 0.0)) return;
    for (int side = 0; side < sides; ++side) {
        ivec2 at = xy + ivec2(0, side * atlas_height);
        vec3 got = imageLoad(intercepted_image, at).rgb;
        if (got == vec3(0.0) && keep == 1.0) continue;
        imageStore(window_image, at, vec4(imageLoad(window_image, at).rgb * keep + got / area * weight, 0.0));
    }
}
)";
}

// The mixed term's deficit (mixed_ambient_deficit, emitted) summed in double over every
// element-side by one work group of 64, striding, then a shared-memory tree.
std::string window_deficit_compute() {
    using namespace window_uniform;
    glsl::function_set fs;
    fs.add("radiosity_mixed_deficit", mixed_ambient_deficit<f32, vec3>, "shaped", "floor_level", "area");
    return window_head() + fs.source() + uniforms({{factor, "vec3 factor"}, {floor, "vec3 floor_level"}}) +
           image(window_unit, "readonly image2D window_image") +
           storage_block(partial_binding, "buffer deficit_block { double deficit[]; }") + R"(
shared double s[64 * 3];
void main() {
    uint i = gl_LocalInvocationID.x;
    dvec3 d = dvec3(0.0);
    for (uint e = i; e < element_count; e += 64u) {
        ivec2 xy = element_xy(e);
        float area = element_area(xy);
        if (!(area > 0.0)) continue;
        for (int side = 0; side < sides; ++side) {
            vec3 h = imageLoad(window_image, xy + ivec2(0, side * atlas_height)).rgb;
            d += dvec3(radiosity_mixed_deficit(h * factor, floor_level, area));
        }
    }
    s[i * 3u] = d.x; s[i * 3u + 1u] = d.y; s[i * 3u + 2u] = d.z;
    for (uint stride = 32u; stride > 0u; stride >>= 1u) {
        barrier();
        if (i < stride)
            for (uint c = 0u; c < 3u; ++c) s[i * 3u + c] += s[(i + stride) * 3u + c];
    }
    barrier();
    if (i == 0u)
        for (uint c = 0u; c < 3u; ++c) deficit[c] = s[c];
}
)";
}

}  // namespace bounce::gl::radiosity_glsl
