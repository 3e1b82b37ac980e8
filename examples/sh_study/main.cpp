// sh_study: the SH toolkit measured.
//  1. Speed: SH projection (3 bands, RGB) of a probe bake's worth of 6 x size^2 cube maps
//     back to back with cpu::cube_map_sh_projector, float and binary16 texels, on 1 thread and
//     on --threads, each beside a streaming read of the same bytes (the memory ceiling), the
//     same projection on cache-resident data (compute alone), the AVX2 and portable paths,
//     and the one-off table construction (cpu::benchmark_sh_projection).
//  2. Accuracy per order (1 .. 8): radiance truncation error (Parseval) and irradiance error
//     (max and mean over the sphere, relative to the peak) for a directional light, a uniform
//     sky and a cone light, from the closed-form coefficients and through a rasterized cube
//     map; the widest non-negative Hann window's cost on the directional light; Oat's
//     gradient extrapolation (study::sh_accuracy_table, study::sh_gradient_table).
// --json PATH writes one object with the figures and provenance (study::collect_provenance).
#include "../common/cli_number_checks.hpp"
#include "../common/run_program.hpp"

#include <bounce/cpu/sh_projection_benchmark.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/study/memory_budget.hpp>
#include <bounce/study/provenance.hpp>
#include <bounce/study/sh_accuracy.hpp>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <string>

using namespace bounce;
using json = nlohmann::ordered_json;

