// ic_splatting: irradiance caching by splatting (Gautron 2008, Algorithm 5) through the
// library's cpu::irradiance_cache and gl::irradiance_splatter, its classical octree baseline,
// and the figures that compare them against the reference integrator.
//
//   build/bin/ic_splatting --scene cornell --width 512 --height 512 --a 0.15
//       --weight ward-smooth --gradients on --interp splat-cpu --json ic.json --out ic.png
//
// The program parses, calls and reports: a frame is cpu::render_frame or
// gl::irradiance_splatter::frame, a camera path cpu::walkthrough, and the measurements
// bounce::study's cache studies (study/cache_study.hpp). Stages (the names of timings_ms):
// gbuffer, splat_existing (step 2), scan (step 4 minus record computation), compute_records,
// interpolate (the final splat of step 5, or the octree's lookups), normalize, total.
#include <bounce/cpu/cache_walkthrough.hpp>
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/irradiance_probe.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/cache_study.hpp>
#include <bounce/study/camera_path.hpp>
#include <bounce/study/record_cache.hpp>
#include <bounce/study/run_report.hpp>
#ifdef BOUNCE_WITH_GL
#include <bounce/gl/context.hpp>
#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/gl/irradiance_splatter.hpp>
#include <bounce/gl/raster_record_sampler.hpp>
#endif

#include "../common/run_program.hpp"
#include "options.hpp"

#include <fmt/core.h>

#include <fstream>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

using namespace bounce;
using namespace bounce::examples;

