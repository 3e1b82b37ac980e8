// The benchmark's radiosity: cpu::progressive_radiosity with the stereographic item buffer,
// seen as the radiosity program sees it by default (embree::lightmap_direct_view: the lights'
// direct light per pixel, the rest of B from the lightmap), against the all-bounce reference.
#include <bounce/study/benchmark_parts.hpp>

#include <bounce/cpu/radiosity.hpp>
#include <bounce/cpu/radiosity_item_buffer.hpp>
#include <bounce/embree/lightmap_view.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/radiosity/options.hpp>
#include <bounce/radiosity/solve.hpp>
#include <bounce/study/stage_timer.hpp>

#include <fmt/core.h>

#include <algorithm>

namespace bounce::study::bench {

technique_run run_radiosity(const scene_setup& s) {
    // radiosity's defaults (examples/radiosity/options.hpp): 10,000 elements shot in 8 x 8
    // blocks with the near-field rule at 4 sides, visibility from the stereographic item
    // buffer of 128^2 pixels (edges within 0.25 px), lights shot at 4 x 4 points a texel, the
    // mixed ambient term, until 90% of the power the surfaces reflect is shot (the indirect
    // measure: a scene lit mostly by direct light is not "converged" before any bounce).
    constexpr std::size_t elements = 10000;
    constexpr int block = 8, resolution = 128;
    constexpr float tolerance_px = 0.25f;
    constexpr double converge = 0.9;
    const std::string name(technique_name(bench_technique::radiosity));

    s.clock.report(name, "atlas");
    const auto t0 = std::chrono::steady_clock::now();
    atlas_options ao;
    ao.elements = elements;
    ao.block_texels = block;
    ao.padding = 1;
    const lightmap_atlas atlas = build_lightmap_atlas(s.scene, ao);
    const double atlas_ms = ms_since(t0);
    cpu::item_buffer_visibility::options vo;
    vo.projection = cpu::item_projection::stereographic;
    vo.resolution = resolution;
    vo.tolerance_px = tolerance_px;
    radiosity_options ro;
    ro.shoot_blocks = block > 1;
    ro.near_field = 4;
    ro.light_samples = 4;
    ro.ambient_shape = radiosity_ambient::mixed;
    s.clock.report(name, "lights");
    cpu::progressive_radiosity solver(s.scene, atlas, cpu::item_buffer_visibility(s.scene, atlas, vo), ro);
    // The library's solve (radiosity/solve.hpp): to the target, within the run's time cap,
    // refusing energy created or light reaching no surface's front with radiosity_error.
    radiosity_solve_options so;
    so.converge = converge;
    so.measure = radiosity_measure::indirect;
    so.max_seconds = s.settings.radiosity_max_seconds;
    auto last_report = std::chrono::steady_clock::now();
    so.progress = [&](const radiosity_progress& p) {
        if (ms_since(last_report) > 2000) {
            last_report = std::chrono::steady_clock::now();
            s.clock.report(name, fmt::format("solve: {:.1f}% shot, {} shots", 100.0 * (1.0 - p.unshot_fraction), p.shots));
        }
        return true;
    };
    const radiosity_solve_report report = solver.solve(so);
    const double solve_ms = ms_since(t0);

    s.clock.report(name, "view");
    technique_run r;
    r.technique = bench_technique::radiosity;
    r.quantity = bench_quantity::all_bounces;
    const auto tv = std::chrono::steady_clock::now();
    const image<glm::vec3> front = bounced_radiosity_lightmap(solver, 0, 0), back = bounced_radiosity_lightmap(solver, 0, 1);
    r.radiance = embree::lightmap_direct_view(s.bvh, s.scene, solver.atlas(), front.view(), back.view(), 0, s.scene.camera,
                                              s.g.width(), s.g.height());
    const double view_ms = ms_since(tv);
    // The solve is the technique's work; the view (a lookup of the lightmap in a renderer's
    // raster pass and its direct-light pass; here ray casts) is reported beside, as the shared
    // G-buffer is.
    r.ms = solve_ms;
    const radiosity_timings& t = solver.timings();
    r.timings_ms = {{"atlas", atlas_ms},           {"lights", t.lights_ms},     {"visibility", t.visibility_ms},
                    {"shooter_choice", t.choice_ms}, {"reconstruction", t.distribution_ms},
                    {"total", solve_ms},           {"lightmap_view", view_ms}};
    const glm::dvec3 emitted = solver.emitted_power();
    r.counts = {{"elements", solver.atlas().size()},
                {"charts", solver.atlas().charts.size()},
                {"shots", solver.progress().shots},
                {"steps", solver.progress().steps},
                {"shot_fraction", 1.0 - solver.unshot_fraction()},
                {"emitted_w", emitted.x + emitted.y + emitted.z},
                {"stop", to_string(report.stop)},
                {"solve_ms", report.solve_ms}};
    r.parameters = {{"elements", elements},      {"block", block},       {"visibility", "stereo"},
                    {"resolution", resolution},  {"tolerance_px", tolerance_px}, {"adaptive", false},
                    {"converge", converge},      {"converge_on", "indirect"}, {"light_samples", 4},
                    {"ambient", "mixed"},        {"view", "direct+indirect"}, {"max_seconds", s.settings.radiosity_max_seconds}};
    return r;
}

}  // namespace bounce::study::bench
