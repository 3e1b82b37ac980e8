// irradiance_volume: an irradiance volume (Oat, "Irradiance Volumes for Real-time
// Rendering", ShaderX5 2006) baked with Embree over a static scene lights a sphere moving
// along a straight path through it.
//
//   build/bin/irradiance_volume --scene sponza --mode adaptive --max-depth 5 --interp weighted
//       --b 2 --gradients on --json iv.json --out iv.png
//
// Light transport: probes hold the one-bounce indirect light (reference_integrator::
// incoming_radiance: Kd / pi times the direct irradiance at the first hit), and the
// reference on the sphere is reference_integrator::indirect_irradiance at its surface
// points (study::volume_sphere_study). The path and radius come from the scene's free space
// along the camera's view (study::default_sphere_path) unless --path / --radius give them.
// Reports probes, bake_ms, lookup_ns per shaded point, error.rel_rms of the luminance over
// every sphere point of every frame, popping (largest step-to-step change at the point
// facing down, against the camera's up, over its mean) with the reference's own figure,
// and popping_excess (the part of the change the true field does not have), for every
// lookup under "lookups".
// --sh-study instead captures environments along the path and prints SH errors per order.
// --surface instead lights the G-buffer of the scene's camera (study::volume_surface_study)
// with and without the probes' visibility (DDGI distance moments baked by Embree) and
// reports rel_rms against the one-bounce reference over every covered pixel and over the
// pixels within one finest cell of another surface (where walls meet floors).
#include "../common/run_program.hpp"
#include "options.hpp"

#include <bounce/embree/probe_baker.hpp>
#include <bounce/embree/probe_relocation.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/memory_budget.hpp>
#include <bounce/study/provenance.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/study/stage_timer.hpp>
#include <bounce/study/volume_sphere.hpp>
#include <bounce/study/volume_surface.hpp>
#include <bounce/study/volume_sweep.hpp>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

using namespace bounce;
using ojson = nlohmann::ordered_json;

namespace {

using options = examples::volume_options;
using examples::volume_mode;
using examples::mode_names, examples::refine_names, examples::noise_names, examples::interp_names;

study::volume_surface_settings surface_settings(const options& o) {
    study::volume_surface_settings s;
    s.width = s.height = o.surface_size;
    s.reference_samples = std::max(2u, o.sphere.reference_samples);
    s.seed = o.sphere.seed;
    return s;
}

// --surface: the volume at the camera's G-buffer, without and with visibility, against the
// one-bounce reference at the same points; printed, and written to --json.
int run_surface(const options& o, const io::scene& scene, const embree::accel& bvh, const embree::reference_integrator& light,
                const irradiance_volume& volume, std::span<const glm::vec3> baked_at, glm::vec3 extent, ojson report) {
    study::probe_visibility_report_settings s;
    s.visibility = o.visibility;
    s.surface = surface_settings(o);
    const glm::vec3 cell = extent / float(1 << o.max_depth);
    s.wall_distance = std::min({cell.x, cell.y, cell.z});
    s.self_shadow_bias = o.self_shadow_bias;
    s.picture = o.out;
    const ojson surface = study::report_probe_visibility(light, bvh, scene, volume, baked_at, s);
    if (o.json.empty()) return 0;
    report["technique"] = "irradiance_volume_surface";
    report["surface"] = surface;
    report["timings_note"] = "wall-clock times on a loaded shared 2-core machine";
    report["provenance"] = study::collect_provenance().to_json();
    io::write_text_file(o.json, report.dump(2, ' ', false, ojson::error_handler_t::replace) + "\n");
    return 0;
}

// Refuses a depth whose worst case (the uniform grid) would not fit in memory.
void check_memory(const options& o) {
    const double need = irradiance_volume::estimated_bytes(o.max_depth), have = double(study::available_memory_bytes());
    if (have > 0 && need > have)
        throw parameter_error("--max-depth", std::to_string(o.max_depth) + ": the volume may hold up to " +
                                                 std::to_string(std::uint64_t(irradiance_volume::uniform_probe_count(o.max_depth))) +
                                                 " probes, about " + study::format_bytes(need) + ", more than the " +
                                                 study::format_bytes(have) + " of memory available; choose a smaller depth");
}

int run(const options& o) {
    if (!o.json.empty()) io::check_output_file("--json", o.json);
    if (!o.out.empty()) io::check_image_output("--out", o.out);
    check_memory(o);
    examples::check_volume_options(o);
    std::optional<tbb::global_control> threads;
    if (o.threads > 0) threads.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(o.threads));

