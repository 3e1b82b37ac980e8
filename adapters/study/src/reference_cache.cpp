// Reference images cached as EXR under a content hash of everything they depend on.
#include <bounce/study/reference_cache.hpp>

#include <bounce/study/content_hash.hpp>
#include <bounce/study/image_entry.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/output_files.hpp>

#include <cstdio>
#include <cstdlib>
#include <cctype>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <utility>
#include <vector>
#include <system_error>

#include <nlohmann/json.hpp>
#include <unistd.h>

namespace bounce::study {

using embree::accel;
using embree::reference_images;
using embree::reference_settings;

namespace {

// Bump when the estimator changes in a way that changes its images.
constexpr const char* integrator_version = "bounce-reference-1";

// The key hashes vectors' bytes: three floats and no padding, as the keys always did.
static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "a padded glm::vec3 would change every cache key");

std::string safe_name(const std::string& name) {
    std::string s;
    for (char c : name) s += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
    return s.empty() ? std::string("scene") : s;
}

nlohmann::json json_of(const glm::vec3& v) { return {v.x, v.y, v.z}; }

// The key of a reference render: "<scene>-<W>x<H>-<S>spp-<kind><16 hex digits>", hashing
// `tag` (when not empty), the integrator's version, the scene's view and the settings.
std::string settings_key(std::string_view tag, std::string_view kind, const io::scene& scene, const bounce::camera& cam,
                         std::size_t width, std::size_t height, const reference_settings& settings,
                         std::string_view device_config) {
    fnv1a_hash h;
    if (!tag.empty()) h.text(tag);
    h.text(integrator_version);
    hash_scene_view(h, scene, cam, width, height);
    h.values(settings.hemisphere_samples, settings.area_samples, settings.secondary_area_samples, settings.environment,
             settings.ray_epsilon, settings.seed);
    if (!device_config.empty()) h.text(device_config);  // Embree's default: the keys of earlier versions
    return view_cache_key(safe_name(scene.name), width, height,
                          std::to_string(settings.hemisphere_samples) + "spp-" + std::string(kind), h);
}

// What every entry's JSON says of its source: the scene, the view and the settings.
nlohmann::json describe(const std::string& key, const io::scene& scene, const bounce::camera& cam, std::size_t width,
                        std::size_t height, const embree::hemisphere_grid& grid, const reference_settings& settings,
                        std::string_view device_config) {
    nlohmann::json d = {
        {"key", key},
        {"integrator", integrator_version},
        {"scene", scene.name},
        {"source", scene.source.string()},
        {"triangles", scene.triangles.size()},
        {"width", width},
        {"height", height},
        {"camera",
         {{"position", json_of(cam.position)},
          {"look_at", json_of(cam.look_at)},
          {"up", json_of(cam.up)},
          {"fov_y_deg", cam.fov_y_deg}}},
        {"hemisphere_samples", settings.hemisphere_samples},
        {"grid", {grid.m, grid.n}},
        {"area_samples", settings.area_samples},
        {"secondary_area_samples", settings.secondary_area_samples},
        {"environment", json_of(settings.environment)},
        {"ray_epsilon", settings.ray_epsilon},
        {"seed", settings.seed},
    };
    if (!device_config.empty()) d["embree_config"] = std::string(device_config);
    return d;
}

image<glm::vec3> sum_of(const image<glm::vec3>& a, const image<glm::vec3>& b) {
    image<glm::vec3> s(a.width(), a.height());
    for (std::size_t y = 0; y < a.height(); ++y)
        for (std::size_t x = 0; x < a.width(); ++x) s(x, y) = a(x, y) + b(x, y);
    return s;
}

// The cached_* functions: the entry `key_of` names in `dir` when `load` finds it, else
// `render` on the view's ray-cast G-buffer, stored (the folder checked first: a cache that
// cannot be written is reported before minutes of rendering, not at the store).
template <class Key, class Load, class Render, class Store>
auto load_or_render(const accel& bvh, const io::scene& scene, const bounce::camera& cam, std::size_t width,
                    std::size_t height, const reference_settings& settings, const std::filesystem::path& dir,
                    bool* from_cache, Key key_of, Load load, Render render, Store store) {
    const std::string& config = bvh.owner().config();
    const std::string key = key_of(scene, cam, width, height, settings, config);
    if (auto cached = load(dir, key, width, height, settings)) {
        if (from_cache) *from_cache = true;
        return std::move(*cached);
    }
    check_cache_dir(dir);
    auto g = ray_cast_gbuffer(bvh, scene, cam, width, height);
    auto rendered = render(bvh, scene, g.view(), settings);
    store(dir, key, rendered, scene, cam, settings, config);
    if (from_cache) *from_cache = false;
    return rendered;
}

}  // namespace

