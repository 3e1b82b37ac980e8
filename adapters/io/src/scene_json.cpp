// scene.json (docs/scenes.md) through nlohmann-json.
//
// Every fault names the file and the field as a path ("lights[0].intensity"); syntax errors
// name the line. The whole JSON is checked before the OBJ is read, so a typo costs no
// seconds of mesh loading.
#include "scene_assembly.hpp"
#include "text_lines.hpp"

#include <bounce/io/scene.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace bounce::io {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

constexpr std::size_t max_json_bytes = std::size_t(1) << 20;  // a scene.json is a few hundred bytes
constexpr int max_json_depth = 16;                             // the format nests 3 deep

class field_reader {
public:
    explicit field_reader(fs::path file) : file_(std::move(file)) {}

    [[noreturn]] void fail(const std::string& field, const std::string& what) const {
        throw scene_error(file_, 0, field + ": " + what);
    }

    void expect_object(const json& v, const std::string& field) const {
        if (!v.is_object()) fail(field, "expected an object {...}");
    }

    // Refuses keys the format does not have: a misspelt optional key would otherwise be
    // ignored without a word.
    void only_keys(const json& obj, std::initializer_list<const char*> keys, const std::string& field) const {
        for (const auto& item : obj.items()) {
            const std::string& key = item.key();  // not a structured binding: clang 14 cannot capture one
            if (std::none_of(keys.begin(), keys.end(), [&](const char* k) { return key == k; })) {
                std::string known;
                for (const char* k : keys) known += std::string(known.empty() ? "" : ", ") + k;
                fail(join(field, key), "unknown field (expected one of " + known + ")");
            }
        }
    }

    const json& member(const json& obj, const char* key, const std::string& field) const {
        const auto it = obj.find(key);
        if (it == obj.end()) fail(join(field, key), "missing");
        return *it;
    }

    static std::string join(const std::string& field, const std::string& key) {
        return field.empty() ? key : field + "." + key;
    }

    float number(const json& v, const std::string& field) const {
        if (!v.is_number()) fail(field, "expected a number");
        const double d = v.get<double>();
        if (!std::isfinite(d) || std::abs(d) > double(std::numeric_limits<float>::max()))
            fail(field, "expected a finite number");
        return static_cast<float>(d);
    }

    // position: within +-max_world_coordinate; light: in [0, max_light_value] (light.hpp).
    enum class range { any, non_negative, unit, position, light };
    glm::vec3 vec3(const json& v, const std::string& field, range r = range::any) const {
        const char* what = r == range::unit           ? "expected 3 numbers in [0, 1]"
                           : r == range::non_negative ? "expected 3 numbers >= 0"
                           : r == range::position     ? "expected 3 numbers within +-1e18 (what float32 rays carry)"
                           : r == range::light        ? "expected 3 numbers in [0, 1e30]"
                                                      : "expected 3 numbers";
        if (!v.is_array() || v.size() != 3) fail(field, what);
        glm::vec3 out;
        for (int i = 0; i < 3; ++i) {
            if (!v[std::size_t(i)].is_number()) fail(field, what);
            const double d = v[std::size_t(i)].get<double>();
            if (!std::isfinite(d) || std::abs(d) > double(std::numeric_limits<float>::max()))
                fail(field, std::string(what) + ", finite");
            if (((r == range::non_negative || r == range::unit || r == range::light) && d < 0.0) ||
                (r == range::unit && d > 1.0) || (r == range::light && d > double(max_light_value)) ||
                (r == range::position && std::abs(d) > double(max_world_coordinate)))
                fail(field, what);
            out[i] = static_cast<float>(d);
        }
        return out;
    }

    // A direction: any non-zero length, returned unit.
    glm::vec3 direction(const json& v, const std::string& field) const {
        const glm::vec3 d = vec3(v, field);
        const float len = glm::length(d);
        if (!(len > 0.f) || !std::isfinite(len)) fail(field, "expected a non-zero direction");
        return d / len;
    }

