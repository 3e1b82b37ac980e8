// The benchmark runner's pieces: option parsing, equal-error points read off a Monte Carlo
// sweep, and one whole scene (the built-in Cornell box at 16 x 16, few samples) giving the
// results file's shape with every technique run and every figure finite.
#include <bounce/study/benchmark.hpp>
#include <bounce/study/benchmark_parts.hpp>

#include "../scoped_environment.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <unistd.h>

using namespace bounce;
using namespace bounce::study;
namespace fs = std::filesystem;

namespace {

struct temporary_folder {
    fs::path path = fs::temp_directory_path() / ("bounce-test-benchmark-" + std::to_string(::getpid()));
    temporary_folder() {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~temporary_folder() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

// Monte Carlo whose debiased error is 0.8 / sqrt(spp), SSIM 1 - 0.5 / sqrt(spp), 10 ms per spp.
bench::mc_sweep power_law_sweep(std::uint32_t max_spp) {
    bench::mc_sweep s;
    for (std::uint32_t spp = 1; spp <= max_spp; spp *= 2) {
        bench::sweep_step step;
        step.spp = spp;
        step.ms = 10.0 * spp;
        step.error.rel_rms_debiased = 0.8 / std::sqrt(double(spp));
        step.error.ssim = 1.0 - 0.5 / std::sqrt(double(spp));
        s.push_back(step);
    }
    return s;
}

benchmark_settings tiny_settings(const fs::path& cache) {
    benchmark_settings s = benchmark_settings::defaults(true, 16, 16);
    s.one_bounce = s.unoccluded = s.volume_points = {64, 16};
    s.all_bounces = {16, 8};
    s.repeat = 1;
    s.cache_dir = cache;
    return s;
}

bool finite_number(const nlohmann::ordered_json& v) { return v.is_number() && std::isfinite(v.get<double>()); }

void require_error_figures(const nlohmann::ordered_json& e) {
    for (const char* key : {"rel_rms", "rel_rms_debiased", "rel_rms_debiased_se", "ssim"}) {
        INFO(key);
        REQUIRE(finite_number(e.at(key)));
    }
    CHECK(e["rel_rms"].get<double>() >= 0.0);
    CHECK(e["ssim"].get<double>() <= 1.0);
}

// An mc_equal_error object: each figure met with a positive speedup, or skipped with a reason.
void require_equal_error(const nlohmann::ordered_json& m) {
    for (const char* measure : {"rel_rms", "ssim"}) {
        INFO(measure);
        const auto& p = m.at(measure);
        if (p.contains("skipped")) {
            CHECK(std::string(measure) == "rel_rms");  // SSIM always has a target
            continue;
        }
        REQUIRE(finite_number(p.at("speedup")));
        CHECK(p["speedup"].get<double>() > 0.0);
        CHECK(p["spp"].get<double>() >= 1.0);
        CHECK(p["ms"].get<double>() > 0.0);
        CHECK(p.at("reached").is_boolean());
    }
}

}  // namespace

TEST_CASE("techniques are parsed by name, in order, without repeats", "[benchmark]") {
    const auto t = parse_techniques("sii,irradiance_cache,sii");
    REQUIRE(t.size() == 2);
    CHECK(t[0] == bench_technique::sii);
    CHECK(t[1] == bench_technique::irradiance_cache);
    for (const auto x : all_bench_techniques) CHECK(parse_techniques(technique_name(x)) == std::vector{x});
    CHECK_THROWS_WITH(parse_techniques("sii,photon_mapping"), Catch::Contains("--techniques") &&
                                                                 Catch::Contains("unknown technique 'photon_mapping'"));
    CHECK_THROWS_WITH(parse_techniques(""), Catch::Contains("unknown technique ''"));
    CHECK(parse_visibilities("rays,none,rays") == std::vector{indirect_visibility::rays, indirect_visibility::none});
    CHECK(parse_visibilities("ism") == std::vector{indirect_visibility::ism});
    CHECK_THROWS_WITH(parse_visibilities("rays,shadow_maps"), Catch::Contains("--visibility") &&
                                                                  Catch::Contains("unknown visibility 'shadow_maps'"));
}

TEST_CASE("benchmark settings refuse what cannot run", "[benchmark]") {
    REQUIRE_NOTHROW(benchmark_settings::defaults(false, 256, 256).validate());
    REQUIRE_NOTHROW(benchmark_settings::defaults(true, 64, 64).validate());
    auto s = benchmark_settings::defaults(false, 0, 256);
    CHECK_THROWS_WITH(s.validate(), Catch::Contains("--width"));
    s = benchmark_settings::defaults(false, 256, 256);
    s.one_bounce.reference = 7;
    CHECK_THROWS_WITH(s.validate(), Catch::Contains("one_bounce") && Catch::Contains("even"));
    s = benchmark_settings::defaults(false, 256, 256);
    s.techniques.clear();
    CHECK_THROWS_WITH(s.validate(), Catch::Contains("--techniques"));
    s = benchmark_settings::defaults(false, 256, 256);
    s.visibility.clear();
    CHECK_THROWS_WITH(s.validate(), Catch::Contains("--visibility"));
    s = benchmark_settings::defaults(false, 256, 256);
    s.rsm_lights = 15;  // fewer than SII's 4x4 sub-buffers
    CHECK_THROWS_WITH(s.validate(), Catch::Contains("--vpls"));
}

TEST_CASE("a scene argument that names nothing is refused with the path tried", "[benchmark]") {
    bounce::test::scoped_environment env("BOUNCE_SCENES");
    env.set("/nowhere/scenes");
    CHECK_NOTHROW(check_scene_arg("cornell"));
    CHECK_THROWS_WITH(check_scene_arg("atlantis"),
                      Catch::Contains("--scenes") && Catch::Contains("/nowhere/scenes/atlantis/scene.json"));
    CHECK(default_benchmark_scenes() == std::vector<std::string>{"cornell"});
}

TEST_CASE("equal error is read off a Monte Carlo sweep in log-log", "[benchmark]") {
    const bench::mc_sweep sweep = power_law_sweep(8);
    // Between 2 and 4 spp: the power law puts 0.8 / sqrt(3) at 3 spp exactly.
    auto p = bench::equal_error_by_rel_rms(sweep, 0.8 / std::sqrt(3.0));
    CHECK(p.reached);
    CHECK_FALSE(p.at_first_step);
    CHECK(p.spp == Approx(3.0));
    CHECK(p.ms == Approx(30.0));
    p = bench::equal_error_by_ssim(sweep, 1.0 - 0.5 / std::sqrt(3.0));
    CHECK(p.reached);
    CHECK(p.spp == Approx(3.0));
    // Below the sweep's last error: a lower bound at its last run.
    p = bench::equal_error_by_rel_rms(sweep, 0.01);
    CHECK_FALSE(p.reached);
    CHECK(p.spp == 8.0);
    CHECK(p.ms == 80.0);
    // Above its first: one sample per pixel already does better (an upper bound).
    p = bench::equal_error_by_rel_rms(sweep, 2.0);
    CHECK(p.reached);
    CHECK(p.at_first_step);
    CHECK(p.spp == 1.0);
    // A run lost in the reference's noise (debiased error 0) continues the run before as spp^-1/2.
    bench::mc_sweep noisy = power_law_sweep(4);
    noisy[2].error.rel_rms_debiased = 0.0;
    p = bench::equal_error_by_rel_rms(noisy, 0.5);
    CHECK(p.reached);
    CHECK(p.spp == Approx(2.0 * (0.32 / 0.25)));  // 2 (0.8^2 / 2) / 0.5^2
    CHECK_THROWS_WITH(bench::equal_error_by_rel_rms(sweep, 0.0), Catch::Contains("target"));
    CHECK_THROWS_WITH(bench::equal_error_by_rel_rms({}, 0.1), Catch::Contains("sweep"));
}

TEST_CASE("one scene: every technique runs and the results have their shape", "[benchmark]") {
    temporary_folder cache;
    const benchmark_settings settings = tiny_settings(cache.path);
    const io::scene scene = io::cornell_box();
    const auto j = benchmark_scene(scene, settings);

    CHECK(j.at("scene") == "cornell");
    CHECK(j.at("triangles").get<std::size_t>() == scene.triangles.size());
    CHECK(j.at("lights").get<std::size_t>() == 1);
    REQUIRE(finite_number(j.at("bounds_diagonal")));
    for (const auto q : all_bench_quantities) {
        INFO(quantity_name(q));
        const auto& r = j.at("references").at(std::string(quantity_name(q)));
        CHECK(r.at("spp").get<std::uint32_t>() == settings.samples_of(q).reference);
        CHECK(finite_number(r.at("ms")));
        CHECK_FALSE(r.at("cached").get<bool>());
        REQUIRE(finite_number(r.at("noise_rel_rms")));
        CHECK(r["noise_rel_rms"].get<double>() > 0.0);
        const auto& mc = j.at("monte_carlo").at(std::string(quantity_name(q)));
        REQUIRE(mc.size() >= 3);
        for (const auto& step : mc) {
            CHECK(finite_number(step.at("ms")));
            CHECK(finite_number(step.at("rel_rms")));
            CHECK(finite_number(step.at("rel_rms_debiased")));
            CHECK(finite_number(step.at("ssim")));
        }
        CHECK(mc.back().at("spp").get<std::uint32_t>() == settings.samples_of(q).mc_max);
    }
    // The RSM techniques run once per visibility (none, rays: the defaults), the others once.
    std::vector<std::pair<std::string, std::string>> expected;
    for (const auto x : all_bench_techniques) {
        const std::string name(technique_name(x));
        const bool rsm = name == "rsm_gather" || name == "sii" || name == "sii_interleaved";
        expected.emplace_back(name, "none");
        if (rsm) expected.emplace_back(name, "rays");
    }
    const auto& techniques = j.at("techniques");
    REQUIRE(techniques.size() == expected.size());
    for (std::size_t k = 0; k < techniques.size(); ++k) {
        const auto& t = techniques[k];
        const auto& [name, visibility] = expected[k];
        INFO(name << ": " << t.dump());
        REQUIRE(t.at("technique") == name);
        REQUIRE(t.at("visibility") == visibility);
        REQUIRE_FALSE(t.contains("failed"));
        CHECK(t.at("quantity").is_string());
        REQUIRE(finite_number(t.at("ms")));
        CHECK(t["ms"].get<double>() > 0.0);
        CHECK(t.at("parameters").is_object());
        CHECK(t.at("counts").is_object());
        require_error_figures(t.at("error"));
        require_equal_error(t.at("mc_equal_error"));
        const bool rsm = name == "rsm_gather" || name == "sii" || name == "sii_interleaved";
        CHECK(t.contains("error_unoccluded") == rsm);
        if (rsm) {
            require_error_figures(t.at("error_unoccluded"));
            require_equal_error(t.at("mc_equal_error_unoccluded"));
        }
    }
    // Issue 29's figure per RSM technique: rays against the occluded reference over none
    // against the unoccluded one.
    REQUIRE(j.at("visibility").size() == 3);
    for (const auto& v : j["visibility"]) {
        INFO(v.dump());
        CHECK(finite_number(v.at("rays_vs_occluded")));
        REQUIRE(finite_number(v.at("none_vs_unoccluded")));
        // The debiased error is 0 where the frame is within the reference's own noise (the
        // gather without visibility, its clamp compensated, on this small frame): no ratio.
        if (v["none_vs_unoccluded"].get<double>() > 0.0)
            CHECK(finite_number(v.at("ratio")));
        else
            CHECK(v.at("ratio").is_null());
    }
    CHECK(techniques[0]["counts"]["records"].get<std::size_t>() > 0);
    CHECK(techniques[7]["counts"]["elements"].get<std::size_t>() > 0);
    CHECK(techniques[8]["counts"]["probes"].get<std::size_t>() > 0);

    // The references come from the cache the second time.
    benchmark_settings again = settings;
    again.techniques = {bench_technique::sii};
    const auto k = benchmark_scene(scene, again);
    CHECK(k.at("references").at("one_bounce").at("cached").get<bool>());
    CHECK(k.at("references").at("unoccluded").at("cached").get<bool>());
    CHECK(k.at("references").at("one_bounce").at("noise_rel_rms") == j.at("references").at("one_bounce").at("noise_rel_rms"));
}

TEST_CASE("the results file carries its provenance and settings", "[benchmark]") {
    temporary_folder cache;
    benchmark_settings settings = tiny_settings(cache.path);
    settings.techniques = {bench_technique::rsm_gather};
    settings.visibility = {indirect_visibility::rays};
    std::size_t scenes_seen = 0;
    const auto j = run_benchmark({"cornell"}, settings, "benchmark --test",
                                 [&](const nlohmann::ordered_json& so_far) { scenes_seen = so_far.at("scenes").size(); });
    CHECK(scenes_seen == 1);
    const auto& p = j.at("provenance");
    for (const char* key : {"commit", "date", "cpu", "embree"}) CHECK(p.at(key).is_string());
    CHECK(p.at("cores").get<unsigned>() > 0);
    CHECK(p.at("command") == "benchmark --test");
    CHECK(p.at("settings").at("width") == 16);
    CHECK(p.at("settings").at("quick") == true);
    CHECK(p.at("settings").at("reference_spp").at("one_bounce") == 64);
    CHECK(p.at("settings").at("visibility") == nlohmann::ordered_json::array({"rays"}));
    REQUIRE(j.at("scenes").size() == 1);
    REQUIRE(j["scenes"][0]["techniques"].size() == 1);
    CHECK(j["scenes"][0]["techniques"][0]["visibility"] == "rays");
    CHECK(j["scenes"][0]["visibility"].empty());  // no run without visibility to compare with
    CHECK_FALSE(any_technique_failed(j));
    CHECK_FALSE(scene_summary(j["scenes"][0]).empty());
    CHECK_THROWS_WITH(run_benchmark({"cornell", "no-such-scene-here"}, settings, ""), Catch::Contains("no-such-scene-here"));
}

TEST_CASE("the visibility error split: the frame without visibility in the occluded reference's units, what visibility changes, the references' ratio",
          "[benchmark]") {
    // Noise-free halves (a == b); the occluded reference is half the unoccluded one on the
    // right half of the image. Both frames 10% above their references: the frame without
    // visibility errs 0.1 |r_u| / |r_o| in the occluded units, visibility changes
    // 0.1 |r_o - r_u| / |r_o|, and the references' ratio is |r_u| / |r_o|.
    const std::size_t w = 8, h = 4;
    bench::halves_reference occ, unocc;
    for (auto* r : {&occ, &unocc}) r->a = r->b = r->mean = image<glm::vec3>(w, h);
    image<glm::vec3> rays(w, h), none(w, h);
    double uu = 0, oo = 0, dd = 0;
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            const float u = 1.f + float(x), o = x < w / 2 ? u : 0.5f * u;
            unocc.a(x, y) = unocc.b(x, y) = glm::vec3(u);
            occ.a(x, y) = occ.b(x, y) = glm::vec3(o);
            none(x, y) = glm::vec3(1.1f * u);
            rays(x, y) = glm::vec3(1.1f * o);
            uu += double(u) * u, oo += double(o) * o, dd += 0.01 * double(o - u) * (o - u);
        }
    const auto s = bench::visibility_error_split(rays.view(), none.view(), occ, unocc, {});
    CHECK(s["none_error_in_occluded_units"].get<double>() == Approx(0.1 * std::sqrt(uu / oo)).epsilon(1e-5));
    CHECK(s["visibility_change"].get<double>() == Approx(std::sqrt(dd / oo)).epsilon(1e-5));
    CHECK(s["references_rms_ratio"].get<double>() == Approx(std::sqrt(uu / oo)).epsilon(1e-6));
}
