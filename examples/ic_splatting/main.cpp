// ic_splatting: irradiance caching by splatting (seed 000, Algorithm 5), its classical
// octree baseline, and the figures that compare them against the reference integrator.
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
#include <bounce/study/equal_error.hpp>
#include <bounce/study/frame_comparison.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/record_cache.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/io/scene.hpp>
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

#include <CLI/CLI.hpp>
#include "../common/cli_number_checks.hpp"
#include <fmt/core.h>

#include <chrono>
#include <functional>
#include <cmath>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace bounce;

namespace {

using clock_type = std::chrono::steady_clock;
double ms_since(clock_type::time_point t0) {
    return std::chrono::duration<double, std::milli>(clock_type::now() - t0).count();
}

struct options {
    std::string scene = "cornell";
    std::size_t width = 512, height = 512;
    float a = 0.15f;
    std::string weight = "ward-smooth";
    bool gradients = true;
    std::string sampler = "embree";
    float falloff_kappa = 1.f;  // raster sampler: fall-off stretching's band factor (1: border stretching)
    double plane_turn = 0.0;    // raster sampler: plane_camera::turn_deg
    bool hashed_turn = false;   // raster sampler: plane_camera::hashed_turn
    int shadow_resolution = 2048;  // GL: texels per side of the shadow maps (raster records, GL frames' direct light)
    std::string interp = "splat-cpu";
    std::size_t progressive = 0;  // records per frame; 0: two-pass quality mode
    float fill_holes = 4.f;       // progressive: wide splat's a / a (0: leave holes black)
    std::size_t frames = 8;
    std::vector<float> a_sweep;
    std::uint32_t record_samples = 1024, ref_spp = 1024;
    float min_pixels = 1.5f, max_pixels = 64.f;
    bool neighbour_clamp = false;
    std::string scan = "batched";
    std::string scan_order;  // linear | coarse-to-fine; empty: linear, coarse-to-fine when progressive
    std::size_t scan_batch = 0;
    bool gradient_limit = true;
    float max_extrapolation = 1.f;
    float front_tolerance = 1.f;
    float min_weight = 0.f;  // 0: a, as the seed's Eq. 8.8
    int repeat = 1;
    bool mc_compare = false;
    fs::path json, out, exr, indirect_out, indirect_exr, cache_in, cache_out;
};

weighting_kind parse_weight(const std::string& w) {
    if (w == "ward") return weighting_kind::ward;
    if (w == "ward-smooth") return weighting_kind::ward_smooth;
    if (w == "ward-gpu") return weighting_kind::ward_early_reject;
    if (w == "ward-gpu-shader") return weighting_kind::ward_scaled_normal;
    if (w == "tabellion") return weighting_kind::tabellion;
    throw parameter_error("--weight", "unknown weighting function '" + w + "'");
}

// The record sampler the options chose, behind one type (it models bounce::record_sampler).
struct chosen_sampler {
    std::function<void(std::span<const glm::vec3>, std::span<const glm::vec3>, std::span<const double>,
                       std::span<std::optional<irradiance_record>>)>
        measure;
    void operator()(std::span<const glm::vec3> p, std::span<const glm::vec3> n, std::span<const double> footprint,
                    std::span<std::optional<irradiance_record>> out) {
        measure(p, n, footprint, out);
    }
};

// The parameters records depend on (not a: records are valid for every a). falloff_kappa
// and the plane's turn keep their defaults unless the raster sampler takes them (run()
// refuses them with the Embree sampler).
nlohmann::json cache_parameters(const options& o, const io::scene& s) {
    return {{"scene", s.name},         {"sampler", o.sampler},           {"record_samples", o.record_samples},
            {"falloff_kappa", o.falloff_kappa}, {"plane_turn", o.plane_turn}, {"hashed_turn", o.hashed_turn},
            {"shadow_resolution", o.sampler == "raster" ? o.shadow_resolution : 0},  // the raster's records see the maps
            {"min_pixels", o.min_pixels}, {"max_pixels", o.max_pixels}, {"neighbour_clamp", o.neighbour_clamp},
            {"gradient_limit", o.gradient_limit}, {"height", o.height}};
}

// What one frame gives the report: what it saw, its indirect image, the GL backend's
// composed image, and the scan's counts.
struct frame_result {
    gbuffer<float> g;
    image<glm::vec3> indirect;
    std::optional<image<glm::vec3>> combined;
    std::size_t new_records = 0, measured = 0, wasted = 0;
};

cpu::irradiance_cache_options cache_options_for(const options& o, float a) {
    cpu::irradiance_cache_options c;
    c.splat.a = a;
    c.splat.gradients = o.gradients;
    c.splat.max_extrapolation = o.max_extrapolation;
    c.splat.front_tolerance = o.front_tolerance;
    c.min_weight = o.min_weight;
    c.interpolation = o.interp == "octree"         ? cpu::cache_interpolation::octree
                      : o.interp == "octree-lanes" ? cpu::cache_interpolation::octree_lanes
                                                   : cpu::cache_interpolation::splat;
    c.scan = o.scan == "sequential" ? cpu::scan_kind::sequential : cpu::scan_kind::batched;
    c.batch.max_records = o.scan_batch;
    const std::string order = !o.scan_order.empty() ? o.scan_order : (o.progressive > 0 ? "coarse-to-fine" : "linear");
    c.order = order == "coarse-to-fine" ? cpu::scan_order::coarse_to_fine : cpu::scan_order::linear;
    if (o.progressive > 0) c.max_new_records = o.progressive;
    c.fill_holes = c.interpolation == cpu::cache_interpolation::splat ? o.fill_holes : 0.f;
    c.neighbour_clamp = o.neighbour_clamp;
    return c;
}

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
    const embree::record_sampler embree_sampler(integrator, embree::hemisphere_grid_for(o.record_samples), limits);
    chosen_sampler sampler{std::cref(embree_sampler)};
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
        sampler.measure = std::ref(*raster_sampler);
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

