#pragma once
/// \file probe_baker.hpp
/// Irradiance-volume probes ray-cast with Embree: a `bounce::probe_source` for
/// `irradiance_volume::build`.
///
/// A probe at p casts `rays` rays from p along a spherical Fibonacci set of directions
/// (Gonzalez, "Measurement of areas on a sphere using Fibonacci and latitude-longitude
/// lattices", Mathematical Geosciences 2010: near-equal areas, each ray standing for
/// 4 pi / rays sr), takes the radiance each brings from the reference integrator
/// (`reference_integrator::incoming_radiance`: Kd / pi times the direct irradiance at the
/// first hit, the environment on a miss; so the volume holds one-bounce indirect light, the
/// same light the reference's `indirect_irradiance` integrates) and projects it onto SH
/// bands 0..2 with `sh_project_monte_carlo` (density 1 / (4 pi)). Every probe uses the same
/// directions, so the central differences of the gradients carry no Monte Carlo noise of
/// their own, only the directional discretization, which is the same at p +- h.
///
/// - Harmonic mean distance: rays / sum_j 1 / d_j over the hits (misses add 0).
/// - Noise: the probe's `noise` is half the largest difference, over the six axis normals,
///   between the irradiance luminance projected from the even rays and from the odd rays
///   (the standard error of the whole estimate, from its two halves); or measured without
///   a model (probe_baker_settings::noise, probe_noise_estimate).
/// - Inside geometry: a probe whose rays hit the back of triangles (the side opposite
///   their counter-clockwise normal) in more than `inside_fraction` of the cases is
///   flagged inside; it gets no gradient.
/// - Gradients (sh_translational_gradient): central differences of six re-projected
///   probes at p +- h e_k with h = min(gradient_step, nearest_fraction * the nearest hit
///   distance), so that a displaced probe does not cross the surface nearest to it
///   (sh/gradients.hpp explains the step's two errors).

#include <bounce/embree/accel.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/volume/probe_octree.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::embree {

/// How the probe baker finds a probe's `noise`, its standard error at the six axis normals
/// (issue 31, third session: the merge criterion is only as good as this).
enum class probe_noise_estimate {
    /// Half the difference of the irradiance from the even and from the odd rays of the one
    /// Fibonacci set, the worst of the six normals. The two halves are not independent
    /// (together they err less than their difference says), so it overstates the error by a
    /// factor that varies over the scene.
    even_odd,
    /// The rays are two Fibonacci sets of rays / 2, each turned by its own uniformly random
    /// rotation (seeded by the probe's position, shared by its gradient's displaced probes):
    /// independent unbiased halves a, b; the probe is their mean and `noise` the root mean
    /// square over the six normals of (a - b) / 2, whose square is an unbiased estimate of
    /// the mean's variance (E (a - b)^2 / 4 = var (a + b) / 2), without a model. It costs
    /// accuracy: two turned halves err more than one set of all the rays.
    independent_halves,
    /// The probe is the one Fibonacci set of `rays` (as even_odd); a second projection along
    /// the same set turned by a uniformly random rotation (seeded by the position) measures
    /// it: `noise` is the root mean square over the six normals of their difference over
    /// sqrt 2 (the unturned set is one draw of the turned ones: E d^2 = 2 var). One more
    /// projection per probe (an eighth more rays with gradients).
    rotated_repeat,
};

/// Parameters of the probe baker (unit and typical value with each).
struct probe_baker_settings {
    /// Rays per probe (and per displaced probe of a gradient). Typical: 256-1024.
    std::uint32_t rays = 512;
    /// Largest central-difference step h of the gradients (world units); 0: no gradients
    /// (6 fewer probes' worth of rays each). Typical: a tenth of the finest cell edge.
    float gradient_step = 0.f;
    /// The step is also at most this fraction of the distance to the nearest hit.
    /// Typical: 0.5.
    float nearest_fraction = 0.5f;
    /// Gradients only where their signal exceeds their noise: an axis's gradient (the
    /// luminance of its 9 coefficients, as a vector) is set to 0 when its length is at most
    /// this ratio times the noise, estimated as half the difference of the gradients from
    /// the even and the odd rays. Typical: 1-2; 0 keeps every gradient.
    float gradient_noise_ratio = 1.f;
    /// How a probe's `noise` is found (probe_noise_estimate).
    probe_noise_estimate noise = probe_noise_estimate::even_odd;
    /// Fraction of back-facing hits above which a probe is inside geometry. Typical: 0.5.
    float inside_fraction = 0.5f;
    /// Base seed of the area-light samples at the hits (unused without emitters).
    std::uint64_t seed = 1;
    /// Called with (probes done, probes in the batch) as probes finish, serialized, from a
    /// worker thread; may be empty.
    std::function<void(std::size_t done, std::size_t total)> progress;
};

/// Bakes probes over one scene with the reference integrator's light. Holds references
/// to the integrator (and through it the BVH and scene): they must outlive it. Safe to
/// call from many threads.
class probe_baker {
public:
    /// Throws parameter_error naming the setting: rays = 0, a negative or non-finite
    /// gradient_step or gradient_noise_ratio, nearest_fraction outside (0, 1], inside_fraction
    /// outside [0, 1].
    probe_baker(const reference_integrator& light, const accel& bvh, const scene_view& scene,
                probe_baker_settings settings = {});

    const probe_baker_settings& settings() const noexcept { return settings_; }
    /// The unit ray directions every probe uses (with independent_halves: the two halves'
    /// unturned sets, one after the other; each probe turns each half its own way).
    const std::vector<glm::dvec3>& directions() const noexcept { return directions_; }
    /// The directions of the probe at `position` (directions(), each half turned by the
    /// position's own rotation with independent_halves).
    std::vector<glm::dvec3> directions_at(glm::vec3 position) const;

    /// One probe at `position` (finite; throws parameter_error naming "position").
    irradiance_probe bake(glm::vec3 position) const;
    /// Probes at every position, in parallel (TBB), reporting progress.
    void bake(std::span<const glm::vec3> positions, std::span<irradiance_probe> out) const;
    /// `bake` of a batch: makes the baker a bounce::probe_source.
    void operator()(std::span<const glm::vec3> positions, std::span<irradiance_probe> out) const {
        bake(positions, out);
    }

    /// A projection from every ray, and from the even and the odd rays alone.
    struct estimate {
        irradiance_probe::coefficients all{};
        std::array<irradiance_probe::coefficients, 2> half{};
    };

private:
    struct cast;
    estimate project(glm::vec3 position, std::uint64_t seed, std::span<const glm::dvec3> directions, cast* details) const;

    const reference_integrator& light_;
    const accel& bvh_;
    scene_view scene_;
    probe_baker_settings settings_;
    std::vector<glm::dvec3> directions_;
};

}  // namespace bounce::embree
