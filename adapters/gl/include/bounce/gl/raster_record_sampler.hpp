#pragma once
/// \file raster_record_sampler.hpp
/// Irradiance records by single-plane rasterization (Gautron 2008, section 8.4): the record sampler
/// interface of embree::record_sampler,
///   std::optional<irradiance_record> operator()(glm::vec3 p, glm::vec3 n, double pixel_footprint),
/// over gl::hemisphere_raster with a plane weighting (border stretching by default) and the
/// GPU reduction.
///
/// One record per call renders a batch of one plane; the batch form renders many planes
/// per atlas, which is what cpu::scan_cache_misses_batched gives it (its guesses). In the
/// fixed modes a plane depends only on its record's point and normal, so both forms make the
/// same records up to the rounding of the atlas placement, and the batched scan keeps the
/// sequential scan's result bit for bit.
///
/// In falloff_mode::running the band factor kappa of fall-off stretching comes from the
/// running radial profile (cache/radial_profile.hpp, docs/hemisphere-sampling.md): each batch
/// takes the kappa of every plane the sampler has rendered, its own batch included. A record
/// then depends on the batches before it and on the other planes of its own batch, so it is
/// no longer a pure function of its point: the batched scan's records (its guesses, the
/// discarded ones included, enter the profile) differ from the sequential scan's, and
/// the same points in other batches give other records.

#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/cache/plane_weights.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/cache/radial_profile.hpp>
#include <bounce/cache/record_sampler.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>
#include <span>

namespace bounce::gl {

/// Where fall-off stretching's band factor kappa comes from.
enum class falloff_mode {
    fixed,    ///< raster_record_sampler_options::kappa, for the sampler's life
    running,  ///< the radial profile of every plane rendered so far, the batch's own included
};

/// Settings of a raster_record_sampler.
struct raster_record_sampler_options {
    plane_weighting kind = plane_weighting::stretch;  ///< the plane weighting; typical: stretch, or falloff
    falloff_mode falloff = falloff_mode::fixed;        ///< running: kind must be falloff
    /// Fixed mode, kind falloff: the band's radiance factor in [0, 1] (radial_profile::
    /// falloff_factor of an earlier run's planes; typical 0.85-0.9). Must stay 1 otherwise.
    double kappa = 1.0;

    /// Throws parameter_error naming the field: kappa outside [0, 1] or other than 1 with a
    /// weighting other than falloff or in running mode; falloff running with another kind.
    void validate() const {
        require(falloff == falloff_mode::fixed || falloff == falloff_mode::running, "falloff", "unknown mode");
        require(std::isfinite(kappa) && kappa >= 0.0 && kappa <= 1.0, "kappa", "must lie in [0, 1]");
        require(kind == plane_weighting::falloff || kappa == 1.0, "kappa", "applies to fall-off stretching only");
        require(falloff == falloff_mode::fixed || kind == plane_weighting::falloff, "falloff",
                "the running profile is a mode of fall-off stretching (kind falloff)");
        require(falloff == falloff_mode::fixed || kappa == 1.0, "kappa",
                "the running profile sets kappa itself; leave it 1");
    }
};

class raster_record_sampler {
public:
    /// `raster` must outlive the sampler (and its context be current when it is called);
    /// `limits`: radius clamps. Throws parameter_error for bad options (see validate).
    raster_record_sampler(hemisphere_raster& raster, radius_limits limits, const raster_record_sampler_options& options)
        : raster_(raster), limits_(limits), options_((options.validate(), options)),
          weights_(make_plane_weights(raster.options().camera, options.kind, options.kappa)),
          profile_(raster.options().camera) {}

    /// The fixed modes: `kind` the plane weighting (typical: stretch), `kappa` fall-off
    /// stretching's band factor for the sampler's life. Throws parameter_error for a kappa
    /// outside [0, 1], or a kappa other than 1 with another weighting.
    raster_record_sampler(hemisphere_raster& raster, radius_limits limits,
                          plane_weighting kind = plane_weighting::stretch, double kappa = 1.0)
        : raster_record_sampler(raster, limits, raster_record_sampler_options{kind, falloff_mode::fixed, kappa}) {}