    const nlohmann::json cache_params = cache_parameters(o, scene);
    if (!o.cache_in.empty()) cache.assign(study::load_records(o.cache_in, cache_params));
    const std::size_t loaded = cache.records().size();

    study::run_report report;
    report.technique = "ic_splatting";
    report.scene = scene.name;
    report.width = o.width;
    report.height = o.height;
    report.backend = o.interp.starts_with("octree") ? "cpu-" + o.interp : o.interp == "splat-gl" ? "gl" : "cpu";
    report.parameters = {{"a", o.a}, {"weight", o.weight}, {"gradients", o.gradients}, {"sampler", o.sampler},
                         {"falloff_kappa", o.falloff_kappa}, {"plane_turn", o.plane_turn}, {"hashed_turn", o.hashed_turn},
                         {"shadow_resolution", o.shadow_resolution},
                         {"interp", o.interp}, {"record_samples", o.record_samples}, {"reference_spp", o.ref_spp},
                         {"min_pixels", o.min_pixels}, {"max_pixels", o.max_pixels},
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

    nlohmann::ordered_json extra = nlohmann::ordered_json::object();
    study::stage_timer timer;

    if (o.progressive > 0) {
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

        if (!o.out.empty() || !o.exr.empty()) {
            image<glm::vec3> combined(o.width, o.height);
            if (fr.combined) combined = *fr.combined;
            else cpu::compose(ref.direct.view(), fr.indirect.view(), combined.view());
            if (!o.exr.empty()) io::write_exr(o.exr, combined.view());
            if (!o.out.empty()) io::write_png(o.out, combined.view(), io::auto_exposure(combined.view(), mask.view()));
        }
        if (!o.indirect_exr.empty()) io::write_exr(o.indirect_exr, fr.indirect.view());
        if (!o.indirect_out.empty()) {
            // The indirect images side by side with one exposure: the cache's, the reference's.
            image<glm::vec3> pair(2 * o.width, o.height);
            for (std::size_t y = 0; y < o.height; ++y)
                for (std::size_t x = 0; x < o.width; ++x) {
                    pair(x, y) = fr.indirect(x, y);
                    pair(o.width + x, y) = ref.indirect(x, y);
                }
            io::write_png(o.indirect_out, pair.view(), io::auto_exposure(ref.indirect.view(), mask.view()));
        }
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
    app.add_option("--scene", o.scene, "cornell, a scene.json, its folder, an .obj, or a name under the scenes folder")->capture_default_str();
    app.add_option("--width", o.width, "image width")->check(CLI::Range(1, 16384))->capture_default_str();
    app.add_option("--height", o.height, "image height")->check(CLI::Range(1, 16384))->capture_default_str();
    app.add_option("--a", o.a, "accuracy a (Eq. 8.3); smaller means more records")->check(examples::finite_positive)->capture_default_str();
    app.add_option("--weight", o.weight, "ward | ward-smooth | ward-gpu | ward-gpu-shader | tabellion")
        ->check(CLI::IsMember({"ward", "ward-smooth", "ward-gpu", "ward-gpu-shader", "tabellion"}))->capture_default_str();
    app.add_option("--gradients", gradients, "on | off")->check(CLI::IsMember({"on", "off"}))->capture_default_str();
    app.add_option("--sampler", o.sampler, "record sampler: embree | raster")->check(CLI::IsMember({"embree", "raster"}))->capture_default_str();
    app.add_option("--falloff-kappa", o.falloff_kappa,
                   "raster sampler: fall-off stretching with this band factor (hemisphere_study's falloff_kappa for the "
                   "scene); 1: border stretching")
        ->check(examples::unit_interval)
        ->capture_default_str();
    app.add_option("--plane-turn", o.plane_turn,
                   "raster sampler: turn of every plane about its normal from orthonormal_basis(n), degrees in [0, 90)")
        ->check(examples::quarter_turn_deg)
        ->capture_default_str();
    app.add_flag("--hashed-turn", o.hashed_turn,
                 "raster sampler: also turn each plane by its own angle in [0, 90) degrees, hashed from its point");
    app.add_option("--shadow-resolution", o.shadow_resolution,
                   "GL: texels per side of the shadow maps (raster sampler's records, splat-gl's direct light)")
        ->check(CLI::Range(64, 8192))
        ->capture_default_str();
    app.add_option("--interp", o.interp,
                   "splat-cpu | splat-gl | octree (classical, one record at a time) | octree-lanes (four at a time)")
        ->check(CLI::IsMember({"splat-cpu", "splat-gl", "octree", "octree-lanes"}))->capture_default_str();
    app.add_option("--progressive", o.progressive, "at most N new records per frame over a camera path (0: two-pass quality mode)");
    app.add_option("--fill-holes", o.fill_holes,
                   "progressive: fill pixels no zone reaches from a splat with a this many times wider (0: off)")
        ->check(examples::finite_non_negative)
        ->capture_default_str();
    app.add_option("--frames", o.frames, "frames of the progressive camera path")->check(examples::finite_positive)->capture_default_str();
    app.add_option("--a-sweep", o.a_sweep, "comma-separated a values rendered from one growing cache")
        ->delimiter(',')
        ->check(examples::finite_positive);
    app.add_option("--record-samples", o.record_samples, "hemisphere rays per record")->check(CLI::Range(4u, 1u << 20))->capture_default_str();
    app.add_option("--ref-spp", o.ref_spp, "reference integrator samples per pixel")->check(CLI::Range(1u, 1u << 20))->capture_default_str();
    app.add_option("--min-pixels", o.min_pixels, "record radius at least this many pixel footprints")->check(examples::finite_non_negative)->capture_default_str();
    app.add_option("--max-pixels", o.max_pixels, "record radius at most this many pixel footprints")->check(examples::finite_positive)->capture_default_str();
    app.add_option("--scan", o.scan, "batched: measure records ahead in parallel (same result); sequential: one at a time")
        ->check(CLI::IsMember({"batched", "sequential"}))
        ->capture_default_str();
    app.add_option("--scan-order", o.scan_order,
                   "cache-miss scan order: linear | coarse-to-fine (default: linear; coarse-to-fine when progressive)")
        ->check(CLI::IsMember({"linear", "coarse-to-fine"}));
    app.add_option("--scan-batch", o.scan_batch, "records measured together by the batched scan (0: one per thread; 16 planes per atlas for --sampler raster)")
        ->check(CLI::Range(0, 4096))
        ->capture_default_str();
    app.add_flag("--neighbour-clamp", o.neighbour_clamp, "clamp radii to neighbours (R_i <= R_j + |p_i - p_j|)");
    app.add_flag("!--no-gradient-limit", o.gradient_limit, "do not limit R by E / |grad_t E|");
    app.add_option("--max-extrapolation", o.max_extrapolation, "gradient term clamped to this times E_k")->check(examples::finite_non_negative)->capture_default_str();
    app.add_option("--front-tolerance", o.front_tolerance,
                   "skip records whose tangent plane the point lies this fraction of the zone behind (Ward's in-front test; 1: off)")
        ->check(examples::unit_interval)->capture_default_str();
    app.add_option("--min-weight", o.min_weight, "cache-miss threshold on the weight sum (default: a, the seed's Eq. 8.8)")->check(examples::finite_non_negative);
    app.add_option("--repeat", o.repeat, "repeats per measurement (timings are medians)")->check(CLI::Range(1, 1000))->capture_default_str();
    app.add_flag("--mc-compare", o.mc_compare, "also time brute-force Monte Carlo indirect light at equal error");
    app.add_option("--json", o.json, "write the run report here");
    app.add_option("--out", o.out, "write the final image (direct + indirect) as PNG");
    app.add_option("--exr", o.exr, "write the final image as EXR");
    app.add_option("--indirect-out", o.indirect_out, "write the indirect image beside the reference's as PNG");
    app.add_option("--indirect-exr", o.indirect_exr, "write the indirect image alone as EXR (linear, for error maps)");
    app.add_option("--cache-in", o.cache_in, "start from the records saved in this file");
    app.add_option("--cache-out", o.cache_out, "save the records to this file");
    CLI11_PARSE(app, argc, argv);
    o.gradients = gradients == "on";
    try {
        return run(o);
    } catch (const bounce::error& e) {
        fmt::print(stderr, "ic_splatting: {}\n", e.what());
        return 2;
    }
}
