#pragma once
// ic_splatting's options: what the command line sets, how it is spelled and checked (alone
// and against each other, before any work), and the library settings they spell (the
// program's main.cpp runs and reports).
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/errors.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/cache/weighting.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include "../common/cli_choices.hpp"
#include "../common/cli_number_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace bounce::examples {

/// Where records come from: Embree's rays or the GL raster of hemisphere planes.
enum class record_source { embree, raster };
inline const choices<record_source> sampler_names{{"embree", record_source::embree}, {"raster", record_source::raster}};

/// How the frame interpolates the records: splatting on the CPU or GL, or the octree baseline.
enum class interpolation { splat_cpu, splat_gl, octree, octree_lanes };
inline const choices<interpolation> interp_names{{"splat-cpu", interpolation::splat_cpu},
                                                 {"splat-gl", interpolation::splat_gl},
                                                 {"octree", interpolation::octree},
                                                 {"octree-lanes", interpolation::octree_lanes}};

// The spellings of the library's choices.
inline const choices<radius_policy> radius_names{{"split-sphere", radius_policy::split_sphere},
                                                 {"hessian", radius_policy::hessian}};
inline const choices<cpu::scan_kind> scan_names{{"batched", cpu::scan_kind::batched},
                                                {"sequential", cpu::scan_kind::sequential}};
inline const choices<cpu::scan_order> scan_order_names{{"linear", cpu::scan_order::linear},
                                                       {"coarse-to-fine", cpu::scan_order::coarse_to_fine}};
inline choices<weighting_kind> weight_names() {  // the library's (weighting_name)
    choices<weighting_kind> names;
    for (const weighting_kind k : weighting_kinds) names.emplace_back(weighting_name(k), k);
    return names;
}

struct options {
    std::string scene = "cornell";
    std::size_t width = 512, height = 512;
    float a = 0.4f;  // the best speed at equal error on Sponza and the Cornell box (docs/irradiance-splatting.md)
    weighting_kind weight = weighting_kind::ward_smooth;
    bool gradients = true;
    record_source sampler = record_source::embree;
    float falloff_kappa = 1.f;  // raster sampler: fall-off stretching's band factor (1: border stretching)
    double plane_turn = 0.0;    // raster sampler: plane_camera::turn_deg
    bool hashed_turn = false;   // raster sampler: plane_camera::hashed_turn
    int shadow_resolution = 2048;  // GL: texels per side of the shadow maps (raster records, GL frames' direct light)
    interpolation interp = interpolation::splat_cpu;
    std::size_t progressive = 0;  // records per frame; 0: two-pass quality mode
    float fill_holes = 4.f;       // progressive: wide splat's a / a (0: leave holes black)
    std::size_t frames = 8;
    std::size_t walkthrough = 0;      // frames of the walkthrough (0: off)
    bool walkthrough_fresh = false;   // walkthrough: also render each frame from an empty cache
    std::size_t walkthrough_mc_stride = 1;  // walkthrough: Monte Carlo at equal error on every k-th frame (0: none)
    std::vector<float> a_sweep;
    std::uint32_t record_samples = 1024, ref_spp = 1024;
    float min_pixels = 1.5f, max_pixels = 64.f;
    float ambient_resolution = 0.f;  // world limits: R in [size / this, max_world_ratio * size / this] (0: none)
    float max_world_ratio = 64.f;
    float min_mean_distance = 0.f;   // R >= this * the record's mean hit distance (0: none)
    float hessian_zone_cap = std::numeric_limits<float>::infinity();  // --radius hessian: a R <= this * harmonic mean
    radius_policy radius = radius_policy::split_sphere;
    bool adaptive_rays = false;              // records from min_record_samples up to record_samples rays
    std::uint32_t min_record_samples = 256;  // adaptive: the first round's rays
    float record_error = 0.2f;               // adaptive: target relative standard error of E, times a
    float record_error_floor = 1.f;          // adaptive: irradiance floor, times the scene's mean irradiance
    bool importance_rays = false;            // record_samples rays per record, min_record_samples first, the rest by radiance
    float importance_defensive = 0.5f;       // importance: every pair's floor, times the mean first-round luminance
    bool importance_cell_gradients = false;  // importance: gradients on the first round's grid of cell means
    bool importance_contrast = false;        // importance: by the neighbours' range of luminance, not its largest
    bool neighbour_clamp = true;
    float filter_k = 0.f;      // neighbour filter: merge within this many standard errors (0: off)
    float filter_reach = 2.f;  // neighbour filter: neighbours' weights at this times a
    bool filter_soft = true;   // neighbour filter: count the prediction's bias estimated from the difference
    std::uint32_t verify_rounds = 2;  // verification passes after the scan (0: off; none where it cannot run)
    std::uint32_t verify_rays = 8;    // verification: probe rays per pixel
    std::uint32_t verify_tile = 4;    // verification: pixels per side of a pooled tile
    float verify_k = 3.f;             // verification: standard errors of the tile's mean residual
    float verify_tolerance = 0.25f;   // verification: and this times the frame's mean
    cpu::scan_kind scan = cpu::scan_kind::batched;
    cpu::scan_order scan_order = cpu::scan_order::linear;  // unless given: coarse-to-fine when progressive
    std::size_t scan_batch = 0;
    bool gradient_limit = true;
    float max_extrapolation = 1.f;
    float front_tolerance = 1.f;
    float min_weight = 0.f;  // 0: a, as the seed's Eq. 8.8
    int repeat = 1;
    bool mc_compare = false;
    bool raw_equal_error = false;  // equal-error searches on the raw error (default: debiased)
    std::uint32_t mc_max_spp = 0;  // Monte Carlo's largest spp at equal error (0: 4 ref_spp debiased, ref_spp / 2 raw)
    bool ray_rates = false;  // time records against Embree's raw rate for the same rays
    std::filesystem::path json, out, exr, indirect_out, indirect_exr, cache_in, cache_out;
};

