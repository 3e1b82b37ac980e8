#pragma once
// The GLSL texts of gl::progressive_radiosity's passes (private to adapters/gl/src), the
// locations of their uniforms and the bindings of their storage buffers and images. Each
// number is named once, here: the shader texts declare their uniforms, buffers and images
// from these names (radiosity_shaders.cpp) and the passes set and bind them by the same
// names (radiosity_shooting.cpp), so the two cannot drift apart.
#include <string>

namespace bounce::gl::radiosity_glsl {

// Storage-buffer bindings and image units.
constexpr unsigned texels_binding = 0, nodes_binding = 1, planes_binding = 2, first_binding = 3, element_binding = 4,
                   partial_binding = 5, keep_binding = 6;
constexpr unsigned radiosity_unit = 0, unshot_unit = 1, intercepted_unit = 2, item_unit = 3;
// The lightmap pass's: the atlas texel each lightmap texel shows, where the passes keep the
// element texels, and the lightmap image, where they keep the intercepted power.
constexpr unsigned source_binding = element_binding, lightmap_unit = intercepted_unit;

// The item buffer's fragment shader (stereographic visibility).
namespace item_uniform {
enum : int { resolution = 0, depth_scale = 1 };
}

// The hemicube's vertex and fragment shaders: the shooter's frame, the face drawn (its axes
// and its number), and the depth range.
namespace hemicube_uniform {
enum : int {
    shot_position = 0,
    shot_t = 1,
    shot_b = 2,
    shot_n = 3,
    face_right = 4,
    face_up = 5,
    face_forward = 6,
    face = 7,
    near_z = 8,
    far_z = 9,
    shot_chart = 10,
};
}

// A directional light's orthographic buffer.
namespace parallel_uniform {
enum : int {
    shot_t = 0,
    shot_b = 1,
    shot_n = 2,
    ortho_lo = 3,
    ortho_scale = 4,
    parallel_resolution = 5,
    depth_lo = 6,
    depth_hi = 7,
};
}

// What the distribution and the light passes share: the atlas, the shot, the visibility lookup.
namespace shot_uniform {
enum : int {
    atlas_width = 0,
    atlas_height = 1,
    shot_position = 2,
    shot_t = 3,
    shot_b = 4,
    shot_n = 5,
    shot_chart = 6,
    occlusion = 7,
    resolution = 8,
    diagonal = 9,
    hemicube = 20,
    element_count = 21,
    two_sided = 22,  // 1: the backs' rows follow the fronts' (atlas_height rows on)
};
}

// The distribution pass, beside shot_uniform: the shooter's near-field tree, and whether a
// re-bake's receiver mask (keep_binding) limits the receivers.
namespace distribute_uniform {
enum : int { node_count = 10, near2 = 11, masked = 12 };
}

// The light pass, beside shot_uniform: the light and a directional light's buffer.
namespace light_uniform {
enum : int {
    spot = 10,
    light_axis = 11,
    intensity = 12,
    cos_cone = 13,
    cosine_falloff = 14,
    strict_side = 15,
    parallel = 16,
    ortho_lo = 17,
    ortho_scale = 18,
    parallel_resolution = 19,
};
}

// The display lightmap's pass (update_lightmap_texture); the ambient's shape: 0 the uniform
// `ambient`, 1 shots, 2 mixed (shot_ambient_terms, read at window_unit).
namespace lightmap_uniform {
enum : int { atlas_width = 0, atlas_height = 1, ambient = 2, source_row = 3, shape = 4, factor = 5, floor = 6, scale = 7,
             at_least_direct = 8 };
}
// With the ambient term, the lightmap pass shows at least the direct radiosity (B once the
// lights were shot), read at direct_unit (radiosity_with_ambient_at_least_direct).
constexpr unsigned direct_unit = item_unit;

// The shaped ambient term's passes (radiosity_ambient.cpp): a shot added to the window's
// irradiance, h = h keep + intercepted / area weight; the mixed term's deficit summed into the
// buffer at partial_binding. The window's texture at window_unit (the lightmap pass's too).
namespace window_uniform {
enum : int { atlas_width = 0, atlas_height = 1, element_count = 2, sides = 3, keep = 4, weight = 5, factor = 6, floor = 7 };
}
constexpr unsigned window_unit = unshot_unit;

// The reduction's two passes.
namespace reduce_uniform {
enum : int { atlas_width = 0, shooter_count = 1, blocks = 2, atlas_height = 3 };
}
namespace finish_uniform {
enum : int { shooter_count = 0 };
}

// The pass that scales a shot down to its power.
namespace rescale_uniform {
enum : int { atlas_width = 0, element_count = 1, scale = 2, atlas_height = 3, sides = 4 };
}

std::string item_buffer_vertex();
std::string item_buffer_fragment();
std::string hemicube_vertex();
std::string hemicube_fragment();
std::string parallel_vertex();
std::string parallel_fragment();
// The compute passes; max_nodes and stack_size bound the near-field traversal.
std::string distribute_compute(int max_nodes, int stack_size);
std::string light_compute();
std::string reduce_compute();
std::string finish_compute();
std::string rescale_compute();
std::string lightmap_compute();
std::string window_record_compute();
std::string window_deficit_compute();

}  // namespace bounce::gl::radiosity_glsl
