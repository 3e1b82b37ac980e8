// ic_splatting: irradiance caching by splatting (Gautron 2008, Algorithm 5) through the
// library's cpu::irradiance_cache and gl::irradiance_splatter, its classical octree baseline,
// and the figures that compare them against the reference integrator.
//
//   build/bin/ic_splatting --scene cornell --width 512 --height 512 --a 0.15
//       --weight ward-smooth --gradients on --interp splat-cpu --json ic.json --out ic.png
//
// Stages (the names of timings_ms): gbuffer, splat_existing (step 2), scan (step 4 minus
// record computation), compute_records, interpolate (making the indirect image from the
// cache: the final splat of step 5, or the octree's lookups), normalize, total.
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/equal_error.hpp>
#include <bounce/study/frame_comparison.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/record_cache.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/study/run_report.hpp>
#ifdef BOUNCE_IC_WITH_GL
#include <bounce/gl/context.hpp>
#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/gl/irradiance_splatter.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/gl/raster_record_sampler.hpp>
#include <bounce/gl/splat_pass.hpp>
#endif

#include "options.hpp"

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
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

// The record sampler the options chose, behind one type (it models bounce::record_sampler).
using chosen_sampler = std::function<void(std::span<const glm::vec3>, std::span<const glm::vec3>,
                                          std::span<const double>, std::span<std::optional<irradiance_record>>)>;

// What one frame gives the report: what it saw, its indirect image, the GL backend's
// composed image, and the scan's counts.
struct frame_result {
    gbuffer<float> g;
    image<glm::vec3> indirect;
    std::optional<image<glm::vec3>> combined;
    std::size_t new_records = 0, measured = 0, wasted = 0;
};

#ifdef BOUNCE_IC_WITH_GL
// What the GL frames keep: the context, the scene on the GPU, the renderer's own passes
// (G-buffer, direct light) and the library's splatter; the raster record sampler.
struct gl_frames {
    gl::context context;
    gl::scene_mesh mesh;
    gl::gbuffer_pass gbuffer;
    gl::direct_light light;
    gl::irradiance_splatter splatter;
    std::optional<gl::hemisphere_raster> raster;
    gl_frames(const io::scene& s, int shadow_resolution) : mesh(s), light(s, mesh, shadow_resolution) {}
};
#endif

nlohmann::ordered_json error_json(const study::error_figures& e) {
    return {{"rel_rms", e.rel_rms}, {"max_abs", e.max_abs}, {"sum_sq", e.sum_sq}, {"pixels", e.pixels}};
}

embree::reference_settings reference_settings_for(std::uint32_t spp, std::uint64_t seed) {
    embree::reference_settings s;
    s.hemisphere_samples = spp;
    s.seed = seed;
    return s;
}

