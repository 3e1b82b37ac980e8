#pragma once
// What the scene-loader fuzz targets share: a private folder for the files one input
// becomes, and the invariants every scene the loaders return must satisfy.
#include <bounce/io/scene.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <glm/geometric.hpp>
#include <unistd.h>

namespace bounce::fuzz {

inline const std::filesystem::path& work_folder() {
    static const std::filesystem::path dir = [] {
        namespace fs = std::filesystem;
        const fs::path base = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
        fs::path d = base / ("bounce_fuzz_" + std::to_string(::getpid()));
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

// Writes `content` to `file`, or removes it when not `present`.
inline void put(const std::filesystem::path& file, std::string_view content, bool present) {
    std::error_code ec;
    std::filesystem::remove(file, ec);
    if (!present) return;
    std::ofstream out(file, std::ios::binary);
    out.write(content.data(), std::streamsize(content.size()));
}

// Up to `n` parts of `input` separated by lines "%%%"; returns how many there are.
inline int split_parts(std::string_view input, std::string_view* part, int n) {
    constexpr std::string_view separator = "\n%%%\n";
    int parts = 0;
    std::size_t start = 0;
    while (parts < n) {
        const std::size_t end = parts < n - 1 ? input.find(separator, start) : std::string_view::npos;
        part[parts++] = input.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start);
        if (end == std::string_view::npos) break;
        start = end + separator.size();
    }
    return parts;
}

// What every returned scene must satisfy; a violation aborts (a finding).
inline void check(const io::scene& s) {
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
    s.camera.validate();     // throws parameter_error (a finding) when the camera is unusable
    validate_lights(s.lights);  // likewise for a light no backend could render
}

}  // namespace bounce::fuzz
