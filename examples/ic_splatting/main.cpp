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
#include <system_error>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <unistd.h>

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

// A frame's indirect error against a reference in halves: the raw figures against their
// mean, and the error with the reference's own noise taken out.
struct frame_error {
    study::error_figures raw;
    study::noisy_reference_error debiased;
    // The error the equal-error searches compare.
    double target(bool raw_measure) const { return raw_measure ? raw.rel_rms : debiased.rel_rms_debiased; }
};

frame_error measure_error(const image<glm::vec3>& indirect, const study::reference_halves& ref, const image<float>& mask) {
    return {study::compare_luminance(indirect.view(), ref.whole.indirect.view(), mask.view()),
            study::compare_luminance_debiased(indirect.view(), ref.indirect_a.view(), ref.indirect_b.view(), mask.view())};
}

// JSON has no infinity: null says "no finite value".
nlohmann::ordered_json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nullptr; }

// The debiased figures beside the raw rel_rms (frames[], fresh, the report's error).
void add_debiased(nlohmann::ordered_json& j, const study::noisy_reference_error& d) {
    j["rel_rms_debiased"] = finite_or_null(d.rel_rms_debiased);
    j["rel_rms_debiased_se"] = finite_or_null(d.rel_rms_debiased_se);
    j["rel_sq_debiased"] = finite_or_null(d.rel_sq_debiased);
    j["rel_sq_debiased_se"] = finite_or_null(d.rel_sq_debiased_se);
    j["debiased_resolved"] = d.resolved();
    j["reference_noise_rel_rms"] = finite_or_null(d.reference_noise_rel_rms);
}

nlohmann::ordered_json error_json(const frame_error& e) {
    nlohmann::ordered_json j = {{"rel_rms", finite_or_null(e.raw.rel_rms)},
                                {"max_abs", finite_or_null(e.raw.max_abs)},
                                {"sum_sq", finite_or_null(e.raw.sum_sq)},
                                {"pixels", e.raw.pixels}};
    add_debiased(j, e.debiased);
    return j;
}

// "0.0312 (debiased 0.0290 +- 0.0011)", or "(debiased < 0.0050, unresolved)" when the
// debiased error is within two standard errors of 0.
std::string error_text(const frame_error& e) {
    const auto& d = e.debiased;
    if (d.resolved()) return fmt::format("{:.4f} (debiased {:.4f} +- {:.4f})", e.raw.rel_rms, d.rel_rms_debiased, d.rel_rms_debiased_se);
    return fmt::format("{:.4f} (debiased < {:.4f}, unresolved)", e.raw.rel_rms,
                       std::sqrt(std::max(0.0, d.rel_sq_debiased) + 2.0 * d.rel_sq_debiased_se));
}

// Before any minutes of work: every output file must be writable where it is to go (its
// folder exists or can be made, and the file, when present, may be overwritten), and the
// records to start from must be readable. Throws parameter_error naming the option.
void check_paths(const options& o) {
    const std::pair<const char*, const std::filesystem::path*> outputs[] = {
        {"--json", &o.json},         {"--out", &o.out},
        {"--exr", &o.exr},           {"--indirect-out", &o.indirect_out},
        {"--indirect-exr", &o.indirect_exr}, {"--cache-out", &o.cache_out}};
    for (const auto& [name, path] : outputs) {
        if (path->empty()) continue;
        std::error_code ec;
        if (std::filesystem::is_directory(*path, ec)) throw parameter_error(name, path->string() + " is a folder");
        const std::filesystem::path dir = path->has_parent_path() ? path->parent_path() : std::filesystem::path(".");
        std::filesystem::create_directories(dir, ec);
        if (ec || !std::filesystem::is_directory(dir, ec))
            throw parameter_error(name, "cannot make the folder " + dir.string());
        if (::access(dir.c_str(), W_OK) != 0) throw parameter_error(name, "the folder " + dir.string() + " is not writable");
        if (std::filesystem::exists(*path, ec) && ::access(path->c_str(), W_OK) != 0)
            throw parameter_error(name, path->string() + " exists and is not writable");
    }
    if (!o.cache_in.empty() && ::access(o.cache_in.c_str(), R_OK) != 0)
        throw parameter_error("--cache-in", o.cache_in.string() + " is missing or not readable");
}

embree::reference_settings reference_settings_for(std::uint32_t spp, std::uint64_t seed) {
    embree::reference_settings s;
    s.hemisphere_samples = spp;
    s.seed = seed;
    return s;
}

