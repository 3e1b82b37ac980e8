#pragma once
/// \file multi_bounce_reference.hpp
/// The all-bounce diffuse reference radiosity is compared with: the radiance a camera sees
/// off Lambertian, flat-shaded surfaces lit by the scene's lights and emitters after any
/// number of diffuse interreflections, by path tracing (Kajiya 1986) with next-event
/// estimation at every vertex.
///
/// At a surface point p with unit normal n (the geometric normal, as radiosity's flat
/// elements have) and albedo rho, the outgoing radiance is
///   L(p) = L_e(p) + rho / pi (E_d(p) + E_i(p)),
/// E_d the direct irradiance of reference_integrator::direct_irradiance (lights with shadow
/// rays, emitters by area sampling), E_i the irradiance of every other surface's
/// L - L_e. With cosine-weighted directions (pdf cos / pi) one path estimates
///   E_i(p) ~ rho_1 E_d(q_1) + rho_1 rho_2 E_d(q_2) + ...,
/// q_k the k-th surface a path from p meets: term k is bounce k. A path stops on a miss
/// (nothing lights the scene from outside), after `max_bounces`, or by Russian roulette
/// (Arvo and Kirk 1990) from bounce `roulette_after` on, which keeps the estimate unbiased.
///
/// How many bounces it takes: in a closed scene of albedo at most rho_max, bounce k carries
/// at most rho_max^k of the direct light, so cutting after B bounces loses at most
/// rho_max^(B+1) / (1 - rho_max) of it (a geometric series). The Cornell box's rho_max is
/// 0.78 (the light's housing; its walls 0.725): a 1e-2 relative cut needs B = 24 by this
/// bound, 1e-3 needs B = 33, and the default cap of 64 loses below 1e-6. The open box
/// converges faster (measured: 6 and 10 bounces, docs/radiosity.md); the per_bounce tally of
/// render() measures it.
///
/// Every random number comes from a pcg32 seeded by derive_seed(settings.seed, stage,
/// point index), so images do not depend on threads.

#include <bounce/camera.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/image.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::embree {

/// Parameters of the multi-bounce reference (each with its unit and a typical value).
struct multi_bounce_settings {
    std::uint32_t paths = 256;          ///< paths per point (pixel); typical: 256-4096
    std::uint32_t max_bounces = 64;     ///< cap on indirect bounces (0: direct light only); typical: 64
    std::uint32_t roulette_after = 4;   ///< bounces before Russian roulette may end a path; typical: 3-8
    std::uint32_t area_samples = 4;     ///< samples on emitters at each path vertex (square grid); typical: 1-16
    std::uint64_t seed = 1;             ///< base seed; the same seed gives bitwise the same images
    /// Called after each row with (rows done, rows total), serialized, from a worker thread;
    /// may be empty.
    std::function<void(std::size_t done, std::size_t total)> progress;

    /// Throws parameter_error naming the field.
    void validate() const;
};

/// A multi-bounce render: radiance per pixel and how much each bounce contributed.
struct multi_bounce_image {
    image<glm::vec3> radiance;  ///< W/(m^2 sr) per channel; 0 where no geometry is seen
    /// Sum over the pixels of each bounce's radiance (index 0: emission and direct light,
    /// k: bounce k), per channel; its size is the deepest bounce any path reached, plus one.
    std::vector<glm::dvec3> per_bounce;
};

/// The multi-bounce reference over one scene and its BVH (both must outlive it).
/// Immutable after construction; safe to call from many threads.
class multi_bounce_reference {
public:
    /// Throws parameter_error on bad settings, lights, or a scene that does not match `bvh`.
    multi_bounce_reference(const accel& bvh, const scene_view& scene, multi_bounce_settings settings = {});

    const multi_bounce_settings& settings() const noexcept { return settings_; }

    /// Outgoing radiance (W/(m^2 sr)) of the surface point `p` with unit normal `n` (facing
    /// the viewer) on triangle `triangle`, from settings().paths paths seeded by `seed`.
    /// `per_bounce`, when not null, receives each bounce's share (resized as needed).
    glm::vec3 radiance(glm::vec3 p, glm::vec3 n, std::uint32_t triangle, std::uint64_t seed,
                       std::vector<glm::dvec3>* per_bounce = nullptr) const;

    /// The camera's view, `width` x `height`, one primary ray through each pixel centre.
    multi_bounce_image render(const bounce::camera& cam, std::size_t width, std::size_t height) const;

private:
    const accel& bvh_;
    scene_view scene_;
    multi_bounce_settings settings_;
    reference_integrator direct_;
    float epsilon_;
};

}  // namespace bounce::embree
