#pragma once
/// \file raster_record_sampler.hpp
/// Irradiance records by single-plane rasterization (seed section 8.4): the record sampler
/// interface of embree::record_sampler,
///   std::optional<irradiance_record> operator()(glm::vec3 p, glm::vec3 n, double pixel_footprint),
/// over gl::hemisphere_raster with border-stretching weights and the GPU reduction.
///
/// The irradiance cache's scan asks for one record at a time, so each call renders a batch
/// of one plane; a renderer that can gather misses first should call hemisphere_raster
/// with full batches instead.

#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/hemisphere.hpp>
#include <bounce/irradiance_record.hpp>
#include <bounce/sampling.hpp>

#include <cmath>
#include <optional>
#include <span>

namespace bounce::gl {

class raster_record_sampler {
public:
    /// `raster` must outlive the sampler (and its context be current when it is called);
    /// `kind`: the plane weighting (typical: stretch); `limits`: radius clamps.
    raster_record_sampler(hemisphere_raster& raster, radius_limits limits,
                          plane_weighting kind = plane_weighting::stretch)
        : raster_(raster), limits_(limits) {
        raster_.set_weights(make_plane_weights(raster_.options().camera, kind));
    }

    std::optional<irradiance_record> operator()(glm::vec3 p, glm::vec3 n, double pixel_footprint) {
        raster_.render(std::span(&p, 1), std::span(&n, 1));
        const hemisphere_estimate est = raster_.reduce().at(0);
        // The planes are rendered in the frame of orthonormal_basis(n) (hemisphere.hpp).
        const auto tb = orthonormal_basis<float, glm::vec3>(n);
        const irradiance_record rec = make_record(p, n, tb[0], tb[1], est, limits_, pixel_footprint);
        if (!std::isfinite(rec.radius) || !(rec.radius > 0.f)) return std::nullopt;
        return rec;
    }

private:
    hemisphere_raster& raster_;
    radius_limits limits_;
};

}  // namespace bounce::gl