std::filesystem::path default_cache_dir() {
    if (const char* env = std::getenv("BOUNCE_CACHE"); env && *env) return env;
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec && exe.parent_path().filename() == "bin") return exe.parent_path().parent_path() / "cache";
    return std::filesystem::path("build") / "cache";
}

void check_cache_dir(const std::filesystem::path& dir) {
    const char* env = std::getenv("BOUNCE_CACHE");
    const std::string name = (env && *env && std::filesystem::path(env) == dir) ? "BOUNCE_CACHE" : "cache";
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (!std::filesystem::is_directory(dir, ec))
        throw parameter_error(name, "cannot make the cache folder " + dir.string() +
                                        (ec ? " (" + ec.message() + ")" : std::string(" (a file is in the way)")));
    const std::filesystem::path probe = dir / (".write-test-" + std::to_string(::getpid()));
    {
        std::ofstream out(probe, std::ios::binary | std::ios::trunc);
        if (!out) throw parameter_error(name, "cannot write into the cache folder " + dir.string());
    }
    std::filesystem::remove(probe, ec);
}

void hash_scene_view(fnv1a_hash& h, const io::scene& scene, const bounce::camera& cam, std::size_t width,
                     std::size_t height) {
    h.value(scene.positions.size());
    for (const auto& p : scene.positions) h.value(p);
    h.value(scene.normals.size());
    for (const auto& n : scene.normals) h.value(n);
    h.value(scene.triangles.size());
    for (const auto& t : scene.triangles) {
        h.value(t.x);
        h.value(t.y);
        h.value(t.z);
    }
    for (auto m : scene.material_of) h.value(m);
    h.value(scene.materials.size());
    for (const auto& m : scene.materials) {
        h.value(m.albedo);
        h.value(m.emission);
    }
    h.value(scene.lights.size());
    for (const auto& l : scene.lights) {
        h.value(l.index());
        if (const auto* p = std::get_if<point_light>(&l)) {
            h.value(p->position);
            h.value(p->intensity);
        } else if (const auto* s = std::get_if<spot_light>(&l)) {
            h.value(s->position);
            h.value(s->direction);
            h.value(s->intensity);
            h.value(s->cone_deg);
            h.value(int(s->falloff));
        } else {
            const auto& d = std::get<directional_light>(l);
            h.value(d.direction);
            h.value(d.irradiance);
        }
    }
    h.value(scene.use_emission);
    h.value(cam.position);
    h.value(cam.look_at);
    h.value(cam.up);
    h.value(cam.fov_y_deg);
    h.value(cam.near_plane);
    h.value(cam.far_plane);
    h.value(width);
    h.value(height);
}

std::string view_cache_key(std::string_view name, std::size_t width, std::size_t height, std::string_view what,
                           const fnv1a_hash& h) {
    return std::string(name) + "-" + std::to_string(width) + "x" + std::to_string(height) + "-" + std::string(what) +
           h.hex_digest();
}

std::string reference_cache_key(const io::scene& scene, const bounce::camera& cam, std::size_t width,
                                std::size_t height, const reference_settings& settings,
                                std::string_view device_config) {
    return settings_key({}, {}, scene, cam, width, height, settings, device_config);
}

std::optional<reference_images> load_cached_reference(const std::filesystem::path& dir, const std::string& key,
                                                      std::size_t width, std::size_t height,
                                                      const reference_settings& settings) {
    auto images = load_image_entry(dir, key, {".direct.exr", ".indirect.exr"}, width, height);
    if (!images) return std::nullopt;
    reference_images r;
    r.direct = std::move((*images)[0]);
    r.indirect = std::move((*images)[1]);
    r.combined = sum_of(r.direct, r.indirect);
    r.grid = embree::hemisphere_grid_for(settings.hemisphere_samples);
    return r;
}

void store_cached_reference(const std::filesystem::path& dir, const std::string& key, const reference_images& images,
                            const io::scene& scene, const bounce::camera& cam, const reference_settings& settings,
                            std::string_view device_config) {
    store_image_entry(dir, key, {{".direct.exr", &images.direct}, {".indirect.exr", &images.indirect}},
                      describe(key, scene, cam, images.direct.width(), images.direct.height(), images.grid, settings,
                               device_config)
                              .dump(2) + '\n');
}

reference_images cached_reference(const accel& bvh, const io::scene& scene, const bounce::camera& cam,
                                  std::size_t width, std::size_t height, const reference_settings& settings,
                                  const std::filesystem::path& dir, bool* from_cache) {
    return load_or_render(bvh, scene, cam, width, height, settings, dir, from_cache, reference_cache_key,
                          load_cached_reference, embree::render_reference, store_cached_reference);
}

