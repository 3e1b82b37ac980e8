#pragma once
/// \file scene.hpp
/// `io::scene`: triangles, per-vertex normals, per-triangle materials, lights and a camera,
/// loaded from OBJ+MTL (tinyobjloader) or glTF 2.0 (tinygltf) and the `scene.json` beside
/// it, or built in (`cornell_box()`). The scene.json format is specified in docs/scenes.md,
/// what bounce takes from a glTF file in docs/gltf.md.

#include <bounce/camera.hpp>
#include <bounce/errors.hpp>
#include <bounce/light.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::io {

/// A malformed, truncated, empty or missing scene file. `file()` and `line()` say where
/// (line 0 when the fault is not tied to a line, e.g. a missing file or a JSON field).
struct scene_error : bounce::error {
    /// \param file the file at fault; \param line 1-based line, 0 when not tied to a line;
    /// \param what the fault, starting with the field for JSON faults ("camera.fov_y_deg: ...").
    scene_error(std::filesystem::path file, std::size_t line, const std::string& what);
    const std::filesystem::path& file() const noexcept { return file_; }
    std::size_t line() const noexcept { return line_; }

private:
    std::filesystem::path file_;
    std::size_t line_;
};

/// A triangle mesh with per-vertex normals, per-triangle materials, lights and a camera, owned;
/// `view()` hands the adapters the non-owning `scene_view` they take.
struct scene {
    std::string name;                        ///< "cornell" or the scene folder's name
    std::filesystem::path source;            ///< the scene.json, OBJ or glTF it came from (empty if built in)
    std::vector<glm::vec3> positions;        ///< vertex positions
    std::vector<glm::vec3> normals;          ///< unit vertex normals, one per position
    std::vector<glm::uvec3> triangles;       ///< indices into positions/normals
    std::vector<std::uint32_t> material_of;  ///< material index per triangle
    std::vector<bounce::material> materials;  ///< MTL Kd as albedo, Ke as emission
    std::vector<std::string> material_names;  ///< one per material (MTL newmtl), for messages
    std::vector<bounce::light> lights;
    bool use_emission = false;  ///< faces whose material has ke > 0 are area lights too
    bounce::camera camera;
    /// What the loader repaired or dropped without failing (degenerate triangles, repeated
    /// triangles, zero normals), one line each, for programs to print.
    std::vector<std::string> warnings;

    /// The view of this scene every adapter takes; valid while the scene lives and is not
    /// resized (as a string_view is of its string).
    scene_view view() const& noexcept {
        return {positions, normals, triangles, material_of, materials, lights, use_emission};
    }
    /// The same view, so that a scene can be passed wherever a scene_view is taken.
    operator scene_view() const& noexcept { return view(); }

    /// Indices of triangles that emit (only when use_emission).
    std::vector<std::uint32_t> emissive_triangles() const { return view().emissive_triangles(); }
    /// Axis-aligned bounds of all vertices: {min, max}.
    std::pair<glm::vec3, glm::vec3> bounds() const noexcept { return view().bounds(); }
};

/// Loads a scene.json (and the OBJ+MTL or glTF it names), as docs/scenes.md specifies.
/// \param scene_json path of the JSON file; the mesh path inside it is relative to its folder.
/// \throws scene_error naming the file and the line (OBJ, MTL, JSON syntax) or the field
///         (e.g. "lights[0].intensity: expected 3 numbers").
scene load_scene(const std::filesystem::path& scene_json);
/// Loads an OBJ (+MTL) alone. The camera sits on the +z side of the bounds looking at their
/// centre (fov_y 45 deg, bounding sphere in view); the light is a point light at the camera
/// giving about 1 W/m^2 at the centre, or none with use_emission when a used material has Ke.
/// \param default_material the material of faces without `usemtl`.
/// \throws scene_error naming the file and line.
scene load_obj(const std::filesystem::path& obj, const bounce::material& default_material = {});
/// Loads a glTF 2.0 file (.gltf with its buffers, or .glb) alone, as docs/gltf.md specifies:
/// the meshes of the scene's nodes in world space, base colour as albedo, emission (and
/// use_emission set when a used material emits), KHR_lights_punctual lights and the first
/// perspective camera. Without a camera it is placed as load_obj places it; without lights
/// and emission a head light is added as load_obj adds it.
/// \param default_material the material of primitives without one.
/// \throws scene_error naming the file and the glTF object at fault ("accessors[3]: ...").
scene load_gltf(const std::filesystem::path& file, const bounce::material& default_material = {});
/// The Cornell box from its published dimensions (Cornell University Program of Computer
/// Graphics, "Cornell Box Data"), in metres, with the published camera, the light quad as
/// an emissive material (Ke = (17, 12, 4), use_emission false) and a cosine spot of the same
/// power just below it. 38 triangles, all facing into the box (see docs/scenes.md).
scene cornell_box();
/// What every program's `--scene` accepts: `cornell` for the built-in box, a path to a
/// scene.json, a folder holding a scene.json, an .obj (loaded with load_obj), a .gltf or
/// .glb (load_gltf), or the name
/// of a scene folder under scenes_dir() (`sponza`) when no file or folder here has it.
/// \throws scene_error
scene load_scene_arg(std::string_view arg);
/// Where the shared scenes live: $BOUNCE_SCENES when set and non-empty, else
/// "../shared/scenes" (relative to the working directory).
std::filesystem::path scenes_dir();

}  // namespace bounce::io