inline std::string weight_help() {  // "ward | ward-smooth | ..."
    std::string help;
    for (const auto& [name, k] : weight_names()) help += (help.empty() ? "" : " | ") + name;
    return help;
}

/// The report's `backend`: gl, cpu, or cpu-octree and cpu-octree-lanes for the baseline.
inline std::string report_backend(interpolation i) {
    if (i == interpolation::octree || i == interpolation::octree_lanes) return "cpu-" + name_of(interp_names, i);
    return i == interpolation::splat_gl ? "gl" : "cpu";
}

/// The cache settings the options ask for, at accuracy `a`.
inline cpu::irradiance_cache_options cache_options_for(const options& o, float a) {
    cpu::irradiance_cache_options c;
    c.splat.a = a;
    c.splat.gradients = o.gradients;
    c.splat.max_extrapolation = o.max_extrapolation;
    c.splat.front_tolerance = o.front_tolerance;
    c.min_weight = o.min_weight;
    c.interpolation = o.interp == interpolation::octree         ? cpu::cache_interpolation::octree
                      : o.interp == interpolation::octree_lanes ? cpu::cache_interpolation::octree_lanes
                                                                : cpu::cache_interpolation::splat;
    c.scan = o.scan;
    c.batch.max_records = o.scan_batch;
    c.order = o.scan_order;
    if (o.progressive > 0) c.max_new_records = o.progressive;
    c.fill_holes = c.interpolation == cpu::cache_interpolation::splat ? o.fill_holes : 0.f;
    c.neighbour_clamp = o.neighbour_clamp;
    c.filter.k = o.filter_k;
    c.filter.reach = o.filter_reach;
    c.filter.soft = o.filter_soft;
    c.verify = {o.verify_rounds, o.verify_tile, o.verify_k, o.verify_tolerance};
    return c;
}

