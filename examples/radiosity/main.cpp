// radiosity: progressive refinement radiosity with texels as elements (Cohen et al. 1988, on
// textures as Coombe and Harris 2005, GPU Gems 2 ch. 39) through the library's solvers
// (cpu::progressive_radiosity with the stereographic or hemicube item buffer or Embree ray
// casts, or gl::progressive_radiosity), compared with the multi-bounce path-traced reference.
// The solve, its checkpoints and its time limit are the library's (radiosity/solve.hpp);
// this program parses, checks, calls and reports.
//
//   build/bin/radiosity --scene cornell --elements 10000 --visibility stereo --adaptive off
//       --backend cpu --converge 0.9 --json r.json --out r.png --lightmaps maps/
//
// Stages (the names of timings_ms): atlas (elements from the scene), lights (point, spot and
// directional lights shot first), visibility (item buffers or nothing, per shot),
// shooter_choice (the reduction), reconstruction (every receiving element's form factor,
// visibility lookup and update, per shot), subdivision, total (atlas to convergence: all of
// the above and the solvers' bookkeeping, the checkpoints' error measurements left out),
// and, outside total, lightmap_view (rendering the view from the lightmap) and reference.
#include <bounce/cpu/radiosity.hpp>
#include <bounce/embree/radiosity_visibility.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/frame_comparison.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/multi_bounce_cache.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/study/stage_timer.hpp>

#ifdef BOUNCE_WITH_GL
#include <bounce/gl/context.hpp>
#include <bounce/gl/radiosity.hpp>
#endif

#include "../common/run_program.hpp"
#include "holes.hpp"
#include "memory.hpp"
#include "options.hpp"
#include "oracle.hpp"
#include "rebake.hpp"
#include "report.hpp"

#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <span>
#include <tuple>
#include <vector>

using namespace bounce;
using namespace bounce::examples;
using study::ms_since;
using clock_type = std::chrono::steady_clock;

