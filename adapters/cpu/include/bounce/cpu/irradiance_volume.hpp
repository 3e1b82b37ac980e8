#pragma once
/// \file irradiance_volume.hpp
/// Lighting many points from an irradiance volume at once: the per-frame call a renderer
/// makes for the surface points of its moving objects (Oat 2006). Each point's lookup is
/// independent (volume/probe_octree.hpp), so the result does not depend on the thread count.

#include <bounce/errors.hpp>
#include <bounce/output.hpp>
#include <bounce/volume/probe_octree.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <span>

#include <glm/vec3.hpp>

namespace bounce::cpu {

/// Which interpolation a lookup uses.
enum class volume_interpolation {
    trilinear,  ///< the leaf's 8 corners (exact on uniform grids; pops at T-junctions)
    weighted,   ///< distance-weighted average over neighbouring leaves, optional gradients
};

/// A lookup's choice of interpolation and, for `weighted`, its exponent and gradients.
struct volume_lookup {
    /// Trilinear by default: the weighted lookups lose to it on every shared scene
    /// (docs/sh-and-irradiance-volumes.md, issue 31).
    volume_interpolation interpolation = volume_interpolation::trilinear;
    weighted_lookup weighted{};
};

/// The light at each point with its unit normal as `quantity` (output.hpp): irradiance
/// (W/m^2, RGB; the default) or radiance rho/pi * E with `albedo` (one per point), rows of
/// 256 points in parallel. Throws parameter_error naming "normals", "out" or "albedo" when
/// sizes differ, and "b" for an exponent outside (0, 16].
inline void light_points(const irradiance_volume& volume, std::span<const glm::vec3> points,
                         std::span<const glm::vec3> normals, std::span<glm::vec3> out, const volume_lookup& how,
                         output_quantity quantity = output_quantity::irradiance,
                         std::span<const glm::vec3> albedo = {}) {
    require(normals.size() == points.size(), "normals", "one normal per point");
    require(out.size() == points.size(), "out", "one result per point");
    require(quantity == output_quantity::irradiance || albedo.size() == points.size(), "albedo",
            "one albedo per point is needed for radiance");
    require(how.weighted.b > 0 && how.weighted.b <= 16, "b", "the distance exponent must lie in (0, 16]");
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
            out[i] = how.interpolation == volume_interpolation::trilinear ? volume.trilinear(points[i], normals[i])
                                                                          : volume.weighted(points[i], normals[i], how.weighted);
    });
    apply_output(quantity, albedo, out);
}

}  // namespace bounce::cpu
