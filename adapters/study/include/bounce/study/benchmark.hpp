#pragma once
/// \file benchmark.hpp
/// Every technique with its defaults on a scene, timed, against the reference of the quantity
/// it computes, beside brute-force Monte Carlo on the same ray tracer as that quantity's
/// baseline (docs/architecture.md section 6). `build/bin/benchmark` parses options and calls
/// run_benchmark; the results file it writes makes docs/benchmark.md.
///
/// Quantities and their references (each in two independent halves A and B whose
/// difference takes the reference's own noise out of every error, compare_luminance_debiased):
/// - one_bounce: one-bounce indirect radiance with visibility (cached_reference_halves);
///   the irradiance cache computes it, and the RSM gather and SII are measured against it.
/// - unoccluded: one bounce without the receiver-sender visibility
///   (embree::unoccluded_reference), what the RSM gather and SII without visibility
///   approximate: reported beside. The RSM techniques run once per visibility policy of the
///   settings (none as published, rays: exact, issue 29); the scene's "visibility" entry
///   sets each one's error with rays against the occluded reference beside its error without
///   visibility against the unoccluded one (their ratio: what visibility adds).
/// - all_bounces: the view's radiance after every diffuse bounce
///   (embree::multi_bounce_reference), what radiosity computes.
/// - volume_points: one-bounce indirect irradiance (times rho / pi) at points off the
///   surfaces: each visible surface point moved a fraction of the scene's diagonal along its
///   normal (at most half the free distance there), facing the same way; what the
///   irradiance volume computes for moving objects.
/// Each quantity's Monte Carlo baseline is its reference's estimator at 1, 2, 4 ... samples
/// per pixel (paths, for all_bounces), run once per scene; every technique's equal-error
/// sample count is read off that sweep.
///
/// The results file (run_benchmark):
/// ```
/// { "provenance": {"commit", "date", "cpu", "cores", "embree", "command",
///                  "settings": {"width", "height", "quick", "reference_spp": {...}, ...},
///                  "machine_use": {"wall_s", "cpu_s", "load_average_start", "load_average_end"}},
///   "scenes": [ { "scene", "triangles", "lights", "bounds_diagonal",
///       "references": { "<quantity>": {"spp", "ms", "cached", "noise_rel_rms"} },
///       "techniques": [ { "technique", "visibility", "quantity", "ms", "parameters", "counts", "timings_ms",
///             "error": {"rel_rms", "rel_rms_debiased", "rel_rms_debiased_se", "ssim"},
///             "error_unoccluded": {...}                  // RSM gather and SII only
///             "mc_equal_error": {"rel_rms": {"spp", "ms", "reached", "speedup"},
///                                "ssim": {...}},
///             "mc_equal_error_unoccluded": {...} } ],    // RSM gather and SII only
///       "monte_carlo": { "<quantity>": [ {"spp", "ms", "rel_rms", "rel_rms_debiased", "ssim"} ] },
///       "visibility": [ {"technique", "rays_vs_occluded", "none_vs_unoccluded", "ratio"} ] } ] }
///                      // ratio null when none_vs_unoccluded is 0 (within the reference's noise)
/// ```
/// Non-finite numbers are written as null. A technique that fails on a scene is listed with
/// `failed` (the message) instead of its figures.

#include <bounce/errors.hpp>
#include <bounce/indirect/visibility.hpp>
#include <bounce/io/scene.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace bounce::study {

/// The techniques the benchmark runs, by their names in `--techniques` and the results.
enum class bench_technique { irradiance_cache, rsm_gather, sii, sii_interleaved, radiosity, irradiance_volume };
inline constexpr std::array<bench_technique, 6> all_bench_techniques = {
    bench_technique::irradiance_cache, bench_technique::rsm_gather,  bench_technique::sii,
    bench_technique::sii_interleaved,  bench_technique::radiosity,   bench_technique::irradiance_volume};

/// "irradiance_cache", "rsm_gather", "sii", "sii_interleaved", "radiosity", "irradiance_volume".
std::string_view technique_name(bench_technique t);
/// A comma-separated list of names, in the order given, without repeats. Throws
/// parameter_error naming "--techniques" for an empty list or an unknown name (listing the
/// known ones).
std::vector<bench_technique> parse_techniques(std::string_view list);
/// A comma-separated list of visibility names ("none", "rays"), in the order given, without
/// repeats. Throws parameter_error naming "--visibility" for an empty list or an unknown name.
std::vector<indirect_visibility> parse_visibilities(std::string_view list);

/// The quantities techniques compute (see the file comment).
enum class bench_quantity { one_bounce, unoccluded, all_bounces, volume_points };
inline constexpr std::array<bench_quantity, 4> all_bench_quantities = {
    bench_quantity::one_bounce, bench_quantity::unoccluded, bench_quantity::all_bounces, bench_quantity::volume_points};
