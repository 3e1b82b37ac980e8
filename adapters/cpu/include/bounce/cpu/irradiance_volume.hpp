#pragma once
/// \file irradiance_volume.hpp
/// Lighting many points from an irradiance volume at once: the per-frame call a renderer
/// makes for the surface points of its moving objects (Oat 2006). Each point's lookup is
/// independent (volume/probe_octree.hpp), so the result does not depend on the thread count.
/// With the probes' distance moments (volume/probe_visibility.hpp) the trilinear lookup
/// tests each corner probe's visibility (DDGI), and `light_gbuffer` lights the surface
/// points of a view.

#include <bounce/errors.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/output.hpp>
#include <bounce/volume/probe_octree.hpp>
#include <bounce/volume/probe_visibility.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <span>
#include <vector>

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
    /// The visibility test, where the caller gives the probes' distance moments (the
    /// light_points overload with a probe_visibility); it weighs the trilinear corners, so
    /// the weighted lookup takes volume_visibility::none.
    visibility_lookup visibility{};
};

namespace volume_detail {

/// light_points with or without moments (`vis` null: none) and the eye (for the view
/// direction of the visibility test's bias).
inline void light_points_with(const irradiance_volume& volume, const probe_visibility* vis, glm::vec3 eye,
                              std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                              std::span<glm::vec3> out, const volume_lookup& how, output_quantity quantity,
                              std::span<const glm::vec3> albedo) {
    require(normals.size() == points.size(), "normals", "one normal per point");
    require(out.size() == points.size(), "out", "one result per point");
    require(quantity == output_quantity::irradiance || albedo.size() == points.size(), "albedo",
            "one albedo per point is needed for radiance");
    require(how.weighted.b > 0 && how.weighted.b <= 16, "b", "the distance exponent must lie in (0, 16]");
    const bool visible = vis && how.visibility.mode != volume_visibility::none;
    require(!visible || how.interpolation == volume_interpolation::trilinear, "visibility",
            "the visibility test weighs the trilinear lookup's corners; the weighted lookup takes none");
    require(!visible || (std::isfinite(eye.x) && std::isfinite(eye.y) && std::isfinite(eye.z)), "eye", "must be finite");
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const glm::vec3 p = points[i], n = normals[i];
            if (visible) {
                out[i] = trilinear_visible(volume, *vis, p, n, view_direction<float, glm::vec3>(p, n, eye), how.visibility);
            } else {
                out[i] = how.interpolation == volume_interpolation::trilinear ? volume.trilinear(p, n)
                                                                              : volume.weighted(p, n, how.weighted);
            }
        }
    });
    apply_output(quantity, albedo, out);
}

}  // namespace volume_detail

/// The light at each point with its unit normal as `quantity` (output.hpp): irradiance
/// (W/m^2, RGB; the default) or radiance rho/pi * E with `albedo` (one per point), rows of
/// 256 points in parallel. Without distance moments there is no visibility test
/// (how.visibility is not used). Throws parameter_error naming "normals", "out" or "albedo"
/// when sizes differ, and "b" for an exponent outside (0, 16].
inline void light_points(const irradiance_volume& volume, std::span<const glm::vec3> points,
                         std::span<const glm::vec3> normals, std::span<glm::vec3> out, const volume_lookup& how,
                         output_quantity quantity = output_quantity::irradiance,
                         std::span<const glm::vec3> albedo = {}) {
    volume_detail::light_points_with(volume, nullptr, glm::vec3(0.f), points, normals, out, how, quantity, albedo);
}

/// As above with the probes' distance moments `vis` (one map per probe of `volume`): with
/// how.visibility.mode = chebyshev each point is lit by trilinear_visible, its view direction
/// towards `eye` (the camera). Throws as above, and parameter_error naming "visibility" for
/// the weighted lookup with a visibility test or moments of another volume, "eye" when not
/// finite.
inline void light_points(const irradiance_volume& volume, const probe_visibility& vis, glm::vec3 eye,
                         std::span<const glm::vec3> points, std::span<const glm::vec3> normals, std::span<glm::vec3> out,
                         const volume_lookup& how, output_quantity quantity = output_quantity::irradiance,
                         std::span<const glm::vec3> albedo = {}) {
    volume_detail::light_points_with(volume, &vis, eye, points, normals, out, how, quantity, albedo);
}

/// The volume's light at the surface points of a view: every covered pixel of `g` (seen
/// from `eye`) lit by light_points (with `vis` when not null), as `quantity` (radiance with
/// g's albedo); uncovered pixels are 0. Throws as light_points.
inline image<glm::vec3> light_gbuffer(const irradiance_volume& volume, const probe_visibility* vis,
                                      const gbuffer_view<float>& g, glm::vec3 eye, const volume_lookup& how,
                                      output_quantity quantity = output_quantity::irradiance) {
    std::vector<glm::vec3> points, normals, albedo;
    std::vector<std::size_t> pixels;
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x) {
            if (!g.covered(x, y)) continue;
            points.push_back(g.position(x, y));
            normals.push_back(g.normal(x, y));
            albedo.push_back(g.albedo(x, y));
            pixels.push_back(y * g.width() + x);
        }
    std::vector<glm::vec3> lit(points.size());
    volume_detail::light_points_with(volume, vis, eye, points, normals, lit, how, quantity, albedo);
    image<glm::vec3> out(g.width(), g.height(), glm::vec3(0.f));
    for (std::size_t i = 0; i < pixels.size(); ++i) out(pixels[i] % g.width(), pixels[i] / g.width()) = lit[i];
    return out;
}

}  // namespace bounce::cpu
