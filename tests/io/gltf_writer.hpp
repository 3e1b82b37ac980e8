#pragma once
// glTF 2.0 files the tests write themselves: a JSON document and one binary buffer, written
// as a .gltf with the buffer embedded as a base64 data URI or as a .glb. Nothing here
// checks what it writes, so that tests can write broken files too. write_scene_as_gltf
// exports an io::scene (the Cornell box): one primitive per run of triangles of one
// material, the camera as a node, point and directional lights as KHR_lights_punctual.
#include <bounce/io/scene.hpp>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <variant>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <nlohmann/json.hpp>

namespace bounce::test {

inline std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::uint32_t n = (std::uint32_t(bytes[i]) << 16) | (i + 1 < bytes.size() ? std::uint32_t(bytes[i + 1]) << 8 : 0u) |
                                (i + 2 < bytes.size() ? std::uint32_t(bytes[i + 2]) : 0u);
        out += digits[(n >> 18) & 63];
        out += digits[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? digits[(n >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? digits[n & 63] : '=';
    }
    return out;
}

struct gltf_writer {
    nlohmann::json doc = {{"asset", {{"version", "2.0"}}}};
    std::vector<unsigned char> bin;

    // Appends `bytes` (4-byte aligned) as a new bufferView; returns its index.
    int view(const void* data, std::size_t bytes, std::size_t stride = 0) {
        while (bin.size() % 4) bin.push_back(0);
        nlohmann::json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}};
        if (stride) v["byteStride"] = stride;
        const auto* p = static_cast<const unsigned char*>(data);
        bin.insert(bin.end(), p, p + bytes);
        return push("bufferViews", v);
    }
    // A new accessor over a new view holding `values`.
    template <class T>
    int accessor(const std::vector<T>& values, int component_type, const char* type) {
        const int v = view(values.data(), values.size() * sizeof(T));
        return push("accessors", {{"bufferView", v}, {"componentType", component_type}, {"count", values.size()}, {"type", type}});
    }
    int vec3s(const std::vector<glm::vec3>& v) {
        const int a = accessor(v, 5126, "VEC3");
        // POSITION accessors need min and max; the loader does not read them.
        glm::vec3 lo(1e30f), hi(-1e30f);
        for (const auto& p : v) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        doc["accessors"][std::size_t(a)]["min"] = {lo.x, lo.y, lo.z};
        doc["accessors"][std::size_t(a)]["max"] = {hi.x, hi.y, hi.z};
        return a;
    }
    template <class T>
    int indices(const std::vector<std::uint32_t>& idx) {
        const std::vector<T> narrow(idx.begin(), idx.end());
        return accessor(narrow, sizeof(T) == 1 ? 5121 : sizeof(T) == 2 ? 5123 : 5125, "SCALAR");
    }
    int push(const char* array, const nlohmann::json& value) {
        doc[array].push_back(value);
        return int(doc[array].size()) - 1;
    }
    void scene(const std::vector<int>& roots) {
        doc["scenes"] = {{{"nodes", roots}}};
        doc["scene"] = 0;
    }
    void use_lights(const nlohmann::json& lights) {
        doc["extensions"]["KHR_lights_punctual"]["lights"] = lights;
        doc["extensionsUsed"].push_back("KHR_lights_punctual");
    }

