#pragma once
/// \file scene.hpp
/// `io::scene`: triangles, per-vertex normals, per-triangle materials, lights and a camera,
/// loaded from OBJ+MTL (tinyobjloader) and the `scene.json` beside it, or built in
/// (`cornell_box()`). The scene.json format is specified in docs/scenes.md.

#include <bounce/camera.hpp>
#include <bounce/errors.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <variant>
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

/// A diffuse material: MTL `Kd` and `Ke`.
struct material {
    std::string name;
    glm::vec3 kd{0.8f};  ///< diffuse reflectance rho_d, each channel in [0, 1]
    glm::vec3 ke{0.f};   ///< emitted radiance (W / m^2 / sr), used when scene::use_emission
};

/// Isotropic point light; `intensity` in W/sr per channel.
struct point_light {
    glm::vec3 position{0.f}, intensity{1.f};
};

/// Spot light; `intensity` in W/sr on the axis; dark beyond `cone_deg` from the axis.
struct spot_light {
    enum class falloff_kind { none, cosine };
    glm::vec3 position{0.f}, direction{0, -1, 0}, intensity{1.f};
    float cone_deg = 45.f;
    falloff_kind falloff = falloff_kind::cosine;
};

/// Distant light; `direction` is the way the light travels; `irradiance` in W/m^2 on a
/// surface facing it.
struct directional_light {
    glm::vec3 direction{0, -1, 0}, irradiance{1.f};
};

using light = std::variant<point_light, spot_light, directional_light>;

/// A triangle mesh with per-vertex normals, per-triangle materials, lights and a camera.
struct scene {
    std::string name;                        ///< "cornell" or the scene folder's name
    std::filesystem::path source;            ///< the scene.json or OBJ it came from (empty if built in)
    std::vector<glm::vec3> positions;        ///< vertex positions
    std::vector<glm::vec3> normals;          ///< unit vertex normals, one per position
    std::vector<glm::uvec3> triangles;       ///< indices into positions/normals
    std::vector<std::uint32_t> material_of;  ///< material index per triangle
    std::vector<material> materials;
    std::vector<light> lights;
    bool use_emission = false;  ///< faces whose material has ke > 0 are area lights too
    bounce::camera camera;
    /// What the loader repaired or dropped without failing (degenerate triangles, repeated
    /// triangles, zero normals), one line each, for programs to print.
    std::vector<std::string> warnings;

    /// Indices of triangles that emit (only when use_emission).
    std::vector<std::uint32_t> emissive_triangles() const;
    /// Axis-aligned bounds of all vertices: {min, max}.
    std::pair<glm::vec3, glm::vec3> bounds() const;
};

/// Throws parameter_error naming "scene.lights[i]" and the field unless every light can
/// be rendered: finite positions, finite non-negative intensities and irradiances, finite
/// non-zero directions, spot cones in (0, 180] degrees. Code that builds scenes by hand
/// gets the same check from every adapter that shades lights.
void validate_lights(const scene& s);

/// Loads a scene.json (and the OBJ+MTL it names), as docs/scenes.md specifies.
/// \param scene_json path of the JSON file; the OBJ path inside it is relative to its folder.
/// \throws scene_error naming the file and the line (OBJ, MTL, JSON syntax) or the field
///         (e.g. "lights[0].intensity: expected 3 numbers").
scene load_scene(const std::filesystem::path& scene_json);
/// Loads an OBJ (+MTL) alone. The camera sits on the +z side of the bounds looking at their
/// centre (fov_y 45 deg, bounding sphere in view); the light is a point light at the camera
/// giving about 1 W/m^2 at the centre, or none with use_emission when a used material has Ke.
/// \param default_material the material of faces without `usemtl`.
/// \throws scene_error naming the file and line.
scene load_obj(const std::filesystem::path& obj, const material& default_material = {});
/// The Cornell box from its published dimensions (Cornell University Program of Computer
/// Graphics, "Cornell Box Data"), in metres, with the published camera, the light quad as
/// an emissive material (Ke = (17, 12, 4), use_emission false) and a cosine spot of the same
/// power just below it. 38 triangles, all facing into the box (see docs/scenes.md).
scene cornell_box();
/// What every program's `--scene` accepts: `cornell` for the built-in box, a path to a
/// scene.json, a folder holding a scene.json, an .obj (loaded with load_obj), or the name
/// of a scene folder under scenes_dir() (`sponza`) when no file or folder here has it.
/// \throws scene_error
scene load_scene_arg(std::string_view arg);
/// Where the shared scenes live: $BOUNCE_SCENES when set and non-empty, else
/// "../shared/scenes" (relative to the working directory).
std::filesystem::path scenes_dir();

}  // namespace bounce::io
