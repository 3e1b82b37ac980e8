// The on-disk cache of reference images: the key follows every input, entries come back
// bitwise, and a damaged entry is recomputed rather than trusted.
#include <bounce/study/reference_cache.hpp>

#include "../embree/hand_built_scenes.hpp"
#include "../scoped_environment.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace bounce;
using namespace bounce::embree;
using namespace bounce::study;
namespace fs = std::filesystem;

namespace {

// A fresh folder under the system temporary directory, removed afterwards.
struct temporary_folder {
    fs::path path = fs::temp_directory_path() / ("bounce-test-embree-cache-" + std::to_string(::getpid()));
    temporary_folder() {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~temporary_folder() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

io::scene small_scene() {
    io::scene s;
    s.name = "small box";
    const auto white = hand_built::add_material(s, glm::vec3(0.7f)), red = hand_built::add_material(s, {0.6f, 0.1f, 0.1f});
    hand_built::add_square_z(s, 0.f, 1.f, true, white);
    hand_built::add_quad(s, {-1, -1, 0}, {-1, 1, 0}, {-1, 1, 2}, {-1, -1, 2}, {1, 0, 0}, red);
    s.lights.push_back(bounce::point_light{{0.f, 0.f, 1.5f}, glm::vec3(1.f)});
    s.camera.position = {0.5f, -3.f, 1.f};
    s.camera.look_at = {0.f, 0.f, 0.5f};
    s.camera.up = {0.f, 0.f, 1.f};
    return s;
}

bool same_pixels(const image<glm::vec3>& a, const image<glm::vec3>& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.data(), b.data(), a.width() * a.height() * sizeof(glm::vec3)) == 0;
}

}  // namespace

TEST_CASE("the cache key changes with every input and only with them", "[reference][cache]") {
    const io::scene s = small_scene();
    reference_settings settings;
    const std::string key = reference_cache_key(s, s.camera, 32, 24, settings);
    CHECK(key == reference_cache_key(s, s.camera, 32, 24, settings));
    CHECK(key.find("small_box-32x24-1024spp-") == 0);  // readable prefix, file-name safe

    std::vector<std::string> others;
    others.push_back(reference_cache_key(s, s.camera, 24, 32, settings));
    io::scene moved = s;
    moved.positions[3].z += 1e-6f;
    others.push_back(reference_cache_key(moved, s.camera, 32, 24, settings));
    io::scene brighter = s;
    std::get<bounce::point_light>(brighter.lights[0]).intensity.y = 1.5f;
    others.push_back(reference_cache_key(brighter, s.camera, 32, 24, settings));
    io::scene redder = s;
    redder.materials[1].albedo.x = 0.61f;
    others.push_back(reference_cache_key(redder, s.camera, 32, 24, settings));
    io::scene emitting = s;
    emitting.use_emission = true;
    others.push_back(reference_cache_key(emitting, s.camera, 32, 24, settings));
    camera cam = s.camera;
    cam.fov_y_deg += 1.f;
    others.push_back(reference_cache_key(s, cam, 32, 24, settings));
    for (int k = 0; k < 4; ++k) {
        reference_settings changed = settings;
        if (k == 0) changed.hemisphere_samples = 512;
        if (k == 1) changed.seed = 2;
        if (k == 2) changed.environment = glm::vec3(0.1f);
        if (k == 3) changed.area_samples = 64;
        others.push_back(reference_cache_key(s, s.camera, 32, 24, changed));
    }
    // Pinned Embree kernels round hits differently; Embree's default keeps the key.
    others.push_back(reference_cache_key(s, s.camera, 32, 24, settings, "max_isa=sse4.2"));
    CHECK(reference_cache_key(s, s.camera, 32, 24, settings, "") == key);
    for (const auto& o : others) CHECK(o != key);
    // The progress callback is not an input of the images.
    reference_settings with_progress = settings;
    with_progress.progress = [](std::size_t, std::size_t) {};
    CHECK(reference_cache_key(s, s.camera, 32, 24, with_progress) == key);
}

TEST_CASE("cached references come back bitwise and are recomputed when damaged", "[reference][cache]") {
    const temporary_folder dir;
    const io::scene s = small_scene();
    const accel bvh(s);
    reference_settings settings;
    settings.hemisphere_samples = 16;

    bool from_cache = true;
    const auto first = cached_reference(bvh, s, s.camera, 32, 24, settings, dir.path, &from_cache);
    CHECK_FALSE(from_cache);
    const std::string key = reference_cache_key(s, s.camera, 32, 24, settings, bvh.owner().config());
    CHECK(fs::exists(dir.path / (key + ".direct.exr")));
    CHECK(fs::exists(dir.path / (key + ".indirect.exr")));
    CHECK(fs::exists(dir.path / (key + ".json")));

    const auto second = cached_reference(bvh, s, s.camera, 32, 24, settings, dir.path, &from_cache);
    CHECK(from_cache);
    CHECK(same_pixels(first.direct, second.direct));
    CHECK(same_pixels(first.indirect, second.indirect));
    CHECK(same_pixels(first.combined, second.combined));
    CHECK(second.grid.count() == first.grid.count());

    // Asking for another size under the same key is a miss, not a wrong answer.
    CHECK_FALSE(load_cached_reference(dir.path, key, 16, 16, settings).has_value());

    // A truncated file is not trusted: the reference is recomputed, identical.
    fs::resize_file(dir.path / (key + ".indirect.exr"), 100);
    CHECK_FALSE(load_cached_reference(dir.path, key, 32, 24, settings).has_value());
    const auto third = cached_reference(bvh, s, s.camera, 32, 24, settings, dir.path, &from_cache);
    CHECK_FALSE(from_cache);
    CHECK(same_pixels(first.indirect, third.indirect));
    CHECK(load_cached_reference(dir.path, key, 32, 24, settings).has_value());

    // A device with pinned kernels has its own entry, which names the configuration.
    const accel pinned(device("max_isa=sse2"), s);
    const auto fourth = cached_reference(pinned, s, s.camera, 32, 24, settings, dir.path, &from_cache);
    CHECK_FALSE(from_cache);
    const std::string pinned_key = reference_cache_key(s, s.camera, 32, 24, settings, "max_isa=sse2");
    REQUIRE(fs::exists(dir.path / (pinned_key + ".json")));
    std::ifstream description(dir.path / (pinned_key + ".json"));
    CHECK(nlohmann::json::parse(description).at("embree_config") == "max_isa=sse2");
}

TEST_CASE("the default cache folder follows BOUNCE_CACHE", "[reference][cache]") {
    const bounce::test::scoped_environment cache("BOUNCE_CACHE");
    cache.set("/tmp/bounce-cache-from-env");
    CHECK(default_cache_dir() == fs::path("/tmp/bounce-cache-from-env"));
    cache.unset();
    // Test programs live in build/bin: the default is build/cache beside it.
    const fs::path d = default_cache_dir();
    CHECK(d.filename() == "cache");
}
