#include <bounce/study/multi_bounce_cache.hpp>

#include <bounce/io/image_io.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/study/content_hash.hpp>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <system_error>

namespace bounce::study {

std::string multi_bounce_cache_key(const io::scene& scene, const bounce::camera& cam, std::size_t width,
                                   std::size_t height, const embree::multi_bounce_settings& settings,
                                   std::string_view device_config) {
    fnv1a_hash hash;
    hash.text("multi_bounce_reference v2");
    hash_scene_view(hash, scene, cam, width, height);
    hash.values(settings.paths, settings.max_bounces, settings.roulette_after, settings.area_samples, settings.seed);
    hash.text(device_config);
    return view_cache_key(scene.name, width, height, std::to_string(settings.paths) + "paths-multibounce-", hash);
}

std::optional<embree::multi_bounce_image> load_multi_bounce(const std::filesystem::path& dir, const std::string& key,
                                                            std::size_t width, std::size_t height) {
    const auto exr = dir / (key + ".exr"), meta = dir / (key + ".json");
    std::error_code ec;
    if (!std::filesystem::exists(exr, ec) || !std::filesystem::exists(meta, ec)) return std::nullopt;
    try {
        embree::multi_bounce_image m;
        m.radiance = io::read_rgb(exr);
        if (m.radiance.width() != width || m.radiance.height() != height) return std::nullopt;
        std::ifstream in(meta);
        const auto j = nlohmann::json::parse(in);
        for (const auto& b : j.at("per_bounce"))
            m.per_bounce.emplace_back(b.at(0).get<double>(), b.at(1).get<double>(), b.at(2).get<double>());
        return m;
    } catch (const std::exception&) {
        return std::nullopt;
    }
}

void store_multi_bounce(const std::filesystem::path& dir, const std::string& key, const embree::multi_bounce_image& image) {
    check_cache_dir(dir);
    const auto tmp_exr = dir / (key + ".tmp.exr"), tmp_meta = dir / (key + ".json.tmp");
    io::write_exr(tmp_exr, image.radiance.view());
    nlohmann::json j;
    j["per_bounce"] = nlohmann::json::array();
    for (const auto& b : image.per_bounce) j["per_bounce"].push_back({b.x, b.y, b.z});
    io::write_text_file(tmp_meta, j.dump());
    std::error_code ec;
    std::filesystem::rename(tmp_exr, dir / (key + ".exr"), ec);
    if (!ec) std::filesystem::rename(tmp_meta, dir / (key + ".json"), ec);
    if (ec) throw io::output_error(dir / (key + ".exr"), "cannot rename the cache entry into place: " + ec.message());
}

embree::multi_bounce_image cached_multi_bounce(const embree::accel& bvh, const io::scene& scene, const bounce::camera& cam,
                                               std::size_t width, std::size_t height,
                                               const embree::multi_bounce_settings& settings,
                                               const std::filesystem::path& dir, bool* from_cache) {
    const std::string key = multi_bounce_cache_key(scene, cam, width, height, settings, bvh.owner().config());
    if (auto cached = load_multi_bounce(dir, key, width, height)) {
        if (from_cache) *from_cache = true;
        return std::move(*cached);
    }
    if (from_cache) *from_cache = false;
    const embree::multi_bounce_reference reference(bvh, scene, settings);
    embree::multi_bounce_image image = reference.render(cam, width, height);
    store_multi_bounce(dir, key, image);
    return image;
}

}  // namespace bounce::study