/// "one_bounce", "unoccluded", "all_bounces", "volume_points".
std::string_view quantity_name(bench_quantity q);

/// A quantity's reference and Monte Carlo sweep.
struct quantity_samples {
    std::uint32_t reference = 256;  ///< samples (paths) per pixel of the reference, both halves together (even, >= 2)
    std::uint32_t mc_max = 256;     ///< the Monte Carlo sweep's largest samples per pixel (1, 2, 4 ... up to it)
};

/// Where the run stands, for a progress line.
struct benchmark_progress {
    std::string scene;        ///< the scene's name
    std::size_t scene_index = 0, scenes = 0;
    std::string technique;    ///< a technique's name, or "reference" / "monte carlo" / "setup"
    std::string stage;        ///< what it does now ("one_bounce", "4 spp", "solve" ...)
    double elapsed_s = 0;     ///< since the run began
    double left_s = -1;       ///< estimated time left (< 0: not yet known)
};

/// What a run does.
struct benchmark_settings {
    std::size_t width = 256, height = 256;
    bool quick = false;  ///< the settings of quick_settings (recorded in the results)
    std::vector<bench_technique> techniques{all_bench_techniques.begin(), all_bench_techniques.end()};
    /// Lights a frame of the RSM techniques (SII: VPLs; the gather: disc samples per pixel and
    /// map), rsm_sii's default 1,024 (`--vpls`); at least the 16 sub-buffers of SII's 4x4.
    std::size_t rsm_lights = 1024;
    /// The RSM techniques' visibility policies, each a run of its own (`--visibility`).
    std::vector<indirect_visibility> visibility{indirect_visibility::none, indirect_visibility::rays};
    quantity_samples one_bounce{1024, 512}, unoccluded{512, 256}, all_bounces{256, 128}, volume_points{512, 256};
    /// The volume's points: each surface point moved this fraction of the scene's bounding
    /// diagonal along its normal (at most half the free distance along it).
    double volume_offset = 0.02;
    /// Radiosity's solve stops here if it has not shot its defaults' fraction by then
    /// (seconds; recorded in the technique's counts when it happens).
    double radiosity_max_seconds = 120;
    /// Renders per timing of the techniques that take milliseconds (RSM gather, SII): medians.
    int repeat = 3;
    /// Reference cache folder; empty: default_cache_dir().
    std::filesystem::path cache_dir;
    /// Called at each stage (serialized, from the calling thread); may be empty.
    std::function<void(const benchmark_progress&)> progress;

    /// The defaults for a full run at `width` x `height` (sizes chosen so that every shared
    /// scene and the built-in box fit about an hour on two cores, references included), or
    /// with `quick` the few-minute run: the built-in box's figures at small sample counts.
    static benchmark_settings defaults(bool quick, std::size_t width, std::size_t height);
    const quantity_samples& samples_of(bench_quantity q) const;
    /// Throws parameter_error naming the option ("--width", "--techniques" ...).
    void validate() const;
    /// {"width", "height", "quick", "reference_spp": {quantity: spp}, "mc_max_spp": {...}, ...}.
    nlohmann::ordered_json to_json() const;
};

/// Refuses, before any work, a scene argument that names nothing loadable: "cornell", a
/// file or folder that exists, or a folder under io::scenes_dir() holding a scene.json.
/// Throws parameter_error naming "--scenes" and the paths it tried.
void check_scene_arg(std::string_view arg);

/// The default scenes: "cornell" and, sorted, every folder under io::scenes_dir() with a
/// scene.json.
std::vector<std::string> default_benchmark_scenes();

/// One scene's entry of the results file (see the file comment); `index` of `count`
/// scenes for the progress line.
nlohmann::ordered_json benchmark_scene(const io::scene& scene, const benchmark_settings& settings, std::size_t index = 0,
                                       std::size_t count = 1);

/// The results file for `scene_args`: {"provenance": {..., "command": command, "settings":
/// settings.to_json()}, "scenes": [...]}. Before any work: the settings are validated, each
/// argument checked (check_scene_arg) and loaded, and the cache folder checked
/// (check_cache_dir). `after_scene` (optional) sees the results so far after each scene
/// (to write them as they grow).
nlohmann::ordered_json run_benchmark(const std::vector<std::string>& scene_args, const benchmark_settings& settings,
                                     const std::string& command,
                                     const std::function<void(const nlohmann::ordered_json&)>& after_scene = {});

/// A scene's figures as a text table (one line per technique: time, errors, speedups).
std::string scene_summary(const nlohmann::ordered_json& scene);

/// Whether any technique of `results` (run_benchmark's) failed.
bool any_technique_failed(const nlohmann::ordered_json& results);

}  // namespace bounce::study