// The parameters records depend on (not a: records are valid for every a). falloff_kappa
// and the plane's turn keep their defaults unless the raster sampler takes them (run()
// refuses them with the Embree sampler).
inline nlohmann::json cache_parameters(const options& o, const std::string& scene, const radius_limits& limits) {
    const bool hessian = o.radius == radius_policy::hessian;
    const bool raster = o.sampler == record_source::raster;  // the raster's records see the shadow maps
    nlohmann::json p = {{"scene", scene},         {"sampler", name_of(sampler_names, o.sampler)}, {"record_samples", o.record_samples},
            {"falloff_kappa", o.falloff_kappa}, {"plane_turn", o.plane_turn}, {"hashed_turn", o.hashed_turn},
            {"shadow_resolution", raster ? o.shadow_resolution : 0},
            {"min_pixels", o.min_pixels}, {"max_pixels", o.max_pixels}, {"neighbour_clamp", o.neighbour_clamp},
            {"gradient_limit", o.gradient_limit}, {"height", o.height}, {"radius", name_of(radius_names, o.radius)},
            {"hessian_a", hessian ? o.a : 0.f},
            // Radii of the first, edge-bound Hessian rule differ. Adaptive rays: the three
            // fields below are 0 without them (no key of its own, so saved caches still load).
            {"hessian_rule", hessian ? "total-error" : ""},
            {"min_record_samples", o.adaptive_rays ? o.min_record_samples : 0u},
            {"record_error", o.adaptive_rays ? o.record_error * o.a : 0.f},
            {"record_error_floor", o.adaptive_rays ? o.record_error_floor : 0.f}};
    // The world limits, keyed only where set, so caches saved before them still load.
    if (limits.min_world > 0.f || std::isfinite(limits.max_world))
        p["world_limits"] = {limits.min_world, limits.max_world};
    if (limits.min_mean_distance > 0.f) p["min_mean_distance"] = limits.min_mean_distance;
    if (hessian && std::isfinite(limits.hessian_zone_cap)) p["hessian_zone_cap"] = limits.hessian_zone_cap;
    // Filtered records depend on the filter and on a; keyed only where on.
    if (o.filter_k > 0.f) p["record_filter"] = {o.filter_k, o.filter_reach, o.a, o.filter_soft};
    if (o.importance_rays) p["importance_rays"] = {o.min_record_samples, o.importance_defensive, o.importance_contrast,
                                                o.importance_cell_gradients};
    return p;
}

/// The record radius limits the options ask for, in a scene of bounds [lo, hi].
inline radius_limits radius_limits_for(const options& o, const glm::vec3& lo, const glm::vec3& hi) {
    radius_limits limits = scene_radius_limits({}, lo, hi, o.ambient_resolution, o.max_world_ratio);
    limits.min_pixels = o.min_pixels;
    limits.max_pixels = o.max_pixels;
    limits.min_mean_distance = o.min_mean_distance;
    limits.gradient_limit = o.gradient_limit;
    if (o.radius == radius_policy::hessian) {
        limits.policy = radius_policy::hessian;
        limits.hessian_a = o.a;
        limits.hessian_gradients = o.gradients;  // the error model follows the interpolation in use
        limits.hessian_zone_cap = o.hessian_zone_cap;
    }
    return limits;
}

/// The largest spp Monte Carlo at equal error runs (--mc-max-spp, or its default).
inline std::uint32_t monte_carlo_max_spp(const options& o) {
    if (o.mc_max_spp > 0) return o.mc_max_spp;
    return o.raw_equal_error ? std::max(1u, o.ref_spp / 2) : 4u * o.ref_spp;
}

