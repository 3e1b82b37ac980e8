// Figures for docs/radiosity.md: the Cornell box (about 10,000 elements) solved to 90% by the
// CPU solver with each visibility method, timed per stage. A study: it prints, and checks
// only that each run reached the fraction; speed is reported, never asserted.
#include "radiosity_scenes.hpp"

#include <bounce/cpu/radiosity.hpp>

#include <catch2/catch.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

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
    std::printf("%-34s elements %6zu shooters %6zu shots %6zu unshot %.4f escaped %.4f total %8.1f ms (lights %.1f, "
                "visibility %.1f, choice %.1f, distribution %.1f)\n",
                name, atlas.size(), solver.shooters(), solver.progress().shots, solver.unshot_fraction(),
                solver.escaped_power().x / solver.emitted_power().x, total, t.lights_ms, t.visibility_ms, t.choice_ms,
                t.distribution_ms);
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

TEST_CASE("study: adaptive subdivision in the Cornell box", "[radiosity][study]") {
    // The chapter's leaves are 16 x 16 textures; here base leaves of 16 x 16 (about 2,500
    // elements) and of 8 x 8 texels, subdivided after each of the first 200 steps (the chapter
    // tests after every reconstruction pass) down to level 2, then solved to 90%.
    const auto scene = cornell_box();
    for (int block : {16, 8}) {
        const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 2500, .block_texels = block});
        const auto t0 = std::chrono::steady_clock::now();
        cpu::progressive_radiosity solver(scene.view(), atlas,
                                          cpu::item_buffer_visibility(scene.view(), atlas, {.resolution = 128}));
        std::size_t splits = 0;
        for (int s = 0; s < 200 && solver.step(); ++s)
            splits += solver.subdivide(scene.view(), {.threshold = 0.25, .min_texels = 2, .max_level = 2});
        solver.solve(0.1);
        const double total = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        std::size_t per_level[3] = {0, 0, 0};
        const auto& a = solver.atlas();
        for (std::size_t k = 0; k < a.blocks(); ++k) per_level[a.block_level[k]] += a.block_first[k + 1] - a.block_first[k];
        std::printf("subdivision, leaves %dx%d: %zu -> %zu elements (level 0/1/2: %zu/%zu/%zu), %zu splits, %zu shots, "
                    "unshot %.3f, %.0f ms (subdivision %.0f ms)\n",
                    block, block, atlas.size(), a.size(), per_level[0], per_level[1], per_level[2], splits,
                    solver.progress().shots, solver.unshot_fraction(), total, solver.timings().subdivision_ms);
        CHECK(solver.unshot_fraction() <= 0.1);
    }
}

namespace {

// Sponza's mesh from ../shared/scenes/sponza/sponza.obj (or $BOUNCE_SCENES): only its "v" and
// "f" lines (all triangles), one material (scene.json's default kd) and scene.json's two
// lights copied by hand. A reader this small keeps the study off io::scene, as the issue asks.
bool load_sponza(owned_scene& s) {
    const char* dir = std::getenv("BOUNCE_SCENES");
    std::ifstream in(std::string(dir ? dir : BOUNCE_SOURCE_DIR "/../shared/scenes") + "/sponza/sponza.obj");
    if (!in) return false;
    s.use_emission = false;
    const auto m = s.add_material({0.627f, 0.573f, 0.561f});
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ls(line);
        std::string tag;
        ls >> tag;
        if (tag == "v") {
            glm::vec3 p;
            ls >> p.x >> p.y >> p.z;
            s.positions.push_back(p);
        } else if (tag == "f") {
            std::uint32_t idx[3];
            for (auto& i : idx) {
                std::string token;
                ls >> token;
                i = std::uint32_t(std::stoul(token.substr(0, token.find('/')))) - 1;
            }
            s.triangles.emplace_back(idx[0], idx[1], idx[2]);
            s.material_of.push_back(m);
        }
    }
    s.lights.push_back(directional_light{{0.2f, -1.0f, 0.35f}, {6.0f, 5.6f, 5.0f}});
    s.lights.push_back(point_light{{-9.0f, 3.0f, 0.0f}, {18.0f, 14.0f, 10.0f}});
    return !s.triangles.empty();
}

}  // namespace

TEST_CASE("study: Sponza (66k triangles) to 99%, or as far as a minute of shooting takes it", "[radiosity][study]") {
    owned_scene scene;
    if (!load_sponza(scene)) {
        WARN("sponza.obj not found; skipped");
        return;
    }
    for (std::size_t elements : {std::size_t(100000)}) {
        auto t0 = std::chrono::steady_clock::now();
        const auto atlas = build_lightmap_atlas(scene.view(), {.elements = elements, .block_texels = 8});
        const double atlas_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        std::printf("Sponza: %zu triangles, atlas %zu elements, %zu charts, %zu blocks, %u x %u texels: %.0f ms\n",
                    scene.triangles.size(), atlas.size(), atlas.charts.size(), atlas.blocks(), atlas.width, atlas.height,
                    atlas_ms);
        t0 = std::chrono::steady_clock::now();
        cpu::progressive_radiosity solver(
            scene.view(), atlas,
            cpu::item_buffer_visibility(scene.view(), atlas,
                                        {.projection = cpu::item_projection::hemicube, .resolution = 128}));
        std::printf("lights shot: %.0f ms, unshot %.4f\n", solver.timings().lights_ms, solver.unshot_fraction());
        const double marks[] = {0.5, 0.3, 0.2, 0.1, 0.05, 0.02, 0.01};
        std::size_t mark = 0;
        solver.solve(0.01, [&](const cpu::radiosity_progress& p) {
            const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            if (mark < std::size(marks) && p.unshot_fraction <= marks[mark]) {
                std::printf("  unshot %.3f after %zu shots, %.1f s\n", p.unshot_fraction, p.shots, s);
                while (mark < std::size(marks) && p.unshot_fraction <= marks[mark]) ++mark;
            }
            return s < 60.0;
        });
        const auto& t = solver.timings();
        std::printf("Sponza end: unshot %.4f, %zu shots, visibility %.0f ms, choice %.0f ms, distribution %.0f ms\n",
                    solver.unshot_fraction(), solver.progress().shots, t.visibility_ms, t.choice_ms, t.distribution_ms);
        CHECK(solver.unshot_fraction() < 1.0);
    }
}
