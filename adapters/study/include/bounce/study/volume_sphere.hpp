#pragma once
/// \file volume_sphere.hpp
/// An irradiance volume measured where Oat uses it: on the surface points of a sphere that
/// moves along a straight path through a static scene, lit by the volume's lookups and
/// compared with the reference integrator there (what `irradiance_volume` reports).
///
/// - `default_sphere_path` derives the path and radius from the scene's free space: it
///   walks the camera's view axis (and eight rays around it through the image) inside the
///   volume's box up to the first surface, measures at 64 points along each the distance to
///   the nearest surface (64 rays each), and keeps the longest run of points whose free
///   distance holds a sphere of the largest radius that fits (at most 2% of the box's
///   diagonal), at least four radii from the camera (so that the sphere does not fill its
///   frames), checked by sphere_path_is_clear.
/// - `volume_sphere_study` holds the sphere's points in every frame and the reference
///   there (reference_integrator::indirect_irradiance: the one-bounce indirect light the
///   probe baker's probes hold), and the popping series: the point facing down (against the
///   scene's up direction) at many steps, its reference with one seed for every step (so that its noise is the same
///   pattern at each step and its changes are real).
/// - `render_sphere_strip` renders frames of the scene and the sphere, lit by the volume.

#include <bounce/camera.hpp>
#include <bounce/cpu/irradiance_volume.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/image.hpp>
#include <bounce/volume/probe_octree.hpp>
#include <bounce/study/image_comparison.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace bounce::study {

/// A sphere of `radius` whose centre moves from `a` to `b`.
struct sphere_path {
    glm::vec3 a{0.f}, b{0.f};
    float radius = 0.f;
    /// The centre at step s of `steps` (a at 0, b at steps - 1; the midpoint when steps < 2).
    glm::vec3 centre(std::size_t s, std::size_t steps) const;
};

/// `n` unit directions of a spherical Fibonacci set (z at cell centres, golden-angle phi).
std::vector<glm::vec3> fibonacci_sphere(std::uint32_t n);

/// Whether the sphere stays clear of the scene along the path: 64 centres along it, 256
/// rays of length `radius` from each.
bool sphere_path_is_clear(const embree::accel& bvh, const sphere_path& path);

/// The default path through the free space of the box [lo, hi] (see the file comment).
/// `radius` > 0 fixes the radius (world units) instead of choosing it. Throws
/// parameter_error naming "path" when no ray of the nine finds a free run of at least
/// four radii for any radius down to 1/64 of the largest.
sphere_path default_sphere_path(const embree::accel& bvh, const camera& cam, glm::vec3 lo, glm::vec3 hi,
                                float radius = 0.f);

/// What a volume_sphere_study samples.
struct volume_sphere_settings {
    std::uint32_t frames = 16;              ///< sphere positions along the path for the error
    std::uint32_t sphere_points = 256;      ///< surface points per sphere
    std::uint32_t popping_steps = 128;      ///< steps along the path for popping (>= 2)
    std::uint32_t reference_samples = 1024; ///< hemisphere samples per reference point
    int repeat = 5;                         ///< lookup timing repeats (the median is kept)
    std::uint64_t seed = 7;                 ///< the reference's seed
    /// The normal of the popping point (unit): "down", against the scene's up direction
    /// (programs pass -camera.up).
    glm::vec3 popping_normal{0.f, -1.f, 0.f};
};

/// One lookup's figures on the sphere.
struct volume_lookup_figures {
    std::string name;
    error_figures error;        ///< luminance over every sphere point of every frame
    double popping = 0;         ///< largest step-to-step change at the popping point / its mean
    double popping_excess = 0;  ///< largest change of (lookup - reference) / the reference's mean
    double lookup_ns = 0;       ///< per point, median of the repeats
    std::vector<double> popping_series;  ///< luminance at the popping point, per step

    /// {"rel_rms", "max_abs", "popping", "popping_excess", "lookup_ns", "popping_series"}.
    nlohmann::ordered_json to_json() const;
};

/// How an octree was built: {"split_min_depth", "split_distance", "split_neighbour",
/// "split_geometry", "split_gradient", "split_prediction", "culled", "inside_cells"}.
nlohmann::ordered_json build_stats_json(const irradiance_volume_build_stats& stats);

/// The sphere's points and the reference on them (computed by the constructor, in parallel).
class volume_sphere_study {
public:
    /// Throws parameter_error naming the setting when frames, sphere_points,
    /// reference_samples or repeat is 0, popping_steps < 2, popping_normal is not unit, or
    /// the path is not finite with a radius > 0.
    volume_sphere_study(const embree::reference_integrator& light, const sphere_path& path,
                        const volume_sphere_settings& settings = {});

    /// The lookup `how` of `volume` on every point, against the reference.
    volume_lookup_figures measure(const irradiance_volume& volume, std::string name, const cpu::volume_lookup& how) const;

    const sphere_path& path() const noexcept { return path_; }
    const volume_sphere_settings& settings() const noexcept { return settings_; }
    double reference_ms() const noexcept { return reference_ms_; }
    /// Popping of the reference itself (the real change per step) and its series.
    double reference_popping() const noexcept { return reference_popping_; }
    const std::vector<double>& reference_popping_series() const noexcept { return pop_reference_lum_; }

private:
    sphere_path path_;
    volume_sphere_settings settings_;
    std::vector<glm::vec3> points_, normals_, reference_;
    std::vector<glm::vec3> pop_points_, pop_normals_, pop_reference_;
    std::vector<double> pop_reference_lum_;
    double reference_ms_ = 0, reference_popping_ = 0;
};

/// `frames` frames side by side, each `width` x `height` from `cam`: the scene and the
/// sphere (albedo 0.8) at its position along the path, shaded rho / pi (direct + the
/// volume's irradiance by `how`).
image<glm::vec3> render_sphere_strip(const embree::accel& bvh, const scene_view& scene, const camera& cam,
                                     const embree::reference_integrator& light, const irradiance_volume& volume,
                                     const cpu::volume_lookup& how, const sphere_path& path, std::size_t frames,
                                     std::size_t width, std::size_t height);

/// SH of the environments at `points`: radiance over 16384 directions at each, projected
/// at orders 0 .. 8; per order the relative L2 error of the radiance (luminance, Parseval)
/// and of the irradiance at 256 normals against the irradiance integrated from the same
/// samples, relative to its peak. Rows {"position", "orders": [{"order",
/// "radiance_rel_l2", "irradiance_max_rel_peak", "irradiance_mean_rel_peak"}]}.
nlohmann::ordered_json sh_environment_study(const embree::reference_integrator& light, const std::vector<glm::vec3>& points);

/// sh_environment_study's rows as a table on stdout, one block per environment.
void print_sh_environments(const nlohmann::ordered_json& environments);

}  // namespace bounce::study