    const io::scene scene = io::load_scene_arg(o.scene);
    const embree::accel bvh(scene);
    embree::reference_settings rs;
    rs.hemisphere_samples = o.sphere.reference_samples;
    rs.seed = o.seed;
    const embree::reference_integrator light(bvh, scene, rs);
    auto [lo, hi] = scene.bounds();
    const glm::vec3 scene_extent = hi - lo;
    lo -= o.margin * scene_extent;
    hi += o.margin * scene_extent;
    const glm::vec3 extent = hi - lo;

    study::sphere_path path;
    if (o.surface) {
    } else if (o.path.empty()) {
        path = study::default_sphere_path(bvh, scene.camera, lo, hi, o.radius * glm::length(extent));
    } else {
        path = {lo + extent * glm::vec3(o.path[0], o.path[1], o.path[2]), lo + extent * glm::vec3(o.path[3], o.path[4], o.path[5]),
                (o.radius > 0 ? o.radius : 0.02f) * glm::length(extent)};
        if (!study::sphere_path_is_clear(bvh, path))
            throw parameter_error("--path", "the sphere (radius " + std::to_string(path.radius) +
                                                ") intersects the scene along the path; choose another --path or --radius");
    }
    if (!o.surface)
        std::fprintf(stderr, "path (%.4g %.4g %.4g) -> (%.4g %.4g %.4g), radius %.4g\n", path.a.x, path.a.y, path.a.z, path.b.x,
                     path.b.y, path.b.z, path.radius);

    if (o.sh_study) {
        std::vector<glm::vec3> points;
        for (std::size_t s = 0; s < 4; ++s) points.push_back(path.centre(s, 4));
        const ojson environments = study::sh_environment_study(light, points);
        study::print_sh_environments(environments);
        if (!o.json.empty())
            io::write_text_file(o.json, ojson{{"technique", "irradiance_volume_sh_study"}, {"scene", scene.name},
                                              {"environments", environments},
                                              {"provenance", study::collect_provenance().to_json()}}.dump(2) + "\n");
        return 0;
    }

    irradiance_volume_settings vs = examples::volume_settings(o);  // the bake
    vs.memory_limit_bytes = study::available_memory_bytes();
    const glm::vec3 finest = extent / float(1 << o.max_depth);
    embree::probe_baker_settings bs;
    bs.rays = o.rays;
    bs.seed = o.seed;
    bs.gradient_step = o.gradient_step * std::min({finest.x, finest.y, finest.z});
    bs.gradient_noise_ratio = o.gradient_noise;
    bs.noise = o.noise;
    std::size_t batch = 0;
    bs.progress = [&](std::size_t done, std::size_t total) {
        if (done == total || done % 64 < 4) std::fprintf(stderr, "\rbake: batch %zu, %zu / %zu probes   ", batch, done, total);
        if (done == total) ++batch;
    };
    const embree::probe_baker baker(light, bvh, scene, bs);
    embree::relocating_probe_source relocating(baker, bvh, scene, std::min({finest.x, finest.y, finest.z}));
    study::probe_memo memo([&](std::span<const glm::vec3> at, std::span<irradiance_probe> out) {
        o.relocate == "on" ? relocating(at, out) : baker(at, out);
    });  // --sweep-bias-budget builds its octrees from the same probes
    irradiance_volume_build_stats stats;
    const auto bake_start = std::chrono::steady_clock::now();
    const irradiance_volume volume = irradiance_volume::build(scene, lo, hi, vs, memo, &stats);
    const double bake_ms = study::ms_since(bake_start);
    std::fprintf(stderr, "\n");
    if (o.surface)  // the sphere path prints this line below, with the reference's popping
        std::printf("%s %s depth %d: %zu probes (%zu inside), %zu leaves, bake %.0f ms\n", scene.name.c_str(),
                    examples::name_of(mode_names, o.mode).c_str(), volume.depth(), volume.probes().size(), stats.probes_inside,
                    volume.leaf_count(), bake_ms);
    if (o.relocate == "on") std::printf("relocation: %zu probes baked away from their lattice points\n", relocating.moved());
    if (o.surface)
        return run_surface(o, scene, bvh, light, volume, relocating.positions_of(volume), extent,
                           {{"scene", scene.name}, {"mode", examples::name_of(mode_names, o.mode)}, {"max_depth", o.max_depth},
                            {"rays", o.rays}, {"probes", volume.probes().size()}, {"probes_inside", stats.probes_inside},
                            {"leaves", volume.leaf_count()}, {"bake_ms", bake_ms}, {"relocate", o.relocate},
                            {"probes_relocated", relocating.moved()},
                            {"light_transport", "one-bounce indirect irradiance: probes and reference at the G-buffer's points"}});