    const raster_record_sampler_options& options() const noexcept { return options_; }

    /// The band factor of the weights in use: the fixed kappa (0 for plane and coverage, 1
    /// for stretch); in running mode, the kappa of every plane rendered so far (the last
    /// batch's), 1 (border stretching) before the first.
    double falloff_kappa() const noexcept { return weights_.band_factor; }
    /// The running profile: every plane rendered in running mode (none in the fixed modes).
    const radial_profile& profile() const noexcept { return profile_; }

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
        estimates_.resize(points.size());
        estimate(points, normals, estimates_, {});
        for (std::size_t k = 0; k < points.size(); ++k) {
            // The planes are rendered, and estimated, in the camera's frame.
            const auto tb = raster_.options().camera.frame(points[k], normals[k]);
            const irradiance_record rec = make_record(points[k], normals[k], tb[0], tb[1], estimates_[k], limits_, footprints[k]);
            if (std::isfinite(rec.radius) && rec.radius > 0.f) out[k] = rec;
            else out[k] = std::nullopt;
        }
    }

    /// The hemisphere estimates of the records (points[k], normals[k]) in their planes'
    /// frames (hemisphere_raster::reduce: irradiance, gradients, harmonic mean distance),
    /// rendered capacity() planes per atlas in order, and, where `kappas` is not empty, the
    /// band factor each was summed with. Throws parameter_error when the spans' sizes differ,
    /// or in running mode when the raster has reads pending (the sampler reads its batches
    /// back and would collect another's).
    void estimate(std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                  std::span<hemisphere_estimate> out, std::span<double> kappas) {
        require(normals.size() == points.size() && out.size() == points.size(), "points",
                "points, normals and out must have one entry per record");
        require(kappas.empty() || kappas.size() == points.size(), "kappas", "must be empty or have one entry per record");
        const bool running = options_.falloff == falloff_mode::running;
        require(!running || raster_.pending_reads() == 0, "raster", "has reads pending; the running profile reads its batches back");
        raster_.set_weights(weights_);  // the raster may be shared with other samplers or studies
        for (std::size_t first = 0; first < points.size(); first += raster_.capacity()) {
            const std::size_t count = std::min(raster_.capacity(), points.size() - first);
            raster_.render(points.subspan(first, count), normals.subspan(first, count));
            if (running) add_to_profile();
            const std::vector<hemisphere_estimate> est = raster_.reduce();
            std::copy_n(est.begin(), count, out.begin() + std::ptrdiff_t(first));
            if (!kappas.empty()) std::fill_n(kappas.begin() + std::ptrdiff_t(first), count, falloff_kappa());
        }
    }

private:
    // The running profile, as hemisphere_study measured it (docs/hemisphere-sampling.md):
    // the batch's planes come back to the CPU (start_read then finish_read at once: the
    // reduction needs the kappa they give, so there is nothing to overlap the copy with),
    // join the profile in order, and the batch is summed with the kappa of the whole profile.
    // Cost per batch: the atlas read back (16 bytes per texel: 64 KiB per 64^2 plane), N^2
    // luminances per plane added on one CPU thread, and a new weight table when kappa moves.
    void add_to_profile() {
        raster_.start_read();
        const plane_batch planes = raster_.finish_read();
        for (std::size_t k = 0; k < planes.size(); ++k) profile_.add(planes.radiance[k].view());
        const double kappa = profile_.falloff_factor();
        if (kappa != weights_.band_factor) {
            weights_ = make_plane_weights(raster_.options().camera, plane_weighting::falloff, kappa);
            raster_.set_weights(weights_);
        }
    }

    hemisphere_raster& raster_;
    radius_limits limits_;
    raster_record_sampler_options options_;
    plane_weights weights_;
    radial_profile profile_;
    std::vector<hemisphere_estimate> estimates_;
};

static_assert(bounce::record_sampler<raster_record_sampler>);

}  // namespace bounce::gl