namespace {

// What the view is compared with: the reference and the pixels that see geometry.
struct comparison {
    const embree::accel& bvh;
    const io::scene& scene;
    std::optional<embree::multi_bounce_image> reference;
    image<float> mask;
    // The view --view asks for (view.hpp), of both sides for two-sided solves.
    template <class Solver>
    image<glm::vec3> view(const Solver& solver, int level, const options& o) const {
        return render_view(bvh, scene, scene.camera, solver, level, o.view, o.width, o.height);
    }
    double rel_rms(const image<glm::vec3>& v) const {
        return study::compare_luminance(v.view(), reference->radiance.view(), mask.view()).rel_rms;
    }
    std::size_t black_pixels(const image<glm::vec3>& v) const { return examples::black_pixels(v, reference->radiance, mask); }
};

// Solves with `solver` (built after `setup_ms` of atlas and lights) as the options ask, through
// the library's solve; with `cmp` holding a reference, the view's error at checkpoints.
template <class Solver>
solve_result solve(Solver& solver, const options& o, const io::scene& scene, double atlas_ms, double setup_ms,
                   study::stage_timer& timer, const comparison& cmp, bool with_curve) {
    const std::size_t base_elements = solver.atlas().size();  // before any subdivision
    solve_result r;
    r.setup_ms = setup_ms;
    constexpr bool cpu = requires(Solver& s) { s.subdivide(scene, subdivision_options{}); };
    const int level = o.adaptive ? o.max_level : 0;  // 0 on GL, which refuses --adaptive
    radiosity_solve_options s;
    s.converge = o.converge;
    s.measure = o.converge_on;
    s.max_seconds = o.max_seconds;
    s.checkpoints = with_curve && cmp.reference ? o.curve_points : 0;
    auto last_print = clock_type::now();
    const auto print = [&](const radiosity_progress& p, const char* end) {
        fmt::print(stderr, "\rradiosity: step {}, {} shots, {:.1f}% converged ({:.1f}% of the emitted power shot), {:.2f} s   {}",
                   p.steps, p.shots, 100.0 * (1.0 - p.indirect_unshot_fraction), 100.0 * (1.0 - p.unshot_fraction),
                   (setup_ms + p.elapsed_ms) / 1e3, end);
    };
    s.progress = [&](const radiosity_progress& p) {
        if (!o.quiet && ms_since(last_print) > 250) print(p, ""), last_print = clock_type::now();
        return true;
    };
    s.checkpoint = [&](const radiosity_progress& p) {
        const auto v = cmp.view(solver, level, o);
        r.curve.push_back({p.steps, p.shots, solver.atlas().size(), setup_ms + p.elapsed_ms, p.unshot_fraction, cmp.rel_rms(v)});
    };
    if constexpr (cpu) r.report = o.adaptive ? solver.solve(s, scene, subdivision_options_for(o), std::size_t(o.subdivide_steps))
                                             : solver.solve(s);
    else r.report = solver.solve(s);
    if (!o.quiet)
        print({r.report.steps, solver.progress().shots, r.report.unshot_fraction, r.report.solve_ms,
               r.report.indirect_unshot_fraction},
              "\n");
    const auto& t = solver.timings();
    timer.add_sample("atlas", atlas_ms);
    timer.add_sample("lights", t.lights_ms);
    timer.add_sample("visibility", t.visibility_ms);
    timer.add_sample("shooter_choice", t.choice_ms);
    timer.add_sample("reconstruction", t.distribution_ms);
    timer.add_sample("subdivision", t.subdivision_ms);
    timer.add_sample("total", setup_ms + r.report.solve_ms);
    const lightmap_atlas& a = solver.atlas();
    r.shots = solver.progress().shots;
    r.clamped_shots = solver.clamped_shots();
    r.shooters = solver.shooters();
    r.elements = a.size();
    r.charts = a.charts.size();
    r.base_elements = base_elements;
    std::tie(r.emitted, r.absorbed, r.escaped) = std::tuple(solver.emitted_power(), solver.absorbed_power(), solver.escaped_power());
    r.lightmap = solver.radiosity_lightmap(level);
    r.lightmap_back = back_radiosity_lightmap(solver, level);
    const auto u = solver.unshot();
    const std::vector<glm::vec3> unshot(u.begin(), u.end());
    r.unshot = a.to_fine_texels(std::span<const glm::vec3>(unshot), level);
    timer.time("lightmap_view", [&] { r.view = cmp.view(solver, level, o); });
    if (cmp.reference) r.black_pixels = cmp.black_pixels(r.view);
    if (cmp.reference && !o.holes_out.empty())
        write_holes(o.holes_out, cmp.bvh, a, r.lightmap, r.lightmap_back.width() ? r.lightmap_back : r.lightmap,
                    cmp.scene.camera, r.view, cmp.reference->radiance, cmp.mask, level);
    if (cmp.reference && !o.oracle_out.empty())  // (check_options refused it with --adaptive)
        write_oracle(o.oracle_out, cmp.bvh, scene, solver, reference_settings_for(o), *cmp.reference, cmp.mask, r.view, o.width, o.height);
    return r;
}

// One solve on the backend and visibility the options name: the one place they are chosen.
solve_result solve_once(const options& o, const io::scene& scene, const embree::accel& bvh,
                        study::stage_timer& timer, const comparison& cmp, bool with_curve) {
    const auto start = clock_type::now();
    lightmap_atlas atlas = build_lightmap_atlas(scene, atlas_options_for(o));
    const double atlas_ms = ms_since(start);
    if (!o.quiet && double(atlas.size()) > 1.1 * double(o.elements))
        fmt::print(stderr, "radiosity: {} elements for the {} asked: each of the scene's {} charts takes at least one texel\n",
                   atlas.size(), o.elements, atlas.charts.size());
#ifdef BOUNCE_WITH_GL  // (check_options refused --backend gl without it)
    if (o.backend == backend::gl) {
        gl::progressive_radiosity solver(scene, atlas, gl_options_for(o));
        return solve(solver, o, scene, atlas_ms, ms_since(start), timer, cmp, with_curve);
    }
#endif
    if (o.visibility == visibility_kind::rays) {
        embree::radiosity_visibility vis(bvh, atlas.chart_of_triangle);  // through the run's accel
        cpu::progressive_radiosity solver(scene, atlas, std::move(vis), solver_options_for(o));
        atlas = {};  // the solver keeps its own copy
        return solve(solver, o, scene, atlas_ms, ms_since(start), timer, cmp, with_curve);
    }
    cpu::item_buffer_visibility vis(scene, atlas, item_options_for(o));
    cpu::progressive_radiosity solver(scene, atlas, std::move(vis), solver_options_for(o));
    atlas = {};
    return solve(solver, o, scene, atlas_ms, ms_since(start), timer, cmp, with_curve);
}

// Everything the run is asked for is checked here, before any work: outputs, the comparison
// file, option combinations, the cache, the tolerance against the scene and the memory.
std::optional<image<glm::vec3>> check_before_work(const options& o, const io::scene& scene) {
    for (const auto& [name, file] : {std::pair{"--json", o.json}, std::pair{"--oracle-out", o.oracle_out}})
        if (!file.empty()) io::check_output_file(name, file);
    for (const auto& [name, file] : {std::pair{"--out", o.out}, std::pair{"--reference-out", o.reference_out}}) {
        if (file.empty()) continue;
        if (file.extension() != ".png" && file.extension() != ".exr")
            throw parameter_error(name, "must end in .png or .exr: " + file.string());
        io::check_image_output(name, file);
    }
    if (!o.lightmaps.empty()) io::check_image_output("--lightmaps", o.lightmaps / "radiosity.exr");
    if (o.visibility == visibility_kind::stereo) {
        const float finest = stereographic_tolerance_floor(scene, o.elements, o.resolution);
        if (o.tolerance_px < finest)
            throw parameter_error("--tolerance-px", fmt::format("{:g} px cannot change an item buffer of {} pixels over {}: "
                                                                "below {:.4g} px (the rasterizer's 1/256-pixel snap, or float32 "
                                                                "positions at this scene's scale) it only tessellates deeper",
                                                                o.tolerance_px, o.resolution, scene.name, finest));
    }
    if (o.one_sided) check_lights_face_surfaces(scene);  // reversed winding, before the reference
    if (o.reference) study::check_cache_dir();
    check_memory(o, scene);
    if (o.versus.empty()) return std::nullopt;
    // Another run's view to compare with, read now: a missing or wrong-sized file is refused before the solve.
    if (!std::filesystem::is_regular_file(o.versus)) throw parameter_error("--versus", "no such file: " + o.versus.string());
    image<glm::vec3> other = io::read_rgb(o.versus);
    if (other.width() != o.width || other.height() != o.height)
        throw parameter_error("--versus", fmt::format("{} is {} x {}, not the {} x {} view asked (--width, --height)",
                                                      o.versus.string(), other.width(), other.height(), o.width, o.height));
    return other;
}

int run(const options& o) {
    check_options(o);
    const io::scene scene = io::load_scene_arg(o.scene);
    for (const auto& w : scene.warnings) fmt::print(stderr, "{}: {}\n", scene.name, w);
    const std::optional<image<glm::vec3>> versus = check_before_work(o, scene);
    const embree::accel bvh(scene);
    if (!o.rebake_light.empty() || !o.rebake_move.empty()) return run_rebake(o, scene, bvh);  // rebake.hpp

    study::stage_timer timer;
    comparison cmp{bvh, scene, std::nullopt, {}};
    if (o.reference) {
        auto settings = reference_settings_for(o);
        settings.progress = [&](std::size_t done, std::size_t total) {
            if (!o.quiet && (done % 16 == 0 || done == total)) fmt::print(stderr, "\rreference: row {} of {}", done, total);
        };
        bool cached = false;
        const auto t0 = clock_type::now();
        cmp.reference = study::cached_multi_bounce(bvh, scene, scene.camera, o.width, o.height, settings,
                                                   study::default_cache_dir(), &cached);
        if (!cached) timer.add_sample("reference", ms_since(t0));
        if (cached || !o.quiet) fmt::print(stderr, "{}", cached ? "reference: from the cache\n" : "\n");
    }
    if (o.reference || versus)  // the pixels that see geometry, where views are compared
        cmp.mask = study::coverage_mask(embree::ray_cast_gbuffer(bvh, scene, scene.camera, o.width, o.height).view());
#ifdef BOUNCE_WITH_GL
    std::optional<gl::context> gl_context;  // current on this thread while it lives
    if (o.backend == backend::gl) gl_context.emplace();
#endif
    std::optional<solve_result> result;
    for (int rep = 0; rep < o.repeat; ++rep) result = solve_once(o, scene, bvh, timer, cmp, rep == 0);
    const solve_result& r = *result;

    study::run_report report;
    report.technique = "radiosity";
    report.scene = scene.name;
    report.width = o.width;
    report.height = o.height;
    report.backend = name_of(backend_names, o.backend);
#ifdef BOUNCE_WITH_GL
    if (gl_context) report.gl_renderer = gl_context->renderer();
#endif
    report.parameters = parameters_json(o);
    report.parameters["embree_config"] = bvh.owner().config();
    report.set_timings(timer);
    if (cmp.reference) report.error = study::compare_luminance(r.view.view(), cmp.reference->radiance.view(), cmp.mask.view());
    for (const auto& [name, n] : {std::pair{"elements", r.elements}, {"elements_base", r.base_elements},
                                  {"iterations", r.report.steps}, {"shots", r.shots}, {"shooters", r.shooters},
                                  {"charts", r.charts}, {"triangles", scene.triangles.size()}, {"splits", r.report.splits}})
        report.set_count(name, n);
    nlohmann::ordered_json j = report.to_json();
    add_solve_json(j, r);
    if (cmp.reference) j["black_pixels"] = r.black_pixels;
    if (cmp.reference) j["reference"] = reference_json(o, *cmp.reference);
    if (versus) {
        const auto e = study::compare_luminance(r.view.view(), versus->view(), cmp.mask.view());
        j["versus"] = {{"file", o.versus.filename().string()}, {"rel_rms", e.rel_rms}, {"max_abs", e.max_abs}};
        if (cmp.reference) j["versus"]["reference_rel_rms"] = cmp.rel_rms(*versus);  // another seed's: its noise
    }
    const auto write_view = [](const std::filesystem::path& f, const image<glm::vec3>& v) {
        if (f.extension() == ".exr") io::write_exr(f, v.view());
        else io::write_png(f, v.view());
    };
    if (!o.out.empty()) write_view(o.out, r.view);
    if (!o.reference_out.empty() && cmp.reference) write_view(o.reference_out, cmp.reference->radiance);
    if (!o.lightmaps.empty()) {
        io::write_exr(o.lightmaps / "radiosity.exr", r.lightmap.view());
        io::write_exr(o.lightmaps / "unshot.exr", r.unshot.view());
        if (r.lightmap_back.width()) io::write_exr(o.lightmaps / "radiosity_back.exr", r.lightmap_back.view());
    }
    if (!o.json.empty()) io::write_text_file(o.json, j.dump(2) + "\n");
    fmt::print("radiosity {} {} {}: {} elements, {} iterations, {:.1f}% converged ({}; {:.1f}% of the emitted power "
               "shot), total {:.0f} ms (visibility {:.0f}, reconstruction {:.0f}, choice {:.1f}), rel_rms {}, "
               "{} black pixels where the reference is lit\n",
               scene.name, name_of(visibility_names, o.visibility), o.adaptive ? "adaptive" : "uniform", r.elements,
               r.report.steps, 100.0 * (1.0 - r.report.indirect_unshot_fraction), to_string(r.report.stop),
               100.0 * (1.0 - r.report.unshot_fraction), timer.median_ms("total"),
               timer.median_ms("visibility"), timer.median_ms("reconstruction"), timer.median_ms("shooter_choice"),
               report.error ? fmt::format("{:.4f}", report.error->rel_rms) : std::string("-"),
               cmp.reference ? std::to_string(r.black_pixels) : std::string("-"));
    if (versus) fmt::print("  versus {}: rel_rms {:.4f}\n", o.versus.string(), j["versus"]["rel_rms"].get<double>());
    if (r.report.stop == radiosity_stop::time_limit)
        fmt::print(stderr, "radiosity: stopped unconverged by --max-seconds {}: {:.1f}% converged ({}), {:.1f}% asked\n",
                   o.max_seconds,
                   100.0 * (1.0 - (o.converge_on == radiosity_measure::indirect ? r.report.indirect_unshot_fraction
                                                                               : r.report.unshot_fraction)),
                   name_of(measure_names, o.converge_on), 100.0 * o.converge);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce: progressive refinement radiosity (Coombe and Harris, GPU Gems 2 ch. 39)"};
    options o;
    add_options(app, o);
    CLI11_PARSE(app, argc, argv);
    return run_program("radiosity", [&] { return run(o); },
                       "ask for fewer --elements, a smaller view, or a smaller --resolution");
}
