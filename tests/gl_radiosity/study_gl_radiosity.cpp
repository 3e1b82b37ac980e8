// Figures for docs/radiosity-gl.md: the Cornell box (about 10,000 elements) solved to 90% by
// gl::progressive_radiosity (llvmpipe here) and, in the same process, by
// cpu::progressive_radiosity with the same atlas, options and item buffers (stereographic
// 128^2 and 256^2, hemicube 64^2 and 128^2 per face; blocks of 4 x 4 and 8 x 8 texels). A study:
// it prints each run, writes one run report per run into $BOUNCE_STUDY_OUT (when set; the
// script docs/studies/radiosity_gl.sh adds them to docs/results/radiosity_gl.json), and checks
// only that each run reached the fraction; speed is reported, never asserted.
#include "../gl/shared_context.hpp"
#include "../radiosity/radiosity_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/gl/radiosity.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/run_report.hpp>

#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

struct run_figures {
    double total_ms = 0, lights_ms = 0, visibility_ms = 0, choice_ms = 0, distribution_ms = 0;
    std::size_t shots = 0, shooters = 0;
    double unshot = 1, escaped = 0;
};

// Relative L1 difference (area-weighted, channels summed) between two solutions.
double relative_l1(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b, const lightmap_atlas& atlas) {
    double diff = 0, sum = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            diff += std::abs(double(a[i][c]) - double(b[i][c])) * double(atlas.area[i]);
            sum += double(b[i][c]) * double(atlas.area[i]);
        }
    return diff / sum;
}

void write(const std::string& name, const std::string& backend, const std::string& renderer, const lightmap_atlas& atlas,
           bool hemicube, int resolution, const run_figures& f, double versus_cpu = -1, const char* scene = "cornell") {
    std::printf("%-28s %-4s elements %6zu shooters %5zu shots %5zu unshot %.4f escaped %.4f total %8.1f ms (lights %.1f, "
                "visibility %.1f, choice %.1f, distribution %.1f)\n",
                name.c_str(), backend.c_str(), atlas.size(), f.shooters, f.shots, f.unshot, f.escaped, f.total_ms,
                f.lights_ms, f.visibility_ms, f.choice_ms, f.distribution_ms);
    const char* out = std::getenv("BOUNCE_STUDY_OUT");
    if (!out) return;
    study::run_report r;
    r.technique = "radiosity";
    r.scene = scene;
    r.width = atlas.width;
    r.height = atlas.height;
    r.backend = backend;
    r.gl_renderer = renderer;
    r.parameters["visibility"] = hemicube ? "hemicube" : "stereographic";
    r.parameters["resolution"] = resolution;
    r.parameters["block_texels"] = atlas.block_texels;
    r.parameters["near_field"] = 4;
    r.parameters["converge"] = 0.9;
    r.timings_ms = {{"lights", f.lights_ms},
                    {"visibility", f.visibility_ms},
                    {"shooter_choice", f.choice_ms},
                    {"distribution", f.distribution_ms},
                    {"total", f.total_ms}};
    r.set_count("elements", atlas.size());
    r.set_count("shooters", f.shooters);
    r.set_count("iterations", f.shots);
    r.parameters["converged_fraction"] = 1.0 - f.unshot;
    // How far the GL solution at 90% is from the CPU's (relative L1 over the elements).
    if (versus_cpu >= 0) r.parameters["relative_l1_versus_cpu"] = versus_cpu;
    // The machine is shared: the one-minute load average when the run ended, beside its times.
    if (std::FILE* load = std::fopen("/proc/loadavg", "r")) {
        double one_minute = 0;
        if (std::fscanf(load, "%lf", &one_minute) == 1) r.parameters["load_average"] = one_minute;
        std::fclose(load);
    }
    r.write(std::string(out) + "/" + name + "-" + backend + ".json");
}

}  // namespace

