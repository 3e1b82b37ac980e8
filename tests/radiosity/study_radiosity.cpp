// Figures for docs/radiosity.md: the Cornell box (about 10,000 elements) solved to 90% by the
// CPU solver with each visibility method, timed per stage. A study: it prints, and checks
// only that each run reached the fraction; speed is reported, never asserted.
#include "radiosity_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>

#include <catch2/catch.hpp>

#include <chrono>
#include <cstdio>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

template <class Visibility>
void report(const char* name, const scene_view& scene, const lightmap_atlas& atlas, Visibility vis,
            cpu::radiosity_options options, double fraction) {
    const auto t0 = std::chrono::steady_clock::now();
    cpu::progressive_radiosity solver(scene, atlas, std::move(vis), options);
    solver.solve(fraction);
    const double total = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const auto& t = solver.timings();
    std::printf("%-34s elements %6zu shooters %6zu shots %6zu unshot %.4f total %8.1f ms (lights %.1f, visibility %.1f, "
                "choice %.1f, distribution %.1f)\n",
                name, atlas.size(), solver.shooters(), solver.progress().shots, solver.unshot_fraction(), total,
                t.lights_ms, t.visibility_ms, t.choice_ms, t.distribution_ms);
    CHECK(solver.unshot_fraction() <= fraction);
}

}  // namespace

TEST_CASE("study: the Cornell box with about 10,000 elements to 90% convergence", "[radiosity][study]") {
    for (bool spot : {false, true}) {
        const auto scene = cornell_box(spot);
        std::printf("Cornell box, %s\n", spot ? "spot light of scene.json" : "emitting light quad (Ke 17 12 4)");
        for (int block : {4, 8}) {
            const auto t0 = std::chrono::steady_clock::now();
            const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 10000, .block_texels = block});
            std::printf("atlas: %zu elements, %zu charts, %u x %u texels, block %d: %.1f ms\n", atlas.size(),
                        atlas.charts.size(), atlas.width, atlas.height, block,
                        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            for (int res : {64, 128, 256}) {
                char name[64];
                std::snprintf(name, sizeof name, "stereographic %d, block %d", res, block);
                report(name, scene.view(), atlas,
                       cpu::item_buffer_visibility(scene.view(), atlas, {.projection = cpu::item_projection::stereographic,
                                                                        .resolution = res}),
                       {}, 0.1);
                std::snprintf(name, sizeof name, "hemicube %d, block %d", res, block);
                report(name, scene.view(), atlas,
                       cpu::item_buffer_visibility(scene.view(), atlas, {.projection = cpu::item_projection::hemicube,
                                                                        .resolution = res}),
                       {}, 0.1);
            }
            report("all visible (no occlusion)", scene.view(), atlas, cpu::all_visible{}, {}, 0.1);
        }
    }
}
