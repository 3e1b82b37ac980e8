// radiosity: progressive refinement radiosity with texels as elements (Cohen et al. 1988, on
// textures as Coombe and Harris 2005, GPU Gems 2 ch. 39) through the library's
// cpu::progressive_radiosity, with the stereographic or hemicube item buffer or Embree ray
// casts for visibility, compared with the multi-bounce path-traced reference.
//
//   build/bin/radiosity --scene cornell --elements 10000 --visibility stereo --adaptive off
//       --backend cpu --converge 0.9 --json r.json --out r.png --lightmaps maps/
//
// Stages (the names of timings_ms): atlas (elements from the scene), lights (point, spot and
// directional lights shot first), visibility (item buffers or nothing, per shot),
// shooter_choice (the reduction), reconstruction (the chapter's reconstruction pass: every
// receiving element's form factor, visibility lookup and update, per shot), subdivision,
// total (atlas to convergence: everything above and the solver's own bookkeeping), and,
// outside total, lightmap_view (rendering the view from the lightmap) and reference.
#include <bounce/cpu/radiosity.hpp>
#include <bounce/cpu/radiosity_item_buffer.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/lightmap_view.hpp>
#include <bounce/embree/multi_bounce_reference.hpp>
#include <bounce/embree/radiosity_visibility.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/frame_comparison.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/study/stage_timer.hpp>

#ifdef BOUNCE_RADIOSITY_WITH_GL
#include <bounce/gl/context.hpp>
#include <bounce/gl/radiosity.hpp>
#endif

#include "multi_bounce_cache.hpp"
#include "options.hpp"

#include <fmt/core.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <span>
#include <string>
#include <vector>

using namespace bounce;
using namespace bounce::examples;

namespace {

using clock_type = std::chrono::steady_clock;
double ms_since(clock_type::time_point t0) {
    return std::chrono::duration<double, std::milli>(clock_type::now() - t0).count();
}

// Refuses an output path that cannot be written, before minutes of work.
void check_writable(const std::filesystem::path& file, const char* option) {
    if (file.empty()) return;
    std::error_code ec;
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
    const bool existed = std::filesystem::exists(file);
    { std::ofstream probe(file, std::ios::app); if (!probe) throw parameter_error(option, "cannot write " + file.string()); }
    if (!existed) std::filesystem::remove(file, ec);
}

// The point of the convergence curve: where the solve stood, its time without the curve's
// own evaluations, and the view's error then.
struct checkpoint {
    std::size_t step = 0, shots = 0, elements = 0;
    double time_ms = 0, unshot_fraction = 1, rel_rms = 0;
};

// What a solve gives the report.
struct solve_result {
    std::vector<double> converged, iteration_ms;  // 1 - unshot fraction, and time, after each step
    std::vector<checkpoint> curve;
    std::size_t steps = 0, shots = 0, shooters = 0, splits = 0, elements = 0;
    double unshot_fraction = 1;
    glm::dvec3 emitted{0}, absorbed{0}, escaped{0};
    image<glm::vec3> lightmap, unshot;
    lightmap_atlas atlas;
};

// What the view is compared with: the reference and the pixels that see geometry.
struct comparison {
    const embree::accel& bvh;
    const io::scene& scene;
    std::optional<embree::multi_bounce_image> reference;
    image<float> mask;