    std::string string(const json& v, const std::string& field) const {
        if (!v.is_string()) fail(field, "expected a string");
        return v.get<std::string>();
    }

    bool boolean(const json& v, const std::string& field) const {
        if (!v.is_boolean()) fail(field, "expected true or false");
        return v.get<bool>();
    }

private:
    fs::path file_;
};

json parse_json(const fs::path& file, std::string_view text, int max_depth = max_json_depth) {
    // nlohmann's parser keeps its own stack, but the depth callback bounds the work and
    // the tree we would have to destroy for an adversarial file.
    const json::parser_callback_t depth_limit = [&](int depth, json::parse_event_t, json&) {
        if (depth > max_depth) throw scene_error(file, 0, "nested deeper than " + std::to_string(max_depth) + " levels");
        return true;
    };
    try {
        return json::parse(text, depth_limit, /*allow_exceptions=*/true, /*ignore_comments=*/false);
    } catch (const json::exception& e) {
        // "[json.exception.parse_error.101] parse error at line 3, column 5: ..." -> line 3.
        std::string what = e.what();
        if (const auto close = what.find("] "); what.rfind("[json.exception", 0) == 0 && close != std::string::npos)
            what = what.substr(close + 2);
        throw scene_error(file, detail::line_in_message(what), "JSON: " + what);
    }
}

light read_light(const field_reader& r, const json& j, const std::string& field) {
    r.expect_object(j, field);
    const std::string type = r.string(r.member(j, "type", field), field + ".type");
    const auto f = [&](const char* key) { return field + "." + key; };
    if (type == "point") {
        r.only_keys(j, {"type", "position", "intensity"}, field);
        point_light l;
        l.position = r.vec3(r.member(j, "position", field), f("position"), field_reader::range::position);
        l.intensity = r.vec3(r.member(j, "intensity", field), f("intensity"), field_reader::range::light);
        return l;
    }
    if (type == "spot") {
        r.only_keys(j, {"type", "position", "direction", "intensity", "cone_deg", "falloff"}, field);
        spot_light l;
        l.position = r.vec3(r.member(j, "position", field), f("position"), field_reader::range::position);
        l.direction = r.direction(r.member(j, "direction", field), f("direction"));
        l.intensity = r.vec3(r.member(j, "intensity", field), f("intensity"), field_reader::range::light);
        l.cone_deg = r.number(r.member(j, "cone_deg", field), f("cone_deg"));
        if (!(l.cone_deg > 0.f && l.cone_deg <= 180.f)) r.fail(f("cone_deg"), "must lie in (0, 180]");
        const std::string falloff = r.string(r.member(j, "falloff", field), f("falloff"));
        if (falloff == "cosine") l.falloff = spot_light::falloff_kind::cosine;
        else if (falloff == "none") l.falloff = spot_light::falloff_kind::none;
        else r.fail(f("falloff"), "unknown falloff '" + falloff.substr(0, 40) + "' (expected cosine or none)");
        return l;
    }
    if (type == "directional") {
        r.only_keys(j, {"type", "direction", "irradiance"}, field);
        directional_light l;
        l.direction = r.direction(r.member(j, "direction", field), f("direction"));
        l.irradiance = r.vec3(r.member(j, "irradiance", field), f("irradiance"), field_reader::range::light);
        return l;
    }
    r.fail(f("type"), "unknown light type '" + type.substr(0, 40) + "' (expected point, spot or directional)");
}

bounce::camera read_camera(const field_reader& r, const json& cam) {
    r.expect_object(cam, "camera");
    r.only_keys(cam, {"position", "look_at", "up", "fov_y_deg"}, "camera");
    bounce::camera c;
    c.position = r.vec3(r.member(cam, "position", "camera"), "camera.position", field_reader::range::position);
    c.look_at = r.vec3(r.member(cam, "look_at", "camera"), "camera.look_at", field_reader::range::position);
    c.up = r.vec3(r.member(cam, "up", "camera"), "camera.up");
    c.fov_y_deg = r.number(r.member(cam, "fov_y_deg", "camera"), "camera.fov_y_deg");
    try {
        c.validate();
    } catch (const parameter_error& e) {
        const std::string what = e.what();
        r.fail("camera." + e.parameter(), what.substr(what.rfind("': ") == std::string::npos ? 0 : what.rfind("': ") + 3));
    }
    return c;
}

