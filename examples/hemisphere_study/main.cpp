// hemisphere_study: single-plane hemisphere sampling (Gautron 2008, section 8.4, Table 8.1)
// against a full-hemisphere Monte Carlo reference, on K random visible points of a scene:
// irradiance with four weightings (plane, coverage, stretching, fall-off) from the GL raster
// sampler and the ray-cast sampler (which separates the estimator's error from
// rasterization's). The measurements are bounce::study's (hemisphere_comparison.hpp).
//   build/bin/hemisphere_study --scene sponza --resolution 64 --aperture 126 --points 10000 --json study.json
//   build/bin/hemisphere_study --scene sponza --sweep --sweep-points 1000 --json sweep.json
#include <bounce/embree/accel.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/hemisphere_comparison.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/study/stage_timer.hpp>

#ifdef BOUNCE_WITH_GL
#include <bounce/gl/context.hpp>
#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/gl/raster_record_sampler.hpp>
#endif

#include <CLI/CLI.hpp>
#include "../common/cli_number_checks.hpp"
#include "../common/run_program.hpp"
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace bounce;
using json = nlohmann::ordered_json;
using clock_type = std::chrono::steady_clock;

namespace {

void print_row(const std::string& sampler, const json& e, double records_per_s) {
    fmt::print("  {:<16} plane {:6.2f}%  coverage {:6.2f}%  stretch {:6.2f}%  falloff {:6.2f}% (kappa {:.3f}; "
               "running {:6.2f}%)  {:8.1f} records/s\n",
               sampler, 100 * e["rms_plane"].get<double>(), 100 * e["rms_coverage"].get<double>(),
               100 * e["rms_stretch"].get<double>(), 100 * e["rms_falloff"].get<double>(),
               e["falloff_kappa"].get<double>(), 100 * e["rms_falloff_running"].get<double>(), records_per_s);
}

struct raster_run {
    study::plane_estimates cpu;  // read-back + CPU sums, the running sampler's kappas
    double gpu_ms = 0, running_ms = 0, cpu_gpu_difference = 0, running_cpu_gpu_difference = 0;
    double per_s(double ms) const { return 1000.0 * double(cpu.size()) / ms; }
};

#ifdef BOUNCE_WITH_GL

// The raster sampler three ways over the same batches: read-back overlapping the next batch
// with CPU sums; gl::raster_record_sampler's running fall-off (whose kappas the CPU sums
// take, so every weighting is summed the same way); the GPU reduction of the stretch table.
raster_run raster(const gl::hemisphere_raster_options& o, const io::scene& scene, const gl::scene_mesh& mesh,
                  const gl::direct_light& light, const study::surface_points& pts) {
    gl::hemisphere_raster r(scene, mesh, light, o);
    study::plane_estimate_sums sums(o.camera, pts.size(), false);
    const auto t0 = clock_type::now();
    r.read_planes(pts.positions, pts.normals, [&](std::size_t first, const gl::plane_batch& b) { sums.add(first, b.views()); });
    raster_run out{sums.result(study::ms_since(t0))};
    std::vector<hemisphere_estimate> est(pts.size());
    gl::raster_record_sampler running(r, radius_limits{}, {plane_weighting::falloff, gl::falloff_mode::running});
    const auto t1 = clock_type::now();
    running.estimate(pts.positions, pts.normals, est, out.cpu.running_kappa);
    out.running_ms = study::ms_since(t1);
    out.cpu.kappa = running.falloff_kappa();  // after the last batch: pooled over the run
    out.running_cpu_gpu_difference =
        study::max_relative_luminance_difference(study::irradiance_of(est), out.cpu.falloff(out.cpu.running_kappa));
    gl::raster_record_sampler gpu(r, radius_limits{}, plane_weighting::stretch);
    const auto t2 = clock_type::now();
    gpu.estimate(pts.positions, pts.normals, est, {});
    out.gpu_ms = study::ms_since(t2);
    out.cpu_gpu_difference = study::max_relative_luminance_difference(study::irradiance_of(est), out.cpu.stretch);
    return out;
}
#endif

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce hemisphere study: single-plane sampling (plane, coverage, stretching, fall-off) vs a "
                 "Monte Carlo reference"};
    std::string scene_arg = "sponza";
    std::uint32_t resolution = 64;
    double aperture = 126.0, turn = 0.0;
    bool hashed_turn = false, sweep = false, no_raster = false, no_ray_cast = false, no_cache = false;
    std::size_t points = 10000, sweep_points = 1000, batch = 64, texel_points = 0;
    study::point_reference_settings rs;
    int shadow_resolution = 4096;