    image<glm::vec3> view(const lightmap_atlas& atlas, const image<glm::vec3>& lightmap, int level,
                          std::size_t w, std::size_t h) const {
        return embree::lightmap_view(bvh, scene, atlas, lightmap.view(), level, scene.camera, w, h);
    }
    double rel_rms(const image<glm::vec3>& v) const {
        return study::compare_luminance(v.view(), reference->radiance.view(), mask.view()).rel_rms;
    }
};

// What differs between the backends' solvers, for the one solve loop below.
template <class S>
constexpr bool is_cpu_solver = requires(S& s, const io::scene& sc) { s.subdivide(sc, subdivision_options{}); };

template <class Solver>
image<glm::vec3> lightmap_of(const Solver& solver, int level) {
    if constexpr (is_cpu_solver<Solver>) return solver.lightmap(level);
    else return solver.lightmap();
}

template <class Solver>
std::vector<glm::vec3> unshot_of(const Solver& solver) {
    const auto u = solver.unshot();
    return std::vector<glm::vec3>(u.begin(), u.end());
}

// One solve with the solver `make_solver(atlas)` builds (either backend), timed into
// `timer`; with `curve`, the error at checkpoints (their time left out of every timing).
template <class MakeSolver>
solve_result solve_with(const options& o, const io::scene& scene, const MakeSolver& make_solver,
                        study::stage_timer& timer, const comparison* curve) {
    const auto start = clock_type::now();
    double paused_ms = 0;  // spent on the curve's evaluations
    const lightmap_atlas atlas = build_lightmap_atlas(scene, atlas_options_for(o));
    const double atlas_ms = ms_since(start);
    auto solver = make_solver(atlas);
    using solver_type = decltype(solver);
    const int level = o.adaptive ? o.max_level : 0;
    solve_result r;
    const double target = 1.0 - o.converge;
    std::size_t next_mark = 1;  // curve checkpoints at converged = mark / curve_points * converge
    auto last_print = clock_type::now();
    auto evaluate = [&](bool force) {
        if (!curve || !curve->reference || o.curve_points <= 0) return;
        const double converged = 1.0 - solver.unshot_fraction();
        bool due = force || r.steps == 1;
        while (next_mark <= std::size_t(o.curve_points) &&
               converged >= o.converge * double(next_mark) / double(o.curve_points)) {
            due = true;
            ++next_mark;
        }
        if (!due || (!r.curve.empty() && r.curve.back().step == r.steps)) return;
        const auto t0 = clock_type::now();
        const auto v = curve->view(solver.atlas(), lightmap_of(solver, level), level, o.width, o.height);
        r.curve.push_back({r.steps, solver.progress().shots, solver.atlas().size(), ms_since(start) - paused_ms - ms_since(t0),
                           solver.unshot_fraction(), curve->rel_rms(v)});
        paused_ms += ms_since(t0);
    };
    const subdivision_options sub = subdivision_options_for(o);
    while (solver.unshot_fraction() > target) {
        if (o.max_seconds > 0 && (ms_since(start) - paused_ms) > o.max_seconds * 1e3) break;
        if (!solver.step()) break;
        ++r.steps;
        if constexpr (is_cpu_solver<solver_type>)
            if (o.adaptive && r.steps <= std::size_t(o.subdivide_steps)) r.splits += solver.subdivide(scene, sub);
        r.converged.push_back(1.0 - solver.unshot_fraction());
        r.iteration_ms.push_back(ms_since(start) - paused_ms);
        evaluate(false);
        if (!o.quiet && ms_since(last_print) > 250) {
            last_print = clock_type::now();
            fmt::print(stderr, "\rradiosity: step {}, {} shots, {:.1f}% converged, {:.2f} s   ", r.steps,
                       solver.progress().shots, 100.0 * (1.0 - solver.unshot_fraction()), (ms_since(start) - paused_ms) / 1e3);
        }
    }
    const double total_ms = ms_since(start) - paused_ms;
    if (!o.quiet) fmt::print(stderr, "\rradiosity: step {}, {} shots, {:.1f}% converged, {:.2f} s   \n", r.steps,
                             solver.progress().shots, 100.0 * (1.0 - solver.unshot_fraction()), total_ms / 1e3);
    evaluate(true);
    const auto& t = solver.timings();
    timer.add_sample("atlas", atlas_ms);
    timer.add_sample("lights", t.lights_ms);
    timer.add_sample("visibility", t.visibility_ms);
    timer.add_sample("shooter_choice", t.choice_ms);
    timer.add_sample("reconstruction", t.distribution_ms);
    if constexpr (is_cpu_solver<solver_type>) timer.add_sample("subdivision", t.subdivision_ms);
    timer.add_sample("total", total_ms);
    r.shots = solver.progress().shots;
    r.shooters = solver.shooters();
    r.elements = solver.atlas().size();
    r.unshot_fraction = solver.unshot_fraction();
    r.emitted = solver.emitted_power();
    r.absorbed = solver.absorbed_power();
    r.escaped = solver.escaped_power();
    r.lightmap = lightmap_of(solver, level);
    const std::vector<glm::vec3> unshot = unshot_of(solver);
    r.unshot = solver.atlas().to_fine_texels(std::span<const glm::vec3>(unshot), level);
    r.atlas = solver.atlas();
    return r;
}

#ifdef BOUNCE_RADIOSITY_WITH_GL
gl::radiosity_options gl_options_for(const options& o) {
    gl::radiosity_options g;
    g.shooting = solver_options_for(o);  // --shooters-per-step is refused above unless 1
    g.visibility = o.visibility == "hemicube" ? gl::radiosity_visibility::hemicube : gl::radiosity_visibility::stereographic;
    g.resolution = o.resolution;
    g.tolerance_px = o.tolerance_px;
    return g;
}
#endif

// The run on the backend the options name: the one place a backend is chosen. The CPU
// backend takes `make_visibility(atlas)`'s visibility; the GL backend draws its own item
// buffers in the context current on this thread.
template <class MakeVisibility>
solve_result solve_on_backend(const options& o, const io::scene& scene, const MakeVisibility& make_visibility,
                              study::stage_timer& timer, const comparison* curve) {
    if (o.backend == "gl") {
#ifdef BOUNCE_RADIOSITY_WITH_GL
        return solve_with(o, scene, [&](const lightmap_atlas& a) {
            return gl::progressive_radiosity(scene, a, gl_options_for(o));
        }, timer, curve);
#else
        throw parameter_error("--backend", "'gl' needs the GL adapter, which this build does not have");
#endif
    }
    return solve_with(o, scene, [&](const lightmap_atlas& a) {
        return cpu::progressive_radiosity(scene, a, make_visibility(a), solver_options_for(o));
    }, timer, curve);
}

double luminance_sum(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

nlohmann::ordered_json reference_json(const options& o, const embree::multi_bounce_image& ref) {
    // Each bounce's share of the view's luminance, and how many bounces reach 1% and 0.1%
    // of it (the rest of the series after them).
    double total = 0;
    for (const auto& b : ref.per_bounce) total += luminance_sum(b);
    nlohmann::ordered_json shares = nlohmann::ordered_json::array();
    for (const auto& b : ref.per_bounce) shares.push_back(total > 0 ? luminance_sum(b) / total : 0.0);
    auto needed = [&](double tol) {
        double rest = total;
        for (std::size_t k = 0; k < ref.per_bounce.size(); ++k) {
            rest -= luminance_sum(ref.per_bounce[k]);
            if (rest <= tol * total) return int(k);
        }
        return int(ref.per_bounce.size());
    };
    const auto s = reference_settings_for(o);
    return {{"kind", "multi-bounce path tracing"}, {"paths", s.paths}, {"max_bounces", s.max_bounces},
            {"roulette_after", s.roulette_after}, {"area_samples", s.area_samples},
            {"bounce_share", shares}, {"bounces_for_1pct", needed(1e-2)}, {"bounces_for_0.1pct", needed(1e-3)}};
}

int run(const options& o) {
    check_writable(o.json, "--json");
    check_writable(o.out, "--out");
    check_writable(o.reference_out, "--reference-out");
    if (!o.out.empty() && o.out.extension() != ".png" && o.out.extension() != ".exr")
        throw parameter_error("--out", "must end in .png or .exr: " + o.out.string());
    if (!o.lightmaps.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(o.lightmaps, ec);
        check_writable(o.lightmaps / "radiosity.exr", "--lightmaps");
    }
    if (!o.versus.empty() && !std::filesystem::exists(o.versus))
        throw parameter_error("--versus", "no such file: " + o.versus.string());
    if (o.visibility == "hemicube" && o.resolution % 2 != 0)
        throw parameter_error("--resolution", "a hemicube needs an even resolution");
    if (o.backend == "gl") {
        // What the GL solver does not offer (docs/radiosity-gl.md), refused before any work.
        if (o.visibility == "rays") throw parameter_error("--visibility", "'rays' runs on the CPU backend only");
        if (o.adaptive) throw parameter_error("--adaptive", "'on' runs on the CPU backend only");
        if (o.shooters_per_step != 1) throw parameter_error("--shooters-per-step", "must be 1 on the GL backend");
    }
    const io::scene scene = io::load_scene_arg(o.scene);
    for (const auto& w : scene.warnings) fmt::print(stderr, "{}: {}\n", scene.name, w);
    const embree::accel bvh(scene);

    study::stage_timer timer;
    comparison cmp{bvh, scene, std::nullopt, {}};
    std::optional<double> reference_ms;
    if (o.reference) {
        const auto settings = reference_settings_for(o);
        const std::string key = multi_bounce_key(scene, scene.camera, o.width, o.height, settings, bvh.owner().config());
        const auto dir = study::default_cache_dir();
        cmp.reference = load_multi_bounce(dir, key, o.width, o.height);
        if (!cmp.reference) {
            fmt::print(stderr, "reference: {}x{}, {} paths per pixel, all bounces ...\n", o.width, o.height, settings.paths);
            auto s = settings;
            s.progress = [&](std::size_t done, std::size_t total) {
                if (!o.quiet && (done % 16 == 0 || done == total)) fmt::print(stderr, "\rreference: row {} of {}", done, total);
            };
            const auto t0 = clock_type::now();
            const embree::multi_bounce_reference ref(bvh, scene, s);
            cmp.reference = ref.render(scene.camera, o.width, o.height);
            reference_ms = ms_since(t0);
            if (!o.quiet) fmt::print(stderr, "\n");
            store_multi_bounce(dir, key, *cmp.reference);
        } else {
            fmt::print(stderr, "reference: from cache ({})\n", key);
        }
        gbuffer<float> g = embree::ray_cast_gbuffer(bvh, scene, scene.camera, o.width, o.height);
        cmp.mask = study::coverage_mask(g.view());
    }

    // Visibility as the options ask: built per solve from the solve's atlas (its charts).
    const auto item_options = [&] {
        cpu::item_buffer_visibility::options v;
        v.projection = o.visibility == "hemicube" ? cpu::item_projection::hemicube : cpu::item_projection::stereographic;
        v.resolution = o.resolution;
        v.tolerance_px = o.tolerance_px;
        return v;
    }();
    const embree::device device;
#ifdef BOUNCE_RADIOSITY_WITH_GL
    std::optional<gl::context> gl_context;  // current on this thread while it lives
    if (o.backend == "gl") gl_context.emplace();
#endif
    std::optional<solve_result> result;
    for (int rep = 0; rep < o.repeat; ++rep) {
        const comparison* curve = rep == 0 ? &cmp : nullptr;
        if (o.visibility == "rays")
            result = solve_on_backend(o, scene, [&](const lightmap_atlas& a) {
                return embree::radiosity_visibility(device, scene, a.chart_of_triangle);
            }, timer, curve);
        else
            result = solve_on_backend(o, scene, [&](const lightmap_atlas& a) {
                return cpu::item_buffer_visibility(scene, a, item_options);
            }, timer, curve);
    }
    solve_result& r = *result;
    const int level = o.adaptive ? o.max_level : 0;
    image<glm::vec3> view;
    timer.time("lightmap_view", [&] { view = cmp.view(r.atlas, r.lightmap, level, o.width, o.height); });
    if (reference_ms) timer.add_sample("reference", *reference_ms);

    study::run_report report;
    report.technique = "radiosity";
    report.scene = scene.name;
    report.width = o.width;
    report.height = o.height;
    report.backend = o.backend;
#ifdef BOUNCE_RADIOSITY_WITH_GL
    if (gl_context) report.gl_renderer = gl_context->renderer();
#endif
    report.parameters = {{"elements", o.elements}, {"block", o.block}, {"visibility", o.visibility},
                         {"resolution", o.resolution}, {"tolerance_px", o.tolerance_px},
                         {"adaptive", o.adaptive ? "on" : "off"}, {"max_level", o.max_level},
                         {"threshold", o.threshold}, {"subdivide_steps", o.subdivide_steps},
                         {"converge", o.converge}, {"max_seconds", o.max_seconds},
                         {"shooters_per_step", o.shooters_per_step}, {"near_field", o.near_field},
                         {"ambient", o.ambient ? "on" : "off"}, {"reference_paths", o.reference_paths},
                         {"embree_config", bvh.owner().config()}};
    report.set_timings(timer);
    if (cmp.reference) report.error = study::compare_luminance(view.view(), cmp.reference->radiance.view(), cmp.mask.view());
    report.set_count("elements", r.elements);
    report.set_count("elements_base", r.atlas.block_level.empty() ? r.elements
                                                                   : std::size_t(std::count(r.atlas.block_level.begin(),
                                                                                            r.atlas.block_level.end(), 0)));
    report.set_count("iterations", r.steps);
    report.set_count("shots", r.shots);
    report.set_count("shooters", r.shooters);
    report.set_count("charts", r.atlas.charts.size());
    report.set_count("triangles", scene.triangles.size());
    report.set_count("splits", r.splits);
    nlohmann::ordered_json j = report.to_json();
    j["unshot_fraction"] = r.unshot_fraction;
    const double emitted = r.emitted.x + r.emitted.y + r.emitted.z;
    j["energy"] = {{"emitted_w", emitted},
                   {"absorbed_fraction", (r.absorbed.x + r.absorbed.y + r.absorbed.z) / emitted},
                   {"escaped_fraction", (r.escaped.x + r.escaped.y + r.escaped.z) / emitted}};
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    j["peak_rss_mb"] = double(usage.ru_maxrss) / 1024.0;
    j["ms_per_iteration"] = r.steps ? r.iteration_ms.back() / double(r.steps) : 0.0;
    j["converged_fraction"] = r.converged;
    j["iteration_ms"] = r.iteration_ms;
    nlohmann::ordered_json curve = nlohmann::ordered_json::array();
    for (const auto& c : r.curve)
        curve.push_back({{"step", c.step}, {"shots", c.shots}, {"elements", c.elements}, {"time_ms", c.time_ms},
                         {"unshot_fraction", c.unshot_fraction}, {"rel_rms", c.rel_rms}});
    j["convergence"] = curve;
    if (cmp.reference) j["reference"] = reference_json(o, *cmp.reference);

    if (!o.versus.empty()) {
        // Another run's view (say, with ray-cast visibility) as the reference.
        const image<glm::vec3> other = io::read_rgb(o.versus);
        if (other.width() != view.width() || other.height() != view.height())
            throw parameter_error("--versus", o.versus.string() + " is not a " + std::to_string(o.width) + " x " +
                                                  std::to_string(o.height) + " view");
        gbuffer<float> g = embree::ray_cast_gbuffer(bvh, scene, scene.camera, o.width, o.height);
        const image<float> mask = study::coverage_mask(g.view());
        const auto e = study::compare_luminance(view.view(), other.view(), mask.view());
        j["versus"] = {{"file", o.versus.filename().string()}, {"rel_rms", e.rel_rms}, {"max_abs", e.max_abs}};
    }
    if (!o.out.empty()) {
        if (o.out.extension() == ".exr") io::write_exr(o.out, view.view());
        else io::write_png(o.out, view.view());
    }
    if (!o.reference_out.empty() && cmp.reference) {
        if (o.reference_out.extension() == ".exr") io::write_exr(o.reference_out, cmp.reference->radiance.view());
        else io::write_png(o.reference_out, cmp.reference->radiance.view());
    }
    if (!o.lightmaps.empty()) {
        io::write_exr(o.lightmaps / "radiosity.exr", r.lightmap.view());
        io::write_exr(o.lightmaps / "unshot.exr", r.unshot.view());
    }
    if (!o.json.empty()) {
        std::ofstream f(o.json);
        f << j.dump(2) << '\n';
        if (!f) throw study::report_error(o.json, "cannot write the report");
    }
    fmt::print("radiosity {} {} {}: {} elements, {} iterations, {:.1f}% converged, total {:.0f} ms (visibility {:.0f}, "
               "reconstruction {:.0f}, choice {:.1f}), rel_rms {}\n",
               scene.name, o.visibility, o.adaptive ? "adaptive" : "uniform", r.elements, r.steps,
               100.0 * (1.0 - r.unshot_fraction), timer.median_ms("total"), timer.median_ms("visibility"),
               timer.median_ms("reconstruction"), timer.median_ms("shooter_choice"),
               report.error ? fmt::format("{:.4f}", report.error->rel_rms) : std::string("-"));
    if (j.contains("versus")) fmt::print("  versus {}: rel_rms {:.4f}\n", o.versus.string(), j["versus"]["rel_rms"].get<double>());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce: progressive refinement radiosity (Coombe and Harris, GPU Gems 2 ch. 39)"};
    options o;
    std::string adaptive = "off", ambient = "off", reference = "on";
    add_options(app, o, adaptive, ambient, reference);
    CLI11_PARSE(app, argc, argv);
    o.adaptive = adaptive == "on";
    o.ambient = ambient == "on";
    o.reference = reference == "on";
    try {
        return run(o);
    } catch (const bounce::error& e) {
        fmt::print(stderr, "radiosity: {}\n", e.what());
        return 2;
    }
}
