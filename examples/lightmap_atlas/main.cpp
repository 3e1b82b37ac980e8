// lightmap_atlas: builds the radiosity program's lightmap atlas (radiosity/lightmap_atlas.hpp)
// for a scene and reports its charts, texels per chart, packing efficiency, stretch and the
// element count against the count asked, and writes a picture of the atlas: each chart in
// its own colour, shaded by its elements' normals, padding darker, empty texels black.
//
//   build/bin/lightmap_atlas --scene sponza --elements 100000 --json atlas.json --png atlas.png
#include <bounce/io/image_io.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>

#include "../common/run_program.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>

using namespace bounce;

namespace {

struct options {
    std::string scene = "cornell";
    std::size_t elements = 10000;
    double cone = atlas_options{}.cone_degrees;
    int padding = 1;
    tiny_chart_clusters clusters = atlas_options{}.clusters;
    std::filesystem::path json, png;
    int zoom = 1;
};

// A chart's colour: a hash of its index to a saturated hue.
glm::vec3 chart_colour(std::uint32_t c) {
    std::uint32_t h = c * 2654435761u;
    h ^= h >> 15;
    const float hue = float(h % 3600u) / 600.f;  // [0, 6)
    const float f = hue - std::floor(hue);
    const glm::vec3 table[6] = {{1, f, 0}, {1 - f, 1, 0}, {0, 1, f}, {0, 1 - f, 1}, {f, 0, 1}, {1, 0, 1 - f}};
    return 0.25f + 0.75f * table[int(hue) % 6];
}

int run(const options& o) {
    if (!o.json.empty()) io::check_output_file("--json", o.json);
    if (!o.png.empty()) io::check_image_output("--png", o.png);
    const io::scene scene = io::load_scene_arg(o.scene);
    const auto t0 = std::chrono::steady_clock::now();
    const lightmap_atlas atlas = build_lightmap_atlas(scene.view(), {.elements = o.elements, .padding = o.padding,
                                                                     .cone_degrees = o.cone, .clusters = o.clusters});
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const atlas_statistics& s = atlas.statistics;
    nlohmann::ordered_json j;
    j["scene"] = scene.name;
    j["elements_asked"] = o.elements;
    j["cone_degrees"] = o.cone;
    j["triangles"] = s.triangles;
    j["charts"] = s.charts;
    j["curved_charts"] = s.curved_charts;
    j["one_element_charts"] = s.one_element_charts;
    j["elements"] = s.elements;
    j["elements_over_asked"] = double(s.elements) / double(o.elements);
    j["elements_per_chart_mean"] = double(s.elements) / double(s.charts);
    j["elements_per_chart_median"] = s.median_elements_per_chart;
    j["chart_texels"] = s.chart_texels;
    j["atlas_size"] = {atlas.width, atlas.height};
    j["packing_efficiency"] = s.packing_efficiency;
    j["stretch_mean"] = s.stretch_mean;
    j["stretch_max"] = s.stretch_max;
    j["cone_max_degrees"] = s.cone_max_degrees;
    j["seed_plane_kept"] = s.seed_plane_kept;
    j["overlaps_refused"] = s.overlaps_refused;
    j["texel_size"] = s.texel_size;
    j["densities_tried"] = s.densities_tried;
    j["clusters"] = s.clusters;
    j["clustered_charts"] = s.clustered_charts;
    j["atlas_ms"] = ms;
    fmt::print("{}\n", j.dump());
    if (!o.json.empty()) io::write_text_file(o.json, j.dump(2) + "\n");
    if (!o.png.empty()) {
        const std::size_t z = std::size_t(o.zoom);
        image<glm::vec3> pic(atlas.width * z, atlas.height * z, glm::vec3(0.f));
        const glm::vec3 light = glm::normalize(glm::vec3(0.3f, 0.8f, 0.5f));
        for (std::uint32_t y = 0; y < atlas.height; ++y)
            for (std::uint32_t x = 0; x < atlas.width; ++x) {
                const std::int32_t e = atlas.element_at(x, y);
                if (e < 0) continue;
                const auto ee = std::size_t(e);
                const bool own = atlas.texel[ee].x == x && atlas.texel[ee].y == y;
                const float shade = 0.55f + 0.45f * std::abs(glm::dot(atlas.normal[ee], light));
                const glm::vec3 c = chart_colour(atlas.chart[ee]) * shade * (own ? 1.f : 0.35f);
                for (std::size_t dy = 0; dy < z; ++dy)
                    for (std::size_t dx = 0; dx < z; ++dx) pic(x * z + dx, (atlas.height - 1 - y) * z + dy) = c;
            }
        io::write_png(o.png, pic.view());
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"The lightmap atlas of a scene: charts, texels, packing, stretch, element count"};
    options o;
    app.add_option("--scene", o.scene, "cornell, a scene name under BOUNCE_SCENES, or a path");
    app.add_option("--elements", o.elements, "element count asked")->check(CLI::PositiveNumber);
    app.add_option("--cone", o.cone, "chart cone half-angle, degrees, in [0, 90)");
    app.add_option("--padding", o.padding, "texels around each chart");
    app.add_option("--clusters", o.clusters, "tiny charts sharing one element: never, when-needed (the budget missed by >10%), always")
        ->transform(CLI::CheckedTransformer(std::map<std::string, tiny_chart_clusters>{
            {"never", tiny_chart_clusters::never}, {"when-needed", tiny_chart_clusters::when_needed},
            {"always", tiny_chart_clusters::always}}));
    app.add_option("--json", o.json, "report file");
    app.add_option("--png", o.png, "picture of the atlas");
    app.add_option("--zoom", o.zoom, "pixels per texel in the picture")->check(CLI::Range(1, 16));
    CLI11_PARSE(app, argc, argv);
    return bounce::examples::run_program("lightmap_atlas", [&] { return run(o); });
}
