// libFuzzer target over the scene loader: one input is a scene.json, an OBJ and an MTL
// separated by lines "%%%" (fewer parts: the later files do not exist). Each run writes
// them to a private folder, loads the scene and the OBJ alone, and requires that the
// loader either returns a well-formed scene or throws io::scene_error; any other
// exception, a crash, a sanitizer report, a hang or a broken invariant is a finding.
#include <bounce/io/scene.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <glm/geometric.hpp>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;

const fs::path& work_folder() {
    static const fs::path dir = [] {
        const fs::path base = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
        fs::path d = base / ("bounce_fuzz_" + std::to_string(::getpid()));
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

void put(const fs::path& file, std::string_view content, bool present) {
    std::error_code ec;
    fs::remove(file, ec);
    if (!present) return;
    std::ofstream out(file, std::ios::binary);
    out.write(content.data(), std::streamsize(content.size()));
}

// What every returned scene must satisfy; a violation aborts (a finding).
void check(const bounce::io::scene& s) {
    if (s.triangles.empty() || s.normals.size() != s.positions.size() || s.material_of.size() != s.triangles.size())
        std::abort();
    for (const auto& t : s.triangles)
        if (t.x >= s.positions.size() || t.y >= s.positions.size() || t.z >= s.positions.size()) std::abort();
    for (const auto m : s.material_of)
        if (m >= s.materials.size()) std::abort();
    for (const auto& n : s.normals)
        if (!(std::abs(glm::length(n) - 1.f) < 1e-5f)) std::abort();
    for (const auto& p : s.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
    s.camera.validate();  // throws parameter_error (a finding) when the camera is unusable
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    constexpr std::string_view separator = "\n%%%\n";
    std::string_view part[3];
    int parts = 0;
    std::size_t start = 0;
    while (parts < 3) {
        const std::size_t end = parts < 2 ? input.find(separator, start) : std::string_view::npos;
        part[parts++] = input.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start);
        if (end == std::string_view::npos) break;
        start = end + separator.size();
    }
    const fs::path& dir = work_folder();
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
