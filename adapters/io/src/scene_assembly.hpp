#pragma once
/// \file scene_assembly.hpp
/// Private to the io adapter: the steps the scene builders (load_scene, load_obj,
/// cornell_box) share.

#include <bounce/io/scene.hpp>

#include <filesystem>
#include <utility>

#include <glm/vec3.hpp>

namespace bounce::io::detail {

/// Loads the OBJ (+MTL) `obj` into `out`: positions, normals, triangles, materials and
/// warnings; lights and camera are left alone. Throws scene_error naming the file and line.
void load_obj_mesh(const std::filesystem::path& obj, const bounce::material& default_material, scene& out);

/// Sets the camera's far plane to twice the distance from the eye to the farthest corner
/// of `bounds` and the near plane to 1e-4 of that, so that a raster depth buffer keeps its
/// precision for the scene at hand whatever its units.
void fit_clip_planes(bounce::camera& camera, const std::pair<glm::vec3, glm::vec3>& bounds);

}  // namespace bounce::io::detail
