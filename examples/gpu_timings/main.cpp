// gpu_timings: GPU times of a fixed set of GL passes (G-buffer, direct light, IC splat and
// normalize, RSM maps, RSM gather and SII plain and 8x8 interleaved, the radiosity shot and
// item buffer, the volume lookup, the hemisphere raster) on the built-in Cornell box, in a
// headless EGL context, written to one JSON results file (docs/gpu-timings.md). Links the GL
// adapter alone: scripts/gpu_timings.sh runs it from a build made elsewhere.
//
// Exit codes: 0 done; 3 no OpenGL 4.5 context could be made (one line on stderr says why);
// 2 bad options or an output that cannot be written; 1 anything else.
#include "../common/run_program.hpp"
#include "gpu_timings_commit.hpp"
#include "timed_passes.hpp"

#include <bounce/errors.hpp>
#include <bounce/gl/context.hpp>

#include <CLI/CLI.hpp>
#include <epoxy/gl.h>
#include <fmt/chrono.h>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace bounce;
using json = nlohmann::ordered_json;

namespace {

/// No OpenGL 4.5 context: EGL found no platform, device or driver that gives one.
struct no_gl_context : gl::gl_error {
    using gl::gl_error::gl_error;
};

std::vector<std::pair<std::size_t, std::size_t>> parse_sizes(const std::string& text) {
    std::vector<std::pair<std::size_t, std::size_t>> sizes;
    std::size_t at = 0;
    while (at <= text.size()) {
        const std::size_t comma = std::min(text.find(',', at), text.size());
        const std::string item = text.substr(at, comma - at);
        std::size_t w = 0, h = 0;
        char x = 0, rest = 0;
        if (std::sscanf(item.c_str(), "%zu%c%zu%c", &w, &x, &h, &rest) != 3 || x != 'x' || w == 0 || h == 0 ||
            w > 16384 || h > 16384)
            throw parameter_error("--sizes", "expected WxH[,WxH...] with sides in 1..16384, got \"" + item + "\"");
        sizes.emplace_back(w, h);
        at = comma + 1;
    }
    return sizes;
}

gl::context make_context(gl::egl_platform platform) {
    try {
        return gl::context({.platform = platform});
    } catch (const gl::gl_error& e) {
        // One line: the adapter lists each platform tried on a line of its own ("\n  - ...").
        std::istringstream lines(e.what());
        std::string line, part;
        for (int i = 0; std::getline(lines, part); ++i) {
            part.erase(0, part.find_first_not_of(' '));
            line += (i == 0 ? "" : i == 1 ? " " : "; ") + part;
        }
        throw no_gl_context("no OpenGL 4.5 context: " + line);
    }
}

std::string gl_string(GLenum name) {
    const auto* s = reinterpret_cast<const char*>(glGetString(name));
    return s ? s : "";
}

std::string utc_now() { return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", fmt::gmtime(std::time(nullptr))); }

json pass_json(const gpu_timings::pass_timing& p) {
    const gpu_timings::summary s = gpu_timings::summarize(p.ms);
    json j{{"name", p.name},           {"method", p.method},     {"covers", p.covers},
           {"repetitions", p.ms.size()}, {"median_ms", s.median_ms}, {"min_ms", s.min_ms},
           {"max_ms", s.max_ms},       {"spread_ms", s.max_ms - s.min_ms}, {"samples_ms", p.ms}};
    if (!p.wall_ms.empty()) {
        j["wall_median_ms"] = gpu_timings::summarize(p.wall_ms).median_ms;
        j["wall_samples_ms"] = p.wall_ms;
    }
    for (const auto& [key, value] : p.extra) j[key] = value;
    return j;
}

json settings_json(const gpu_timings::settings& s) {
    return {{"repetitions", s.repetitions},       {"warm_up", 1},
            {"records", s.records},               {"rsm_resolution", s.rsm_resolution},
            {"radiosity_elements_asked", s.elements}, {"item_buffer", s.item_buffer},
            {"plane_resolution", s.plane_resolution}, {"plane_batch", s.plane_batch},
            {"volume_depth", s.volume_depth},     {"gather_samples", s.gather_samples},
            {"sii_vpls", s.sii_vpls}};
}

json results_json(const gl::context& ctx, const gpu_timings::settings& s, const gpu_timings::timing_run& run) {
    json j;
    j["program"] = "gpu_timings";
    j["gl"] = {{"vendor", gl_string(GL_VENDOR)},
               {"renderer", gl_string(GL_RENDERER)},
               {"version", gl_string(GL_VERSION)},
               {"glsl_version", gl_string(GL_SHADING_LANGUAGE_VERSION)},
               {"egl_platform", ctx.platform()}};
    j["provenance"] = {{"commit", BOUNCE_SOURCE_COMMIT}, {"date", utc_now()}, {"build_type", BOUNCE_BUILD_TYPE},
                       {"compiler", __VERSION__}};
    j["settings"] = settings_json(s);
    j["scene"] = {{"name", "cornell"},
                  {"subdivide", s.subdivide},
                  {"triangles", run.scene.triangles},
                  {"rsm_maps", run.scene.rsm_maps},
                  {"radiosity_elements", run.scene.radiosity_elements},
                  {"volume_probes", run.scene.volume_probes}};
    json scene_passes = json::array();
    for (const auto& p : run.scene.passes) scene_passes.push_back(pass_json(p));
    j["scene_passes"] = scene_passes;
    json sizes = json::array();
    for (const auto& image : run.images) {
        json passes = json::array();
        for (const auto& p : image.passes) passes.push_back(pass_json(p));
        sizes.push_back({{"width", image.width}, {"height", image.height}, {"passes", passes}});
    }
    j["sizes"] = sizes;
    return j;
}

// Fails on the output before the work: the file must open for writing (it is left as it was).
void check_output(const std::string& path) {
    std::error_code ec;
    const bool existed = std::filesystem::exists(path, ec);
    const bool opened = std::ofstream(path, std::ios::app).is_open();
    if (!existed) std::filesystem::remove(path, ec);
    if (!opened) throw parameter_error("--out", "cannot write " + path);
}

void write_results(const std::string& path, const json& results) {
    std::ofstream out(path, std::ios::trunc);
    out << results.dump(2) << '\n';
    out.close();
    if (!out) throw parameter_error("--out", "could not write " + path);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"GPU times of a fixed set of GL passes on the built-in Cornell box (docs/gpu-timings.md)"};
    gpu_timings::settings s;
    std::string sizes_text = "1920x1080,512x512", out_path = "gpu_timings.json", platform = "any";
    app.add_option("--sizes", sizes_text, "image sizes WxH, comma-separated")->capture_default_str();
    app.add_option("--out", out_path, "the JSON results file")->capture_default_str();
    app.add_option("--repeat", s.repetitions, "timed runs per pass (after one warm-up)")
        ->check(CLI::Range(1, 1000))->capture_default_str();
    app.add_option("--subdivide", s.subdivide, "split each Cornell box triangle into 4^N (a denser mesh)")
        ->check(CLI::Range(0, 8))->capture_default_str();
    app.add_option("--records", s.records, "irradiance records splatted")->check(CLI::Range(64, 1 << 22))->capture_default_str();
    app.add_option("--rsm-resolution", s.rsm_resolution, "RSM side, texels")->check(CLI::Range(8, 4096))->capture_default_str();
    app.add_option("--elements", s.elements, "radiosity elements")->check(CLI::Range(16, 1 << 22))->capture_default_str();
    app.add_option("--item-buffer", s.item_buffer, "radiosity item buffer side, pixels")
        ->check(CLI::Range(16, 4096))->capture_default_str();
    app.add_option("--plane-resolution", s.plane_resolution, "hemisphere plane side, pixels")
        ->check(CLI::Range(4, 512))->capture_default_str();
    app.add_option("--batch", s.plane_batch, "hemisphere planes per batch")->check(CLI::Range(1, 4096))->capture_default_str();
    app.add_option("--volume-depth", s.volume_depth, "irradiance-volume octree depth")->check(CLI::Range(1, 7))->capture_default_str();
    app.add_option("--platform", platform, "EGL platform: any, device or surfaceless")
        ->check(CLI::IsMember({"any", "device", "surfaceless"}))->capture_default_str();
    CLI11_PARSE(app, argc, argv);

    return examples::run_program("gpu_timings", [&] {
        const auto sizes = parse_sizes(sizes_text);
        if (s.records < s.plane_batch) throw parameter_error("--records", "must be at least --batch");
        check_output(out_path);
        const gl::egl_platform p = platform == "device"        ? gl::egl_platform::device
                                   : platform == "surfaceless" ? gl::egl_platform::surfaceless
                                                               : gl::egl_platform::any;
        std::optional<gl::context> ctx;
        try {
            ctx.emplace(make_context(p));
        } catch (const no_gl_context& e) {
            fmt::print(stderr, "gpu_timings: {}\n", e.what());
            return 3;
        }
        fmt::print("gpu_timings: {} ({}), {}\n", gl_string(GL_RENDERER), gl_string(GL_VENDOR), gl_string(GL_VERSION));
        const gpu_timings::timing_run run = gpu_timings::run_timings(s, sizes);
        write_results(out_path, results_json(*ctx, s, run));
        fmt::print("gpu_timings: wrote {}\n", out_path);
        return 0;
    });
}