    // Every lookup on the same volume, against the reference on the sphere; popping at the
    // point facing down, against the scene's up.
    study::volume_sphere_settings ss = o.sphere;
    ss.popping_normal = -glm::normalize(scene.camera.up);
    const study::volume_sphere_study sphere(light, path, ss);
    const std::vector<std::pair<std::string, cpu::volume_lookup>> variants = {
        {"trilinear", {cpu::volume_interpolation::trilinear, {o.b, false, o.support}}},
        {"weighted", {cpu::volume_interpolation::weighted, {o.b, false, o.support}}},
        {"weighted_gradients", {cpu::volume_interpolation::weighted, {o.b, true, o.support}}},
    };
    const std::string chosen = o.interp == cpu::volume_interpolation::trilinear ? "trilinear"
                               : o.gradients == "on"                          ? "weighted_gradients"
                                                                              : "weighted";
    ojson lookups = ojson::object();
    study::volume_lookup_figures best;
    cpu::volume_lookup chosen_how;
    for (const auto& [name, how] : variants) {
        if (name != chosen && !volume.hanging_corners().empty()) continue;  // only trilinear computes hanging corners
        auto f = sphere.measure(volume, name, how);
        lookups[name] = f.to_json();
        std::printf("%-20s rel_rms %.4f  popping %.4f (excess %.4f)  lookup %.0f ns\n", name.c_str(), f.error.rel_rms, f.popping,
                    f.popping_excess, f.lookup_ns);
        if (name == chosen) best = std::move(f), chosen_how = how;
    }
    irradiance_volume_settings merged = vs;  // the sweep: adaptive octrees of the same lattice
    merged.min_depth = o.min_depth >= 0 ? o.min_depth : std::min(1, o.max_depth);
    std::optional<study::volume_surface_study> surface;  // --sweep-surface: wall distance = the finest cell
    if (o.sweep_surface) surface.emplace(light, bvh, scene, scene.camera, std::min({finest.x, finest.y, finest.z}), surface_settings(o));
    study::volume_rebake rebake{[&](std::uint32_t rays, std::span<const glm::vec3> at, std::span<irradiance_probe> out) {
        embree::probe_baker_settings more = bs;  // --sweep-equal-rays: the same probes with more rays
        more.rays = rays, more.progress = {};
        embree::probe_baker(light, bvh, scene, more)(at, out);
    }, std::uint64_t(irradiance_volume::uniform_probe_count(std::max(0, o.sweep_equal_rays))) * o.rays, o.rays};
    const auto* rebaking = o.sweep_equal_rays >= 0 ? &rebake : nullptr;
    const auto sweep = o.sweep_depths.empty()
                           ? study::bias_budget_sweep(scene, lo, hi, merged, memo, sphere, o.sweep, o.sweep_sigmas,
                                                      surface ? &*surface : nullptr, rebaking)
                           : study::volume_depth_sweep(scene, lo, hi, merged, memo, sphere, o.sweep_depths, o.sweep,
                                                       o.sweep_tolerances, o.sweep_sigmas, surface ? &*surface : nullptr, rebaking);
    std::printf("%s %s depth %d: %zu probes (%zu inside), %zu leaves, bake %.0f ms; reference popping %.4f\n",
                scene.name.c_str(), examples::name_of(mode_names, o.mode).c_str(), volume.depth(), volume.probes().size(),
                stats.probes_inside, volume.leaf_count(), bake_ms, sphere.reference_popping());