namespace {

struct options {
    std::size_t maps = 1000, size = 64;
    int repeat = 5, threads = 0;
    std::string json_path;
};

void print_speed(const cpu::sh_projection_benchmark_result& r, const options& o, int threads) {
    const auto per_s = [](double count, double ms) { return count / (ms * 1e-3); };
    fmt::print("SH projection, 3 bands RGB, {} maps of 6 x {}^2 texels ({:.0f} MB of float texels), up to {} threads, {} path\n",
               o.maps, o.size, r.texels * 12 / 1e6, threads, r.path);
    fmt::print("  load average {:.2f} before, {:.2f} after (other processes share the cores: compare CPU time)\n",
               r.load_before, r.load_after);
    fmt::print("  best of {} runs (median in brackets); Gtexel/CPU-s from the best run's own CPU time\n", o.repeat);
    fmt::print("  {:<24} {:>3} {:>17} {:>17} {:>8} {:>8} {:>12}\n", "", "thr", "wall ms", "Gtexel/s", "GB/s", "CPU ms",
               "Gtexel/CPU-s");
    for (const auto& f : r.figures) {
        const auto& t = f.timing;
        fmt::print("  {:<24} {:>3} {:>7.2f} [{:>7.2f}] {:>7.3f} [{:>7.3f}] {:>8.2f} {:>8.1f} {:>12.3f}\n", f.name, f.threads,
                   t.best_wall_ms, t.wall_ms, per_s(r.texels, t.best_wall_ms) / 1e9, per_s(r.texels, t.wall_ms) / 1e9,
                   per_s(f.bytes, t.best_wall_ms) / 1e9, t.best_cpu_ms, per_s(r.texels, t.best_cpu_ms) / 1e9);
    }
    fmt::print("  table construction (once per size): {:.2f} ms, {:.2f} MB\n", r.table_ms, double(r.table_bytes) / 1e6);
    fmt::print("  checksums: read {:.6g}, c00 of map 0 {:.6g}\n\n", r.checksum, r.first_coefficient);
}

json speed_json(const cpu::sh_projection_benchmark_result& r) {
    const auto per_s = [](double count, double ms) { return count / (ms * 1e-3); };
    json figures = json::array();
    for (const auto& f : r.figures) {
        const auto& t = f.timing;
        figures.push_back({{"name", f.name}, {"threads", f.threads}, {"bytes", f.bytes},
                           {"wall_ms", {{"best", t.best_wall_ms}, {"median", t.wall_ms}}},
                           {"cpu_ms", {{"of_best", t.best_cpu_ms}, {"median", t.cpu_ms}}},
                           {"texels_per_s", {{"best", per_s(r.texels, t.best_wall_ms)}, {"median", per_s(r.texels, t.wall_ms)}}},
                           {"gb_per_s_best", per_s(f.bytes, t.best_wall_ms) / 1e9},
                           {"texels_per_cpu_s_best", per_s(r.texels, t.best_cpu_ms)}});
    }
    return {{"texels", r.texels}, {"table_ms", r.table_ms}, {"table_bytes", r.table_bytes}, {"figures", figures},
            {"load_average", {{"before", r.load_before}, {"after", r.load_after}}}};
}

void print_accuracy(const study::sh_environment& env, const json& rows, std::size_t size) {
    fmt::print("{}: irradiance error relative to the peak (closed-form coefficients | via a {}^2 cube map)\n", env.name, size);
    fmt::print("  order coeffs   max      mean   |   max      mean   | radiance L2\n");
    for (const auto& r : rows) {
        fmt::print("  {:>5} {:>6} {:>8.5f} {:>8.5f} | {:>8.5f} {:>8.5f} | {}\n", r["order"].get<int>(),
                   r["coefficients"].get<int>(), r["irradiance_max_rel"].get<double>(), r["irradiance_mean_rel"].get<double>(),
                   r["cube_irradiance_max_rel"].get<double>(), r["cube_irradiance_mean_rel"].get<double>(),
                   r["radiance_rel_l2"].is_null() ? std::string("-") : fmt::format("{:.4f}", r["radiance_rel_l2"].get<double>()));
        if (r.contains("hann_nonnegative")) {
            const auto& h = r["hann_nonnegative"];
            fmt::print("        widest non-negative Hann: w = {:.3f}, energy kept {:.3f}, peak kept {:.3f}, max {:.5f}, mean {:.5f}\n",
                       h["width"].get<double>(), h["energy_kept"].get<double>(), h["peak_kept"].get<double>(),
                       h["irradiance_max_rel"].get<double>(), h["irradiance_mean_rel"].get<double>());
        }
    }
}

int run(const options& o) {
    if (!o.json_path.empty()) io::check_output_file("--json", o.json_path);
    const int threads = o.threads > 0 ? o.threads : tbb::info::default_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));

    cpu::sh_projection_benchmark_settings bs;
    bs.maps = o.maps;
    bs.size = o.size;
    bs.repeat = o.repeat;
    bs.threads = threads;
    bs.memory_limit_bytes = study::available_memory_bytes();
    const auto speed = cpu::benchmark_sh_projection(bs);
    print_speed(speed, o, threads);

    json accuracy = json::object();
    for (const auto& env : study::sh_study_environments()) {
        accuracy[env.name] = study::sh_accuracy_table(env, o.size);
        print_accuracy(env, accuracy[env.name], o.size);
    }
    const json gradients = study::sh_gradient_table();
    fmt::print("gradients: sphere light r = 0.5 m, 3 m above the probe, order 2, step 0.1 m; max irradiance error / peak\n");
    for (const auto& r : gradients)
        fmt::print("  {:<18} d = {:.2f} m: stale probe {:.4f}, extrapolated {:.4f}\n", r["direction"].get<std::string>(),
                   r["distance_m"].get<double>(), r["stale_max_rel"].get<double>(), r["extrapolated_max_rel"].get<double>());

    if (!o.json_path.empty()) {
        json report = {{"technique", "sh"},
                       {"backend", "cpu"},
                       {"parameters", {{"bands", 3}, {"maps", o.maps}, {"size", o.size}, {"repeat", o.repeat},
                                       {"threads", threads}, {"path", speed.path}}}};
        report.update(speed_json(speed));
        report["error"] = accuracy;
        report["gradients"] = gradients;
        report["provenance"] = study::collect_provenance(BOUNCE_SOURCE_DIR).to_json();
        io::write_text_file(o.json_path, report.dump(2) + '\n');
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"sh_study: speed and accuracy of the SH toolkit (projection, irradiance, windowing)"};
    options o;
    app.add_option("--maps", o.maps, "cube maps projected back to back (a probe bake)")->check(CLI::Range(1, 100000));
    app.add_option("--size", o.size, "texels per cube-face edge")->check(CLI::Range(1, 1024));
    app.add_option("--repeat", o.repeat, "timed runs per figure (the best and the median are reported)")->check(CLI::Range(1, 1000));
    app.add_option("--threads", o.threads, "TBB threads (0: all)")->check(CLI::Range(0, 1024));
    app.add_option("--json", o.json_path, "write the figures and provenance to this file");
    CLI11_PARSE(app, argc, argv);
    return examples::run_program("sh_study", [&] { return run(o); }, "choose fewer --maps or a smaller --size");
}