// The mesh file: exactly one of "obj" and "gltf".
std::pair<std::string, bool> mesh_file(const field_reader& r, const json& root) {
    const bool obj = root.contains("obj"), gltf = root.contains("gltf");
    if (obj == gltf) r.fail(obj ? "gltf" : "obj", obj ? "given with obj: name one mesh file" : "missing (or gltf)");
    const char* key = obj ? "obj" : "gltf";
    const std::string name = r.string(root.at(key), key);
    if (name.empty()) r.fail(key, "empty file name");
    if (obj && root.contains("gltf_lights")) r.fail("gltf_lights", "only with gltf");
    return {name, gltf};
}

}  // namespace

namespace detail {
void check_json_text(const fs::path& file, std::string_view text, int max_depth) { parse_json(file, text, max_depth); }
}  // namespace detail

scene load_scene(const fs::path& file) {
    const std::string text = detail::read_text_file(file, max_json_bytes);
    const json root = parse_json(file, text);
    const field_reader r(file);
    if (!root.is_object()) throw scene_error(file, 0, "expected a JSON object {...} at the top");
    r.only_keys(root, {"obj", "gltf", "gltf_lights", "default_material", "camera", "lights", "use_emission"}, "");

    scene s;
    s.source = file;
    s.name = file.parent_path().filename().string();
    if (s.name.empty() || s.name == "." || s.name == "..") s.name = file.stem().string();
    const auto [mesh, gltf] = mesh_file(r, root);

    bounce::material default_material;
    if (const auto it = root.find("default_material"); it != root.end()) {
        r.expect_object(*it, "default_material");
        r.only_keys(*it, {"kd"}, "default_material");
        default_material.albedo = r.vec3(r.member(*it, "kd", "default_material"), "default_material.kd", field_reader::range::unit);
    }
    // With a glTF file, camera and lights are optional: the file's own, overridden or added to.
    std::optional<bounce::camera> camera;
    if (!gltf || root.contains("camera")) camera = read_camera(r, r.member(root, "camera", ""));
    std::vector<light> lights;
    if (!gltf || root.contains("lights")) {
        const json& list = r.member(root, "lights", "");
        if (!list.is_array()) r.fail("lights", "expected an array [...]");
        for (std::size_t i = 0; i < list.size(); ++i) lights.push_back(read_light(r, list[i], "lights[" + std::to_string(i) + "]"));
    }
    std::optional<bool> use_emission;
    if (const auto it = root.find("use_emission"); it != root.end()) use_emission = r.boolean(*it, "use_emission");
    const bool gltf_lights = !root.contains("gltf_lights") || r.boolean(root.at("gltf_lights"), "gltf_lights");

    if (gltf) {
        detail::gltf_extras extras = detail::load_gltf_mesh(file.parent_path() / mesh, default_material, s);
        if (gltf_lights) s.lights = std::move(extras.lights);
        if (!camera) camera = extras.camera;
        s.use_emission = true;
        s.use_emission = use_emission.value_or(!s.emissive_triangles().empty());
    } else {
        detail::load_obj_mesh(file.parent_path() / mesh, default_material, s);
        s.use_emission = use_emission.value_or(false);
    }
    s.lights.insert(s.lights.end(), lights.begin(), lights.end());
    if (s.lights.empty() && s.emissive_triangles().empty())
        r.fail("lights", s.use_emission ? std::string("empty, and no face of the ") + (gltf ? "glTF emits (emissiveFactor)" : "OBJ emits (Ke)") + ": the scene has no light"
                                        : "empty and use_emission is false: the scene has no light");
    detail::place_camera_and_light(file, s, camera);
    return s;
}

}  // namespace bounce::io
