#pragma once
/// \file reference_cache.hpp
/// Reference images cached on disk, so every example computes its ground truth once.
///
/// A cache entry is `<dir>/<key>.direct.exr` and `<key>.indirect.exr` (linear float RGB),
/// with `<key>.json` describing what it was computed from. The key names the scene, the
/// size and the sample count for people, and ends in a 64-bit FNV-1a hash of everything
/// the images depend on: the scene's geometry, normals, materials, lights and
/// use_emission, the camera, the size, the integrator settings (samples, environment,
/// ray offset, seed), the integrator's version and, when one was given, the Embree device's
/// configuration (pinned kernels round hits differently; Embree's default leaves the key as
/// it was). Change any of them and the key changes.

#include <bounce/camera.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/content_hash.hpp>

#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace bounce::study {

/// $BOUNCE_CACHE when set; else `cache/` beside the `bin/` folder the running program lives
/// in (build/bin/reference -> build/cache); else ./build/cache.
std::filesystem::path default_cache_dir();

/// Throws parameter_error naming "BOUNCE_CACHE" (when `dir` came from it) or "cache" unless
/// `dir` is a folder that exists or can be made and in which a file can be created (tried,
/// then removed). Call it before the work whose result is to be cached: a cache that cannot
/// be written is a mistake to report at once, not after the reference has been computed.
void check_cache_dir(const std::filesystem::path& dir = default_cache_dir());

/// Adds to `h` all that a rendered view of `scene` depends on: positions, normals, triangles,
/// materials, lights, use_emission, the camera and the image size. Every cache key of a
/// rendered reference starts from it (then adds its integrator's version and settings).
void hash_scene_view(fnv1a_hash& h, const io::scene& scene, const bounce::camera& cam, std::size_t width,
                     std::size_t height);

/// The file name every cached view's key has: "<name>-<width>x<height>-<what><the 16 hex
/// digits of h>", where `what` says the samples and the kind ("1024spp-", "256paths-multibounce-").
std::string view_cache_key(std::string_view name, std::size_t width, std::size_t height, std::string_view what,
                           const fnv1a_hash& h);

/// The cache key of a reference render of `scene` seen by `cam` at `width` x `height` with
/// `settings` on a device configured with `device_config` (device::config()):
/// "<scene name>-<W>x<H>-<spp>spp-<16 hex digits>" (file-name safe).
std::string reference_cache_key(const io::scene& scene, const bounce::camera& cam, std::size_t width,
                                std::size_t height, const embree::reference_settings& settings,
                                std::string_view device_config = {});

/// The cached images under `key` in `dir`, or nothing when an entry is missing, unreadable
/// or of another size than `width` x `height` (the caller then recomputes). The combined
/// image is recomputed as direct + indirect.
std::optional<embree::reference_images> load_cached_reference(const std::filesystem::path& dir, const std::string& key,
                                                      std::size_t width, std::size_t height,
                                                      const embree::reference_settings& settings);

/// Writes `images` under `key` in `dir` (created when missing), with a JSON description
/// (including `device_config` when not empty). Each file is written to a
/// temporary name and renamed, so a reader never sees half an entry. Throws bounce::error
/// (from the image writer) when the directory or a file cannot be written.
void store_cached_reference(const std::filesystem::path& dir, const std::string& key, const embree::reference_images& images,
                            const io::scene& scene, const bounce::camera& cam, const embree::reference_settings& settings,
                            std::string_view device_config = {});

/// The reference images of `scene` through `cam`: from the cache when present, else ray
/// cast G-buffer + render_reference, stored for next time. `from_cache` (optional)
/// receives whether the cache answered.
embree::reference_images cached_reference(const embree::accel& bvh, const io::scene& scene, const bounce::camera& cam,
                                  std::size_t width, std::size_t height, const embree::reference_settings& settings,
                                  const std::filesystem::path& dir = default_cache_dir(), bool* from_cache = nullptr);

// ---- References in two independent halves ------------------------------------------------
//
// A reference of `settings.hemisphere_samples` = S samples per pixel computed as two halves A
// and B of S / 2 samples each, with unrelated seeds (half_seed(settings.seed, 0) and
// (seed, 1)): R = (A + B) / 2 costs what a whole S-sample reference costs, and mean |A - B|^2 / 4
// measures R's own noise, which compare_luminance_debiased takes out of an error measured
// against R. The direct image is computed once (with half A's seed). An entry is
// `<key>.direct.exr`, `<key>.indirect-a.exr`, `<key>.indirect-b.exr` and `<key>.json`;
// its key reads "<scene>-<W>x<H>-<S>spp-halves-<hash>" and its hash starts from another
// tag than a whole reference's, so the two kinds never share an entry.

/// A reference made of two independent halves, and their mean.
struct reference_halves {
    /// direct (half A's seed), indirect = (A + B) / 2, combined = direct + indirect; grid is
    /// one half's M x N grid.
    embree::reference_images whole;
    image<glm::vec3> indirect_a, indirect_b;  ///< the halves' indirect images
    std::uint32_t half_samples = 0;           ///< hemisphere samples per pixel of each half
};

/// The seed of half `which` (0: A, 1: B) of a reference with base seed `seed`: a SplitMix64
/// hash (embree::derive_seed), unrelated to `seed` itself and to the Monte Carlo runs' seeds.
std::uint64_t half_seed(std::uint64_t seed, int which);

/// The cache key of the halves of a reference with `settings` (hemisphere_samples: both
/// halves together; at least 2).
std::string reference_halves_cache_key(const io::scene& scene, const bounce::camera& cam, std::size_t width,
                                       std::size_t height, const embree::reference_settings& settings,
                                       std::string_view device_config = {});

/// The cached halves under `key`, or nothing when a file is missing, unreadable or of
/// another size.
std::optional<reference_halves> load_cached_reference_halves(const std::filesystem::path& dir, const std::string& key,
                                                             std::size_t width, std::size_t height,
                                                             const embree::reference_settings& settings);

/// Writes `halves` under `key` in `dir` as store_cached_reference does.
void store_cached_reference_halves(const std::filesystem::path& dir, const std::string& key,
                                   const reference_halves& halves, const io::scene& scene, const bounce::camera& cam,
                                   const embree::reference_settings& settings, std::string_view device_config = {});

/// Computes the halves over the G-buffer `g` (no cache): A and B with S / 2 samples each.
/// Throws parameter_error when settings.hemisphere_samples < 2.
reference_halves render_reference_halves(const embree::accel& bvh, const scene_view& scene,
                                         const gbuffer_view<float>& g, const embree::reference_settings& settings);

/// The halves of the reference of `scene` through `cam`: from the cache when present, else
/// ray cast G-buffer + render_reference_halves, stored for next time.
reference_halves cached_reference_halves(const embree::accel& bvh, const io::scene& scene, const bounce::camera& cam,
                                         std::size_t width, std::size_t height,
                                         const embree::reference_settings& settings,
                                         const std::filesystem::path& dir = default_cache_dir(),
                                         bool* from_cache = nullptr);

}  // namespace bounce::study
