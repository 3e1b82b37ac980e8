#pragma once
/// \file scene_assembly.hpp
/// Private to the io adapter: the steps the scene builders (load_scene, load_obj,
/// cornell_box) share.

#include <bounce/io/scene.hpp>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::io::detail {

/// Loads the OBJ (+MTL) `obj` into `out`: positions, normals, triangles, materials and
/// warnings; lights and camera are left alone. Throws scene_error naming the file and line.
void load_obj_mesh(const std::filesystem::path& obj, const bounce::material& default_material, scene& out);

/// Sets the camera's far plane to twice the distance from the eye to the farthest corner
/// of `bounds` and the near plane to 1e-4 of that, so that a raster depth buffer keeps its
/// precision for the scene at hand whatever its units.
void fit_clip_planes(bounce::camera& camera, const std::pair<glm::vec3, glm::vec3>& bounds);

/// Sets `s.camera` to `given` (clip planes fitted), or, without one, frames the bounding
/// sphere from +z as load_obj documents (throws scene_error naming `file` when float cannot).
/// Then, when `s` has no light and no emitting face, adds a point light at the camera
/// giving about 1 W/m^2 at the centre of the bounds.
void place_camera_and_light(const std::filesystem::path& file, scene& s, const std::optional<bounce::camera>& given);

/// Zero area up to float resolution: the third vertex lies within one float epsilon
/// (relative to the longest edge) of the line through the other two, i.e.
/// |e1 x e2| <= eps * max |e|^2; its face normal would be noise.
inline bool zero_area(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2) {
    const double longest2 = std::max({glm::dot(p1 - p0, p1 - p0), glm::dot(p2 - p1, p2 - p1), glm::dot(p0 - p2, p0 - p2)});
    return !(glm::length(glm::cross(p1 - p0, p2 - p0)) > double(std::numeric_limits<float>::epsilon()) * longest2);
}

/// Checks that `text` is JSON nested at most `max_depth` deep; throws scene_error naming
/// `file` and the line of a syntax error.
void check_json_text(const std::filesystem::path& file, std::string_view text, int max_depth);

/// What a glTF file gives besides the mesh: its first perspective camera, if any, and its
/// KHR_lights_punctual lights in the order of the scene's nodes.
struct gltf_extras {
    std::optional<bounce::camera> camera;
    std::vector<bounce::light> lights;
};

/// Loads the glTF (.gltf or .glb) `file` into `out` (positions, normals, triangles,
/// materials, warnings) and returns its camera and lights (docs/gltf.md). Primitives
/// without a material get `default_material`. Throws scene_error naming the file and the
/// glTF object at fault.
gltf_extras load_gltf_mesh(const std::filesystem::path& file, const bounce::material& default_material, scene& out);

}  // namespace bounce::io::detail