namespace {
// The hash's first text: a halves entry never shares a key with a whole reference.
constexpr const char* halves_tag = "reference-halves";
constexpr std::uint64_t stage_halves = 0x68616c766573ull;  // "halves": derive_seed's stage tag

reference_settings half_settings(const reference_settings& settings, int which) {
    reference_settings s = settings;
    s.hemisphere_samples = settings.hemisphere_samples / 2;
    s.seed = half_seed(settings.seed, which);
    return s;
}

image<glm::vec3> mean_of(const image<glm::vec3>& a, const image<glm::vec3>& b) {
    image<glm::vec3> m(a.width(), a.height());
    for (std::size_t y = 0; y < a.height(); ++y)
        for (std::size_t x = 0; x < a.width(); ++x) m(x, y) = 0.5f * (a(x, y) + b(x, y));
    return m;
}

void finish_whole(reference_halves& h) {
    h.whole.indirect = mean_of(h.indirect_a, h.indirect_b);
    h.whole.combined = sum_of(h.whole.direct, h.whole.indirect);
}
}  // namespace

std::uint64_t half_seed(std::uint64_t seed, int which) {
    require(which == 0 || which == 1, "which", "a reference has halves 0 and 1");
    return embree::derive_seed(seed, stage_halves, std::uint64_t(which));
}

std::string reference_halves_cache_key(const io::scene& scene, const bounce::camera& cam, std::size_t width,
                                       std::size_t height, const reference_settings& settings,
                                       std::string_view device_config) {
    require(settings.hemisphere_samples >= 2, "hemisphere_samples", "a reference in halves needs at least 2 samples");
    return settings_key(halves_tag, "halves-", scene, cam, width, height, settings, device_config);
}

std::optional<reference_halves> load_cached_reference_halves(const std::filesystem::path& dir, const std::string& key,
                                                             std::size_t width, std::size_t height,
                                                             const reference_settings& settings) {
    auto images = load_image_entry(dir, key, {".direct.exr", ".indirect-a.exr", ".indirect-b.exr"}, width, height);
    if (!images) return std::nullopt;
    reference_halves h;
    h.whole.direct = std::move((*images)[0]);
    h.indirect_a = std::move((*images)[1]);
    h.indirect_b = std::move((*images)[2]);
    h.half_samples = settings.hemisphere_samples / 2;
    h.whole.grid = embree::hemisphere_grid_for(h.half_samples);
    finish_whole(h);
    return h;
}

void store_cached_reference_halves(const std::filesystem::path& dir, const std::string& key,
                                   const reference_halves& halves, const io::scene& scene, const bounce::camera& cam,
                                   const reference_settings& settings, std::string_view device_config) {
    nlohmann::json d = describe(key, scene, cam, halves.whole.direct.width(), halves.whole.direct.height(),
                                halves.whole.grid, settings, device_config);
    d["kind"] = "halves: indirect = (indirect-a + indirect-b) / 2, direct computed with half a's seed";
    d["half_samples"] = settings.hemisphere_samples / 2;
    d["half_seeds"] = {half_seed(settings.seed, 0), half_seed(settings.seed, 1)};
    store_image_entry(dir, key,
                      {{".direct.exr", &halves.whole.direct},
                       {".indirect-a.exr", &halves.indirect_a},
                       {".indirect-b.exr", &halves.indirect_b}},
                      d.dump(2) + '\n');
}

reference_halves render_reference_halves(const accel& bvh, const scene_view& scene, const gbuffer_view<float>& g,
                                         const reference_settings& settings) {
    require(settings.hemisphere_samples >= 2, "hemisphere_samples", "a reference in halves needs at least 2 samples");
    reference_halves h;
    h.half_samples = settings.hemisphere_samples / 2;
    embree::reference_images a = embree::render_reference(bvh, scene, g, half_settings(settings, 0));
    h.whole.direct = std::move(a.direct);
    h.whole.grid = a.grid;
    h.indirect_a = std::move(a.indirect);
    h.indirect_b = embree::reference_integrator(bvh, scene, half_settings(settings, 1)).indirect_image(g);
    finish_whole(h);
    return h;
}

reference_halves cached_reference_halves(const accel& bvh, const io::scene& scene, const bounce::camera& cam,
                                         std::size_t width, std::size_t height, const reference_settings& settings,
                                         const std::filesystem::path& dir, bool* from_cache) {
    return load_or_render(bvh, scene, cam, width, height, settings, dir, from_cache, reference_halves_cache_key,
                          load_cached_reference_halves, render_reference_halves, store_cached_reference_halves);
}

}  // namespace bounce::study
