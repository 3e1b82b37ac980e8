// benchmark: every technique with its defaults on every scene, against the reference of the
// quantity it computes, beside brute-force Monte Carlo on the same ray tracer
// (bounce::study::run_benchmark; docs/benchmark.md is made from its results file).
//
//   build/bin/benchmark                                  # cornell + every scene under BOUNCE_SCENES, 256x256
//   build/bin/benchmark --scenes cornell,sponza --width 128 --height 128 --techniques irradiance_cache,sii
//   build/bin/benchmark --quick --json build/benchmark-quick.json   # a few minutes: the built-in box at 64x64
//
// Progress (scene, technique, stage, time left) goes to stderr, each scene's table to stdout,
// and the results file is rewritten after every scene. Exit status: 0, 2 for bad options
// (refused before any work), 3 when a technique failed on a scene (its message is in the
// results), 1 for any other error.
#include <bounce/io/output_files.hpp>
#include <bounce/study/benchmark.hpp>
#include <bounce/study/reference_cache.hpp>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

using namespace bounce;

namespace {

struct options {
    std::string scenes;      // comma-separated; empty: the defaults
    std::string techniques;  // comma-separated; empty: all
    std::string visibility;  // comma-separated; empty: none,rays
    std::size_t vpls = 1024;  // RSM techniques' lights a frame
    std::size_t width = 0, height = 0;  // 0: 256 (64 with --quick)
    bool quick = false;
    std::filesystem::path json;
};

std::vector<std::string> split(const std::string& list) {
    std::vector<std::string> out;
    std::size_t start = 0;
    while (start <= list.size()) {
        const std::size_t comma = std::min(list.find(',', start), list.size());
        out.push_back(list.substr(start, comma - start));
        start = comma + 1;
    }
    return out;
}

// Run from the source tree (its docs/ and include/bounce/ here), the results go to
// docs/results/benchmark.json; elsewhere --json is required.
std::filesystem::path default_json() {
    std::error_code ec;
    if (std::filesystem::is_directory("docs", ec) && std::filesystem::is_directory("include/bounce", ec))
        return "docs/results/benchmark.json";
    throw parameter_error("--json", "required when not run from the source tree (where it defaults to "
                                    "docs/results/benchmark.json)");
}

std::string duration(double s) {
    if (s < 0) return "?";
    if (s < 90) return fmt::format("{:.0f} s", s);
    if (s < 5400) return fmt::format("{:.0f} min", s / 60);
    return fmt::format("{:.1f} h", s / 3600);
}

void print_progress(const study::benchmark_progress& p) {
    fmt::print(stderr, "[{:>6} elapsed, ~{} left] scene {}/{} {}: {}: {}\n", duration(p.elapsed_s), duration(p.left_s),
               p.scene_index + 1, p.scenes, p.scene, p.technique, p.stage);
    std::fflush(stderr);
}

void print_settings(const study::benchmark_settings& s, const std::vector<std::string>& scenes,
                    const std::filesystem::path& json) {
    std::string names;
    for (const auto& n : scenes) names += (names.empty() ? "" : ", ") + n;
    fmt::print("benchmark: {} scene(s) [{}] at {}x{}{}; results -> {}\n", scenes.size(), names, s.width, s.height,
               s.quick ? " (quick)" : "", json.string());
    for (const auto q : study::all_bench_quantities) {
        const auto& n = s.samples_of(q);
        fmt::print("  {:<14} reference {:>5} spp in two halves; Monte Carlo 1 .. {} spp\n", study::quantity_name(q),
                   n.reference, n.mc_max);
    }
    fmt::print("  volume points {} of the diagonal off the surfaces; radiosity capped at {:.0f} s; RSM/SII timed "
               "as the median of {}\n",
               s.volume_offset, s.radiosity_max_seconds, s.repeat);
    std::fflush(stdout);
}

int run(const options& o, const std::string& command) {
    const std::size_t side = o.quick ? 64 : 256;
    study::benchmark_settings s =
        study::benchmark_settings::defaults(o.quick, o.width ? o.width : side, o.height ? o.height : side);
    if (!o.techniques.empty()) s.techniques = study::parse_techniques(o.techniques);
    if (!o.visibility.empty()) s.visibility = study::parse_visibilities(o.visibility);
    s.rsm_lights = o.vpls;
    s.progress = print_progress;
    s.validate();
    const std::vector<std::string> scenes =
        !o.scenes.empty() ? split(o.scenes) : o.quick ? std::vector<std::string>{"cornell"} : study::default_benchmark_scenes();
    for (const auto& a : scenes) study::check_scene_arg(a);
    const std::filesystem::path json = o.json.empty() ? default_json() : o.json;
    io::check_output_file("--json", json);
    study::check_cache_dir(study::default_cache_dir());
    print_settings(s, scenes, json);

    const auto results = study::run_benchmark(scenes, s, command, [&](const nlohmann::ordered_json& so_far) {
        io::write_text_file(json, so_far.dump(2) + "\n");
        fmt::print("{}", study::scene_summary(so_far["scenes"].back()));
        std::fflush(stdout);
    });
    io::write_text_file(json, results.dump(2) + "\n");
    fmt::print("results: {}\n", json.string());
    if (study::any_technique_failed(results)) {
        fmt::print(stderr, "benchmark: a technique failed on a scene (see 'failed' in {})\n", json.string());
        return 3;
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce: every technique on every scene against its reference and brute-force Monte Carlo"};
    options o;
    app.add_option("--scenes", o.scenes,
                   "comma-separated: cornell, scene.json paths, folders, or names under BOUNCE_SCENES "
                   "(default: cornell and every scene there; with --quick: cornell)");
    app.add_option("--techniques", o.techniques,
                   "comma-separated subset of irradiance_cache, rsm_gather, sii, sii_interleaved, radiosity, "
                   "irradiance_volume (default: all)");
    app.add_option("--visibility", o.visibility,
                   "comma-separated receiver-sender visibility of the RSM techniques, each a run: none (as "
                   "published), rays (exact, Embree occlusion rays), ism (imperfect shadow maps; SII only) "
                   "(default: none,rays)");
    app.add_option("--vpls", o.vpls, "lights a frame of the RSM techniques: SII's VPLs, the gather's disc samples")
        ->capture_default_str();
    app.add_option("--width", o.width, "image width (default 256; 64 with --quick)")->check(CLI::Range(1, 16384));
    app.add_option("--height", o.height, "image height (default 256; 64 with --quick)")->check(CLI::Range(1, 16384));
    app.add_flag("--quick", o.quick, "a few minutes: small reference sample counts, 64x64, the built-in Cornell box");
    app.add_option("--json", o.json, "results file (default docs/results/benchmark.json from the source tree)");
    CLI11_PARSE(app, argc, argv);
    std::string command;
    for (int i = 0; i < argc; ++i) command += (i ? " " : "") + std::string(argv[i]);
    try {
        return run(o, command);
    } catch (const parameter_error& e) {
        fmt::print(stderr, "benchmark: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "benchmark: {}\n", e.what());
        return 1;
    }
}
