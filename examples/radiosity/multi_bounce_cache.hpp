#pragma once
// The multi-bounce reference view cached on disk, as study::cached_reference does for the
// one-bounce reference: `<dir>/<key>.exr` (radiance) and `<key>.json` (each bounce's share),
// the key ending in an FNV-1a hash of everything the image depends on (study::hash_scene_view,
// then the settings and the Embree configuration).
#include <bounce/embree/multi_bounce_reference.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/reference_cache.hpp>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

namespace bounce::examples {

inline std::string multi_bounce_key(const io::scene& s, const camera& cam, std::size_t w, std::size_t h,
                                    const embree::multi_bounce_settings& settings, const std::string& device_config) {
    study::fnv1a_hash hash;
    hash.text("multi_bounce_reference v2");
    study::hash_scene_view(hash, s, cam, w, h);
    hash.value(settings.paths);
    hash.value(settings.max_bounces);
    hash.value(settings.roulette_after);
    hash.value(settings.area_samples);
    hash.value(settings.seed);
    hash.text(device_config);
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash.digest()));
    return s.name + "-" + std::to_string(w) + "x" + std::to_string(h) + "-" + std::to_string(settings.paths) +
           "paths-multibounce-" + hex;
}

/// The cached view under `key`, or nothing when absent, unreadable or of another size.
inline std::optional<embree::multi_bounce_image> load_multi_bounce(const std::filesystem::path& dir, const std::string& key,
                                                                   std::size_t w, std::size_t h) {
    const auto exr = dir / (key + ".exr"), meta = dir / (key + ".json");
    if (!std::filesystem::exists(exr) || !std::filesystem::exists(meta)) return std::nullopt;
    try {
        embree::multi_bounce_image m;
        m.radiance = io::read_rgb(exr);
        if (m.radiance.width() != w || m.radiance.height() != h) return std::nullopt;
        std::ifstream in(meta);
        const auto j = nlohmann::json::parse(in);
        for (const auto& b : j.at("per_bounce")) m.per_bounce.emplace_back(b.at(0).get<double>(), b.at(1).get<double>(), b.at(2).get<double>());
        return m;
    } catch (const std::exception&) {
        return std::nullopt;
    }
}

/// Writes `m` under `key` (temporary names renamed, so a reader never sees half an entry).
inline void store_multi_bounce(const std::filesystem::path& dir, const std::string& key, const embree::multi_bounce_image& m) {
    std::filesystem::create_directories(dir);
    const auto tmp_exr = dir / (key + ".tmp.exr"), tmp_meta = dir / (key + ".json.tmp");
    io::write_exr(tmp_exr, m.radiance.view());
    nlohmann::json j;
    j["per_bounce"] = nlohmann::json::array();
    for (const auto& b : m.per_bounce) j["per_bounce"].push_back({b.x, b.y, b.z});
    std::ofstream(tmp_meta) << j.dump();
    std::filesystem::rename(tmp_exr, dir / (key + ".exr"));
    std::filesystem::rename(tmp_meta, dir / (key + ".json"));
}

}  // namespace bounce::examples