TEST_CASE("study: the Cornell box with about 10,000 elements to 90% on GL and on the CPU", "[gl][radiosity][study]") {
    auto& context = gl_test::shared_context();
    const std::string renderer = context.renderer();
    const auto scene = cornell_box();
    const double fraction = 0.1;
    for (const bool hemicube : {false, true})
    for (const int block : {4, 8})
        for (const int resolution : {128, 256}) {
            const int res = hemicube ? resolution / 2 : resolution;  // a face of 64^2 or 128^2
            const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 10000, .block_texels = block});
            const std::string name = std::string("cornell-") + (hemicube ? "hemicube" : "stereo") + "-b" +
                                     std::to_string(block) + "-r" + std::to_string(res);
            std::vector<glm::vec3> gl_solution;
            run_figures gl_figures;
            {
                const auto t0 = std::chrono::steady_clock::now();
                gl::progressive_radiosity solver(
                    scene.view(), atlas,
                    {.visibility = hemicube ? gl::radiosity_visibility::hemicube : gl::radiosity_visibility::stereographic,
                     .resolution = res});
                solver.solve(fraction);
                gl::finish();
                gl_solution = solver.radiosity();
                run_figures f;
                f.total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
                const auto& t = solver.timings();
                f = {f.total_ms, t.lights_ms, t.visibility_ms, t.choice_ms, t.distribution_ms, solver.progress().shots,
                     solver.shooters(), solver.unshot_fraction(), solver.escaped_power().x / solver.emitted_power().x};
                gl_figures = f;
                CHECK(solver.unshot_fraction() <= fraction);
            }
            {
                // The same without a glFinish after visibility and distribution: one wait per
                // step (the reduction's read-back); stage times are then not split.
                const auto t0 = std::chrono::steady_clock::now();
                gl::progressive_radiosity solver(
                    scene.view(), atlas,
                    {.visibility = hemicube ? gl::radiosity_visibility::hemicube : gl::radiosity_visibility::stereographic,
                     .resolution = res,
                     .timed_stages = false});
                solver.solve(fraction);
                gl::finish();
                run_figures f;
                f.total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
                const auto& t = solver.timings();
                f = {f.total_ms, t.lights_ms, t.visibility_ms, t.choice_ms, t.distribution_ms, solver.progress().shots,
                     solver.shooters(), solver.unshot_fraction(), solver.escaped_power().x / solver.emitted_power().x};
                write(name, "gl-untimed", renderer, atlas, hemicube, res, f);
                CHECK(solver.unshot_fraction() <= fraction);
            }
            {
                const auto t0 = std::chrono::steady_clock::now();
                cpu::progressive_radiosity solver(
                    scene.view(), atlas,
                    cpu::item_buffer_visibility(
                        scene.view(), atlas,
                        {.projection = hemicube ? cpu::item_projection::hemicube : cpu::item_projection::stereographic,
                         .resolution = res}));  // two-sided, as the GL solver's default
                solver.solve(fraction);
                run_figures f;
                f.total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
                const auto& t = solver.timings();
                f = {f.total_ms, t.lights_ms, t.visibility_ms, t.choice_ms, t.distribution_ms, solver.progress().shots,
                     solver.shooters(), solver.unshot_fraction(), solver.escaped_power().x / solver.emitted_power().x};
                write(name, "cpu", "", atlas, hemicube, res, f);
                const auto b = solver.radiosity();
                const double versus = relative_l1(gl_solution, std::vector<glm::vec3>(b.begin(), b.end()), atlas);
                std::printf("%-28s GL versus CPU at 90%%: relative L1 %.3g\n", name.c_str(), versus);
                write(name, "gl", renderer, atlas, hemicube, res, gl_figures, versus);
                CHECK(solver.unshot_fraction() <= fraction);
            }
        }
}

TEST_CASE("study: Sponza (66k triangles, 100,000 elements) to 90% on GL and on the CPU", "[gl][radiosity][study]") {
    // scene.json's sun and point light, its default material; hemicube 128^2, 8 x 8 blocks
    // (the CPU study's Sponza settings, docs/radiosity.md section 6); at most a minute each.
    const char* dir = std::getenv("BOUNCE_SCENES");
    const std::string path = std::string(dir ? dir : BOUNCE_SOURCE_DIR "/../shared/scenes") + "/sponza/scene.json";
    if (!std::ifstream(path)) {
        WARN("sponza/scene.json not found; skipped");
        return;
    }
    auto& context = gl_test::shared_context();
    const io::scene scene = io::load_scene(path);
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 100000, .block_texels = 8});
    const double fraction = 0.1;
    const auto within_a_minute = [](std::chrono::steady_clock::time_point t0) {
        return [t0](const auto&) {
            return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < 60.0;
        };
    };
    std::vector<glm::vec3> gl_solution;
    run_figures gl_figures;
    {
        const auto t0 = std::chrono::steady_clock::now();
        gl::progressive_radiosity solver(scene.view(), atlas,
                                         {.visibility = gl::radiosity_visibility::hemicube, .resolution = 128});
        solver.solve(fraction, within_a_minute(t0));
        gl::finish();
        const double total = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        const auto& t = solver.timings();
        gl_figures = {total, t.lights_ms, t.visibility_ms, t.choice_ms, t.distribution_ms, solver.progress().shots,
                      solver.shooters(), solver.unshot_fraction(), solver.escaped_power().x / solver.emitted_power().x};
        gl_solution = solver.radiosity();
        CHECK(solver.unshot_fraction() < 1.0);
    }
    {
        const auto t0 = std::chrono::steady_clock::now();
        cpu::progressive_radiosity solver(
            scene.view(), atlas,
            cpu::item_buffer_visibility(scene.view(), atlas, {.projection = cpu::item_projection::hemicube, .resolution = 128}));
        // two-sided, as the GL solver's default
        solver.solve(fraction, within_a_minute(t0));
        const double total = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        const auto& t = solver.timings();
        const run_figures f{total, t.lights_ms, t.visibility_ms, t.choice_ms, t.distribution_ms, solver.progress().shots,
                            solver.shooters(), solver.unshot_fraction(),
                            solver.escaped_power().x / solver.emitted_power().x};
        write("sponza-hemicube-b8-r128", "cpu", "", atlas, true, 128, f, -1, "sponza");
        const auto b = solver.radiosity();
        const double versus = relative_l1(gl_solution, std::vector<glm::vec3>(b.begin(), b.end()), atlas);
        std::printf("sponza GL versus CPU: relative L1 %.3g\n", versus);
        write("sponza-hemicube-b8-r128", "gl", context.renderer(), atlas, true, 128, gl_figures,
              solver.progress().shots == gl_figures.shots ? versus : -1, "sponza");
        CHECK(solver.unshot_fraction() < 1.0);
    }
}
