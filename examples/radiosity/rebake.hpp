#pragma once
// radiosity's re-bakes (docs/radiosity.md, "Re-baking what changed"): with
// --rebake-light K,SCALE (light K's intensity times SCALE) or --rebake-move OBJECT,DX,DY,DZ
// (OBJECT: a material's name, with #N for its N-th group of connected triangles, moved by
// DX, DY, DZ), the scene is baked as the options ask, changed, re-baked from that solution
// (cpu::rebake_light, cpu::rebake_move) and solved fresh (atlas, lights, solve). The fresh
// solve is then converged on to --rebake-check of the same measure: the answer both should
// reach. Reported: the fresh solve's time to --converge and its error against that answer;
// the re-bake's time (correction + solve) to the same error, measured at checkpoints with the
// clock paused; the re-bake's and the fresh solve's views both converged, against each other;
// the ratio of the times; and, with --reference on, both against the multi-bounce reference
// of the changed scene. CPU, ray-cast visibility, uniform atlas.
#include <bounce/cpu/radiosity_rebake.hpp>
#include <bounce/embree/radiosity_visibility.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/frame_comparison.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/multi_bounce_cache.hpp>
#include <bounce/study/stage_timer.hpp>

#include "options.hpp"
#include "view.hpp"

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <map>
#include <numeric>
#include <optional>
#include <sstream>
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