/// Options that do not go together, refused before any work (parameter_error naming one).
/// `with_gl`: whether this build has the GL adapter.
inline void check_combinations(const options& o, bool with_gl) {
    const bool raster = o.sampler == record_source::raster, hessian = o.radius == radius_policy::hessian;
    if (o.falloff_kappa != 1.f && !raster)
        throw parameter_error("--falloff-kappa", "applies to --sampler raster only");
    if (o.walkthrough > 0 && (o.progressive > 0 || !o.a_sweep.empty()))
        throw parameter_error("--walkthrough", "renders its own frames: not with --progressive or --a-sweep");
    if ((o.plane_turn != 0.0 || o.hashed_turn) && !raster)
        throw parameter_error("--plane-turn/--hashed-turn", "apply to --sampler raster only");
    if (o.ref_spp % 2 != 0)
        throw parameter_error("--ref-spp", "must be even: the reference is two independent halves of N/2 samples");
    if (hessian && raster)
        throw parameter_error("--radius", "'hessian' needs the Embree sampler (the raster's reduction has no Hessian)");
    if (o.min_mean_distance > 0.f && raster)
        throw parameter_error("--min-mean-distance", "needs the Embree sampler (the raster's reduction has no mean distance)");
    if (std::isfinite(o.hessian_zone_cap) && !hessian)
        throw parameter_error("--hessian-zone-cap", "applies to --radius hessian only");
    if (hessian && !o.a_sweep.empty())
        throw parameter_error("--a-sweep", "the Hessian radius depends on a: sweep a over separate runs");
    if (o.adaptive_rays && raster) throw parameter_error("--adaptive-rays", "needs the Embree sampler");
    if (o.importance_rays && raster) throw parameter_error("--importance-rays", "needs the Embree sampler");
    if (o.importance_rays && o.adaptive_rays)
        throw parameter_error("--importance-rays", "allocates a fixed budget: not with --adaptive-rays");
    if (o.importance_rays && o.min_record_samples > o.record_samples)
        throw parameter_error("--min-record-samples", "importance rays: the first round must not exceed --record-samples");
    if (o.importance_rays && o.ray_rates)
        throw parameter_error("--ray-rates", "times the fixed grid's rays: not with --importance-rays");
    if (o.filter_k > 0.f && raster)
        throw parameter_error("--record-filter", "needs the Embree sampler (the raster's records carry no variance)");
    if (o.filter_k > 0.f && !o.a_sweep.empty())
        throw parameter_error("--a-sweep", "the neighbour filter weighs neighbours at a: sweep a over separate runs");
    if (o.adaptive_rays && o.ray_rates)
        throw parameter_error("--ray-rates", "times the fixed grid's rays: not with --adaptive-rays");
    if (o.adaptive_rays && !o.a_sweep.empty())
        throw parameter_error("--a-sweep", "adaptive rays aim at a standard error tied to a: sweep a over separate runs");
    if (o.verify_rounds > 0 && o.interp != interpolation::splat_cpu && o.interp != interpolation::splat_gl)
        throw parameter_error("--verify", "runs in the splat frames only (--interp splat-cpu or splat-gl)");
    if (o.verify_rounds > 0 && o.progressive > 0)
        throw parameter_error("--verify", "checks a whole frame: not with --progressive's record budget");
    if (o.ray_rates && raster) throw parameter_error("--ray-rates", "applies to --sampler embree only");
    if (!with_gl && raster)
        throw parameter_error("--sampler", "'raster' needs the GL adapter, which this build does not have");
    if (!with_gl && o.interp == interpolation::splat_gl)
        throw parameter_error("--interp", "'splat-gl' needs the GL adapter, which this build does not have");
}

/// The run report's `parameters`: the options as run (`cache` the cache's options, with the
/// raster sampler's batch; `embree_config` the device's; `mc_max_spp` monte_carlo_max_spp).
inline nlohmann::ordered_json report_parameters(const options& o, const cpu::irradiance_cache_options& cache,
                                                const std::string& embree_config, std::uint32_t mc_max_spp) {
    return {{"a", o.a}, {"weight", weighting_name(o.weight)}, {"gradients", o.gradients},
            {"sampler", name_of(sampler_names, o.sampler)},
            {"falloff_kappa", o.falloff_kappa}, {"plane_turn", o.plane_turn}, {"hashed_turn", o.hashed_turn},
            {"shadow_resolution", o.shadow_resolution},
            {"interp", name_of(interp_names, o.interp)}, {"record_samples", o.record_samples},
            {"reference_spp", o.ref_spp}, {"min_pixels", o.min_pixels}, {"max_pixels", o.max_pixels},
            {"ambient_resolution", o.ambient_resolution}, {"max_world_ratio", o.max_world_ratio},
            {"min_mean_distance", o.min_mean_distance},
            {"hessian_zone_cap", std::isfinite(o.hessian_zone_cap) ? nlohmann::ordered_json(o.hessian_zone_cap) : nullptr},
            {"radius", name_of(radius_names, o.radius)},
            {"adaptive_rays", o.adaptive_rays}, {"min_record_samples", o.min_record_samples},
            {"record_error", o.record_error}, {"record_error_floor", o.record_error_floor},
            {"importance_rays", o.importance_rays}, {"importance_defensive", o.importance_defensive},
            {"importance_by", o.importance_contrast ? "contrast" : "radiance"},
            {"importance_cell_gradients", o.importance_cell_gradients},
            {"neighbour_clamp", o.neighbour_clamp}, {"gradient_limit", o.gradient_limit},
            {"record_filter", o.filter_k}, {"filter_reach", o.filter_reach}, {"filter_soft", o.filter_soft},
            {"verify_rounds", o.verify_rounds}, {"verify_rays", o.verify_rays}, {"verify_tile", o.verify_tile},
            {"verify_k", o.verify_k}, {"verify_tolerance", o.verify_tolerance},
            {"max_extrapolation", o.max_extrapolation},
            {"front_tolerance", o.front_tolerance},
            {"min_weight", o.min_weight > 0.f ? o.min_weight : o.a}, {"progressive", o.progressive},
            {"fill_holes", o.progressive > 0 ? o.fill_holes : 0.f},
            {"scan", name_of(scan_names, o.scan)}, {"scan_batch", cache.batch.max_records},
            {"scan_order", name_of(scan_order_names, cache.order)},
            {"embree_config", embree_config},
            {"equal_error_measure", o.raw_equal_error ? "raw" : "debiased"},
            {"mc_max_spp", mc_max_spp}};
}