namespace {

#ifdef BOUNCE_WITH_GL
constexpr bool with_gl = true;
// What GL frames keep: the context, the scene on the GPU, the renderer's passes, the splatter
// and the raster record sampler's hemisphere planes.
struct gl_frames {
    gl::context context;
    gl::scene_mesh mesh;
    gl::gbuffer_pass gbuffer;
    gl::direct_light light;
    gl::irradiance_splatter splatter;
    std::optional<gl::hemisphere_raster> raster;
    gl_frames(const io::scene& s, const options& o)
        : mesh(s), light(s, mesh, o.shadow_resolution), splatter({{}, o.weight, 0.f, true}) {}
};
#else
constexpr bool with_gl = false;
#endif

// Every output checked before the work: writable files, known image formats, a readable
// --cache-in and a writable reference cache.
void check_paths(const options& o) {
    if (!o.json.empty()) io::check_output_file("--json", o.json);
    if (!o.cache_out.empty()) io::check_output_file("--cache-out", o.cache_out);
    const std::pair<const char*, const std::filesystem::path*> images[] = {
        {"--out", &o.out}, {"--exr", &o.exr}, {"--indirect-out", &o.indirect_out}, {"--indirect-exr", &o.indirect_exr}};
    for (const auto& [name, path] : images)
        if (!path->empty()) io::check_image_output(name, *path);
    std::error_code ec;
    if (!o.cache_in.empty() && (!std::filesystem::is_regular_file(o.cache_in, ec) || !std::ifstream(o.cache_in)))
        throw parameter_error("--cache-in", o.cache_in.string() + " is missing or not a readable file");
    study::check_cache_dir();
}

// The adaptive-rays settings (enabled = false without --adaptive-rays). The floor is in units
// of the scene's mean irradiance over 256 points of the camera's view (the setup stage
// "irradiance_scale").
adaptive_rays adaptive_settings(const options& o, const embree::accel& bvh, const io::scene& scene,
                                const embree::reference_integrator& integrator, const radius_limits& limits,
                                study::stage_timer& setup) {
    adaptive_rays a;
    if (o.importance_rays) {  // a fixed budget: no target, no floor
        a = {true, o.min_record_samples, o.record_samples, 1.0, 0.0,
             o.importance_contrast ? ray_allocation::contrast : ray_allocation::radiance, o.importance_cell_gradients,
             double(o.importance_defensive)};
        a.validate();
        return a;
    }
    if (!o.adaptive_rays) return a;
    a = {true, o.min_record_samples, o.record_samples, double(o.record_error) * o.a, 0.0};
    if (o.record_error_floor > 0.f)
        setup.time("irradiance_scale", [&] {
            const embree::record_sampler probe(integrator, a, limits);
            a.irradiance_floor = double(o.record_error_floor) * study::view_mean_irradiance(probe, bvh, scene, scene.camera);
        });
    a.validate();
    return a;
}

template <class W>
int run_with(const options& o) {
    check_combinations(o, with_gl);
    check_paths(o);
    study::stage_timer setup;
    const io::scene scene = io::load_scene_arg(o.scene);
    std::optional<embree::accel> bvh_storage;
    setup.time("bvh", [&] { bvh_storage.emplace(scene); });
    const embree::accel& bvh = *bvh_storage;
    embree::reference_settings integrator_settings;  // the record sampler's rays: 64 samples, seed 1, as ever
    integrator_settings.hemisphere_samples = 64;
    integrator_settings.seed = 1;
    const embree::reference_integrator integrator(bvh, scene, integrator_settings);
    const auto [lo, hi] = scene.bounds();
    const radius_limits limits = radius_limits_for(o, lo, hi);
    const adaptive_rays adaptive = adaptive_settings(o, bvh, scene, integrator, limits, setup);
    const embree::record_sampler embree_sampler =
        adaptive.enabled ? embree::record_sampler(integrator, adaptive, limits)
                        : embree::record_sampler(integrator, embree::hemisphere_grid_for(o.record_samples), limits);
    // The record sampler the options chose, behind one type (a bounce::record_sampler).
    std::function<void(std::span<const glm::vec3>, std::span<const glm::vec3>, std::span<const double>,
                       std::span<std::optional<irradiance_record>>)>
        sampler = std::cref(embree_sampler);
    cpu::irradiance_cache_options cache_options = cache_options_for(o, o.a);
    cpu::irradiance_cache<W> cache(lo, hi, cache_options);
    // --verify's probe: a few rays per pixel from the records' integrator.
    const embree::irradiance_probe probe(integrator, o.verify_rays);
    if (o.verify_rounds > 0) cache.set_probe(std::cref(probe));
    std::function<cache_frame(const camera&)> frame = [&](const camera& cam) {
        const auto ray_cast = [&](const camera& c) { return embree::ray_cast_gbuffer(bvh, scene, c, o.width, o.height); };
        return cpu::render_frame(cache, cam, ray_cast, sampler);
    };
#ifdef BOUNCE_WITH_GL
    std::optional<gl_frames> gl_state;
    std::optional<gl::raster_record_sampler> raster_sampler;
    const bool gl_frame = o.interp == interpolation::splat_gl, raster = o.sampler == record_source::raster;
    if (gl_frame || raster) setup.time("gl_setup", [&] { gl_state.emplace(scene, o); });
    if (raster) {
        // Records from 64 x 64 planes of 126 degrees with border stretching (Gautron 2008,
        // section 8.4), or fall-off stretching with a fixed kappa (docs/hemisphere-sampling.md),
        // one atlas per batch of the scan's guesses (16 planes unless --scan-batch says).
        const std::size_t planes = o.scan_batch > 0 ? o.scan_batch : 16;
        gl_state->raster.emplace(scene, gl_state->mesh, gl_state->light,
                                 gl::hemisphere_raster_options{{64, 126.0, o.plane_turn, o.hashed_turn}, planes});
        raster_sampler.emplace(*gl_state->raster, limits,
                               o.falloff_kappa < 1.f ? plane_weighting::falloff : plane_weighting::stretch,
                               double(o.falloff_kappa));
        sampler = std::ref(*raster_sampler);
        cache_options.batch.max_records = planes;
        cache.set_options(cache_options);
    }
    if (gl_frame)
        frame = [&](const camera& cam) {
            gl_frames& gs = *gl_state;
            const gl::splatting_passes passes{gs.mesh, gs.gbuffer, gs.light};
            if (raster) return gs.splatter.frame(passes, cache, cam, o.width, o.height, sampler);
            // The Embree sampler starts its rays at its own hits of the pixels.
            return gs.splatter.frame(passes, cache, cam, o.width, o.height, sampler,
                                     [&](gbuffer_view<float> p) { embree::snap_to_ray_hits(bvh, scene, cam, p); });
        };
#endif

    const nlohmann::json cache_params = cache_parameters(o, scene.name, limits);
    if (!o.cache_in.empty()) cache.assign(study::load_records(o.cache_in, cache_params));
    const std::size_t loaded = cache.records().size();

    study::run_report report;
    report.technique = "ic_splatting";
    report.scene = scene.name;
    report.width = o.width;
    report.height = o.height;
    report.backend = report_backend(o.interp);
#ifdef BOUNCE_WITH_GL
    if (gl_state) report.gl_renderer = gl_state->context.renderer();
#endif
    report.parameters = report_parameters(o, cache_options, bvh.owner().config(), monte_carlo_max_spp(o));

    study::cache_study_settings settings;
    settings.width = o.width;
    settings.height = o.height;
    settings.reference_spp = o.ref_spp;
    settings.measure = o.raw_equal_error ? study::error_measure::raw : study::error_measure::debiased;
    settings.mc_max_spp = monte_carlo_max_spp(o);
    settings.rasterized_gbuffer = o.interp == interpolation::splat_gl;
    const study::cache_frame_study measure(bvh, scene, settings);

    // --indirect-exr and --indirect-out: the indirect image, and it beside the reference's.
    auto write_indirect = [&](const study::measured_frame& m) {
        if (!o.indirect_exr.empty()) io::write_exr(o.indirect_exr, m.frame.indirect.view());
        if (!o.indirect_out.empty())
            study::write_beside_reference(o.indirect_out, m.frame.indirect.view(), m.reference.whole.indirect.view(),
                                          m.mask.view());
    };
    nlohmann::ordered_json extra = nlohmann::ordered_json::object();
    study::stage_timer timer;
    double reference_noise = 0;  // the reference's own rel_rms (the frame's, the last frame's, the walkthrough's mean)
    if (o.walkthrough > 0) {
        // One cache grown along the camera path, each frame against its own reference, and
        // Monte Carlo at each (every --walkthrough-mc-stride-th) frame's error.
        study::walkthrough_report walk(measure, o.walkthrough, o.walkthrough_mc_stride);
        cpu::walkthrough(cache, study::camera_path(bvh, scene.camera, o.walkthrough), frame, {o.walkthrough_fresh},
                         [&](cpu::walkthrough_step&& s) { walk.add(s, timer); });
        extra["walkthrough"] = walk.json();
        reference_noise = walk.mean_reference_noise();
        write_indirect(*walk.last());
    } else if (o.progressive > 0) {
        // Records are view-independent: each frame of the path reuses the cache and adds at
        // most --progressive records.
        study::progressive_report path(measure);
        cpu::walkthrough(cache, study::camera_path(bvh, scene.camera, o.frames), frame, {},
                         [&](cpu::walkthrough_step&& s) { path.add(s, timer); });
        extra["frames"] = path.frames();
        reference_noise = path.reference_noise();
    } else {
        // One frame (or one per a of --a-sweep, from one growing cache), --repeat times each.
        const std::vector<float> as = o.a_sweep.empty() ? std::vector<float>{o.a} : o.a_sweep;
        study::a_sweep_result sweep = study::a_sweep(cache, std::span(as), o.repeat, scene.camera, frame, measure);
        const study::measured_frame& last = sweep.last;
        timer = sweep.timer;
        report.error = last.error.raw;
        reference_noise = last.error.debiased.reference_noise_rel_rms;
        if (!o.a_sweep.empty()) extra["a_sweep"] = sweep.entries;
        extra["error_debiased"] = nlohmann::ordered_json::object();
        study::add_debiased(extra["error_debiased"], last.error.debiased);
        study::add_frame_counts(report, extra, cache.records().size(), last.frame, cache.last_stats(), o.filter_k > 0.f,
                                o.verify_rounds > 0);
        if (o.mc_compare) extra.update(study::monte_carlo_report(measure, last, timer.median_ms("total")));
        if (o.ray_rates) extra["ray_rates"] = study::ray_rates(embree_sampler, cache.records());
        if (!o.out.empty() || !o.exr.empty()) {
            image<glm::vec3> combined(o.width, o.height);
            if (last.frame.combined) combined = *last.frame.combined;
            else cpu::compose(last.reference.whole.direct.view(), last.frame.indirect.view(), combined.view());
            if (!o.exr.empty()) io::write_exr(o.exr, combined.view());
            if (!o.out.empty()) io::write_png(o.out, combined.view(), io::auto_exposure(combined.view(), last.mask.view()));
        }
        write_indirect(last);
    }
    report.set_timings(timer);
    report.set_count("records", cache.records().size());

    if (!o.cache_out.empty()) study::save_records(o.cache_out, cache.records(), cache_params);
    if (o.sampler == record_source::embree) {
        // Hemisphere rays per record measured in this run (adaptive or fixed; --ray-rates' re-measures included).
        const auto t = embree_sampler.rays_cast();
        extra["rays_per_record"] = {{"mean", t.mean()}, {"fewest", t.fewest}, {"most", t.most}, {"records", t.records},
                                    {"irradiance_floor", adaptive.irradiance_floor}};
        fmt::print("rays per record: mean {:.0f} (fewest {}, most {}) over {} records measured\n", t.mean(), t.fewest,
                   t.most, t.records);
    }
    if (loaded) report.set_count("records_loaded", loaded);
    fmt::print("{} records; total {:.1f} ms", cache.records().size(), timer.median_ms("total"));
    if (report.error) fmt::print("; indirect rel_rms {:.4f}", report.error->rel_rms);
    fmt::print("\n");
    if (o.json.empty()) return 0;
    auto j = report.to_json();
    j["timings_ms"]["bvh"] = setup.median_ms("bvh");
    // The debiased figures join `error` (the single frame's), and `reference` says what the
    // errors were measured against.
    if (extra.contains("error_debiased") && j.contains("error")) j["error"].update(extra["error_debiased"]);
    extra.erase("error_debiased");
    j["reference"] = {{"spp", o.ref_spp},
                      {"halves", 2},
                      {"half_spp", o.ref_spp / 2},
                      {"noise_rel_rms", study::finite_or_null(reference_noise)},
                      {"noise_of", o.walkthrough > 0   ? "mean over the walkthrough's frames"
                                   : o.progressive > 0 ? "the last frame"
                                                       : "the frame"}};
    j.update(extra);
    io::write_text_file(o.json, j.dump(2) + "\n");
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce: irradiance caching by splatting (Gautron, SIGGRAPH 2008 course, ch. 8)"};
    options o;
    std::string gradients = "on";
    add_options(app, o, gradients);
    CLI11_PARSE(app, argc, argv);
    finish_options(app, o, gradients);
    return run_program("ic_splatting",
                       [&] { return with_weighting(o.weight, [&](auto w) { return run_with<decltype(w)>(o); }); });
}