#ifdef BOUNCE_WITH_GL
    gl::direct_light_options shadows;  // its resolution comes from shadow_resolution
#endif
    fs::path json_path, points_csv;
    app.add_option("--scene", scene_arg, "cornell, a scene.json, its folder, an .obj, a .gltf or .glb, or a name under the scenes folder")
        ->capture_default_str();
    app.add_option("--resolution", resolution, "plane resolution N (N x N pixels)")
        ->check(CLI::Range(1u, 1024u))
        ->capture_default_str();
    app.add_option("--aperture", aperture, "full angle of the plane's square field of view, degrees")
        ->check(examples::detail::number_in(1, 179, true, "an aperture"))
        ->capture_default_str();
    app.add_option("--plane-turn", turn, "turn of every plane about its normal from orthonormal_basis(n), degrees in [0, 90)")
        ->check(examples::quarter_turn_deg)
        ->capture_default_str();
    app.add_flag("--hashed-turn", hashed_turn, "also turn each plane by its own angle in [0, 90) degrees, hashed from its point");
    app.add_option("--points", points, "random visible points (fixed seed)")->check(CLI::Range(1, 200000))->capture_default_str();
    app.add_option("--seed", rs.seed, "seed of the points and of the reference")->check(examples::seed_u64)->capture_default_str();
    app.add_option("--reference-spp", rs.spp, "reference rays per point and half (doubled until the error target)")
        ->check(CLI::Range(16u, 1u << 22))
        ->capture_default_str();
    app.add_option("--reference-target", rs.target, "largest acceptable relative RMS error of the reference")
        ->check(examples::detail::number_in(1e-4, 0.5, true, "a target"))
        ->capture_default_str();
    app.add_flag("--sweep", sweep, "also run resolutions 16..128 x apertures 90..150");
    app.add_option("--sweep-points", sweep_points, "points per setting of the sweep (the first of --points)")
        ->check(CLI::Range(1, 200000))
        ->capture_default_str();
    app.add_option("--batch", batch, "records per raster atlas, and per step of the running fall-off profile")
        ->check(CLI::Range(1, 1024))
        ->capture_default_str();
    app.add_option("--shadow-resolution", shadow_resolution, "texels per side of the raster sampler's shadow maps")
        ->check(CLI::Range(64, 8192))
        ->capture_default_str();
#ifdef BOUNCE_WITH_GL
    app.add_option("--shadow-normal-offset", shadows.normal_offset_texels,
                   "raster sampler: shadow lookups moved this many texels along n")
        ->check(examples::finite_non_negative)->capture_default_str();
    app.add_option("--shadow-slope-bias", shadows.slope_bias, "raster sampler: shadow depth bias in depth slopes per texel")
        ->check(examples::finite_non_negative)->capture_default_str();
