#pragma once
// radiosity's re-bakes (docs/radiosity.md, "Re-baking what changed"): with --rebake-light or
// --rebake-move (rebake_change.hpp), the scene is baked as the options ask, changed, re-baked
// from that solution (cpu::rebake_light and cpu::rebake_move, or the GL solver's rebake_light
// and rebake_move) and solved fresh (atlas, lights, solve). The fresh
// solve is then converged on to --rebake-check of the same measure: the answer both should
// reach. Reported: the fresh solve's time to --converge and its error against that answer;
// the re-bake's time (correction + solve) to the same error, measured at checkpoints with the
// clock paused; the re-bake's and the fresh solve's views both converged, against each other;
// the ratio of the times; and, with --reference on, both against the multi-bounce reference
// of the changed scene, and the re-bake's time to the fresh solve's error against it. A move's
// re-bake is measured against a fresh solve on its own elements (the bake's moved), which it
// converges to; how far that lies from the answer (its atlas built from the moved scene) is
// reported. CPU with ray-cast visibility, or GL (stereographic or hemicube item buffers).
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

#ifdef BOUNCE_WITH_GL
#include <bounce/gl/context.hpp>
#include <bounce/gl/radiosity.hpp>
#endif

#include "options.hpp"
#include "rebake_change.hpp"
#include "view.hpp"

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <optional>

namespace bounce::examples {

// The solvers a re-bake run measures: make one, re-bake it, and count the receiver-shooter
// pairs its correction evaluated.
struct cpu_rebaker {
    const options& o;
    auto make(const scene_view& s, const lightmap_atlas& a, const embree::accel& bvh) const {
        return cpu::progressive_radiosity(s, a, embree::radiosity_visibility(bvh, a.chart_of_triangle), solver_options_for(o));
    }
    // A move's unmoved pairs are tested against the object alone (embree::object_visibility;
    // its BVHs timed with the correction).
    template <class Solver>
    radiosity_rebake_report rebake(Solver& s, const io::scene& scene, const embree::accel& bvh, const scene_change& c,
                                   const embree::accel& changed_bvh) const {
        if (c.moved.empty()) return cpu::rebake_light(s, c.light_index, c.changed.lights[c.light_index]);
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<std::uint32_t>& charts = s.atlas().chart_of_triangle;
        const embree::radiosity_visibility after(changed_bvh, charts);
        auto object = embree::object_visibility(scene, embree::radiosity_visibility(bvh, charts), c.changed, after, c.moved, charts);
        const double object_ms = study::ms_since(t0);
        radiosity_rebake_report r = cpu::rebake_move(s, c.changed, c.moved, c.move, after, std::move(object), c.share);
        r.ms += object_ms;
        return r;
    }
    static double pairs(const radiosity_rebake_report& r, std::size_t) { return double(r.pairs); }
};
#ifdef BOUNCE_WITH_GL
struct gl_rebaker {
    const options& o;
    gl::progressive_radiosity make(const scene_view& s, const lightmap_atlas& a, const embree::accel&) const {
        return gl::progressive_radiosity(s, a, gl_options_for(o));
    }
    radiosity_rebake_report rebake(gl::progressive_radiosity& s, const io::scene&, const embree::accel&, const scene_change& c,
                                   const embree::accel&) const {
        if (c.moved.empty()) return s.rebake_light(c.light_index, c.changed.lights[c.light_index]);
        return s.rebake_move(c.changed, c.moved, c.move, c.share);
    }
    // A GL re-shot's pass evaluates every element (its mask keeps the unchanged pairs as they are).
    static double pairs(const radiosity_rebake_report& r, std::size_t elements) { return double(r.shooters) * double(elements); }
};
#endif

// The re-bake's measurement with `backend`'s solvers: see the file comment.
template <class Rebaker>
int measure_rebake(const options& o, const io::scene& scene, const embree::accel& bvh, const scene_change& c, const Rebaker& backend) {
    using clock = std::chrono::steady_clock;
    const io::scene& changed = c.changed;
    const std::vector<std::uint32_t>& moved = c.moved;
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
    auto fresh = backend.make(changed, fresh_atlas, changed_bvh);
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
        move_charts(moved_atlas, moved_charts(atlas, moved), c.move);
        auto same = backend.make(changed, moved_atlas, changed_bvh);
        same.solve(check);
        own_answer = view(same), atlases_apart = error(own_answer, answer);
    }
    auto solver = backend.make(scene, atlas, bvh);
    const radiosity_solve_report bake = solver.solve(s);
    const radiosity_rebake_report rb = backend.rebake(solver, scene, bvh, c, changed_bvh);
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
    // The solve's shots from the moved object's elements (a step of one shooter: the default;
    // the CPU solver names its last shot's).
    const std::vector<std::uint8_t> moved_chart = moved.empty() ? std::vector<std::uint8_t>(atlas.charts.size(), 0) : moved_charts(atlas, moved);
    std::size_t moved_shots = 0;
    again.progress = [&](const radiosity_progress&) {
        if constexpr (requires { solver.last_shot(); }) moved_shots += moved_chart[solver.atlas().chart[solver.last_shot().first_element]];
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
    j["backend"] = name_of(backend_names, o.backend);
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
                   {"share", c.share}, {"uncorrected", rb.uncorrected},
                   {"unshot_before", rb.unshot_before}, {"unshot_after", rb.unshot_after}};
    j["bake"] = {{"steps", bake.steps}, {"ms", bake.solve_ms}};
    j["ratio"] = rebake_ms / fresh_ms;
    // Without the load: receiver-shooter pairs evaluated (a shot walks every element).
    const double fresh_pairs = double(fr.steps) * double(fresh_atlas.size());
    const double rebake_pairs = backend.pairs(rb, atlas.size()) + double(at_steps) * double(atlas.size());
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
                                   {"pairs_ratio", (backend.pairs(rb, atlas.size()) + double(ref_steps) * double(atlas.size())) / fresh_pairs}};
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

// The re-bake's run: checks, the change, the backend's measurement.
inline int run_rebake(const options& o, const io::scene& scene, const embree::accel& bvh) {
    const char* option = o.rebake_move.empty() ? "--rebake-light" : "--rebake-move";
    if (o.adaptive) throw parameter_error(option, "needs --adaptive off");
    if (o.backend == backend::cpu && o.visibility != visibility_kind::rays)
        throw parameter_error(option, "needs --visibility rays on the CPU backend (GL: stereo or hemicube)");
    if (!o.json.empty()) io::check_output_file("--json", o.json);
    const scene_change c = parse_change(o, scene);
#ifdef BOUNCE_WITH_GL
    if (o.backend == backend::gl) {
        const gl::context context;  // current on this thread while it lives
        return measure_rebake(o, scene, bvh, c, gl_rebaker{o});
    }
#endif
    return measure_rebake(o, scene, bvh, c, cpu_rebaker{o});
}

}  // namespace bounce::examples