/// Declares every option on `app`, writing into `o` (and `gradients`: "on" or "off").
inline void add_options(CLI::App& app, options& o, std::string& gradients) {
    app.add_option("--scene", o.scene, "cornell, a scene.json, its folder, an .obj, a .gltf or .glb, or a name under the scenes folder")->capture_default_str();
    app.add_option("--width", o.width, "image width")->check(CLI::Range(1, 16384))->capture_default_str();
    app.add_option("--height", o.height, "image height")->check(CLI::Range(1, 16384))->capture_default_str();
    app.add_option("--a", o.a, "accuracy a (Eq. 8.3); smaller means more records")->check(examples::finite_positive)->capture_default_str();
    add_choice(app, "--weight", o.weight, weight_names(), weight_help())->capture_default_str();
    app.add_option("--gradients", gradients, "on | off")->check(CLI::IsMember({"on", "off"}))->capture_default_str();
    add_choice(app, "--sampler", o.sampler, sampler_names, "record sampler: embree | raster")->capture_default_str();
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
    add_choice(app, "--interp", o.interp, interp_names,
               "splat-cpu | splat-gl | octree (classical, one record at a time) | octree-lanes (four at a time)")
        ->capture_default_str();
    // Unsigned counts get a range: CLI11 reads "-1" into a std::size_t as its largest value.
    app.add_option("--progressive", o.progressive, "at most N new records per frame over a camera path (0: two-pass quality mode)")
        ->check(CLI::Range(0, 1 << 24));
    app.add_option("--fill-holes", o.fill_holes,
                   "progressive: fill pixels no zone reaches from a splat with a this many times wider (0: off)")
        ->check(examples::finite_non_negative)
        ->capture_default_str();
    app.add_option("--frames", o.frames, "frames of the progressive camera path")->check(CLI::Range(1, 100000))->capture_default_str();
    app.add_option("--a-sweep", o.a_sweep, "comma-separated a values rendered from one growing cache")
        ->delimiter(',')
        ->check(examples::finite_positive);
    app.add_option("--record-samples", o.record_samples, "hemisphere rays per record (--adaptive-rays: the most)")->check(CLI::Range(4u, 1u << 20))->capture_default_str();
    app.add_flag("--adaptive-rays,!--no-adaptive-rays", o.adaptive_rays,
                 "records refine their strata until the standard error of E is below --record-error * a * max(E, floor) "
                 "(docs/irradiance-splatting.md, \"Adaptive rays per record\")")
        ->capture_default_str();
    app.add_flag("--importance-rays,!--no-importance-rays", o.importance_rays,
                 "records cast --record-samples rays, --min-record-samples on a grid first and the rest to the strata "
                 "whose neighbours saw the most light (docs/irradiance-splatting.md, \"Importance-sampled records\")")
        ->capture_default_str();
    app.add_option("--importance-defensive", o.importance_defensive,
                   "importance rays: the floor of every stratum pair's share, in units of the mean first-round luminance")
        ->check(examples::finite_non_negative)
        ->capture_default_str();
    app.add_flag("--importance-cell-gradients", o.importance_cell_gradients,
                 "importance rays: gradients on the first round's grid of cell means at their nearest hits, not on the fine grid");
    app.add_flag("--importance-contrast,!--importance-radiance", o.importance_contrast,
                 "importance rays: by the range of the luminance the neighbouring strata saw, not by its largest")
        ->capture_default_str();
    app.add_option("--min-record-samples", o.min_record_samples, "adaptive and importance rays: the first round's rays per record")
        ->check(CLI::Range(4u, 1u << 20))
        ->capture_default_str();
    app.add_option("--record-error", o.record_error, "adaptive rays: target relative standard error of a record's E, in units of a")
        ->check(examples::finite_positive)
        ->capture_default_str();
    app.add_option("--record-error-floor", o.record_error_floor,
                   "adaptive rays: irradiance below which the target is absolute, in units of the scene's mean irradiance "
                   "(from 256 points of the camera's view)")
        ->check(examples::finite_non_negative)
        ->capture_default_str();
    app.add_option("--ref-spp", o.ref_spp,
                   "reference integrator samples per pixel, as two independent halves of N/2 (even; their difference "
                   "measures the reference's own noise, which the debiased error takes out)")
        ->check(CLI::Range(2u, 1u << 20))
        ->capture_default_str();
    add_choice(app, "--radius", o.radius, radius_names,
               "record radius: split-sphere (harmonic mean distance, Ward et al. 1988) | hessian (occlusion Hessian, "
               "Schwarzhaupt et al. 2012: a is the relative error at the zone's edge)")
        ->capture_default_str();
    app.add_option("--min-pixels", o.min_pixels, "record radius at least this many pixel footprints (--walkthrough: 0 unless given)")->check(examples::finite_non_negative)->capture_default_str();
    app.add_option("--max-pixels", o.max_pixels, "record radius at most this many pixel footprints")->check(examples::finite_positive)->capture_default_str();
    app.add_option("--ambient-resolution", o.ambient_resolution,
                   "record radius at least the scene's largest extent over this, and at most --max-world-ratio times "
                   "that (Radiance's -ar; 0: no world limits)")
        ->check(examples::finite_non_negative)
        ->capture_default_str();
    app.add_option("--max-world-ratio", o.max_world_ratio, "largest record radius over the smallest (--ambient-resolution)")
        ->check(examples::finite_positive)
        ->check(CLI::Range(1.f, 1e6f))
        ->capture_default_str();
    app.add_option("--min-mean-distance", o.min_mean_distance,
                   "record radius at least this times the record's mean hit distance (0: no floor)")
        ->check(examples::finite_non_negative)
        ->capture_default_str();
    app.add_option("--hessian-zone-cap", o.hessian_zone_cap,
                   "--radius hessian: the zone a R at most this times the record's harmonic mean distance (the split "
                   "sphere's R; default: no cap)")
        ->check(examples::finite_positive);
    add_choice(app, "--scan", o.scan, scan_names,
               "batched: measure records ahead in parallel (same result); sequential: one at a time")
        ->capture_default_str();
    add_choice(app, "--scan-order", o.scan_order, scan_order_names,
               "cache-miss scan order: linear | coarse-to-fine (default: linear; coarse-to-fine when progressive)");
    app.add_option("--scan-batch", o.scan_batch, "records measured together by the batched scan (0: one per thread; 16 planes per atlas for --sampler raster)")
        ->check(CLI::Range(0, 4096))
        ->capture_default_str();
    app.add_option("--record-filter", o.filter_k,
                   "shrink each new record toward its neighbours' prediction, weighted by both variances, unless they "
                   "differ by more than this many standard errors (0: off; docs/irradiance-splatting.md)")
        ->check(examples::finite_non_negative)
        ->capture_default_str();
    app.add_option("--filter-reach", o.filter_reach, "--record-filter: neighbours' weights at this times a")
        ->check(examples::finite_positive)
        ->capture_default_str();
    app.add_flag("--filter-soft,!--no-filter-soft", o.filter_soft,
                 "--record-filter: also weigh the prediction's bias, estimated from the difference (default on)");
    app.add_option("--verify", o.verify_rounds,
                   "after the scan, check the image against a few-ray Monte Carlo probe per pixel pooled over tiles, "
                   "and add records where a tile disagrees, this many rounds (0: off; unless given, 0 where it cannot run: "
                   "--interp other than splat-cpu and splat-gl, --progressive; docs/irradiance-splatting.md, "
                   "\"Error the records cannot see\")")
        ->check(CLI::Range(0u, 16u))
        ->capture_default_str();
    app.add_option("--verify-rays", o.verify_rays, "--verify: probe rays per pixel")->check(CLI::Range(2u, 4096u))->capture_default_str();
    app.add_option("--verify-tile", o.verify_tile, "--verify: pixels per side of the tiles whose residuals are pooled")
        ->check(CLI::Range(1u, 256u))
        ->capture_default_str();
    app.add_option("--verify-k", o.verify_k, "--verify: a tile disagrees beyond this many standard errors ...")
        ->check(examples::finite_positive)
        ->capture_default_str();
    app.add_option("--verify-tolerance", o.verify_tolerance, "--verify: ... and beyond this times the frame's mean luminance")
        ->check(examples::finite_non_negative)
        ->capture_default_str();
    app.add_flag("--neighbour-clamp,!--no-neighbour-clamp", o.neighbour_clamp,
                 "clamp radii to neighbours (R_i <= R_j + |p_i - p_j|), new records and, each frame, older ones (default on)");
    app.add_option("--walkthrough", o.walkthrough,
                   "render N frames along the camera path (docs/irradiance-splatting.md) with one growing cache, "
                   "reporting per-frame error and time and Monte Carlo at equal per-frame error")
        ->check(CLI::Range(0, 100000));
    app.add_flag("--walkthrough-fresh", o.walkthrough_fresh,
                 "walkthrough: also render every frame from an empty cache (its error and records, not timed in the total)");
    app.add_option("--walkthrough-mc-stride", o.walkthrough_mc_stride,
                   "walkthrough: Monte Carlo at equal error on every k-th frame, its mean time standing for every frame "
                   "(0: none)")
        ->check(CLI::Range(0, 100000))
        ->capture_default_str();
    app.add_flag("!--no-gradient-limit", o.gradient_limit, "do not limit R by E / |grad_t E|");
    app.add_option("--max-extrapolation", o.max_extrapolation, "gradient term clamped to this times E_k")->check(examples::finite_non_negative)->capture_default_str();
    app.add_option("--front-tolerance", o.front_tolerance,
                   "skip records whose tangent plane the point lies this fraction of the zone behind (Ward's in-front test; 1: off)")
        ->check(examples::unit_interval)->capture_default_str();
    app.add_option("--min-weight", o.min_weight, "cache-miss threshold on the weight sum (default: a, the seed's Eq. 8.8)")->check(examples::finite_non_negative);
    app.add_option("--repeat", o.repeat, "repeats per measurement (timings are medians)")->check(CLI::Range(1, 1000))->capture_default_str();
    app.add_flag("--mc-compare", o.mc_compare, "also time brute-force Monte Carlo indirect light at equal error");
    app.add_flag("--raw-equal-error", o.raw_equal_error,
                 "Monte Carlo at equal error on the raw rel_rms against the reference (default: on the debiased "
                 "error, the reference's own noise taken out)");
    app.add_option("--mc-max-spp", o.mc_max_spp,
                   "Monte Carlo at equal error stops doubling here (0: 4x --ref-spp on the debiased error, whose "
                   "reference noise is taken out; --ref-spp / 2 on the raw error, beyond which it meets that noise)")
        ->check(CLI::Range(0u, 1u << 24))
        ->capture_default_str();
    app.add_flag("--ray-rates", o.ray_rates,
                 "Embree sampler: re-measure up to 2048 of the frame's records, and trace their hemisphere rays alone, "
                 "reporting record_rays_per_s and embree_rays_per_s");
    app.add_option("--json", o.json, "write the run report here");
    app.add_option("--out", o.out, "write the final image (direct + indirect) as PNG");
    app.add_option("--exr", o.exr, "write the final image as EXR");
    app.add_option("--indirect-out", o.indirect_out, "write the indirect image beside the reference's as PNG");
    app.add_option("--indirect-exr", o.indirect_exr, "write the indirect image alone as EXR (linear, for error maps)");
    app.add_option("--cache-in", o.cache_in, "start from the records saved in this file");
    app.add_option("--cache-out", o.cache_out, "save the records to this file");
}

/// What the parsed command line implies: `gradients` read, the scan order unless given, and
/// a walkthrough's radius floor.
inline void finish_options(const CLI::App& app, options& o, const std::string& gradients) {
    o.gradients = gradients == "on";
    if (app.count("--scan-order") == 0)  // a budget of records per frame spreads over the image
        o.scan_order = o.progressive > 0 ? cpu::scan_order::coarse_to_fine : cpu::scan_order::linear;
    // A radius floor of pixel footprints ties a record to the camera that made it: another
    // camera's pixels take its inflated zone as coverage (docs/irradiance-splatting.md,
    // "Many frames"), so a walkthrough has none unless asked.
    if (o.walkthrough > 0 && app.count("--min-pixels") == 0) o.min_pixels = 0.f;
    // The verification pass is the default wherever it can run: a whole frame splatted (CPU or GL).
    const bool splats = o.interp == interpolation::splat_cpu || o.interp == interpolation::splat_gl;
    if (app.count("--verify") == 0 && (!splats || o.progressive > 0)) o.verify_rounds = 0;
}

}  // namespace bounce::examples