template <class W>
int run_with(const options& o) {
    if (o.falloff_kappa != 1.f && o.sampler != "raster")
        throw parameter_error("--falloff-kappa", "applies to --sampler raster only");
    if (o.walkthrough > 0 && (o.progressive > 0 || !o.a_sweep.empty()))
        throw parameter_error("--walkthrough", "renders its own frames: not with --progressive or --a-sweep");
    if ((o.plane_turn != 0.0 || o.hashed_turn) && o.sampler != "raster")
        throw parameter_error("--plane-turn/--hashed-turn", "apply to --sampler raster only");
    study::stage_timer setup;
    const io::scene scene = io::load_scene_arg(o.scene);
    std::optional<embree::accel> bvh_storage;
    setup.time("bvh", [&] { bvh_storage.emplace(scene); });
    const embree::accel& bvh = *bvh_storage;
    const embree::reference_integrator integrator(bvh, scene, reference_settings_for(64, 1));
    radius_limits limits;
    limits.min_pixels = o.min_pixels;
    limits.max_pixels = o.max_pixels;
    limits.gradient_limit = o.gradient_limit;
    if (o.radius == "hessian") {
        if (o.sampler != "embree")
            throw parameter_error("--radius", "'hessian' needs the Embree sampler (the raster's reduction has no Hessian)");
        if (!o.a_sweep.empty())
            throw parameter_error("--a-sweep", "the Hessian radius depends on a: sweep a over separate runs");
        limits.policy = radius_policy::hessian;
        limits.hessian_a = o.a;
    }
    const embree::record_sampler embree_sampler(integrator, embree::hemisphere_grid_for(o.record_samples), limits);
    chosen_sampler sampler = std::cref(embree_sampler);
    cpu::irradiance_cache_options cache_options = cache_options_for(o, o.a);
    const auto [lo, hi] = scene.bounds();
    cpu::irradiance_cache<W> cache(lo, hi, cache_options);

#ifdef BOUNCE_IC_WITH_GL
    std::optional<gl_frames> gl_state;
    if (o.interp == "splat-gl" || o.sampler == "raster")
        setup.time("gl_setup", [&] { gl_state.emplace(scene, o.shadow_resolution); });
    std::optional<gl::raster_record_sampler> raster_sampler;
    if (o.sampler == "raster") {
        // Records from 64 x 64 planes of 126 degrees with border stretching (Gautron 2008,
        // section 8.4), or fall-off stretching with a fixed kappa (docs/hemisphere-sampling.md).
        // One atlas per batch of the scan's guesses (16 planes unless --scan-batch says).
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
    const bool gl_frames_on = o.interp == "splat-gl";
#else
    if (o.sampler != "embree")
        throw parameter_error("--sampler", "'raster' needs the GL adapter, which this build does not have");
    if (o.interp == "splat-gl")
        throw parameter_error("--interp", "'splat-gl' needs the GL adapter, which this build does not have");
#endif
    // One frame for `cam` at accuracy `a` with the chosen backend; the G-buffer is part of
    // its timing.
    auto frame = [&](const camera& cam, float a, study::stage_timer& t) -> frame_result {
        cache_options.splat.a = a;
        cache.set_options(cache_options);
        frame_result fr;
        cpu::cache_frame_stats cs;
#ifdef BOUNCE_IC_WITH_GL
        if (gl_frames_on) {
            gl_frames& gs = *gl_state;
            gl::irradiance_splatter_options so;
            so.splat = cache_options.splat;
            so.weighting = parse_weight(o.weight);
            so.fill_holes = cache_options.fills_holes() ? cache_options.fill_holes : 0.f;
            so.time_stages = true;
            gs.splatter.set_options(so);
            t.time("gbuffer", [&] {
                gs.gbuffer.render(gs.mesh, cam, o.width, o.height);
                gl::finish();
            });
            const gl::gbuffer_textures tex = gl::textures_of(gs.gbuffer);
            t.time("direct", [&] {
                gs.light.render(tex);
                gl::finish();
            });
            // Older records shrunk by the cache's neighbour clamp: the GPU's copy restarts.
            if (cache.clamp_to_neighbours() > 0) gs.splatter.reset();
            double snap_ms = 0;
            const auto st = gs.splatter.render(tex, cam, cache.records(), [&](gbuffer_view<float> g, image_view<glm::vec4> splat) {
                if (o.sampler != "embree") {
                    cs = cache.scan(g, cam, sampler, splat);
                    return;
                }
                // The Embree sampler starts its rays at its own hits of the pixels.
                const auto t0 = clock_type::now();
                gbuffer<float> points = gs.splatter.scanned_gbuffer();
                embree::snap_to_ray_hits(bvh, scene, cam, points.view());
                snap_ms = ms_since(t0);
                const gbuffer_view<float> where = points.view();
                cs = cache.scan(g, cam, sampler, splat, &where);
            });
            t.add_sample("splat_existing", st.splat_existing_ms);
            t.add_sample("readback", st.readback_ms);
            t.add_sample("scan", cs.scan_ms);
            t.add_sample("compute_records", cs.records_ms + snap_ms);
            t.add_sample("interpolate", st.interpolate_ms);
            t.time("normalize", [&] {
                fr.indirect = image<glm::vec3>(o.width, o.height);
                fr.combined = image<glm::vec3>(o.width, o.height);
                gs.splatter.read_indirect(fr.indirect.view());
                gl::read_texture(gs.splatter.compose(gs.light.radiance()), fr.combined->view());
            });
            fr.g = gs.splatter.scanned_gbuffer();
        }
#endif
        if (!fr.g.width()) {
            t.time("gbuffer", [&] { fr.g = embree::ray_cast_gbuffer(bvh, scene, cam, o.width, o.height); });
            fr.indirect = image<glm::vec3>(o.width, o.height);
            cs = cache.render(fr.g.view(), cam, sampler, fr.indirect.view());
            t.add_sample("splat_existing", cs.splat_existing_ms);
            t.add_sample("scan", cs.scan_ms);
            t.add_sample("compute_records", cs.records_ms);
            t.add_sample("interpolate", cs.interpolate_ms);
            t.add_sample("normalize", cs.normalize_ms);
        }
        fr.new_records = cs.new_records;
        fr.measured = cs.measured;
        fr.wasted = cs.wasted;
        return fr;
    };

    const nlohmann::json cache_params = cache_parameters(o, scene.name);
    if (!o.cache_in.empty()) cache.assign(study::load_records(o.cache_in, cache_params));
    const std::size_t loaded = cache.records().size();

    study::run_report report;
    report.technique = "ic_splatting";
    report.scene = scene.name;
    report.width = o.width;
    report.height = o.height;
    report.backend = o.interp.starts_with("octree") ? "cpu-" + o.interp : o.interp == "splat-gl" ? "gl" : "cpu";
#ifdef BOUNCE_IC_WITH_GL
    if (gl_state) report.gl_renderer = gl_state->context.renderer();
#endif
    report.parameters = {{"a", o.a}, {"weight", o.weight}, {"gradients", o.gradients}, {"sampler", o.sampler},
                         {"falloff_kappa", o.falloff_kappa}, {"plane_turn", o.plane_turn}, {"hashed_turn", o.hashed_turn},
                         {"shadow_resolution", o.shadow_resolution},
                         {"interp", o.interp}, {"record_samples", o.record_samples}, {"reference_spp", o.ref_spp},
                         {"min_pixels", o.min_pixels}, {"max_pixels", o.max_pixels}, {"radius", o.radius},
                         {"neighbour_clamp", o.neighbour_clamp}, {"gradient_limit", o.gradient_limit},
                         {"max_extrapolation", o.max_extrapolation},
                         {"front_tolerance", o.front_tolerance},
                         {"min_weight", o.min_weight > 0.f ? o.min_weight : o.a}, {"progressive", o.progressive},
                         {"fill_holes", o.progressive > 0 ? o.fill_holes : 0.f},
                         {"scan", o.scan}, {"scan_batch", cache_options.batch.max_records},
                         {"scan_order", cache_options.order == cpu::scan_order::linear ? "linear" : "coarse-to-fine"},
                         {"embree_config", bvh.owner().config()}};

    auto reference_for = [&](const camera& cam) {
        bool hit = false;
        auto ref = study::cached_reference(bvh, scene, cam, o.width, o.height, reference_settings_for(o.ref_spp, 1),
                                            study::default_cache_dir(), &hit);
        fmt::print(stderr, "reference {}x{} at {} spp: {}\n", o.width, o.height, o.ref_spp, hit ? "from cache" : "computed");
        return ref;
    };

    // Error is measured where the frame's G-buffer sees what the reference saw.
    const float scene_size = glm::length(scene.bounds().second - scene.bounds().first);
    auto mask_for = [&](gbuffer<float> g, const camera& cam) {
        if (o.interp != "splat-gl") return study::coverage_mask(g.view());
        auto ray = embree::ray_cast_gbuffer(bvh, scene, cam, o.width, o.height);
        return study::comparable_mask(g.view(), ray.view(), scene_size);
    };

    // --indirect-exr and --indirect-out: the indirect image, and it beside the reference's
    // with one exposure (the walkthrough's last frame, or the single frame).
    auto write_indirect = [&](const image<glm::vec3>& indirect, const embree::reference_images& ref,
                              const image<float>& mask) {
        if (!o.indirect_exr.empty()) io::write_exr(o.indirect_exr, indirect.view());
        if (o.indirect_out.empty()) return;
        image<glm::vec3> pair(2 * o.width, o.height);
        for (std::size_t y = 0; y < o.height; ++y)
            for (std::size_t x = 0; x < o.width; ++x) {
                pair(x, y) = indirect(x, y);
                pair(o.width + x, y) = ref.indirect(x, y);
            }
        io::write_png(o.indirect_out, pair.view(), io::auto_exposure(ref.indirect.view(), mask.view()));
    };

    nlohmann::ordered_json extra = nlohmann::ordered_json::object();
    study::stage_timer timer;

    if (o.walkthrough > 0) {
        // The walkthrough: one cache kept and grown along the camera path, every frame
        // compared with its own reference, and brute-force Monte Carlo timed at each
        // frame's error (on every walkthrough_mc_stride-th frame; their mean time stands
        // for every frame).
        nlohmann::ordered_json frames = nlohmann::ordered_json::array();
        const study::camera_path path(bvh, scene.camera, o.walkthrough);
        double cache_total_ms = 0, error_sum = 0, mc_ms_sum = 0, mc_error_sum = 0;
        std::size_t mc_frames = 0, mc_unreached = 0;
        for (std::size_t f = 0; f < o.walkthrough; ++f) {
            const camera cam = path.at(f);
            study::stage_timer ft;
            const auto t0 = clock_type::now();
            auto fr = frame(cam, o.a, ft);
            const double frame_ms = ms_since(t0);
            cache_total_ms += frame_ms;
            const auto ref = reference_for(cam);
            const image<float> mask = mask_for(fr.g, cam);
            const auto err = study::compare_luminance(fr.indirect.view(), ref.indirect.view(), mask.view());
            error_sum += err.rel_rms;
            nlohmann::ordered_json entry = {{"frame", f},         {"records", cache.records().size()},
                                            {"new_records", fr.new_records}, {"ms", frame_ms},
                                            {"rel_rms", err.rel_rms}};
            fmt::print("frame {:2}: {:6} records (+{:5}), {:8.1f} ms, indirect rel_rms {:.4f}", f, cache.records().size(),
                       fr.new_records, frame_ms, err.rel_rms);
            if (o.walkthrough_fresh) {
                // The same camera from an empty cache: what the grown cache must not lose to.
                const std::vector<irradiance_record> kept = cache.records();
                cache.assign({});
#ifdef BOUNCE_IC_WITH_GL
                if (gl_state) gl_state->splatter.reset();
#endif
                study::stage_timer fresh_t;
                const auto t1 = clock_type::now();
                const auto fresh = frame(cam, o.a, fresh_t);
                const double fresh_ms = ms_since(t1);
                const auto fresh_err =
                    study::compare_luminance(fresh.indirect.view(), ref.indirect.view(), mask_for(fresh.g, cam).view());
                entry["fresh"] = {{"records", cache.records().size()}, {"ms", fresh_ms}, {"rel_rms", fresh_err.rel_rms}};
                fmt::print("; fresh: {:6} records, {:8.1f} ms, rel_rms {:.4f}", cache.records().size(), fresh_ms,
                           fresh_err.rel_rms);
                cache.assign(kept);
#ifdef BOUNCE_IC_WITH_GL
                if (gl_state) gl_state->splatter.reset();
#endif
            }
            if (o.walkthrough_mc_stride > 0 && f % o.walkthrough_mc_stride == 0) {
                const auto mc = study::monte_carlo_at_equal_error(bvh, scene, fr.g.view(), ref.indirect.view(),
                                                                  mask.view(), err.rel_rms, o.ref_spp / 2);
                entry["mc_equal_error"] = mc.equal_error_json(frame_ms);
                mc_ms_sum += mc.ms;
                mc_error_sum += err.rel_rms;
                ++mc_frames;
                if (!mc.reached) ++mc_unreached;
                fmt::print("; monte carlo {}{:.0f} spp, {:.1f} ms", mc.reached ? "~" : ">", mc.spp, mc.ms);
            }
            fmt::print("\n");
            if (f + 1 == o.walkthrough) write_indirect(fr.indirect, ref, mask);
            frames.push_back(entry);
            for (const auto& s : ft.stages()) timer.add_sample(s, ft.median_ms(s));
            timer.add_sample("total", frame_ms);
        }
        nlohmann::ordered_json walk = {{"frames_count", o.walkthrough},
                                       {"path", "study::camera_path: forward a tenth of the way to the target "
                                                "(at most half way to the first surface), panning -10 to +10 degrees"},
                                       {"total_ms", cache_total_ms},
                                       {"mean_rel_rms", error_sum / double(o.walkthrough)},
                                       {"frames", frames}};
        if (mc_frames > 0) {
            const double mc_total = mc_ms_sum / double(mc_frames) * double(o.walkthrough);
            walk["mc_equal_error"] = {{"frames_measured", mc_frames},
                                      {"stride", o.walkthrough_mc_stride},
                                      {"frames_not_reached", mc_unreached},
                                      // Monte Carlo stopped short of a frame's error: its time, and the
                                      // speedup, are lower bounds.
                                      {"lower_bound", mc_unreached > 0},
                                      {"mean_rel_rms_measured", mc_error_sum / double(mc_frames)},
                                      {"total_ms", mc_total},
                                      {"speedup", mc_total / cache_total_ms}};
            fmt::print("walkthrough: cache {:.1f} ms over {} frames, mean rel_rms {:.4f}; Monte Carlo at equal per-frame "
                       "error {}{:.1f} ms: {:.1f}x\n",
                       cache_total_ms, o.walkthrough, error_sum / double(o.walkthrough), mc_unreached ? ">" : "~",
                       mc_total, mc_total / cache_total_ms);
        }
        extra["walkthrough"] = walk;
        report.set_timings(timer);
        report.set_count("records", cache.records().size());
    } else if (o.progressive > 0) {
        // Progressive mode: records are view-independent, so each frame of the camera path
        // reuses the cache and adds at most N records.
        nlohmann::ordered_json frames = nlohmann::ordered_json::array();
        const study::camera_path path(bvh, scene.camera, o.frames);
        for (std::size_t f = 0; f < o.frames; ++f) {
            const camera cam = path.at(f);
            study::stage_timer ft;
            const auto t0 = clock_type::now();
            const auto fr = frame(cam, o.a, ft);
            const double frame_ms = ms_since(t0);
            const auto ref = reference_for(cam);
            const auto err = study::compare_luminance(fr.indirect.view(), ref.indirect.view(), mask_for(fr.g, cam).view());
            fmt::print("frame {:2}: {:5} records (+{:3}), {:8.1f} ms ({:5.2f} fps), indirect rel_rms {:.4f}\n", f,
                       cache.records().size(), fr.new_records, frame_ms, 1000.0 / frame_ms, err.rel_rms);
            frames.push_back({{"frame", f}, {"records", cache.records().size()}, {"new_records", fr.new_records},
                              {"ms", frame_ms}, {"fps", 1000.0 / frame_ms}, {"rel_rms", err.rel_rms}});
            for (const auto& s : ft.stages()) timer.add_sample(s, ft.median_ms(s));
            timer.add_sample("total", frame_ms);
        }
        extra["frames"] = frames;
        report.set_timings(timer);
        report.set_count("records", cache.records().size());
    } else {
        const camera& cam = scene.camera;
        const auto ref = reference_for(cam);
        frame_result fr;
        const std::vector<float> as = o.a_sweep.empty() ? std::vector<float>{o.a} : o.a_sweep;
        nlohmann::ordered_json sweep = nlohmann::ordered_json::array();
        image<float> mask;
        for (float a : as) {
            study::stage_timer at;
            // Each repeat starts from the same cache: what was loaded, or what earlier
            // sweep entries built (records are valid for every a).
            const std::vector<irradiance_record> start = cache.records();
            for (int r = 0; r < o.repeat; ++r) {
                cache.assign(start);
#ifdef BOUNCE_IC_WITH_GL
                if (gl_state) gl_state->splatter.reset();  // the GPU copy restarts from the same cache
#endif
                const auto t0 = clock_type::now();
                fr = frame(cam, a, at);
                at.add_sample("total", ms_since(t0));
            }
            mask = mask_for(fr.g, cam);
            const auto err = study::compare_luminance(fr.indirect.view(), ref.indirect.view(), mask.view());
            fmt::print("a = {:.3f}: {:6} records (+{:5}), total {:9.1f} ms (interpolate {:8.2f}, records {:9.1f}), "
                       "indirect rel_rms {:.4f}\n",
                       a, cache.records().size(), fr.new_records, at.median_ms("total"), at.median_ms("interpolate"),
                       at.median_ms("compute_records"), err.rel_rms);
            nlohmann::ordered_json entry = {{"a", a}, {"records", cache.records().size()}, {"new_records", fr.new_records},
                                            {"timings_ms", nlohmann::ordered_json::object()}, {"error", error_json(err)}};
            for (const auto& s : at.stages()) entry["timings_ms"][s] = at.median_ms(s);
            sweep.push_back(entry);
            timer = at;
            report.error = err;
        }
        if (!o.a_sweep.empty()) extra["a_sweep"] = sweep;
        report.set_timings(timer);
        report.set_count("records", cache.records().size());
        if (fr.measured > 0) {
            // The batched scan's guesses: measured, and dropped because covered by then.
            report.set_count("records_measured", fr.measured);
            report.set_count("records_wasted", fr.wasted);
        }

        if (o.mc_compare) {
            // Brute-force Monte Carlo at doubling sample counts until it reaches this run's
            // error (up to half the reference's samples: beyond, it would meet its own noise).
            const double ms = timer.median_ms("total");
            const auto mc = study::monte_carlo_at_equal_error(
                bvh, scene, fr.g.view(), ref.indirect.view(), mask.view(), report.error->rel_rms, o.ref_spp / 2,
                [](const study::monte_carlo_step& s) {
                    fmt::print("monte carlo {:4} spp: {:9.1f} ms, indirect rel_rms {:.4f}\n", s.spp, s.ms, s.rel_rms);
                });
            extra["mc_equal_error"] = mc.equal_error_json(ms);
            extra["mc_sweep"] = mc.sweep_json();
            fmt::print("at equal error Monte Carlo needs {}{:.0f} spp, {:.1f} ms: {}{:.1f}x the cache's {:.1f} ms\n",
                       mc.reached ? "~" : "more than ", mc.spp, mc.ms, mc.reached ? "" : "at least ", mc.ms / ms, ms);
        }

        if (o.ray_rates) {
            if (o.sampler != "embree") throw parameter_error("--ray-rates", "applies to --sampler embree only");
            // The same records' rays twice in this run: shaded into records, and traced alone.
            const std::size_t count = std::min<std::size_t>(2048, cache.records().size());
            std::vector<glm::vec3> p(count), n(count);
            std::vector<double> footprint(count, 0.0);
            std::vector<std::optional<irradiance_record>> out(count);
            for (std::size_t k = 0; k < count; ++k) {
                p[k] = cache.records()[k].position;
                n[k] = cache.records()[k].normal;
            }
            const double rays = double(count) * embree_sampler.grid().count();
            auto t0 = clock_type::now();
            embree_sampler(std::span<const glm::vec3>(p), std::span<const glm::vec3>(n),
                           std::span<const double>(footprint), std::span(out));
            const double record_s = ms_since(t0) / 1000;
            t0 = clock_type::now();
            embree_sampler.trace_only(p, n);
            const double trace_s = ms_since(t0) / 1000;
            extra["ray_rates"] = {{"records", count},
                                  {"rays", rays},
                                  {"record_rays_per_s", rays / record_s},
                                  {"embree_rays_per_s", rays / trace_s},
                                  {"record_fraction_of_embree", trace_s / record_s}};
            fmt::print("ray rates over {} records: records {:.3g} rays/s, Embree alone {:.3g} rays/s ({:.2f} of it)\n",
                       count, rays / record_s, rays / trace_s, trace_s / record_s);
        }

        if (!o.out.empty() || !o.exr.empty()) {
            image<glm::vec3> combined(o.width, o.height);
            if (fr.combined) combined = *fr.combined;
            else cpu::compose(ref.direct.view(), fr.indirect.view(), combined.view());
            if (!o.exr.empty()) io::write_exr(o.exr, combined.view());
            if (!o.out.empty()) io::write_png(o.out, combined.view(), io::auto_exposure(combined.view(), mask.view()));
        }
        write_indirect(fr.indirect, ref, mask);
    }

    if (!o.cache_out.empty()) study::save_records(o.cache_out, cache.records(), cache_params);
    if (loaded) report.set_count("records_loaded", loaded);
    fmt::print("{} records; total {:.1f} ms", cache.records().size(), timer.median_ms("total"));
    if (report.error) fmt::print("; indirect rel_rms {:.4f}", report.error->rel_rms);
    fmt::print("\n");
    if (!o.json.empty()) {
        auto j = report.to_json();
        j["timings_ms"]["bvh"] = setup.median_ms("bvh");
        for (auto it = extra.begin(); it != extra.end(); ++it) j[it.key()] = it.value();
        std::ofstream(o.json) << j.dump(2) << '\n';
    }
    return 0;
}


int run(const options& o) {
    return with_weighting(parse_weight(o.weight), [&](auto w) { return run_with<decltype(w)>(o); });
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce: irradiance caching by splatting (Gautron, SIGGRAPH 2008 course, ch. 8)"};
    options o;
    std::string gradients = "on";
    add_options(app, o, gradients);
    CLI11_PARSE(app, argc, argv);
    o.gradients = gradients == "on";
    // A radius floor of pixel footprints ties a record to the camera that made it: another
    // camera's pixels take its inflated zone as coverage (docs/irradiance-splatting.md,
    // "Many frames"), so a walkthrough has none unless asked.
    if (o.walkthrough > 0 && app.count("--min-pixels") == 0) o.min_pixels = 0.f;
    try {
        return run(o);
    } catch (const bounce::error& e) {
        fmt::print(stderr, "ic_splatting: {}\n", e.what());
        return 2;
    }
}
