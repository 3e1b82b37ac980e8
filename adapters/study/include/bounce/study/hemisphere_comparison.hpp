#pragma once
/// \file hemisphere_comparison.hpp
/// The hemisphere study's measurements (docs/hemisphere-sampling.md): irradiance from one
/// plane per record (Gautron 2008, section 8.4) under four weightings (plane only, coverage
/// ratio, border stretching, fall-off stretching) at random visible points of a scene,
/// against a full-hemisphere Monte Carlo reference of the same points, as relative RMS of
/// luminance (the seed's Table 8.1).
///
/// The samplers fill the planes (embree::sample_planes; gl::hemisphere_raster::read_planes
/// for the raster, in a program that links the GL adapter); plane_estimate_sums turns planes
/// into estimates; the rest compares and reports them:
///
///     const auto pts = study::visible_points(bvh, scene, scene.camera, 10000, 1);
///     const auto ref = study::indirect_point_reference(integrator, pts, settings);
///     const auto est = study::ray_cast_plane_estimates(integrator, pts, plane_camera{64, 126.0}, 64);
///     nlohmann::ordered_json errors = study::plane_estimate_errors(est, ref.irradiance);

#include <bounce/camera.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/cache/gradients.hpp>
#include <bounce/cache/plane_camera.hpp>
#include <bounce/scene_view.hpp>
#include <bounce/study/reference_cache.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace bounce::study {

/// Surface points, each with the unit normal of the side whose hemisphere is sampled.
struct surface_points {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;

    std::size_t size() const noexcept { return positions.size(); }
    /// The first min(n, size()) points.
    surface_points first(std::size_t n) const;
};

/// `count` distinct pixels that see geometry in a `side` x `side` ray-cast G-buffer of `cam`,
/// chosen by a partial Fisher-Yates shuffle seeded with `seed`: the G-buffer's positions and
/// (normalized) facing normals, the points the camera sees. Throws parameter_error naming
/// "points" when fewer than `count` pixels are covered.
surface_points visible_points(const embree::accel& bvh, const scene_view& scene, const bounce::camera& cam,
                              std::size_t count, std::uint64_t seed, std::size_t side = 512);

/// Settings of indirect_point_reference.
struct point_reference_settings {
    std::uint32_t spp = 16384;  ///< rays per point and half to start from (>= 1)
    std::uint64_t seed = 1;     ///< the halves use embree::derive_seed(seed, 1 or 2, point)
    double target = 0.005;      ///< largest own relative RMS error accepted, in (0, 1)
    std::string scene_name;     ///< names the cache file
    std::filesystem::path cache_dir = default_cache_dir();
    bool use_cache = true;      ///< read and write `cache_dir`
    std::string device_config;  ///< embree::device::config(): keys the cache when not empty

    /// Throws parameter_error naming the field (spp 0, target not in (0, 1) or NaN).
    void validate() const;
};

/// The one-bounce indirect irradiance of every point by Monte Carlo, in two halves.
struct point_reference {
    std::vector<glm::dvec3> irradiance;  ///< per point, the mean of the two halves
    double own_rel_rms = 0;              ///< rms(L_a - L_b) / 2 / rms(L) on luminance: its own error
    std::uint32_t spp = 0;               ///< rays per point and half, as finally used
    bool from_cache = false;

    /// The first min(n, size) points' irradiance.
    std::vector<glm::dvec3> first(std::size_t n) const;
};

/// Two independent halves of `spp` stratified cosine-weighted rays per point
/// (reference_integrator::indirect_irradiance); if their difference says the mean's error is
/// above `target`, the rays double, up to 8 times the start. Cached in `cache_dir` under a
/// hash of the points, the rays, the seed and the device configuration. Throws
/// parameter_error for bad settings or sizes, io::output_error when the cache file cannot
/// be written (check the folder first with check_cache_dir). Progress on stderr.
point_reference indirect_point_reference(const embree::reference_integrator& ref, const surface_points& points,
                                         const point_reference_settings& settings);

/// Irradiance per record from its plane under the four weightings. Coverage and fall-off
/// stretching are linear in the plane-only and stretched sums, so only those two are kept:
/// E_coverage = coverage_scale E_plane (pi / sum of the plane-only weights) and
/// E_falloff = E_plane + kappa (E_stretch - E_plane), kappa the band's radiance factor
/// (radial_profile::falloff_factor).
struct plane_estimates {
    std::vector<glm::dvec3> plane;    ///< plane-only weights
    std::vector<glm::dvec3> stretch;  ///< border stretching
    /// Per record, the kappa a renderer knows when it makes it: the running profile of the
    /// batches so far, the record's own included.
    std::vector<double> running_kappa;
    double coverage_scale = 1;  ///< pi / sum of the plane-only weights
    double kappa = 1;           ///< the profile pooled over the whole run (the last batch's)
    double ms = 0;              ///< wall time of sampling and summing every record

    std::size_t size() const noexcept { return plane.size(); }
    std::vector<glm::dvec3> coverage() const;
    /// Fall-off stretching with the pooled kappa, or with kappas[k] for record k.
    std::vector<glm::dvec3> falloff() const;
    std::vector<glm::dvec3> falloff(std::span<const double> kappas) const;
    /// Records per second (size() / ms).
    double records_per_s() const;
};

/// Relative RMS of luminance of `x` against `reference`, point by point (compare_luminance
/// on size x 1 images). Throws parameter_error when the sizes differ or are 0.
double point_rel_rms(std::span<const glm::dvec3> x, std::span<const glm::dvec3> reference);