// The largest spp Monte Carlo at equal error runs (--mc-max-spp, or its default).
std::uint32_t monte_carlo_max_spp(const options& o) {
    if (o.mc_max_spp > 0) return o.mc_max_spp;
    return o.raw_equal_error ? std::max(1u, o.ref_spp / 2) : 4u * o.ref_spp;
}

// The adaptive-rays settings the options ask for (enabled = false without --adaptive-rays).
// The floor is in units of the scene's mean irradiance, measured from the first rounds of
// 256 points of the camera's view (timed as the setup stage "irradiance_scale").
adaptive_rays adaptive_settings(const options& o, const embree::accel& bvh, const io::scene& scene,
                                const embree::reference_integrator& integrator, const radius_limits& limits,
                                study::stage_timer& setup) {
    adaptive_rays a;
    if (!o.adaptive_rays) return a;
    if (o.sampler != "embree") throw parameter_error("--adaptive-rays", "needs the Embree sampler");
    if (o.ray_rates)
        throw parameter_error("--ray-rates", "times the fixed grid's rays: not with --adaptive-rays");
    if (!o.a_sweep.empty())
        throw parameter_error("--a-sweep", "adaptive rays aim at a standard error tied to a: sweep a over separate runs");
    a.enabled = true;
    a.min_rays = o.min_record_samples;
    a.max_rays = o.record_samples;
    a.target = double(o.record_error) * o.a;
    if (o.record_error_floor > 0.f) {
        setup.time("irradiance_scale", [&] {
            gbuffer<float> frame = embree::ray_cast_gbuffer(bvh, scene, scene.camera, 64, 64);
            const gbuffer_view<float> g = frame.view();
            std::vector<glm::vec3> p, n;
            for (std::size_t y = 0; y < g.height(); y += 4)
                for (std::size_t x = 0; x < g.width(); x += 4)
                    if (g.covered(x, y)) {
                        p.push_back(g.position(x, y));
                        n.push_back(g.normal(x, y));
                    }
            adaptive_rays first = a;
            first.irradiance_floor = 0.0;
            const embree::record_sampler probe(integrator, first, limits);
            a.irradiance_floor = double(o.record_error_floor) * probe.mean_irradiance(p, n);
        });
    }
    a.validate();
    return a;
}

