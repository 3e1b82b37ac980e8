#pragma once
/// \file cache/record_sampler.hpp
/// What an irradiance cache asks of the thing that computes its records: the `record_sampler`
/// concept. A sampler measures the hemisphere above surface points (by rays, by rasterizing
/// one plane per record, by whatever the renderer has) and returns irradiance records with
/// their gradients and radius (cache/record.hpp).
///
/// The cache asks in batches: the batched cache-miss scan guesses several misses ahead and
/// measures them together (a GPU sampler renders a batch in one atlas; a ray tracer traces it
/// on every core). When a record is a pure function of its point, normal and footprint (the
/// sampler seeded by the point, not by a call counter), the scan can measure ahead and keep
/// the result of the one-record-at-a-time scan bit for bit. A sampler that learns as it goes
/// (the raster sampler's running fall-off profile) is still a record sampler, but that
/// equality no longer holds for it.

#include <bounce/cache/record.hpp>

#include <concepts>
#include <optional>
#include <span>

#include <glm/vec3.hpp>

namespace bounce::inline cache {

/// A record sampler: `s(points, normals, footprints, out)` fills out[k] with the record at
/// points[k] (world space) with unit normal normals[k], whose pixel footprint (world units
/// per pixel at that depth, for the radius clamps of radius_limits) is footprints[k], or
/// nullopt where the hemisphere gives no finite estimate. All spans have one entry per record.
template <class S>
concept record_sampler = requires(S& s, std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                                  std::span<const double> footprints,
                                  std::span<std::optional<irradiance_record>> out) {
    s(points, normals, footprints, out);
};

}  // namespace bounce::cache