/// The study's error figures of `e` against `reference`: rms_plane, rms_coverage,
/// rms_stretch, rms_falloff, falloff_kappa, rms_falloff_running, falloff_kappa_first_batch.
nlohmann::ordered_json plane_estimate_errors(const plane_estimates& e, std::span<const glm::dvec3> reference);

/// The irradiance of each estimate (hemisphere_estimate::irradiance), in order.
std::vector<glm::dvec3> irradiance_of(std::span<const hemisphere_estimate> estimates);

/// `errors` holding each sampler's plane_estimate_errors under its name ("ray_cast",
/// "raster"), with the headline figures added at the top level: those of "raster" (the
/// seed's method) where it is present, else of "ray_cast", and rel_rms = rms_stretch.
nlohmann::ordered_json with_headline_errors(const nlohmann::ordered_json& errors);

/// max_k |lum(x_k) - lum(ref_k)| / lum(ref_k) (the absolute difference where lum(ref_k) is
/// 0): how far two sums of the same planes (CPU and GPU) are apart. Throws parameter_error
/// when the sizes differ.
double max_relative_luminance_difference(std::span<const glm::dvec3> x, std::span<const glm::dvec3> reference);

/// Sums planes into plane_estimates: each record's plane with the plane-only and the
/// stretched tables (cpu::estimate_plane) and, when asked, into a running radial profile
/// whose kappa each batch of records takes when it ends.
class plane_estimate_sums {
public:
    /// `count` records of planes of `camera`; `profile`: keep the running profile (else
    /// every running kappa stays 1 unless set through running_kappa()).
    plane_estimate_sums(const plane_camera& camera, std::size_t count, bool profile);
    ~plane_estimate_sums();
    plane_estimate_sums(const plane_estimate_sums&) = delete;
    plane_estimate_sums& operator=(const plane_estimate_sums&) = delete;

    /// Sums record k's plane (and adds it to the calling thread's share of the profile).
    /// Safe to call concurrently for different k. Throws parameter_error for k out of range
    /// and cpu::estimate_plane's errors.
    void add(std::size_t k, plane_view plane);
    /// add(first + k, planes[k]) for every k, in parallel.
    void add(std::size_t first, std::span<const plane_view> planes);
    /// Ends the batch of records [first, last): they take the kappa of every plane added so
    /// far (the threads' profiles pooled). Not concurrent with add.
    void end_batch(std::size_t first, std::size_t last);
    /// The records' running kappas, to be filled by another profile (the raster sampler's).
    std::span<double> running_kappa() noexcept { return out_.running_kappa; }
    /// The estimates; kappa is the last record's running kappa; `ms` as given.
    plane_estimates result(double ms) const;

private:
    struct impl;
    std::unique_ptr<impl> impl_;
    plane_estimates out_;
};

/// The ray-cast sampler over all points: embree::sample_planes in batches of `batch`
/// records (in order, parallel within a batch, as a renderer makes them), summed by
/// plane_estimate_sums with the running profile. Throws parameter_error for batch 0.
plane_estimates ray_cast_plane_estimates(const embree::reference_integrator& ref, const surface_points& points,
                                         const plane_camera& camera, std::size_t batch);

/// How far other planes of the same points (the raster's) are from ray-cast planes, texel
/// by texel: sqrt(sum w_i (L_i - L_ray,i)^2 / sum w_i L_ray,i^2) over every texel of every
/// point, on luminance, w_i the texel's plane-only weight. Errors of opposite sign (a
/// shadow-map leak here, acne there) cannot cancel, unlike in irradiance.
class plane_texel_difference {
public:
    /// `ref`, `camera` and `points` must outlive this object.
    plane_texel_difference(const embree::reference_integrator& ref, const plane_camera& camera,
                           const surface_points& points);
    /// Compares planes[k], the plane of point first + k, with its ray-cast plane (in
    /// parallel). Throws parameter_error for points out of range or planes of another size.
    void add(std::size_t first, std::span<const plane_view> planes);
    /// The difference over every plane added (0 before any).
    double value() const;

private:
    const embree::reference_integrator& ref_;
    plane_camera camera_;
    const surface_points& points_;
    std::vector<double> weights_, squared_, norm_;
};

/// A named sampler of the sweep: the estimates of the sweep's points with a camera.
struct plane_sweep_sampler {
    std::string name;  ///< "ray_cast", "raster"
    std::function<plane_estimates(const plane_camera&)> estimate;
};

/// The study's sweep: resolutions 16, 32, 48, 64, 96, 128 by apertures 90, 105, 120, 126,
/// 135, 140, 150 degrees, the planes turned by turn_deg (and hashed_turn), each sampler in
/// turn. One row per setting and sampler: sampler, resolution, aperture, the figures of
/// plane_estimate_errors against `reference`, records_per_s; `on_row` sees each as it comes.
nlohmann::ordered_json plane_sweep(std::span<const plane_sweep_sampler> samplers, std::span<const glm::dvec3> reference,
                                   double turn_deg, bool hashed_turn,
                                   const std::function<void(const nlohmann::ordered_json& row)>& on_row = {});

/// Writes the per-point CSV: px, py, pz, nx, ny, nz, reference, then for each named
/// estimate <name>_plane, _coverage, _stretch, _falloff (luminance; fall-off with the pooled
/// kappa). Throws parameter_error when sizes differ, io::output_error when it cannot be
/// written.
void write_plane_points_csv(const std::filesystem::path& file, const surface_points& points,
                            std::span<const glm::dvec3> reference,
                            std::span<const std::pair<std::string, const plane_estimates*>> estimates);

}  // namespace bounce::study
