// io::scene basics, the OBJ-only loader, and what `--scene` accepts.
#include "scene_assembly.hpp"

#include <bounce/io/scene.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>

#include <fmt/format.h>
#include <glm/geometric.hpp>

namespace bounce::io {

namespace fs = std::filesystem;

namespace {
// "bounce: FILE:LINE: WHAT", or "bounce: FILE: WHAT" for line 0. (fmt rather than string
// operator+, which trips GCC 12's false -Wrestrict, bug 105651.)
std::string located(const fs::path& file, std::size_t line, const std::string& what) {
    return line > 0 ? fmt::format("bounce: {}:{}: {}", file.string(), line, what)
                    : fmt::format("bounce: {}: {}", file.string(), what);
}
}  // namespace

scene_error::scene_error(fs::path file, std::size_t line, const std::string& what)
    : bounce::error(located(file, line, what)), file_(std::move(file)), line_(line) {}

namespace detail {
void fit_clip_planes(bounce::camera& camera, const std::pair<glm::vec3, glm::vec3>& bounds) {
    bounce::fit_clip_planes(camera, bounds);
}
}  // namespace detail

namespace {
// Frames the bounding sphere in a 45 degree view from +z: distance r / sin(22.5 deg), with
// 5% to spare; returns that distance. In double: a mesh near the float range would overflow.
double frame_from_z(const fs::path& file, scene& s) {
    const auto [lo, hi] = s.bounds();
    const glm::dvec3 centre = 0.5 * (glm::dvec3(lo) + glm::dvec3(hi));
    const double radius = 0.5 * glm::length(glm::dvec3(hi) - glm::dvec3(lo));
    const double distance = 1.05 * radius / std::sin(glm::radians(22.5));
    const glm::dvec3 eye = centre + glm::dvec3(0.0, 0.0, distance);
    const double limit = double(std::numeric_limits<float>::max());
    if (!(std::abs(eye.z) < limit && distance * distance < limit))
        throw scene_error(file, 0, "the mesh is too large (extent " + std::to_string(2 * radius) +
                                       ") to place a camera and a light around it in float");
    s.camera.position = glm::vec3(eye);
    s.camera.look_at = glm::vec3(centre);
    s.camera.up = {0.f, 1.f, 0.f};
    s.camera.fov_y_deg = 45.f;
    detail::fit_clip_planes(s.camera, s.bounds());
    try {
        s.camera.validate();
    } catch (const parameter_error&) {
        // The eye rounds onto the centre: a mesh far smaller than float's resolution at its position.
        throw scene_error(file, 0, "the mesh is too small (extent " + std::to_string(2 * radius) +
                                       ") for float to place a camera around it");
    }
    return distance;
}
}  // namespace

namespace detail {
void place_camera_and_light(const fs::path& file, scene& s, const std::optional<bounce::camera>& given) {
    double distance = 0.0;
    if (given) {
        s.camera = *given;
        detail::fit_clip_planes(s.camera, s.bounds());
        const auto [lo, hi] = s.bounds();
        distance = glm::length(0.5 * (glm::dvec3(lo) + glm::dvec3(hi)) - glm::dvec3(s.camera.position));
    } else {
        distance = frame_from_z(file, s);
    }
    // A head light: E = I / d^2 = 1 W/m^2 at the centre.
    if (s.lights.empty() && s.emissive_triangles().empty())
        s.lights.emplace_back(point_light{s.camera.position, glm::vec3(float(std::min(distance * distance, double(max_light_value))))});
}
}  // namespace detail

scene load_obj(const fs::path& obj, const bounce::material& default_material) {
    scene s;
    s.name = obj.stem().string();
    s.source = obj;
    detail::load_obj_mesh(obj, default_material, s);
    s.use_emission = true;
    s.use_emission = !s.emissive_triangles().empty();
    detail::place_camera_and_light(obj, s, std::nullopt);
    return s;
}

scene load_scene_arg(std::string_view arg) {
    if (arg == "cornell") return cornell_box();
    if (arg.empty()) throw scene_error("", 0, "--scene: empty argument (expected cornell or a path)");
    fs::path p{std::string(arg)};
    std::error_code ec;
    // A bare name that is nothing here is a scene folder under scenes_dir() ("sponza").
    if (!fs::exists(p, ec) && p.has_filename() && p == p.filename()) {
        const fs::path under = scenes_dir() / p;
        if (!fs::is_directory(under, ec)) {
            const char* env = std::getenv("BOUNCE_SCENES");
            throw scene_error(under, 0,
                              "--scene " + p.string() + ": neither cornell, a file here, nor a scene folder under " +
                                  scenes_dir().string() +
                                  (env && *env ? " (BOUNCE_SCENES)" : " (the default; set BOUNCE_SCENES to look elsewhere)"));
        }
        p = under;
    }
    if (fs::is_directory(p, ec)) p /= "scene.json";
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".obj") return load_obj(p);
    if (ext == ".gltf" || ext == ".glb") return load_gltf(p);
    return load_scene(p);
}

fs::path scenes_dir() {
    const char* env = std::getenv("BOUNCE_SCENES");
    if (env && *env) return fs::path(env);
    return fs::path("..") / "shared" / "scenes";
}

}  // namespace bounce::io