    nlohmann::json with_buffer(bool embedded) const {
        nlohmann::json d = doc;
        nlohmann::json b = {{"byteLength", bin.size()}};
        if (embedded) b["uri"] = "data:application/octet-stream;base64," + base64(bin);
        if (!bin.empty()) d["buffers"] = {b};
        return d;
    }
    std::string gltf_text() const { return with_buffer(true).dump(1); }
    std::string glb_bytes() const {
        std::string json = with_buffer(false).dump();
        while (json.size() % 4) json += ' ';
        std::vector<unsigned char> data = bin;
        while (data.size() % 4) data.push_back(0);
        std::string out;
        const auto u32 = [&](std::uint32_t v) { for (int i = 0; i < 4; ++i) out += char((v >> (8 * i)) & 0xff); };
        out += "glTF";
        u32(2);
        u32(std::uint32_t(12 + 8 + json.size() + (data.empty() ? 0 : 8 + data.size())));
        u32(std::uint32_t(json.size()));
        u32(0x4E4F534Au);
        out += json;
        if (!data.empty()) {
            u32(std::uint32_t(data.size()));
            u32(0x004E4942u);
            out.append(reinterpret_cast<const char*>(data.data()), data.size());
        }
        return out;
    }
    void write(const std::filesystem::path& file) const {
        const std::string bytes = file.extension() == ".glb" ? glb_bytes() : gltf_text();
        std::ofstream(file, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    }
};

// The rotation (x y z w) of a glTF node whose -z looks along `forward` with `up` as its +y.
inline std::vector<double> look_rotation(glm::dvec3 forward, glm::dvec3 up) {
    const glm::dvec3 z = -glm::normalize(forward), x = glm::normalize(glm::cross(up, z)), y = glm::cross(z, x);
    const glm::dquat q = glm::quat_cast(glm::dmat3(x, y, z));
    return {q.x, q.y, q.z, q.w};
}

// `s` as a glTF file: materials (emission above 1 through KHR_materials_emissive_strength),
// one mesh with a primitive per run of same-material triangles (triangle order kept), the
// camera, and point and directional lights (spots are left to a scene.json: bounce's cosine
// spot has no glTF form).
inline gltf_writer scene_as_gltf(const io::scene& s) {
    gltf_writer w;
    for (std::size_t m = 0; m < s.materials.size(); ++m) {
        const glm::vec3 a = s.materials[m].albedo, e = s.materials[m].emission;
        const double strength = std::max({1.0, double(e.x), double(e.y), double(e.z)});
        nlohmann::json mat = {{"name", s.material_names[m]},
                              {"pbrMetallicRoughness", {{"baseColorFactor", {a.x, a.y, a.z, 1.0}}, {"metallicFactor", 0.0}}},
                              {"emissiveFactor", {e.x / strength, e.y / strength, e.z / strength}}};
        if (strength > 1.0) mat["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = strength;
        w.push("materials", mat);
    }
    nlohmann::json primitives = nlohmann::json::array();
    for (std::size_t t = 0; t < s.triangles.size();) {
        std::size_t end = t;
        while (end < s.triangles.size() && s.material_of[end] == s.material_of[t]) ++end;
        std::vector<glm::vec3> p, n;
        std::vector<std::uint32_t> idx;
        std::vector<std::uint32_t> local(s.positions.size(), UINT32_MAX);
        for (std::size_t k = t; k < end; ++k)
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t v = s.triangles[k][c];
                if (local[v] == UINT32_MAX) {
                    local[v] = std::uint32_t(p.size());
                    p.push_back(s.positions[v]);
                    n.push_back(s.normals[v]);
                }
                idx.push_back(local[v]);
            }
        primitives.push_back({{"attributes", {{"POSITION", w.vec3s(p)}, {"NORMAL", w.accessor(n, 5126, "VEC3")}}},
                              {"indices", w.indices<std::uint32_t>(idx)},
                              {"material", s.material_of[t]}});
        t = end;
    }
    w.push("meshes", {{"primitives", primitives}});
    std::vector<int> roots = {w.push("nodes", {{"mesh", 0}})};
    const glm::dvec3 eye(s.camera.position), forward = glm::dvec3(s.camera.look_at) - eye;
    w.push("cameras", {{"type", "perspective"},
                       {"perspective", {{"yfov", glm::radians(double(s.camera.fov_y_deg))}, {"znear", 0.01}}}});
    roots.push_back(w.push("nodes", {{"camera", 0}, {"translation", {eye.x, eye.y, eye.z}},
                                     {"rotation", look_rotation(forward, glm::dvec3(s.camera.up))}}));
    nlohmann::json lights = nlohmann::json::array();
    // glTF colours lie in [0, 1]: the largest channel goes into the intensity.
    const auto colour_and_intensity = [](const char* type, glm::vec3 v) {
        const double top = std::max({1.0, double(v.x), double(v.y), double(v.z)});
        return nlohmann::json{{"type", type}, {"color", {v.x / top, v.y / top, v.z / top}}, {"intensity", top}};
    };
    for (const auto& l : s.lights) {
        nlohmann::json node;
        if (const auto* pl = std::get_if<point_light>(&l)) {
            node = {{"translation", {pl->position.x, pl->position.y, pl->position.z}}};
            lights.push_back(colour_and_intensity("point", pl->intensity));
        } else if (const auto* dl = std::get_if<directional_light>(&l)) {
            node = {{"rotation", look_rotation(glm::dvec3(dl->direction), std::abs(dl->direction.y) < 0.9f ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0))}};
            lights.push_back(colour_and_intensity("directional", dl->irradiance));
        } else {
            continue;
        }
        node["extensions"]["KHR_lights_punctual"]["light"] = lights.size() - 1;
        roots.push_back(w.push("nodes", node));
    }
    if (!lights.empty()) w.use_lights(lights);
    w.scene(roots);
    return w;
}

}  // namespace bounce::test

namespace bounce::test {

// Writes `s` as `<stem>.glb` into `folder` with a scene.json beside it that names it and
// gives the spot lights glTF cannot hold, and use_emission as `s` has it: loading the
// scene.json gives `s` again. Returns the scene.json's path.
inline std::filesystem::path write_as_gltf_scene(const io::scene& s, const std::filesystem::path& folder, const std::string& stem) {
    scene_as_gltf(s).write(folder / (stem + ".glb"));
    nlohmann::json spots = nlohmann::json::array();
    for (const auto& l : s.lights)
        if (const auto* sl = std::get_if<spot_light>(&l))
            spots.push_back({{"type", "spot"},
                             {"position", {sl->position.x, sl->position.y, sl->position.z}},
                             {"direction", {sl->direction.x, sl->direction.y, sl->direction.z}},
                             {"intensity", {sl->intensity.x, sl->intensity.y, sl->intensity.z}},
                             {"cone_deg", sl->cone_deg},
                             {"falloff", sl->falloff == spot_light::falloff_kind::cosine ? "cosine" : "none"}});
    const nlohmann::json scene = {{"gltf", stem + ".glb"}, {"lights", spots}, {"use_emission", s.use_emission}};
    const auto file = folder / (stem + ".json");
    std::ofstream(file) << scene.dump(2);
    return file;
}

}  // namespace bounce::test