template <class W>
int run_with(const options& o) {
    if (o.falloff_kappa != 1.f && o.sampler != "raster")
        throw parameter_error("--falloff-kappa", "applies to --sampler raster only");
    if (o.walkthrough > 0 && (o.progressive > 0 || !o.a_sweep.empty()))
        throw parameter_error("--walkthrough", "renders its own frames: not with --progressive or --a-sweep");
    if ((o.plane_turn != 0.0 || o.hashed_turn) && o.sampler != "raster")
        throw parameter_error("--plane-turn/--hashed-turn", "apply to --sampler raster only");
    if (o.ref_spp % 2 != 0)
        throw parameter_error("--ref-spp", "must be even: the reference is two independent halves of N/2 samples");
    check_paths(o);
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
        limits.hessian_gradients = o.gradients;  // the error model follows the interpolation in use
    }
    const adaptive_rays adaptive = adaptive_settings(o, bvh, scene, integrator, limits, setup);
    const embree::record_sampler embree_sampler = o.adaptive_rays
        ? embree::record_sampler(integrator, adaptive, limits)
        : embree::record_sampler(integrator, embree::hemisphere_grid_for(o.record_samples), limits);
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
                         {"adaptive_rays", o.adaptive_rays}, {"min_record_samples", o.min_record_samples},
                         {"record_error", o.record_error}, {"record_error_floor", o.record_error_floor},
                         {"neighbour_clamp", o.neighbour_clamp}, {"gradient_limit", o.gradient_limit},
                         {"max_extrapolation", o.max_extrapolation},
                         {"front_tolerance", o.front_tolerance},
                         {"min_weight", o.min_weight > 0.f ? o.min_weight : o.a}, {"progressive", o.progressive},
                         {"fill_holes", o.progressive > 0 ? o.fill_holes : 0.f},
                         {"scan", o.scan}, {"scan_batch", cache_options.batch.max_records},
                         {"scan_order", cache_options.order == cpu::scan_order::linear ? "linear" : "coarse-to-fine"},
                         {"embree_config", bvh.owner().config()},
                         {"equal_error_measure", o.raw_equal_error ? "raw" : "debiased"},
                         {"mc_max_spp", monte_carlo_max_spp(o)}};

    // Every reference is two independent halves of ref_spp / 2 samples (the debiased error
    // needs their difference); as costly as one of ref_spp.
    auto reference_for = [&](const camera& cam) {
        bool hit = false;
        auto ref = study::cached_reference_halves(bvh, scene, cam, o.width, o.height,
                                                  reference_settings_for(o.ref_spp, 1), study::default_cache_dir(), &hit);
        fmt::print(stderr, "reference {}x{} at {} spp (two halves of {}): {}\n", o.width, o.height, o.ref_spp,
                   ref.half_samples, hit ? "from cache" : "computed");
        return ref;
    };
    // Monte Carlo at equal error: on the debiased error it may go past the reference's
    // samples (an error below the reference's noise is still measured, to its standard
    // error); on the raw error only to half of them, beyond which it would meet that noise.
    const std::uint32_t mc_max_spp = monte_carlo_max_spp(o);
    const study::error_measure mc_measure = o.raw_equal_error ? study::error_measure::raw : study::error_measure::debiased;
    double reference_noise = 0;  // the last reference's own rel_rms (of the single frame, or the walkthrough's mean)

    // Error is measured where the frame's G-buffer sees what the reference saw.
    const float scene_size = glm::length(scene.bounds().second - scene.bounds().first);
    auto mask_for = [&](gbuffer<float> g, const camera& cam) {
        if (o.interp != "splat-gl") return study::coverage_mask(g.view());
        auto ray = embree::ray_cast_gbuffer(bvh, scene, cam, o.width, o.height);
        return study::comparable_mask(g.view(), ray.view(), scene_size);
    };

    // --indirect-exr and --indirect-out: the indirect image, and it beside the reference's
    // with one exposure (the walkthrough's last frame, or the single frame).
    auto write_indirect = [&](const image<glm::vec3>& indirect, const study::reference_halves& ref,
                              const image<float>& mask) {
        if (!o.indirect_exr.empty()) io::write_exr(o.indirect_exr, indirect.view());
        if (o.indirect_out.empty()) return;
        image<glm::vec3> pair(2 * o.width, o.height);
        for (std::size_t y = 0; y < o.height; ++y)
            for (std::size_t x = 0; x < o.width; ++x) {
                pair(x, y) = indirect(x, y);
                pair(o.width + x, y) = ref.whole.indirect(x, y);
            }
        io::write_png(o.indirect_out, pair.view(), io::auto_exposure(ref.whole.indirect.view(), mask.view()));
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
        double cache_total_ms = 0, error_sum = 0, debiased_sum = 0, noise_sum = 0, mc_ms_sum = 0, mc_error_sum = 0;
        std::size_t mc_frames = 0, mc_unreached = 0, mc_skipped = 0, unresolved = 0;
        for (std::size_t f = 0; f < o.walkthrough; ++f) {
            const camera cam = path.at(f);
            study::stage_timer ft;
            const auto t0 = clock_type::now();
            auto fr = frame(cam, o.a, ft);
            const double frame_ms = ms_since(t0);
            cache_total_ms += frame_ms;
            const auto ref = reference_for(cam);
            const image<float> mask = mask_for(fr.g, cam);
            const frame_error err = measure_error(fr.indirect, ref, mask);
            error_sum += err.raw.rel_rms;
            debiased_sum += err.debiased.rel_rms_debiased;
            noise_sum += err.debiased.reference_noise_rel_rms;
            if (!err.debiased.resolved()) ++unresolved;
            nlohmann::ordered_json entry = {{"frame", f},         {"records", cache.records().size()},
                                            {"new_records", fr.new_records}, {"ms", frame_ms},
                                            {"rel_rms", err.raw.rel_rms}};
            add_debiased(entry, err.debiased);
            fmt::print("frame {:2}: {:6} records (+{:5}), {:8.1f} ms, indirect rel_rms {}", f, cache.records().size(),
                       fr.new_records, frame_ms, error_text(err));
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
                const frame_error fresh_err = measure_error(fresh.indirect, ref, mask_for(fresh.g, cam));
                entry["fresh"] = {{"records", cache.records().size()}, {"ms", fresh_ms}, {"rel_rms", fresh_err.raw.rel_rms}};
                add_debiased(entry["fresh"], fresh_err.debiased);
                fmt::print("; fresh: {:6} records, {:8.1f} ms, rel_rms {}", cache.records().size(), fresh_ms,
                           error_text(fresh_err));
                cache.assign(kept);
#ifdef BOUNCE_IC_WITH_GL
                if (gl_state) gl_state->splatter.reset();
#endif
            }
            if (o.walkthrough_mc_stride > 0 && f % o.walkthrough_mc_stride == 0) {
                const double target = err.target(o.raw_equal_error);
                if (target > 0.0) {
                    const auto mc = study::monte_carlo_at_equal_error(bvh, scene, fr.g.view(), ref.indirect_a.view(),
                                                                      ref.indirect_b.view(), mask.view(), target,
                                                                      mc_measure, mc_max_spp);
                    entry["mc_equal_error"] = mc.equal_error_json(frame_ms);
                    mc_ms_sum += mc.ms;
                    mc_error_sum += target;
                    ++mc_frames;
                    if (!mc.reached) ++mc_unreached;
                    fmt::print("; monte carlo {}{:.0f} spp, {:.1f} ms", mc.reached ? "~" : ">", mc.spp, mc.ms);
                } else {
                    // The debiased error came out at or below 0: no error to match.
                    entry["mc_equal_error"] = {{"skipped", "the frame's debiased error is not above 0"}};
                    ++mc_skipped;
                    fmt::print("; monte carlo skipped (debiased error <= 0)");
                }
            }
            fmt::print("\n");
            if (f + 1 == o.walkthrough) write_indirect(fr.indirect, ref, mask);
            frames.push_back(entry);
            for (const auto& s : ft.stages()) timer.add_sample(s, ft.median_ms(s));
            timer.add_sample("total", frame_ms);
        }
        reference_noise = noise_sum / double(o.walkthrough);
        nlohmann::ordered_json walk = {{"frames_count", o.walkthrough},
                                       {"path", "study::camera_path: forward a tenth of the way to the target "
                                                "(at most half way to the first surface), panning -10 to +10 degrees"},
                                       {"total_ms", cache_total_ms},
                                       {"mean_rel_rms", error_sum / double(o.walkthrough)},
                                       {"mean_rel_rms_debiased", debiased_sum / double(o.walkthrough)},
                                       {"frames_debiased_unresolved", unresolved},
                                       {"mean_reference_noise_rel_rms", reference_noise},
                                       {"frames", frames}};
        if (mc_frames > 0) {
            const double mc_total = mc_ms_sum / double(mc_frames) * double(o.walkthrough);
            walk["mc_equal_error"] = {{"measure", o.raw_equal_error ? "raw" : "debiased"},
                                      {"frames_measured", mc_frames},
                                      {"stride", o.walkthrough_mc_stride},
                                      {"frames_not_reached", mc_unreached},
                                      {"frames_skipped", mc_skipped},
                                      // Monte Carlo stopped short of a frame's error: its time, and the
                                      // speedup, are lower bounds.
                                      {"lower_bound", mc_unreached > 0},
                                      {"mean_rel_rms_measured", mc_error_sum / double(mc_frames)},
                                      {"total_ms", mc_total},
                                      {"speedup", mc_total / cache_total_ms}};
            fmt::print("walkthrough: cache {:.1f} ms over {} frames, mean rel_rms {:.4f} (debiased {:.4f}, {} of {} frames "
                       "unresolved; references' own {:.4f}); Monte Carlo at equal per-frame {} error {}{:.1f} ms: {:.1f}x\n",
                       cache_total_ms, o.walkthrough, error_sum / double(o.walkthrough),
                       debiased_sum / double(o.walkthrough), unresolved, o.walkthrough, reference_noise,
                       o.raw_equal_error ? "raw" : "debiased", mc_unreached ? ">" : "~", mc_total, mc_total / cache_total_ms);
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
            const frame_error err = measure_error(fr.indirect, ref, mask_for(fr.g, cam));
            reference_noise = err.debiased.reference_noise_rel_rms;
            fmt::print("frame {:2}: {:5} records (+{:3}), {:8.1f} ms ({:5.2f} fps), indirect rel_rms {}\n", f,
                       cache.records().size(), fr.new_records, frame_ms, 1000.0 / frame_ms, error_text(err));
            nlohmann::ordered_json entry = {{"frame", f}, {"records", cache.records().size()}, {"new_records", fr.new_records},
                                            {"ms", frame_ms}, {"fps", 1000.0 / frame_ms}, {"rel_rms", err.raw.rel_rms}};
            add_debiased(entry, err.debiased);
            frames.push_back(entry);
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
        std::optional<frame_error> last_error;
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
            const frame_error err = measure_error(fr.indirect, ref, mask);
            fmt::print("a = {:.3f}: {:6} records (+{:5}), total {:9.1f} ms (interpolate {:8.2f}, records {:9.1f}), "
                       "indirect rel_rms {}\n",
                       a, cache.records().size(), fr.new_records, at.median_ms("total"), at.median_ms("interpolate"),
                       at.median_ms("compute_records"), error_text(err));
            nlohmann::ordered_json entry = {{"a", a}, {"records", cache.records().size()}, {"new_records", fr.new_records},
                                            {"timings_ms", nlohmann::ordered_json::object()}, {"error", error_json(err)}};
            for (const auto& s : at.stages()) entry["timings_ms"][s] = at.median_ms(s);
            sweep.push_back(entry);
            timer = at;
            report.error = err.raw;
            last_error = err;
        }
        reference_noise = last_error->debiased.reference_noise_rel_rms;
        if (!o.a_sweep.empty()) extra["a_sweep"] = sweep;
        extra["error_debiased"] = nlohmann::ordered_json::object();
        add_debiased(extra["error_debiased"], last_error->debiased);
        report.set_timings(timer);
        report.set_count("records", cache.records().size());
        if (fr.measured > 0) {
            // The batched scan's guesses: measured, and dropped because covered by then.
            report.set_count("records_measured", fr.measured);
            report.set_count("records_wasted", fr.wasted);
        }

        const double mc_target = o.mc_compare ? last_error->target(o.raw_equal_error) : 0.0;
        if (o.mc_compare && !(mc_target > 0.0)) {
            // The debiased error came out at or below 0 (lost in the reference's noise): no
            // error to match; the run's figures are still reported.
            extra["mc_equal_error"] = {{"skipped", "the debiased error is not above 0: raise --ref-spp"}};
            fmt::print("monte carlo at equal error skipped: the debiased error is not above 0 (raise --ref-spp)\n");
        } else if (o.mc_compare) {
            // Brute-force Monte Carlo at doubling sample counts until it reaches this run's
            // error: the debiased one by default, up to monte_carlo_max_spp (4x the reference's
            // spp); with --raw-equal-error the raw one, up to half the reference's spp, beyond
            // which it would meet the reference's noise.
            const double ms = timer.median_ms("total");
            const double target = mc_target;
            if (!o.raw_equal_error && !last_error->debiased.resolved())
                fmt::print("warning: the debiased error is within two standard errors of 0; the ratio below means little\n");
            const auto mc = study::monte_carlo_at_equal_error(
                bvh, scene, fr.g.view(), ref.indirect_a.view(), ref.indirect_b.view(), mask.view(), target, mc_measure,
                mc_max_spp, [](const study::monte_carlo_step& s) {
                    fmt::print("monte carlo {:4} spp: {:9.1f} ms, indirect rel_rms {:.4f} (debiased {:.4f} +- {:.4f})\n",
                               s.spp, s.ms, s.rel_rms, s.rel_rms_debiased, s.rel_rms_debiased_se);
                });
            extra["mc_equal_error"] = mc.equal_error_json(ms);
            extra["mc_sweep"] = mc.sweep_json();
            fmt::print("at equal {} error Monte Carlo needs {}{:.0f} spp, {:.1f} ms: {}{:.1f}x the cache's {:.1f} ms\n",
                       o.raw_equal_error ? "raw" : "debiased", mc.reached ? "~" : "more than ", mc.spp, mc.ms,
                       mc.reached ? "" : "at least ", mc.ms / ms, ms);
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
            else cpu::compose(ref.whole.direct.view(), fr.indirect.view(), combined.view());
            if (!o.exr.empty()) io::write_exr(o.exr, combined.view());
            if (!o.out.empty()) io::write_png(o.out, combined.view(), io::auto_exposure(combined.view(), mask.view()));
        }
        write_indirect(fr.indirect, ref, mask);
    }

    if (!o.cache_out.empty()) study::save_records(o.cache_out, cache.records(), cache_params);
    if (o.sampler == "embree") {
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
    if (!o.json.empty()) {
        auto j = report.to_json();
        j["timings_ms"]["bvh"] = setup.median_ms("bvh");
        // The debiased figures join `error` (the single frame's), and `reference` says what
        // the errors were measured against.
        if (extra.contains("error_debiased") && j.contains("error")) {
            for (auto it = extra["error_debiased"].begin(); it != extra["error_debiased"].end(); ++it)
                j["error"][it.key()] = it.value();
        }
        extra.erase("error_debiased");
        j["reference"] = {{"spp", o.ref_spp},
                          {"halves", 2},
                          {"half_spp", o.ref_spp / 2},
                          {"noise_rel_rms", finite_or_null(reference_noise)},
                          {"noise_of", o.walkthrough > 0 ? "mean over the walkthrough's frames"
                                       : o.progressive > 0 ? "the last frame"
                                                           : "the frame"}};
        for (auto it = extra.begin(); it != extra.end(); ++it) j[it.key()] = it.value();
        std::ofstream out(o.json);
        out << j.dump(2) << '\n';
        out.flush();
        if (!out) throw bounce::error("ic_splatting: cannot write " + o.json.string());
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
