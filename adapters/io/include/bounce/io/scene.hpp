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
    scene_error(std::filesystem::path file, std::size_t line, const std::string& what);
    const std::filesystem::path& file() const noexcept { return file_; }
    std::size_t line() const noexcept { return line_; }

private:
    std::filesystem::path file_;
    std::size_t line_;
};

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

    /// Indices of triangles that emit (only when use_emission).
    std::vector<std::uint32_t> emissive_triangles() const;
    /// Axis-aligned bounds of all vertices: {min, max}.
    std::pair<glm::vec3, glm::vec3> bounds() const;
};

/// Loads a scene.json (and the OBJ+MTL it names). Throws scene_error.
scene load_scene(const std::filesystem::path& scene_json);
/// Loads an OBJ (+MTL) alone with default camera/lights fitted to its bounds.
scene load_obj(const std::filesystem::path& obj, const material& default_material = {});
/// The Cornell box from its published dimensions and reflectances, with camera and light.
scene cornell_box();
/// What every program's `--scene` accepts: `cornell` for the built-in box, or a path to a
/// scene.json (or an .obj).
scene load_scene_arg(std::string_view arg);
/// Where the shared scenes live: $BOUNCE_SCENES, else "../shared/scenes".
std::filesystem::path scenes_dir();

}  // namespace bounce::io
