// libFuzzer target over the glTF loader: one input is a glTF file (a .glb when it starts
// with "glTF", else a .gltf) and, after a line "%%%", the external buffer "b.bin" it may
// name by uri. Each run writes them to a private folder and loads the file alone
// (io::load_gltf) and through a scene.json naming it; the loader must return a well-formed
// scene or throw io::scene_error. Anything else is a finding, as for fuzz_scene_loader.
#include "fuzz_support.hpp"

#include <bounce/io/scene.hpp>

#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace bounce::fuzz;
    std::string_view part[2];
    const int parts = split_parts(std::string_view(reinterpret_cast<const char*>(data), size), part, 2);
    const auto& dir = work_folder();
    const bool binary = part[0].substr(0, 4) == "glTF";
    const auto file = dir / (binary ? "m.glb" : "m.gltf");
    put(dir / "m.glb", part[0], binary);
    put(dir / "m.gltf", part[0], !binary);
    put(dir / "b.bin", part[1], parts >= 2);
    put(dir / "scene.json", binary ? R"({"gltf": "m.glb"})" : R"({"gltf": "m.gltf"})", true);
    try {
        check(bounce::io::load_gltf(file));
    } catch (const bounce::io::scene_error&) {
    }
    try {
        check(bounce::io::load_scene(dir / "scene.json"));
    } catch (const bounce::io::scene_error&) {
    }
    return 0;
}
