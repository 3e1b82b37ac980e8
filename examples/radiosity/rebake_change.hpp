#pragma once
// The change a re-bake run makes to the scene (rebake.hpp): --rebake-light K,SCALE (light K's
// intensity times SCALE) or --rebake-move OBJECT,DX,DY,DZ[,SHARE] (OBJECT: a material's name,
// with #N for its N-th group of connected triangles, moved by DX, DY, DZ; SHARE: the share of
// the shot power the correction re-shoots, cpu::rebake_move's `share`).
#include <bounce/errors.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/radiosity/rebake.hpp>

#include "options.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
#include <tuple>
#include <variant>
#include <vector>

namespace bounce::examples {

// "a,b,c" as numbers; `count` of them, else parameter_error naming `option`.
inline std::vector<double> rebake_numbers(const std::string& text, std::size_t count, const char* option, const char* form) {
    std::vector<double> v;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');) {
        std::size_t used = 0;
        double x = 0;
        try {
            x = std::stod(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != item.size() || !std::isfinite(x)) throw parameter_error(option, "must be " + std::string(form));
        v.push_back(x);
    }
    if (v.size() != count) throw parameter_error(option, "must be " + std::string(form));
    return v;
}

// The triangles of `spec` (MATERIAL[#N]): the material's triangles grouped by shared vertex
// positions, groups numbered by their first triangle.
inline std::vector<std::uint32_t> object_triangles(const io::scene& s, const std::string& spec) {
    const std::size_t hash = spec.find('#');
    const std::string name = spec.substr(0, hash);
    const std::size_t index = hash == std::string::npos ? 0 : std::size_t(rebake_numbers(spec.substr(hash + 1), 1, "--rebake-move", "MATERIAL[#N],DX,DY,DZ")[0]);
    const auto m = std::find(s.material_names.begin(), s.material_names.end(), name);
    if (m == s.material_names.end()) {
        std::string names;
        for (const auto& n : s.material_names) names += (names.empty() ? "" : ", ") + n;
        throw parameter_error("--rebake-move", "no material '" + name + "' in " + s.name + " (" + names + ")");
    }
    const auto material = std::uint32_t(m - s.material_names.begin());
    std::vector<std::uint32_t> parent(s.triangles.size());
    std::iota(parent.begin(), parent.end(), 0u);
    const auto root = [&](std::uint32_t t) {
        while (parent[t] != t) t = parent[t] = parent[parent[t]];
        return t;
    };
    std::map<std::tuple<float, float, float>, std::uint32_t> first_at;
    for (std::uint32_t t = 0; t < s.triangles.size(); ++t) {
        if (s.material_of[t] != material) continue;
        for (int k = 0; k < 3; ++k) {
            const glm::vec3 p = s.positions[s.triangles[t][k]];
            const auto [it, added] = first_at.emplace(std::tuple{p.x, p.y, p.z}, t);
            if (!added) parent[root(t)] = root(it->second);
        }
    }
    std::vector<std::uint32_t> roots;  // in order of their first triangle
    for (std::uint32_t t = 0; t < s.triangles.size(); ++t)
        if (s.material_of[t] == material && std::find(roots.begin(), roots.end(), root(t)) == roots.end()) roots.push_back(root(t));
    if (index >= roots.size())
        throw parameter_error("--rebake-move", fmt::format("{} has {} groups of connected triangles: #0 .. #{}", name, roots.size(),
                                                           roots.size() - 1));
    std::vector<std::uint32_t> out;
    for (std::uint32_t t = 0; t < s.triangles.size(); ++t)
        if (s.material_of[t] == material && root(t) == roots[index]) out.push_back(t);
    return out;
}

// The scene after the change the options ask for, and the change.
struct scene_change {
    io::scene changed;
    std::vector<std::uint32_t> moved;  // the moved object's triangles; empty for a light
    rigid_move move;
    std::size_t light_index = 0;
    double share = 1;  // of the shot power, the share the correction re-shoots
};

inline scene_change parse_change(const options& o, const io::scene& scene) {
    if (!o.rebake_light.empty() && !o.rebake_move.empty())
        throw parameter_error("--rebake-move", "one change at a time: not with --rebake-light");
    scene_change c{scene, {}, {}, 0, 1};
    if (!o.rebake_light.empty()) {
        const auto v = rebake_numbers(o.rebake_light, 2, "--rebake-light", "K,SCALE");
        c.light_index = std::size_t(v[0]);
        if (v[0] < 0 || c.light_index >= scene.lights.size() || v[1] < 0)
            throw parameter_error("--rebake-light", fmt::format("K must be a light of {} (0 .. {}) and SCALE non-negative",
                                                                scene.name, int(scene.lights.size()) - 1));
        std::visit([&](auto& l) {
            if constexpr (requires { l.intensity; }) l.intensity *= float(v[1]);
            else l.irradiance *= float(v[1]);
        }, c.changed.lights[c.light_index]);
    } else {
        const std::size_t comma = o.rebake_move.find(',');
        c.moved = object_triangles(scene, o.rebake_move.substr(0, comma));
        const std::string numbers = comma == std::string::npos ? "" : o.rebake_move.substr(comma + 1);
        const bool with_share = std::count(numbers.begin(), numbers.end(), ',') == 3;
        const auto d = rebake_numbers(numbers, with_share ? 4 : 3, "--rebake-move", "MATERIAL[#N],DX,DY,DZ[,SHARE]");
        c.move.translation = glm::vec3(float(d[0]), float(d[1]), float(d[2]));
        if (with_share) c.share = d[3];
        std::vector<std::uint8_t> vertex(scene.positions.size(), 0);
        for (const std::uint32_t t : c.moved)
            for (int k = 0; k < 3; ++k) vertex[scene.triangles[t][k]] = 1;
        for (std::size_t v = 0; v < vertex.size(); ++v)
            if (vertex[v]) c.changed.positions[v] = c.move.point(c.changed.positions[v]);
    }
    return c;
}

}  // namespace bounce::examples
