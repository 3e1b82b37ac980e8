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
// of the changed scene, and the re-bake's time to the fresh solve's error against it. A move's
// re-bake is measured against a fresh solve on its own elements (the bake's moved), which it
// converges to; how far that lies from the answer (its atlas built from the moved scene) is
// reported. An optional fourth number, --rebake-move ...,SHARE, re-shoots only the shooters
// holding that share of the shot power (cpu::rebake_move's share). CPU, ray-cast visibility.
#include <bounce/cpu/radiosity_rebake.hpp>
#include <bounce/embree/radiosity_object_visibility.hpp>
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
    double share = 1;  // of the shot power, the share the correction re-shoots (cpu::rebake_move)
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
        const std::string numbers = comma == std::string::npos ? "" : o.rebake_move.substr(comma + 1);
        const bool with_share = std::count(numbers.begin(), numbers.end(), ',') == 3;
        const auto d = rebake_numbers(numbers, with_share ? 4 : 3, "--rebake-move", "MATERIAL[#N],DX,DY,DZ[,SHARE]");
        move.translation = glm::vec3(float(d[0]), float(d[1]), float(d[2]));
        if (with_share) share = d[3];
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

    // The bake of the scene as it was, then the re-bake to the fresh solve's error. A move's
    // re-bake keeps the bake's elements (moved) and converges to a fresh solve on them: its
    // answer (the fresh solve's elements, built from the moved scene, may differ: a duplicated
    // face's coincident charts; "atlases_apart").
    const lightmap_atlas atlas = build_lightmap_atlas(scene, atlas_options_for(o));
    image<glm::vec3> own_answer = answer;
    double atlases_apart = 0;
    if (!moved.empty()) {
        lightmap_atlas moved_atlas = atlas;
        move_charts(moved_atlas, moved_charts(atlas, moved), move);
        cpu::progressive_radiosity same(changed, moved_atlas, embree::radiosity_visibility(changed_bvh, moved_atlas.chart_of_triangle),
                                        solver_options_for(o));
        same.solve(check);
        own_answer = view(same), atlases_apart = error(own_answer, answer);
    }
    cpu::progressive_radiosity solver(scene, atlas, embree::radiosity_visibility(bvh, atlas.chart_of_triangle), solver_options_for(o));
    const radiosity_solve_report bake = solver.solve(s);
    radiosity_rebake_report rb;
    if (moved.empty()) rb = cpu::rebake_light(solver, light_index, changed.lights[light_index]);
    else {  // the unmoved pairs tested against the object alone (its BVHs timed with the correction)
        t0 = clock::now();
        const embree::radiosity_visibility after(changed_bvh, atlas.chart_of_triangle);
        auto object = embree::object_visibility(scene, embree::radiosity_visibility(bvh, atlas.chart_of_triangle), changed, after, moved,
                                                atlas.chart_of_triangle);
        const double object_ms = study::ms_since(t0);
        rb = cpu::rebake_move(solver, changed, moved, move, after, std::move(object), share);
        rb.ms += object_ms;
    }
    radiosity_solve_options again = check;
    again.checkpoints = 200;
    image<glm::vec3> rebake_view = view(solver);
    double rebake_error = error(rebake_view, own_answer), at_ms = 0;
    std::size_t at_steps = 0;
    bool reached = rebake_error <= fresh_error;
    // With --reference on, also the time to the fresh solve's error against the reference.
    const double ref_target = reference ? error(fresh_view, reference->radiance) : 0;
    double ref_ms = 0;
    std::size_t ref_steps = 0;
    bool ref_reached = !reference || error(rebake_view, reference->radiance) <= ref_target;
    again.checkpoint = [&](const radiosity_progress& p) {
        if (reached && ref_reached) return;
        const image<glm::vec3> v = view(solver);
        if (!reached) {
            rebake_error = error(v, own_answer), reached = rebake_error <= fresh_error;
            at_ms = p.elapsed_ms, at_steps = p.steps - bake.steps, rebake_view = v;
        }
        if (!ref_reached) ref_reached = error(v, reference->radiance) <= ref_target, ref_ms = p.elapsed_ms, ref_steps = p.steps - bake.steps;
    };
    // The solve's shots from the moved object's elements (a step of one shooter: the default).
    const std::vector<std::uint8_t> moved_chart = moved.empty() ? std::vector<std::uint8_t>(atlas.charts.size(), 0) : moved_charts(atlas, moved);
    std::size_t moved_shots = 0;
    again.progress = [&](const radiosity_progress&) {
        moved_shots += moved_chart[solver.atlas().chart[solver.last_shot().first_element]];
        return !reached || !ref_reached;
    };
    const radiosity_solve_report rr = solver.solve(again);
    if (!reached) at_ms = rr.solve_ms, at_steps = solver.progress().steps - bake.steps, rebake_view = view(solver);
    if (!ref_reached) ref_ms = rr.solve_ms, ref_steps = solver.progress().steps - bake.steps;
    const double rebake_ms = rb.ms + at_ms;
    solver.solve(check);
    const image<glm::vec3> rebake_converged = view(solver);
    const double converged_apart = error(rebake_converged, own_answer), fresh_apart = error(rebake_converged, answer);

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
                   {"error", rebake_error}, {"reached", reached}, {"shooters", rb.shooters}, {"moved_shooters", rb.moved_shooters},
                   {"moved_shots", moved_shots}, {"pairs", rb.pairs}, {"moved_pairs", rb.moved_pairs},
                   {"pairs_tested", rb.pairs_tested}, {"object_tests", rb.object_tests}, {"moved_elements", rb.moved_elements},
                   {"stages_ms", {{"moved", rb.moved_ms}, {"unmoved", rb.unmoved_ms}, {"lights", rb.lights_ms}}},
                   {"share", share}, {"uncorrected", rb.uncorrected},
                   {"unshot_before", rb.unshot_before}, {"unshot_after", rb.unshot_after}};
    j["bake"] = {{"steps", bake.steps}, {"ms", bake.solve_ms}};
    j["ratio"] = rebake_ms / fresh_ms;
    // Without the load: receiver-shooter pairs evaluated (a shot walks every element).
    const double fresh_pairs = double(fr.steps) * double(fresh_atlas.size());
    const double rebake_pairs = double(rb.pairs) + double(at_steps) * double(atlas.size());
    j["pairs"] = {{"fresh", fresh_pairs}, {"rebake", rebake_pairs}, {"ratio", rebake_pairs / fresh_pairs}};
    j["converged_rel_rms"] = converged_apart;
    j["converged_from_fresh"] = fresh_apart;
    j["atlases_apart"] = atlases_apart;
    if (reference) {
        j["reference_rel_rms"] = {{"fresh", ref_target}, {"rebake", error(rebake_view, reference->radiance)},
                                  {"converged", error(answer, reference->radiance)}};
        // The re-bake stopped at the fresh solve's error against the reference instead.
        j["to_reference_error"] = {{"ms", rb.ms + ref_ms}, {"steps", ref_steps}, {"reached", ref_reached},
                                   {"ratio", (rb.ms + ref_ms) / fresh_ms},
                                   {"pairs_ratio", (double(rb.pairs) + double(ref_steps) * double(atlas.size())) / fresh_pairs}};
    }
    if (!o.json.empty()) io::write_text_file(o.json, j.dump(2) + "\n");
    fmt::print("radiosity re-bake {} ({}): {} elements; fresh {:.0f} ms (setup {:.0f}, {} steps), error {:.4f}; re-bake {:.0f} ms "
               "(correction {:.0f}, {} steps), error {:.4f}{}; ratio {:.3f} ({:.3f} in pairs); converged apart {:.4f}{}{}\n",
               scene.name, j["change"].get<std::string>(), atlas.size(), fresh_ms, fresh_setup_ms, fr.steps, fresh_error,
               rebake_ms, rb.ms, at_steps, rebake_error, reached ? "" : " (not reached)", rebake_ms / fresh_ms,
               rebake_pairs / fresh_pairs, converged_apart,
               moved.empty() ? std::string()
                             : fmt::format(" (from the fresh solve {:.4f}; the atlases apart {:.4f})", fresh_apart, atlases_apart),
               reference ? fmt::format("; against the reference fresh {:.4f}, re-bake {:.4f}; to the fresh's error against it: {} steps, "
                                       "ratio {:.3f} ({:.3f} in pairs)",
                                       ref_target, j["reference_rel_rms"]["rebake"].get<double>(), ref_steps,
                                       j["to_reference_error"]["ratio"].get<double>(), j["to_reference_error"]["pairs_ratio"].get<double>())
                         : std::string());
    return 0;
}

}  // namespace bounce::examples
