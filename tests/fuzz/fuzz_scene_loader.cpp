// libFuzzer target over the scene loader: one input is a scene.json, an OBJ and an MTL
// separated by lines "%%%" (fewer parts: the later files do not exist). Each run writes
// them to a private folder, loads the scene and the OBJ alone, and requires that the
// loader either returns a well-formed scene or throws io::scene_error; any other
// exception, a crash, a sanitizer report, a hang or a broken invariant is a finding.
#include "fuzz_support.hpp"

#include <bounce/io/scene.hpp>

#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace bounce::fuzz;
    std::string_view part[3];
    const int parts = split_parts(std::string_view(reinterpret_cast<const char*>(data), size), part, 3);
    const auto& dir = work_folder();
    put(dir / "scene.json", part[0], parts >= 1);
    put(dir / "m.obj", part[1], parts >= 2);
    put(dir / "m.mtl", part[2], parts >= 3);
    try {
        check(bounce::io::load_scene(dir / "scene.json"));
    } catch (const bounce::io::scene_error&) {
    }
    try {
        check(bounce::io::load_obj(dir / "m.obj"));
    } catch (const bounce::io::scene_error&) {
    }
    return 0;
}