// The re-bake's run: see the file comment.
inline int run_rebake(const options& o, const io::scene& scene, const embree::accel& bvh) {
    if (o.backend != backend::cpu || o.visibility != visibility_kind::rays || o.adaptive)
        throw parameter_error(o.rebake_move.empty() ? "--rebake-light" : "--rebake-move",
                              "needs --backend cpu, --visibility rays and --adaptive off");
    if (!o.rebake_light.empty() && !o.rebake_move.empty())
        throw parameter_error("--rebake-move", "one change at a time: not with --rebake-light");
    if (!o.json.empty()) io::check_output_file("--json", o.json);
    using clock = std::chrono::steady_clock;
    io::scene changed = scene;
    std::vector<std::uint32_t> moved;
    rigid_move move;
    std::size_t light_index = 0;
    if (!o.rebake_light.empty()) {
        const auto v = rebake_numbers(o.rebake_light, 2, "--rebake-light", "K,SCALE");
        light_index = std::size_t(v[0]);
        if (v[0] < 0 || light_index >= scene.lights.size() || v[1] < 0)
            throw parameter_error("--rebake-light", fmt::format("K must be a light of {} (0 .. {}) and SCALE non-negative",
                                                                scene.name, int(scene.lights.size()) - 1));
        std::visit([&](auto& l) {
            if constexpr (requires { l.intensity; }) l.intensity *= float(v[1]);
            else l.irradiance *= float(v[1]);
        }, changed.lights[light_index]);
    } else {
        const std::size_t comma = o.rebake_move.find(',');
        moved = object_triangles(scene, o.rebake_move.substr(0, comma));
        const auto d = rebake_numbers(comma == std::string::npos ? "" : o.rebake_move.substr(comma + 1), 3, "--rebake-move",
                                      "MATERIAL[#N],DX,DY,DZ");
        move.translation = glm::vec3(float(d[0]), float(d[1]), float(d[2]));
        std::vector<std::uint8_t> vertex(scene.positions.size(), 0);
        for (const std::uint32_t t : moved)
            for (int k = 0; k < 3; ++k) vertex[scene.triangles[t][k]] = 1;
        for (std::size_t v = 0; v < vertex.size(); ++v)
            if (vertex[v]) changed.positions[v] = move.point(changed.positions[v]);
    }
    auto t0 = clock::now();
    const embree::accel changed_bvh(changed);
    const double bvh_ms = study::ms_since(t0);
    const image<float> mask = study::coverage_mask(embree::ray_cast_gbuffer(changed_bvh, changed, changed.camera, o.width, o.height).view());
    std::optional<embree::multi_bounce_image> reference;
    if (o.reference) reference = study::cached_multi_bounce(changed_bvh, changed, changed.camera, o.width, o.height, reference_settings_for(o));
    const auto view = [&](const auto& solver) { return render_view(changed_bvh, changed, changed.camera, solver, 0, o.view, o.width, o.height); };
    const auto error = [&](const image<glm::vec3>& a, const image<glm::vec3>& b) {
        return study::compare_luminance(a.view(), b.view(), mask.view()).rel_rms;
    };
    radiosity_solve_options s;
    s.converge = o.converge;
    s.measure = o.converge_on;

    // The fresh solve of the changed scene, then on to --rebake-check: the answer.
    t0 = clock::now();
    const lightmap_atlas fresh_atlas = build_lightmap_atlas(changed, atlas_options_for(o));
    cpu::progressive_radiosity fresh(changed, fresh_atlas, embree::radiosity_visibility(changed_bvh, fresh_atlas.chart_of_triangle),
                                     solver_options_for(o));
    const double fresh_setup_ms = study::ms_since(t0);
    const radiosity_solve_report fr = fresh.solve(s);
    const double fresh_ms = fresh_setup_ms + fr.solve_ms;
    const image<glm::vec3> fresh_view = view(fresh);
    radiosity_solve_options check = s;
    check.converge = o.rebake_check;
    fresh.solve(check);
    const image<glm::vec3> answer = view(fresh);
    const double fresh_error = error(fresh_view, answer);

    // The bake of the scene as it was, then the re-bake to the fresh solve's error.
    const lightmap_atlas atlas = build_lightmap_atlas(scene, atlas_options_for(o));
    cpu::progressive_radiosity solver(scene, atlas, embree::radiosity_visibility(bvh, atlas.chart_of_triangle), solver_options_for(o));
    const radiosity_solve_report bake = solver.solve(s);
    const radiosity_rebake_report rb =
        moved.empty() ? cpu::rebake_light(solver, light_index, changed.lights[light_index])
                      : cpu::rebake_move(solver, changed, moved, move, embree::radiosity_visibility(changed_bvh, atlas.chart_of_triangle));
    radiosity_solve_options again = check;
    again.checkpoints = 200;
    double rebake_error = error(view(solver), answer), at_ms = 0;
    std::size_t at_steps = 0;
    bool reached = rebake_error <= fresh_error;
    again.checkpoint = [&](const radiosity_progress& p) {
        if (reached) return;
        rebake_error = error(view(solver), answer);
        reached = rebake_error <= fresh_error;
        at_ms = p.elapsed_ms, at_steps = p.steps - bake.steps;
    };
    again.progress = [&](const radiosity_progress&) { return !reached; };
    const radiosity_solve_report rr = solver.solve(again);
    if (!reached) at_ms = rr.solve_ms, at_steps = solver.progress().steps - bake.steps;
    const double rebake_ms = rb.ms + at_ms;
    const image<glm::vec3> rebake_view = view(solver);
    solver.solve(check);
    const double converged_apart = error(view(solver), answer);

    nlohmann::ordered_json j;
    j["scene"] = scene.name;
    j["change"] = moved.empty() ? "light " + o.rebake_light : "move " + o.rebake_move;
    j["elements"] = atlas.size();
    j["moved_triangles"] = moved.size();
    j["converge"] = o.converge;
    j["check_converge"] = o.rebake_check;
    j["bvh_ms"] = bvh_ms;
    j["fresh"] = {{"ms", fresh_ms}, {"setup_ms", fresh_setup_ms}, {"steps", fr.steps}, {"error", fresh_error}};
    j["rebake"] = {{"ms", rebake_ms}, {"correction_ms", rb.ms}, {"solve_ms", at_ms}, {"steps", at_steps},
                   {"error", rebake_error}, {"reached", reached}, {"shooters", rb.shooters}, {"pairs", rb.pairs},
                   {"pairs_tested", rb.pairs_tested}, {"moved_elements", rb.moved_elements},
                   {"unshot_before", rb.unshot_before}, {"unshot_after", rb.unshot_after}};
    j["bake"] = {{"steps", bake.steps}, {"ms", bake.solve_ms}};
    j["ratio"] = rebake_ms / fresh_ms;
    // Without the load: receiver-shooter pairs evaluated (a shot walks every element).
    const double fresh_pairs = double(fr.steps) * double(fresh_atlas.size());
    const double rebake_pairs = double(rb.pairs) + double(at_steps) * double(atlas.size());
    j["pairs"] = {{"fresh", fresh_pairs}, {"rebake", rebake_pairs}, {"ratio", rebake_pairs / fresh_pairs}};
    j["converged_rel_rms"] = converged_apart;
    if (reference) {
        j["reference_rel_rms"] = {{"fresh", error(fresh_view, reference->radiance)}, {"rebake", error(rebake_view, reference->radiance)},
                                  {"converged", error(answer, reference->radiance)}};
    }
    if (!o.json.empty()) io::write_text_file(o.json, j.dump(2) + "\n");
    fmt::print("radiosity re-bake {} ({}): {} elements; fresh {:.0f} ms (setup {:.0f}, {} steps), error {:.4f}; re-bake {:.0f} ms "
               "(correction {:.0f}, {} steps), error {:.4f}{}; ratio {:.3f} ({:.3f} in pairs); converged apart {:.4f}{}\n",
               scene.name, j["change"].get<std::string>(), atlas.size(), fresh_ms, fresh_setup_ms, fr.steps, fresh_error,
               rebake_ms, rb.ms, at_steps, rebake_error, reached ? "" : " (not reached)", rebake_ms / fresh_ms,
               rebake_pairs / fresh_pairs, converged_apart,
               reference ? fmt::format("; against the reference fresh {:.4f}, re-bake {:.4f}",
                                       j["reference_rel_rms"]["fresh"].get<double>(), j["reference_rel_rms"]["rebake"].get<double>())
                         : std::string());
    return 0;
}

}  // namespace bounce::examples
