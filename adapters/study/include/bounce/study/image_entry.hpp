#pragma once
/// \file image_entry.hpp
/// A cache entry of images on disk: `<dir>/<key><suffix>` linear float EXRs and
/// `<dir>/<key>.json` describing what they were computed from, each written to a temporary
/// name and renamed, so a reader never sees half an entry. The reference caches
/// (reference_cache.hpp) and the benchmark's references keep their images this way.

#include <bounce/image.hpp>

#include <cstddef>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::study {

/// The entry's images, one per suffix in order, or nothing when one is missing, unreadable or
/// not `width` x `height` (the caller then recomputes and overwrites).
std::optional<std::vector<image<glm::vec3>>> load_image_entry(const std::filesystem::path& dir, const std::string& key,
                                                              std::initializer_list<const char*> suffixes,
                                                              std::size_t width, std::size_t height);

/// Writes the entry's images and `description` (JSON text) under `dir` (made when missing).
/// Throws bounce::error naming the folder or file when any of it cannot be written.
void store_image_entry(const std::filesystem::path& dir, const std::string& key,
                       std::initializer_list<std::pair<const char*, const image<glm::vec3>*>> images,
                       std::string_view description);

}  // namespace bounce::study