    std::size_t strip_w = 0, strip_h = 0;
    if (!o.out.empty()) {
        const auto strip = study::render_sphere_strip(bvh, scene, scene.camera, light, volume, chosen_how, path, 4, 192, 144);
        if (std::filesystem::path(o.out).extension() == ".exr") io::write_exr(o.out, strip.view());  // linear
        else io::write_png(o.out, strip.view(), io::auto_exposure(strip.view()));
        strip_w = strip.width(), strip_h = strip.height();
    }
    if (o.json.empty()) return 0;
    study::run_report report;
    report.technique = "irradiance_volume";
    report.scene = scene.name;
    report.width = strip_w ? strip_w : o.sphere.sphere_points;  // the strip, or the sphere's points per frame
    report.height = strip_h ? strip_h : o.sphere.frames;        // the strip, or the frames
    report.backend = "cpu";
    report.parameters = {{"mode", examples::name_of(mode_names, o.mode)}, {"max_depth", o.max_depth},
                         {"min_depth", vs.min_depth}, {"interp", examples::name_of(interp_names, o.interp)},
                         {"b", o.b}, {"gradients", o.gradients}, {"support", o.support}, {"rays", o.rays},
                         {"gradient_step", bs.gradient_step}, {"reference_samples", o.sphere.reference_samples},
                         {"frames", o.sphere.frames}, {"sphere_points", o.sphere.sphere_points}, {"sphere_radius", path.radius},
                         {"path", {{path.a.x, path.a.y, path.a.z}, {path.b.x, path.b.y, path.b.z}}},
                         {"path_from", o.path.empty() ? "free space along the view" : "--path"},
                         {"volume_lo", {lo.x, lo.y, lo.z}}, {"volume_hi", {hi.x, hi.y, hi.z}},
                         {"distance_ratio", o.distance_ratio}, {"neighbour_change", o.neighbour_change},
                         {"geometry_triangles", o.geometry_triangles}, {"gradient_ratio", o.gradient_ratio},
                         {"cull_tolerance", o.cull}, {"prediction_tolerance", o.prediction_tolerance},
                         {"noise_sigmas", o.noise_sigmas}, {"refit", o.refit},
                         {"refine", examples::name_of(refine_names, o.refine)}, {"conforming", o.conforming},
                         {"bias_budget", o.bias_budget}, {"bias_tolerance", o.bias_tolerance}, {"calibrate_noise", o.calibrate}, {"gradient_noise_ratio", o.gradient_noise},
                         {"noise_estimate", examples::name_of(noise_names, o.noise)}, {"sweep_bias_budget", o.sweep},
                         {"sweep_noise_sigmas", o.sweep_sigmas}, {"sweep_depths", o.sweep_depths}, {"sweep_bias_tolerance", o.sweep_tolerances},
                         {"sweep_surface", o.sweep_surface}, {"sweep_equal_rays", o.sweep_equal_rays},
                         {"hanging_corners", examples::name_of(examples::hanging_names, o.hanging)},
                         {"bias_tolerance_unit", examples::name_of(examples::tolerance_unit_names, o.tolerance_unit)}, {"surface_size", o.surface_size},
                         {"seed", o.seed}, {"threads", o.threads}};
    report.timings_ms = {{"bake", bake_ms}, {"reference", sphere.reference_ms()}};
    report.error = best.error;
    report.set_count("probes", volume.probes().size());
    report.set_count("probes_inside", stats.probes_inside);
    report.set_count("probes_baked", stats.probes_baked);
    report.set_count("leaves", volume.leaf_count());
    report.set_count("nodes", volume.nodes().size());
    auto j = report.to_json();
    j["bake_ms"] = bake_ms;
    j["lookup_ns"] = best.lookup_ns;
    j["popping"] = best.popping;
    j["popping_excess"] = best.popping_excess;
    j["popping_reference"] = sphere.reference_popping();
    j["popping_reference_series"] = sphere.reference_popping_series();
    j["lookups"] = lookups;
    j["build"] = study::build_stats_json(stats);
    if (!sweep.empty()) j["sweep"] = study::to_json(sweep);
    j["light_transport"] = "one-bounce indirect: probes and reference integrate Kd/pi * direct irradiance at the first hit";
    j["provenance"] = study::collect_provenance().to_json();
    io::write_text_file(o.json, j.dump(2, ' ', false, ojson::error_handler_t::replace) + "\n");
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    options o;
    CLI::App app{"Irradiance volume lighting a moving sphere (Oat 2006), against the reference integrator"};
    examples::add_volume_options(app, o);
    CLI11_PARSE(app, argc, argv);
    o.sphere.seed = o.seed + 6;  // the reference on the sphere: 7 with the default seed, as before
    return examples::run_program("irradiance_volume", [&] { return run(o); },
                                 "choose a smaller --max-depth, fewer --rays, --frames or --sphere-points");
}
