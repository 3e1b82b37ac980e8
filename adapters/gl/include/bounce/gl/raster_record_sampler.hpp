#pragma once
/// \file raster_record_sampler.hpp
/// Irradiance records by single-plane rasterization (Gautron 2008, section 8.4): the record sampler
/// interface of embree::record_sampler,
///   std::optional<irradiance_record> operator()(glm::vec3 p, glm::vec3 n, double pixel_footprint),
/// over gl::hemisphere_raster with border-stretching weights and the GPU reduction.
///
/// One record per call renders a batch of one plane; the batch form renders many planes
/// per atlas, which is what cpu::scan_cache_misses_batched gives it (its guesses). A plane
/// depends only on its record's point and normal, so both forms make the same records up
/// to the rounding of the atlas placement.

#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/plane_weights.hpp>
#include <bounce/irradiance_record.hpp>
#include <bounce/record_sampler.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>
#include <span>

namespace bounce::gl {

class raster_record_sampler {
public:
    /// `raster` must outlive the sampler (and its context be current when it is called);
    /// `kind`: the plane weighting (typical: stretch); `limits`: radius clamps; `kappa`:
    /// fall-off stretching's band factor, fixed for the sampler's life (for instance
    /// radial_profile::falloff_factor of an earlier run's planes; the reduction does not
    /// keep a profile). Throws parameter_error for a kappa outside [0, 1], or a kappa other
    /// than 1 with another weighting.
    raster_record_sampler(hemisphere_raster& raster, radius_limits limits,
                          plane_weighting kind = plane_weighting::stretch, double kappa = 1.0)
        : raster_(raster), limits_(limits), weights_(make_plane_weights(raster.options().camera, kind, kappa)) {
        require(kind == plane_weighting::falloff || kappa == 1.0, "kappa", "applies to fall-off stretching only");
    }

    std::optional<irradiance_record> operator()(glm::vec3 p, glm::vec3 n, double pixel_footprint) {
        std::optional<irradiance_record> out;
        (*this)(std::span(&p, 1), std::span(&n, 1), std::span(&pixel_footprint, 1), std::span(&out, 1));
        return out;
    }

    /// Records for points[k], normals[k], footprints[k] into out[k], rendered capacity()
    /// planes per atlas. Throws parameter_error when the spans' sizes differ.
    void operator()(std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                    std::span<const double> footprints, std::span<std::optional<irradiance_record>> out) {
        require(normals.size() == points.size() && footprints.size() == points.size() && out.size() == points.size(),
                "points", "points, normals, footprints and out must have one entry per record");
        raster_.set_weights(weights_);  // the raster may be shared with other samplers or studies
        for (std::size_t first = 0; first < points.size(); first += raster_.capacity()) {
            const std::size_t count = std::min(raster_.capacity(), points.size() - first);
            raster_.render(points.subspan(first, count), normals.subspan(first, count));
            const std::vector<hemisphere_estimate> est = raster_.reduce();
            for (std::size_t k = 0; k < count; ++k) {
                const glm::vec3 n = normals[first + k];
                // The planes are rendered, and estimated, in the camera's frame.
                const auto tb = raster_.options().camera.frame(points[first + k], n);
                const irradiance_record rec =
                    make_record(points[first + k], n, tb[0], tb[1], est.at(k), limits_, footprints[first + k]);
                if (std::isfinite(rec.radius) && rec.radius > 0.f) out[first + k] = rec;
                else out[first + k] = std::nullopt;
            }
        }
    }

private:
    hemisphere_raster& raster_;
    radius_limits limits_;
    plane_weights weights_;
};

static_assert(bounce::record_sampler<raster_record_sampler>);

}  // namespace bounce::gl
