#pragma once
/// \file multi_bounce_cache.hpp
/// The multi-bounce reference view (embree::multi_bounce_reference, the ground truth of
/// progressive radiosity and of every all-bounce comparison) cached on disk, as
/// reference_cache.hpp caches the one-bounce reference: an entry is `<dir>/<key>.exr`
/// (radiance, linear float RGB) and `<key>.json` (each bounce's share, per channel). The key
/// reads "<scene>-<W>x<H>-<paths>paths-multibounce-<16 hex digits>", the hash starting from
/// hash_scene_view (geometry, materials, lights, camera, size), then the settings (paths,
/// max_bounces, roulette_after, area_samples, seed) and the Embree device's configuration.

#include <bounce/camera.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/multi_bounce_reference.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/reference_cache.hpp>

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace bounce::study {

/// The cache key of the multi-bounce view of `scene` through `cam` at `width` x `height` with
/// `settings` on a device configured with `device_config` (device::config()).
std::string multi_bounce_cache_key(const io::scene& scene, const bounce::camera& cam, std::size_t width,
                                   std::size_t height, const embree::multi_bounce_settings& settings,
                                   std::string_view device_config = {});

/// The cached view under `key` in `dir`, or nothing when an entry is missing, unreadable or
/// of another size than `width` x `height` (the caller then recomputes).
std::optional<embree::multi_bounce_image> load_multi_bounce(const std::filesystem::path& dir, const std::string& key,
                                                            std::size_t width, std::size_t height);

/// Writes `image` under `key` in `dir` (made when missing), each file under a temporary name
/// renamed into place, so a reader never sees half an entry. Throws bounce::error
/// (io::output_error, the image writer's error, or parameter_error naming the folder) when
/// the folder or a file cannot be written.
void store_multi_bounce(const std::filesystem::path& dir, const std::string& key, const embree::multi_bounce_image& image);

/// The multi-bounce view of `scene` through `cam`: from the cache in `dir` when present, else
/// rendered with `settings` (its progress callback called as it renders) and stored for next
/// time. `from_cache` (optional) receives whether the cache answered. Check the folder with
/// check_cache_dir before calling when a failure to store must come before the render.
embree::multi_bounce_image cached_multi_bounce(const embree::accel& bvh, const io::scene& scene, const bounce::camera& cam,
                                               std::size_t width, std::size_t height,
                                               const embree::multi_bounce_settings& settings,
                                               const std::filesystem::path& dir = default_cache_dir(),
                                               bool* from_cache = nullptr);

}  // namespace bounce::study