#endif
    app.add_option("--texel-points", texel_points,
                   "also compare raster and ray-cast planes texel by texel on this many points (the first of --points)")
        ->check(CLI::Range(std::size_t(0), std::size_t(200000)))
        ->capture_default_str();
    app.add_flag("--no-raster", no_raster, "skip the GL raster sampler");
    app.add_flag("--no-ray-cast", no_ray_cast, "skip the Embree ray-cast sampler");
    app.add_option("--cache-dir", rs.cache_dir, "where the reference is cached ($BOUNCE_CACHE)")->capture_default_str();
    app.add_flag("--no-cache", no_cache, "neither read nor write the reference cache");
    app.add_option("--json", json_path, "run report");
    app.add_option("--points-csv", points_csv, "per-point luminance of the reference and of every estimate (CSV)");
    CLI11_PARSE(app, argc, argv);

    const std::string out_of_memory = fmt::format("{} points, planes of {}^2, batches of {}",
                                                  std::max(points, sweep_points), resolution, batch);
    return examples::run_program("hemisphere_study", [&] {
        // Every output before the work: a run of minutes must not end in an unwritable file.
        if (!json_path.empty()) io::check_output_file("--json", json_path);
        if (!points_csv.empty()) io::check_output_file("--points-csv", points_csv);
        rs.use_cache = !no_cache;
        if (rs.use_cache) study::check_cache_dir(rs.cache_dir);
        const io::scene scene = io::load_scene_arg(scene_arg);
        scene.view().validate();  // magnitudes and lights named before Embree sees them
        const plane_camera cam{resolution, aperture, turn, hashed_turn};
        cam.validate();
        const embree::accel bvh(scene);
        const embree::reference_integrator ref(bvh, scene);
        const std::size_t K = std::max(points, sweep ? sweep_points : std::size_t(0));
        const auto pts = study::visible_points(bvh, scene, scene.camera, K, rs.seed);
        fmt::print("hemisphere_study: {} ({} triangles), {} points, plane {}^2 at {} deg, turned {} deg{}\n", scene.name,
                   scene.triangles.size(), K, resolution, aperture, turn, hashed_turn ? " + hashed" : "");

        rs.scene_name = scene.name;
        rs.device_config = bvh.owner().config();
        const auto t_ref = clock_type::now();
        const study::point_reference reference = study::indirect_point_reference(ref, pts, rs);
        const double reference_ms = study::ms_since(t_ref);
        fmt::print("  reference: 2 x {} rays per point, own error {:.3f}% ({}, {:.1f} s)\n", reference.spp,
                   100 * reference.own_rel_rms, reference.from_cache ? "cache" : "computed", reference_ms / 1000);
        const auto main_pts = pts.first(points);
        const auto main_ref = reference.first(points);

        json report_error = json::object();
        std::vector<study::plane_sweep_sampler> samplers;
        std::optional<raster_run> raster_main;
        std::optional<study::plane_estimates> ray_main;
#ifdef BOUNCE_WITH_GL
        std::optional<gl::context> context;
        std::optional<gl::scene_mesh> mesh;
        std::optional<gl::direct_light> light;
        if (!no_raster) {
            try {
                context.emplace();
                shadows.shadow_resolution = shadow_resolution;
                shadows.validate();
                mesh.emplace(scene);
                light.emplace(scene, *mesh, shadows);
                fmt::print("  GL: {} ({})\n", context->renderer(), context->platform());
            } catch (const gl::gl_error& e) {
                fmt::print(stderr, "  no GL raster sampler: {}\n", e.what());
                no_raster = true;
            }
        }
        const auto run_raster = [&](const study::surface_points& p, const plane_camera& c) {
            return raster({c, std::min(batch, p.size())}, scene, *mesh, *light, p);
        };
        if (!no_raster) {
            const raster_run& r = raster_main.emplace(run_raster(main_pts, cam));
            report_error["raster"] = study::plane_estimate_errors(r.cpu, main_ref);
            print_row("raster (CPU sum)", report_error["raster"], r.cpu.records_per_s());
            fmt::print("  raster (GPU sum)  {:8.1f} records/s; CPU and GPU sums differ by at most {:.2e} (relative)\n",
                       r.per_s(r.gpu_ms), r.cpu_gpu_difference);
            fmt::print("  raster (running)  {:8.1f} records/s (record sampler, running fall-off: read-back, profile, GPU "
                       "sum); its sums differ from the CPU's by at most {:.2e} (relative)\n",
                       r.per_s(r.running_ms), r.running_cpu_gpu_difference);
            if (texel_points > 0) {
                const auto tp = pts.first(texel_points);
                study::plane_texel_difference diff(ref, cam, tp);
                gl::hemisphere_raster tr(scene, *mesh, *light, {cam, std::min(batch, tp.size())});
                tr.read_planes(tp.positions, tp.normals, [&](std::size_t first, const gl::plane_batch& b) { diff.add(first, b.views()); });
                report_error["raster_texel_difference"] = diff.value();
                fmt::print("  raster against ray-cast planes, texel by texel ({} points): {:.2f}%\n", tp.size(),
                           100 * diff.value());
            }
            samplers.push_back({"raster", [&](const plane_camera& c) { return run_raster(pts.first(sweep_points), c).cpu; }});
        }
#else
        no_raster = true;
#endif
        if (!no_ray_cast) {
            ray_main = study::ray_cast_plane_estimates(ref, main_pts, cam, batch);
            report_error["ray_cast"] = study::plane_estimate_errors(*ray_main, main_ref);
            print_row("ray cast", report_error["ray_cast"], ray_main->records_per_s());
            samplers.insert(samplers.begin(), {"ray_cast", [&](const plane_camera& c) {
                                                   return study::ray_cast_plane_estimates(ref, pts.first(sweep_points), c, batch);
                                               }});
        }
        report_error = study::with_headline_errors(report_error);

        json sweep_rows = json::array();
        if (sweep)
            sweep_rows = study::plane_sweep(samplers, reference.first(sweep_points), turn, hashed_turn, [](const json& r) {
                const std::string label = fmt::format("{} {}^2 {}", r["sampler"].get<std::string>(), r["resolution"].get<int>(),
                                                      r["aperture"].get<double>());
                print_row(label, r, r["records_per_s"].get<double>());
            });

        if (!points_csv.empty()) {
            std::vector<std::pair<std::string, const study::plane_estimates*>> named;
            if (raster_main) named.emplace_back("raster", &raster_main->cpu);
            if (ray_main) named.emplace_back("ray_cast", &*ray_main);
            study::write_plane_points_csv(points_csv, main_pts, main_ref, named);
        }

        if (!json_path.empty()) {
            study::run_report report;
            report.technique = "hemisphere_study";
            report.scene = scene.name;
            report.width = report.height = resolution;
            report.backend = no_raster ? "embree" : (no_ray_cast ? "gl" : "gl+embree");
            report.parameters = {{"resolution", resolution}, {"aperture_deg", aperture}, {"plane_turn_deg", turn},
                                 {"hashed_turn", hashed_turn}, {"points", points}, {"seed", rs.seed}, {"batch", batch},
                                 {"embree_config", bvh.owner().config()}, {"shadow_resolution", shadow_resolution}};
#ifdef BOUNCE_WITH_GL
            report.parameters["shadow_normal_offset"] = shadows.normal_offset_texels;
            report.parameters["shadow_slope_bias"] = shadows.slope_bias;
            if (context && !no_raster) report.gl_renderer = context->renderer();
#endif
            report.parameters["reference_spp_per_half"] = reference.spp;
            report.set_count("records", points);
            json j = report.to_json();
            j["timings_ms"] = json::object();
            if (raster_main) j["timings_ms"]["raster"] = raster_main->cpu.ms;
            if (ray_main) j["timings_ms"]["ray_cast"] = ray_main->ms;
            j["timings_ms"]["reference"] = reference_ms;
            j["error"] = report_error;
            j["records_per_s"] = json::object();
            const auto& r = raster_main;
            if (r)
                j["records_per_s"] = {{"raster", r->cpu.records_per_s()}, {"raster_gpu_sum", r->per_s(r->gpu_ms)},
                                      {"raster_falloff_running", r->per_s(r->running_ms)}};
            if (ray_main) j["records_per_s"]["ray_cast"] = ray_main->records_per_s();
            j["reference"] = {{"rays_per_point", 2 * reference.spp},
                              {"own_rel_rms", reference.own_rel_rms},
                              {"from_cache", reference.from_cache}};
            if (r) j["raster_cpu_gpu_max_relative_difference"] = r->cpu_gpu_difference;
            if (r) j["raster_running_cpu_gpu_max_relative_difference"] = r->running_cpu_gpu_difference;
            if (sweep) {
                j["sweep_points"] = sweep_points;
                j["sweep"] = sweep_rows;
            }
            io::write_text_file(json_path, j.dump(2) + "\n");
            fmt::print("wrote {}\n", json_path.string());
        }
        return 0;
    }, out_of_memory);
}
