// The benchmark runner: settings, scenes, the clock, and one scene's references, Monte Carlo
// sweeps and techniques gathered into the results file (benchmark.hpp).
#include <bounce/study/benchmark.hpp>
#include <bounce/study/benchmark_parts.hpp>

#include <bounce/embree/accel.hpp>
#include <bounce/study/provenance.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/study/stage_timer.hpp>

#include <fmt/core.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>

namespace bounce::study {

namespace fs = std::filesystem;
using bench::ojson;

namespace {

constexpr std::array<std::string_view, 6> technique_names = {"irradiance_cache", "rsm_gather",     "sii",
                                                             "sii_interleaved",  "radiosity",      "irradiance_volume"};
constexpr std::array<std::string_view, 4> quantity_names = {"one_bounce", "unoccluded", "all_bounces", "volume_points"};

bool is_rsm(bench_technique t) {
    return t == bench_technique::rsm_gather || t == bench_technique::sii || t == bench_technique::sii_interleaved;
}

// ---- work units, for the time left ---------------------------------------------------------
// One unit: one sample per pixel of the one-bounce estimator over the view. The others'
// relative costs are rough (an unoccluded ray crosses every surface on its way; a path
// makes a few bounces, each with a shadow ray); the estimate adapts as the run measures.

double sample_cost(bench_quantity q) {
    switch (q) {
        case bench_quantity::unoccluded: return 2.0;
        case bench_quantity::all_bounces: return 6.0;
        default: return 1.0;
    }
}
double reference_work(const benchmark_settings& s, bench_quantity q) { return sample_cost(q) * s.samples_of(q).reference; }
double sweep_work(const benchmark_settings& s, bench_quantity q) { return sample_cost(q) * 2.0 * s.samples_of(q).mc_max; }
double technique_work(bench_technique t) {
    return t == bench_technique::irradiance_cache || t == bench_technique::radiosity ? 64.0
           : t == bench_technique::irradiance_volume                                ? 32.0
                                                                                    : 4.0;
}
double scene_work(const benchmark_settings& s) {
    double w = 0;
    for (const bench_quantity q : bench::quantities_for(s.techniques)) w += reference_work(s, q) + sweep_work(s, q);
    for (const bench_technique t : s.techniques) w += technique_work(t) * double(is_rsm(t) ? s.visibility.size() : 1);
    return w;
}

// The one-minute load average (/proc/loadavg), or -1 when unknown: how busy the machine was.
double load_average() {
    std::ifstream in("/proc/loadavg");
    double l = -1;
    return in >> l ? l : -1.0;
}

// User plus system time of this process so far, seconds.
double cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

}  // namespace

std::string_view technique_name(bench_technique t) { return technique_names[std::size_t(t)]; }
std::string_view quantity_name(bench_quantity q) { return quantity_names[std::size_t(q)]; }

namespace {

// The comma-separated names of `list`, each turned into a T by `parse` (nullopt: unknown), in
// the order given and without repeats; parameter_error naming `option` for an unknown name
// (listing `known`). An empty list is one empty, unknown name.
template <class T, class Parse>
std::vector<T> parse_list(std::string_view list, const char* option, const char* what, Parse parse,
                          const std::string& known) {
    std::vector<T> out;
    std::size_t start = 0;
    while (start <= list.size()) {
        const std::size_t comma = std::min(list.find(',', start), list.size());
        const std::string_view name = list.substr(start, comma - start);
        const std::optional<T> t = parse(name);
        if (!t)
            throw parameter_error(option, fmt::format("unknown {} '{}' (known: {})", what, name, known));
        if (std::find(out.begin(), out.end(), *t) == out.end()) out.push_back(*t);
        start = comma + 1;
    }
    return out;
}

}  // namespace

std::vector<bench_technique> parse_techniques(std::string_view list) {
    std::string known;
    for (const auto n : technique_names) known += (known.empty() ? "" : ", ") + std::string(n);
    return parse_list<bench_technique>(
        list, "--techniques", "technique",
        [](std::string_view name) -> std::optional<bench_technique> {
            const auto it = std::find(technique_names.begin(), technique_names.end(), name);
            if (it == technique_names.end()) return std::nullopt;
            return bench_technique(it - technique_names.begin());
        },
        known);
}

std::vector<indirect_visibility> parse_visibilities(std::string_view list) {
    std::string known;
    for (const auto v : indirect_visibilities) known += (known.empty() ? "" : ", ") + std::string(visibility_name(v));
    return parse_list<indirect_visibility>(list, "--visibility", "visibility", parse_visibility, known);
}

// ---- settings ---------------------------------------------------------------------------------

benchmark_settings benchmark_settings::defaults(bool quick, std::size_t width, std::size_t height) {
    benchmark_settings s;
    s.width = width;
    s.height = height;
    s.quick = quick;
    if (quick) {
        s.one_bounce = {256, 128};
        s.unoccluded = {256, 128};
        s.all_bounces = {64, 32};
        s.volume_points = {256, 128};
        s.radiosity_max_seconds = 20;
    }
    return s;
}

const quantity_samples& benchmark_settings::samples_of(bench_quantity q) const {
    switch (q) {
        case bench_quantity::unoccluded: return unoccluded;
        case bench_quantity::all_bounces: return all_bounces;
        case bench_quantity::volume_points: return volume_points;
        default: return one_bounce;
    }
}

void benchmark_settings::validate() const {
    require(width >= 1 && width <= 16384, "--width", "must lie in [1, 16384]");
    require(height >= 1 && height <= 16384, "--height", "must lie in [1, 16384]");
    require(!techniques.empty(), "--techniques", "names no technique");
    require(!visibility.empty(), "--visibility", "names no visibility");
    require(rsm_lights >= 16 && rsm_lights <= (std::size_t(1) << 24), "--vpls",
            "must lie in [16, 2^24] (at least one light for each of SII's 4x4 sub-buffers)");
    for (const bench_quantity q : all_bench_quantities) {
        const quantity_samples& n = samples_of(q);
        const std::string what = "reference samples of " + std::string(quantity_name(q));
        require(n.reference >= 2 && n.reference % 2 == 0 && n.reference <= (1u << 20), what.c_str(),
                "must be even and in [2, 2^20] (two halves)");
        require(n.mc_max >= 1 && n.mc_max <= (1u << 20), ("Monte Carlo samples of " + std::string(quantity_name(q))).c_str(),
                "must lie in [1, 2^20]");
    }
    require(std::isfinite(volume_offset) && volume_offset > 0.0 && volume_offset < 1.0, "volume_offset",
            "must lie in (0, 1) (a fraction of the scene's diagonal)");
    require(std::isfinite(radiosity_max_seconds) && radiosity_max_seconds > 0, "radiosity_max_seconds", "must be positive");
    require(repeat >= 1 && repeat <= 1000, "repeat", "must lie in [1, 1000]");
}

nlohmann::ordered_json benchmark_settings::to_json() const {
    ojson spp = ojson::object(), mc = ojson::object();
    for (const bench_quantity q : all_bench_quantities) {
        spp[std::string(quantity_name(q))] = samples_of(q).reference;
        mc[std::string(quantity_name(q))] = samples_of(q).mc_max;
    }
    ojson names = ojson::array();
    for (const bench_technique t : techniques) names.push_back(std::string(technique_name(t)));
    ojson visibilities = ojson::array();
    for (const indirect_visibility v : visibility) visibilities.push_back(std::string(visibility_name(v)));
    return {{"width", width},
            {"height", height},
            {"quick", quick},
            {"reference_spp", spp},
            {"mc_max_spp", mc},
            {"techniques", names},
            {"visibility", visibilities},
            {"rsm_lights", rsm_lights},
            {"volume_offset", volume_offset},
            {"radiosity_max_seconds", radiosity_max_seconds},
            {"repeat", repeat}};
}

// ---- scenes -------------------------------------------------------------------------------------

void check_scene_arg(std::string_view arg) {
    if (arg == "cornell") return;
    require(!arg.empty(), "--scenes", "names an empty scene");
    const fs::path here(arg);
    std::error_code ec;
    if (fs::exists(here, ec)) return;
    const fs::path under = io::scenes_dir() / here / "scene.json";
    if (fs::exists(under, ec)) return;
    throw parameter_error("--scenes", "no scene '" + std::string(arg) + "': neither " + here.string() + " nor " +
                                          under.string() + " exists (BOUNCE_SCENES sets the scenes folder)");
}

std::vector<std::string> default_benchmark_scenes() {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(io::scenes_dir(), ec))
        if (e.is_directory(ec) && fs::exists(e.path() / "scene.json", ec)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    names.insert(names.begin(), "cornell");
    return names;
}

// ---- the clock ------------------------------------------------------------------------------------

namespace bench {

run_clock::run_clock(std::function<void(const benchmark_progress&)> sink, std::size_t scenes, double work_per_scene)
    : sink_(std::move(sink)), scenes_(std::max<std::size_t>(scenes, 1)),
      total_(std::max(1.0, work_per_scene * double(std::max<std::size_t>(scenes, 1)))) {}

void run_clock::begin_scene(std::string name, std::size_t index) {
    scene_ = std::move(name);
    index_ = index;
}

double run_clock::elapsed_s() const { return ms_since(start_) / 1e3; }

void run_clock::report(const std::string& technique, const std::string& stage) const {
    if (!sink_) return;
    benchmark_progress p;
    p.scene = scene_;
    p.scene_index = index_;
    p.scenes = scenes_;
    p.technique = technique;
    p.stage = stage;
    p.elapsed_s = elapsed_s();
    // Time per unit of work so far, times the units left; unknown before the first units.
    if (done_ > 0.0) p.left_s = p.elapsed_s / done_ * std::max(0.0, total_ - done_);
    sink_(p);
}

std::vector<bench_quantity> quantities_for(const std::vector<bench_technique>& techniques) {
    std::vector<bench_quantity> out;
    auto uses = [&](auto pred) { return std::any_of(techniques.begin(), techniques.end(), pred); };
    if (uses([](bench_technique t) { return t == bench_technique::irradiance_cache || is_rsm(t); }))
        out.push_back(bench_quantity::one_bounce);
    if (uses([](bench_technique t) { return is_rsm(t); })) out.push_back(bench_quantity::unoccluded);
    if (uses([](bench_technique t) { return t == bench_technique::radiosity; })) out.push_back(bench_quantity::all_bounces);
    if (uses([](bench_technique t) { return t == bench_technique::irradiance_volume; }))
        out.push_back(bench_quantity::volume_points);
    return out;
}

}  // namespace bench

// ---- one scene ---------------------------------------------------------------------------------------

namespace {

using bench::halves_reference;
using bench::mc_sweep;

struct quantity_figures {
    halves_reference reference;
    mc_sweep sweep;
};

bench::technique_run run_technique(const bench::scene_setup& s, bench_technique t, indirect_visibility visibility,
                                   const gbuffer_view<float>* points) {
    switch (t) {
        case bench_technique::irradiance_cache: return bench::run_irradiance_cache(s);
        case bench_technique::radiosity: return bench::run_radiosity(s);
        case bench_technique::irradiance_volume: return bench::run_irradiance_volume(s, *points);
        default: return bench::run_rsm_sii(s, t, visibility);
    }
}

// A technique's entry: its run, its error against its quantity's reference (and, for the
// RSM techniques, against the unoccluded one beside it), and Monte Carlo's time at equal error.
ojson technique_entry(const bench::scene_setup& s, const bench::technique_run& r,
                      const std::map<bench_quantity, quantity_figures>& figures) {
    ojson j = {{"technique", std::string(technique_name(r.technique))},
               {"visibility", std::string(visibility_name(r.visibility))},
               {"quantity", std::string(quantity_name(r.quantity))},
               {"ms", bench::number_or_null(r.ms)},
               {"parameters", r.parameters},
               {"counts", r.counts},
               {"timings_ms", r.timings_ms}};
    const quantity_figures& f = figures.at(r.quantity);
    const bench::measured_error e = bench::measure_error(r.radiance.view(), f.reference, s.mask.view());
    j["error"] = e.to_json();
    std::optional<bench::measured_error> eu;
    if (is_rsm(r.technique)) {
        eu = bench::measure_error(r.radiance.view(), figures.at(bench_quantity::unoccluded).reference, s.mask.view());
        j["error_unoccluded"] = eu->to_json();
    }
    j["mc_equal_error"] = bench::mc_equal_error_json(f.sweep, e, r.ms);
    if (eu) j["mc_equal_error_unoccluded"] = bench::mc_equal_error_json(figures.at(bench_quantity::unoccluded).sweep, *eu, r.ms);
    return j;
}

// Issue 29's headline per RSM technique run both ways: its debiased error with rays against
// the occluded reference, without visibility against the unoccluded one, and their ratio
// (at most 1.2 when visibility adds no error of its own).
ojson visibility_figures(const ojson& techniques) {
    ojson out = ojson::array();
    const auto find = [&](const std::string& name, std::string_view v) -> const ojson* {
        for (const auto& t : techniques)
            if (t["technique"] == name && t["visibility"] == v && !t.contains("failed")) return &t;
        return nullptr;
    };
    for (const auto& t : techniques) {
        if (t["visibility"] != "rays" || t.contains("failed")) continue;
        const std::string name = t["technique"];
        const ojson* plain = find(name, "none");
        if (!plain) continue;
        const auto& with = t["error"]["rel_rms_debiased"];
        const auto& without = (*plain)["error_unoccluded"]["rel_rms_debiased"];
        ojson e = {{"technique", name}, {"rays_vs_occluded", with}, {"none_vs_unoccluded", without}};
        e["ratio"] = with.is_number() && without.is_number() && without.get<double>() > 0
                         ? bench::number_or_null(with.get<double>() / without.get<double>())
                         : ojson();
        out.push_back(e);
    }
    return out;
}

ojson scene_with(const io::scene& scene, const benchmark_settings& settings, bench::run_clock& clock) {
    clock.report("setup", "bvh and G-buffer");
    const embree::accel bvh(scene);
    const bench::scene_setup s = bench::make_scene_setup(scene, bvh, settings, clock);
    ojson out = {{"scene", scene.name},
                 {"triangles", scene.triangles.size()},
                 {"lights", scene.lights.size()},
                 {"bounds_diagonal", bench::number_or_null(s.diagonal)}};
    std::optional<gbuffer<float>> points_storage;
    std::optional<gbuffer_view<float>> points;
    std::map<bench_quantity, quantity_figures> figures;
    ojson references = ojson::object(), monte_carlo = ojson::object();
    for (const bench_quantity q : bench::quantities_for(settings.techniques)) {
        const std::string name(quantity_name(q));
        clock.report("reference", name);
        quantity_figures f;
        switch (q) {
            case bench_quantity::one_bounce: f.reference = bench::one_bounce_reference(s); break;
            case bench_quantity::unoccluded: f.reference = bench::unoccluded_reference(s); break;
            case bench_quantity::all_bounces: f.reference = bench::all_bounces_reference(s); break;
            case bench_quantity::volume_points:
                points_storage = bench::volume_points(s);
                points = points_storage->view();
                f.reference = bench::volume_points_reference(s, *points);
                break;
        }
        clock.advance(reference_work(settings, q));
        references[name] = f.reference.to_json();
        f.sweep = bench::quantity_monte_carlo(s, q, f.reference, points ? &*points : nullptr);
        clock.advance(sweep_work(settings, q));
        monte_carlo[name] = bench::sweep_to_json(f.sweep);
        figures.emplace(q, std::move(f));
    }
    ojson techniques = ojson::array();
    for (const bench_technique t : settings.techniques) {
        const std::string name(technique_name(t));
        const std::vector<indirect_visibility> none{indirect_visibility::none};
        for (const indirect_visibility v : is_rsm(t) ? settings.visibility : none) {
            try {
                techniques.push_back(technique_entry(s, run_technique(s, t, v, points ? &*points : nullptr), figures));
            } catch (const bounce::error& e) {
                // Reported, not fatal: the other techniques' figures still count.
                clock.report(name, std::string("FAILED: ") + e.what());
                techniques.push_back({{"technique", name}, {"visibility", visibility_name(v)}, {"failed", e.what()}});
            }
            clock.advance(technique_work(t));
        }
    }
    out["visibility"] = visibility_figures(techniques);
    out["references"] = references;
    out["techniques"] = techniques;
    out["monte_carlo"] = monte_carlo;
    return out;
}

}  // namespace

nlohmann::ordered_json benchmark_scene(const io::scene& scene, const benchmark_settings& settings, std::size_t index,
                                       std::size_t count) {
    settings.validate();
    bench::run_clock clock(settings.progress, count, scene_work(settings));
    clock.begin_scene(scene.name, index);
    return scene_with(scene, settings, clock);
}

nlohmann::ordered_json run_benchmark(const std::vector<std::string>& scene_args, const benchmark_settings& settings,
                                     const std::string& command,
                                     const std::function<void(const nlohmann::ordered_json&)>& after_scene) {
    settings.validate();
    require(!scene_args.empty(), "--scenes", "names no scene");
    for (const auto& a : scene_args) check_scene_arg(a);
    check_cache_dir(settings.cache_dir.empty() ? default_cache_dir() : settings.cache_dir);
    bench::run_clock clock(settings.progress, scene_args.size(), scene_work(settings));
    // Every scene loads before the work, so that a broken scene.json fails at once.
    std::vector<io::scene> scenes;
    for (std::size_t k = 0; k < scene_args.size(); ++k) {
        clock.begin_scene(scene_args[k], k);
        clock.report("setup", "loading");
        scenes.push_back(io::load_scene_arg(scene_args[k]));
    }
    const double load_start = load_average(), cpu_start = cpu_seconds();
    const provenance p = collect_provenance();
    ojson results = {{"provenance",
                      {{"commit", p.commit},
                       {"date", p.date},
                       {"cpu", p.cpu},
                       {"cores", p.cores},
                       {"embree", p.embree_isa},
                       {"command", command},
                       {"settings", settings.to_json()}}},
                     {"scenes", ojson::array()}};
    for (std::size_t k = 0; k < scenes.size(); ++k) {
        clock.begin_scene(scenes[k].name, k);
        results["scenes"].push_back(scene_with(scenes[k], settings, clock));
        // How much of the machine the run had: CPU time over wall time near the core count
        // means the timings are the machine's; far below it, others shared the cores.
        results["provenance"]["machine_use"] = {{"wall_s", clock.elapsed_s()},
                                                {"cpu_s", cpu_seconds() - cpu_start},
                                                {"load_average_start", load_start},
                                                {"load_average_end", load_average()}};
        if (after_scene) after_scene(results);
    }
    return results;
}

bool any_technique_failed(const nlohmann::ordered_json& results) {
    for (const auto& scene : results.at("scenes"))
        for (const auto& t : scene.at("techniques"))
            if (t.contains("failed")) return true;
    return false;
}

std::string scene_summary(const nlohmann::ordered_json& scene) {
    auto num = [](const ojson& v, const char* format) {
        return v.is_number() ? fmt::format(fmt::runtime(format), v.get<double>()) : std::string("-");
    };
    auto speedup = [&](const ojson& m) {
        if (!m.contains("speedup")) return std::string("-");
        const std::string bound = !m.contains("bound") ? "" : m["bound"] == "lower" ? ">" : "<";
        return bound + num(m["speedup"], "{:.2f}") + "x";
    };
    std::string out = fmt::format("{} ({} triangles, {} lights)\n", scene.at("scene").get<std::string>(),
                                  scene.at("triangles").get<std::size_t>(), scene.at("lights").get<std::size_t>());
    out += fmt::format("  {:<21} {:>10} {:>8} {:>9} {:>6} {:>9} {:>9}  {}\n", "technique", "ms", "rel_rms", "debiased",
                       "ssim", "mc x rms", "mc x ssim", "unoccluded rel_rms / mc x");
    for (const auto& t : scene.at("techniques")) {
        const std::string visibility = t.value("visibility", "none");
        const std::string name = fmt::format("{}{}{}", t.at("technique").get<std::string>(),
                                             visibility == "none" ? "" : "+", visibility == "none" ? "" : visibility);
        if (t.contains("failed")) {
            out += fmt::format("  {:<21} failed: {}\n", name, t["failed"].get<std::string>());
            continue;
        }
        const auto& e = t.at("error");
        const auto& m = t.at("mc_equal_error");
        out += fmt::format("  {:<21} {:>10} {:>8} {:>9} {:>6} {:>9} {:>9}", name, num(t["ms"], "{:.1f}"),
                           num(e["rel_rms"], "{:.4f}"), num(e["rel_rms_debiased"], "{:.4f}"), num(e["ssim"], "{:.3f}"),
                           speedup(m["rel_rms"]), speedup(m["ssim"]));
        if (t.contains("error_unoccluded"))
            out += fmt::format("  {} / {}", num(t["error_unoccluded"]["rel_rms"], "{:.4f}"),
                               speedup(t["mc_equal_error_unoccluded"]["rel_rms"]));
        out += "\n";
    }
    if (scene.contains("visibility"))
        for (const auto& v : scene["visibility"])
            out += fmt::format("  visibility {}: rays vs occluded {} / none vs unoccluded {} = {} (at most 1.2)\n",
                               v["technique"].get<std::string>(), num(v["rays_vs_occluded"], "{:.4f}"),
                               num(v["none_vs_unoccluded"], "{:.4f}"), num(v["ratio"], "{:.2f}"));
    for (const auto& [q, r] : scene.at("references").items())
        out += fmt::format("  reference {}: {} spp, noise {}{}\n", q, r["spp"].get<std::uint32_t>(),
                           num(r["noise_rel_rms"], "{:.4f}"), r["cached"].get<bool>() ? " (cached)" : "");
    return out;
}

}  // namespace bounce::study
