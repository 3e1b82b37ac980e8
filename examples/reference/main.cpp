// reference: ground-truth direct, one-bounce indirect and combined images by ray tracing
// (bounce::embree::reference_integrator), cached on disk for every other example.
//
//   build/bin/reference --scene cornell --width 256 --height 256 --spp 1024
//       --out ref.exr --png ref.png --json ref.json   (one command line)
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/io/scene.hpp>

#include <CLI/CLI.hpp>
#include "../common/cli_number_checks.hpp"
#include "../common/run_program.hpp"
#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace bounce;

namespace {

// X.exr -> X.direct.exr: the sibling file of a stage.
fs::path sibling(const fs::path& file, const std::string& stage) {
    fs::path p = file;
    return p.replace_extension("." + stage + file.extension().string());
}

// Prints a stage's progress in steps of 10% on stderr.
embree::reference_settings with_progress(embree::reference_settings s, const char* stage, bool quiet) {
    if (quiet) return s;
    s.progress = [stage, last = -1](std::size_t done, std::size_t total) mutable {
        const int tenth = int(10 * done / total);
        if (tenth != last) {
            last = tenth;
            fmt::print(stderr, "  {}: {}%\n", stage, 10 * tenth);
        }
    };
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce reference integrator: direct, one-bounce indirect and combined images by ray tracing"};
    std::string scene_arg = "cornell";
    std::size_t width = 256, height = 256;
    std::uint32_t spp = 1024, area_samples = 16, secondary_area_samples = 1;
    std::uint64_t seed = 1;
    std::vector<float> environment = {0.f, 0.f, 0.f};
    fs::path out = "reference.exr", png, json, cache_dir = study::default_cache_dir();
    float exposure = 0.f;
    int repeat = 1;
    bool no_cache = false, quiet = false;
    app.add_option("--scene", scene_arg, "cornell, a scene.json, its folder, an .obj, a .gltf or .glb, or a name under the scenes folder")->capture_default_str();
    app.add_option("--width", width, "image width in pixels")->check(CLI::Range(1, 16384))->capture_default_str();
    app.add_option("--height", height, "image height in pixels")->check(CLI::Range(1, 16384))->capture_default_str();
    app.add_option("--spp", spp, "hemisphere samples per pixel for indirect light (an M x N grid, N ~ pi M)")
        ->check(CLI::Range(1u, 1u << 20))
        ->capture_default_str();
    app.add_option("--area-samples", area_samples, "samples on emissive triangles per pixel (use_emission scenes)")
        ->check(CLI::Range(1u, 1u << 16))
        ->capture_default_str();
    app.add_option("--secondary-area-samples", secondary_area_samples, "samples on emissive triangles per hemisphere hit")
        ->check(CLI::Range(1u, 1u << 10))
        ->capture_default_str();
    app.add_option("--seed", seed, "base seed of every random stream")->check(examples::seed_u64)->capture_default_str();
    app.add_option("--environment", environment, "uniform radiance R G B of rays that escape (W/m^2/sr)")
        ->expected(3)
        ->check(examples::finite_non_negative)
        ->capture_default_str();
    app.add_option("--out", out, "combined image (EXR); X.direct.exr and X.indirect.exr beside it")->capture_default_str();
    app.add_option("--png", png, "tone-mapped combined image (PNG); X.direct.png and X.indirect.png beside it");
    app.add_option("--json", json, "run report (design.md section 6)");
    app.add_option("--exposure", exposure, "PNG exposure; 0 maps the 99th luminance percentile to white")
        ->check(examples::detail::number_in(0, 1e9, true, "an exposure"))
        ->capture_default_str();
    app.add_option("--repeat", repeat, "compute N times (bypassing the cache) and report median timings")
        ->check(CLI::Range(1, 100))
        ->capture_default_str();
    app.add_option("--cache-dir", cache_dir, "where reference images are cached ($BOUNCE_CACHE)")->capture_default_str();
    app.add_flag("--no-cache", no_cache, "neither read nor write the cache");
    app.add_flag("--quiet", quiet, "no progress output");
    CLI11_PARSE(app, argc, argv);

    // A G-buffer (40 bytes a pixel) and three float RGB images (36) at the least.
    const std::string out_of_memory =
        fmt::format("{}x{} pixels need about {:.1f} GiB of images; try a smaller --width/--height", width, height,
                    76.0 * double(width) * double(height) / double(1ull << 30));
    return examples::run_program("reference", [&] {
        // Every output before the work: the images, their siblings, the report and the cache.
        io::check_image_output("--out", out);
        for (const char* stage : {"direct", "indirect"}) io::check_image_output("--out", sibling(out, stage));
        if (!png.empty()) {
            io::check_image_output("--png", png);
            for (const char* stage : {"direct", "indirect"}) io::check_image_output("--png", sibling(png, stage));
        }
        if (!json.empty()) io::check_output_file("--json", json);
        if (!no_cache) study::check_cache_dir(cache_dir);
        const io::scene scene = io::load_scene_arg(scene_arg);
        scene.view().validate();  // magnitudes and lights named before Embree sees them
        for (const auto& w : scene.warnings) fmt::print(stderr, "warning: {}\n", w);

        embree::reference_settings settings;
        settings.hemisphere_samples = spp;
        settings.area_samples = area_samples;
        settings.secondary_area_samples = secondary_area_samples;
        settings.environment = {environment[0], environment[1], environment[2]};
        settings.seed = seed;

        study::stage_timer timer;
        const embree::device dev;  // BOUNCE_EMBREE_CONFIG, when set, pins its kernels (and keys the cache)
        std::optional<embree::accel> bvh;
        gbuffer<float> g;
        embree::reference_images images;
        const std::string key =
            study::reference_cache_key(scene, scene.camera, width, height, settings, dev.config());
        std::string cache_state = no_cache ? "off" : "miss";

        for (int r = 0; r < repeat; ++r) {
            auto total = timer.measure("total");
            bvh.reset();
            timer.time("bvh", [&] { bvh.emplace(dev, scene); });
            g = timer.time("gbuffer", [&] { return embree::ray_cast_gbuffer(*bvh, scene, scene.camera, width, height); });
            if (!no_cache && repeat == 1) {
                auto cached = timer.time("cache_load", [&] {
                    return study::load_cached_reference(cache_dir, key, width, height, settings);
                });
                if (cached) {
                    images = std::move(*cached);
                    cache_state = "hit";
                    break;
                }
            }
            const embree::reference_integrator direct_ri(*bvh, scene, with_progress(settings, "direct", quiet));
            const embree::reference_integrator indirect_ri(*bvh, scene, with_progress(settings, "indirect", quiet));
            images.direct = timer.time("direct", [&] { return direct_ri.direct_image(g.view()); });
            images.indirect = timer.time("indirect", [&] { return indirect_ri.indirect_image(g.view()); });
            images.combined = image<glm::vec3>(width, height);
            for (std::size_t y = 0; y < height; ++y)
                for (std::size_t x = 0; x < width; ++x)
                    images.combined(x, y) = images.direct(x, y) + images.indirect(x, y);
            images.grid = embree::hemisphere_grid_for(spp);
        }
        if (!no_cache && cache_state == "miss")
            study::store_cached_reference(cache_dir, key, images, scene, scene.camera, settings, dev.config());

        io::write_exr(out, images.combined.view());
        io::write_exr(sibling(out, "direct"), images.direct.view());
        io::write_exr(sibling(out, "indirect"), images.indirect.view());
        if (!png.empty()) {
            const float e = exposure > 0.f ? exposure : io::auto_exposure(images.combined.view(), g.depth.view());
            io::write_png(png, images.combined.view(), e);
            io::write_png(sibling(png, "direct"), images.direct.view(), e);
            // The indirect image alone is dim; its own exposure shows the colour bleeding.
            io::write_png(sibling(png, "indirect"), images.indirect.view(),
                          exposure > 0.f ? exposure : io::auto_exposure(images.indirect.view(), g.depth.view()));
        }

        std::size_t covered = 0;
        for (std::size_t y = 0; y < height; ++y)
            for (std::size_t x = 0; x < width; ++x) covered += std::isfinite(g.depth(x, y)) ? 1 : 0;
        if (!json.empty()) {
            study::run_report report;
            report.technique = "reference";
            report.scene = scene.name;
            report.width = width;
            report.height = height;
            report.backend = "embree";
            report.parameters["spp"] = spp;
            report.parameters["grid"] = nlohmann::ordered_json::array({images.grid.m, images.grid.n});
            report.parameters["area_samples"] = area_samples;
            report.parameters["secondary_area_samples"] = secondary_area_samples;
            report.parameters["seed"] = seed;
            report.parameters["environment"] = environment;
            report.parameters["cache"] = cache_state;
            report.parameters["cache_key"] = key;
            report.parameters["embree_config"] = dev.config();
            report.set_timings(timer);
            report.set_count("samples_per_pixel", images.grid.count());
            report.set_count("pixels_covered", covered);
            report.write(json);
        }
        fmt::print("reference: {} {}x{}, {} x {} = {} hemisphere samples per pixel, cache {} ({})\n", scene.name, width,
                   height, images.grid.m, images.grid.n, images.grid.count(), cache_state, key);
        for (const auto& stage : timer.stages()) fmt::print("  {:<10} {:10.1f} ms\n", stage, timer.median_ms(stage));
        fmt::print("wrote {}, {}, {}\n", out.string(), sibling(out, "direct").string(), sibling(out, "indirect").string());
        return 0;
    }, out_of_memory);
}
