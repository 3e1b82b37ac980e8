// The run report: the stage timer's medians, and the JSON object every example writes.
#include "../io/scratch_folder.hpp"

#include <bounce/io/output_files.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <thread>

using namespace bounce;
using bounce::test::scratch_folder;

TEST_CASE("the stage median is the middle sample, or the mean of the middle two", "[study][report][timer]") {
    pcg32 rng(41);
    const int n = GENERATE(range(1, 60));
    study::stage_timer timer;
    std::vector<double> xs;
    for (int i = 0; i < n; ++i) {
        xs.push_back(100.0 * rng.next_double());
        timer.add_sample("splat", xs.back());
    }
    std::sort(xs.begin(), xs.end());
    const double median = n % 2 ? xs[std::size_t(n / 2)] : 0.5 * (xs[std::size_t(n / 2 - 1)] + xs[std::size_t(n / 2)]);
    CHECK(timer.median_ms("splat") == median);
    CHECK(timer.repeats() == std::size_t(n));
    CHECK(timer.samples("splat").size() == std::size_t(n));
    // Half the samples lie at or below the median, half at or above.
    const auto below = std::count_if(xs.begin(), xs.end(), [&](double x) { return x <= median; });
    const auto above = std::count_if(xs.begin(), xs.end(), [&](double x) { return x >= median; });
    CHECK(2 * below >= n);
    CHECK(2 * above >= n);
}

TEST_CASE("the stage timer records scopes and calls in first-timed order", "[study][report][timer]") {
    study::stage_timer timer;
    for (int r = 0; r < 3; ++r) {
        auto total = timer.measure("total");
        {
            auto g = timer.measure("gbuffer");
            std::this_thread::sleep_for(std::chrono::microseconds(100));
        }
        const int v = timer.time("interpolate", [] { return 42; });
        CHECK(v == 42);
        timer.time("scan", [] {});
        const double ms = total.stop();
        CHECK(ms >= 0.0);
        CHECK(total.stop() == 0.0);  // a stopped scope records nothing more
    }
    CHECK(timer.stages() == std::vector<std::string>{"total", "gbuffer", "interpolate", "scan"});
    for (const auto& s : timer.stages()) {
        CHECK(timer.samples(s).size() == 3);
        for (double ms : timer.samples(s)) CHECK(ms >= 0.0);
    }
    // steady_clock: a stage enclosing another takes at least as long, sample by sample.
    const auto total = timer.samples("total"), g = timer.samples("gbuffer");
    for (std::size_t i = 0; i < 3; ++i) CHECK(total[i] >= g[i]);
    CHECK(timer.repeats() == 3);
    CHECK_THROWS_AS(timer.median_ms("never"), parameter_error);
    CHECK_THROWS_AS(timer.add_sample("x", -1.0), parameter_error);
    CHECK_THROWS_AS(timer.add_sample("x", std::numeric_limits<double>::quiet_NaN()), parameter_error);
    CHECK_THROWS_AS(timer.add_sample("", 1.0), parameter_error);
    timer.clear();
    CHECK(timer.stages().empty());
}

namespace {
study::run_report sample_report() {
    study::run_report r;
    r.technique = "ic_splatting";
    r.scene = "cornell";
    r.width = 512;
    r.height = 384;
    r.backend = "cpu";
    r.parameters["a"] = 0.15;
    r.parameters["weight"] = "ward";
    study::stage_timer t;
    for (double ms : {3.0, 1.0, 2.0}) t.add_sample("gbuffer", ms);
    for (double ms : {10.0, 30.0, 20.0}) t.add_sample("total", ms);
    r.set_timings(t);
    r.error = study::error_figures{0.041, 0.8, 12.5, 1000};
    r.set_count("records", 1834);
    r.set_count("vpls", 0);
    r.set_count("records", 1835);  // replaces
    return r;
}
}  // namespace

TEST_CASE("the run report is the object every example writes", "[study][report]") {
    const auto j = sample_report().to_json();
    std::vector<std::string> keys;
    for (const auto& [k, v] : j.items()) keys.push_back(k);
    CHECK(keys == std::vector<std::string>{"technique", "scene", "width", "height", "backend", "parameters", "repeat",
                                           "timings_ms", "error", "records", "vpls"});
    CHECK(j["technique"] == "ic_splatting");
    CHECK(j["width"] == 512);
    CHECK(j["height"] == 384);
    CHECK(j["parameters"]["a"] == 0.15);
    CHECK(j["repeat"] == 3);
    CHECK(j["timings_ms"]["gbuffer"] == 2.0);  // medians
    CHECK(j["timings_ms"]["total"] == 20.0);
    CHECK(j["error"]["rel_rms"] == 0.041);
    CHECK(j["error"]["max_abs"] == 0.8);
    CHECK(j["error"]["sum_sq"] == 12.5);
    CHECK(j["records"] == 1835);
    CHECK(j["vpls"] == 0);
}

TEST_CASE("a run that used GL names its renderer after the backend, and one without GL does not", "[study][report]") {
    auto r = sample_report();
    CHECK_FALSE(r.to_json().contains("gl_renderer"));
    r.gl_renderer = "llvmpipe (LLVM 15.0.6, 256 bits)";
    const auto j = r.to_json();
    std::vector<std::string> keys;
    for (const auto& [k, v] : j.items()) keys.push_back(k);
    REQUIRE(keys.size() > 5);
    CHECK(keys[4] == "backend");
    CHECK(keys[5] == "gl_renderer");
    CHECK(j["gl_renderer"] == "llvmpipe (LLVM 15.0.6, 256 bits)");
}

TEST_CASE("the run report writes valid JSON, null for non-finite figures, and no error without a reference",
          "[study][report]") {
    scratch_folder dir;
    auto r = sample_report();
    r.error->rel_rms = std::numeric_limits<double>::infinity();
    const auto file = dir.path() / "sub" / "run.json";
    r.write(file);
    std::ifstream in(file);
    const auto j = nlohmann::json::parse(in);
    CHECK(j["error"]["rel_rms"].is_null());
    CHECK(j["error"]["max_abs"] == 0.8);
    r.error.reset();
    CHECK_FALSE(r.to_json().contains("error"));
}

TEST_CASE("an incomplete or clashing report is refused and an unwritable file raises io::output_error",
          "[study][report][bad-input]") {
    auto r = sample_report();
    r.technique.clear();
    CHECK_THROWS_AS(r.to_json(), parameter_error);
    r = sample_report();
    r.width = 0;
    CHECK_THROWS_AS(r.to_json(), parameter_error);
    r = sample_report();
    r.set_count("width", 3);
    CHECK_THROWS_AS(r.to_json(), parameter_error);
    r = sample_report();
    r.parameters = 5;
    CHECK_THROWS_AS(r.to_json(), parameter_error);

    scratch_folder dir;
    const auto blocker = dir.write("file", "x");
    const auto target = blocker / "run.json";  // a file where a folder should be
    try {
        sample_report().write(target);
        FAIL("wrote under a regular file");
    } catch (const io::output_error& e) {
        CHECK(e.file() == target);
    }
    // A device that takes the open but fails the write: the failure must not pass as success.
    if (std::filesystem::exists("/dev/full")) CHECK_THROWS_AS(sample_report().write("/dev/full"), io::output_error);
}
