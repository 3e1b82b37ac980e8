#pragma once
/// \file reference.hpp
/// The reference integrator: ground truth for every error figure in bounce.
///
/// - Direct irradiance E_d(p, n): point, spot and directional lights (the kernels of
///   bounce/direct_light.hpp) times a shadow ray each, plus, when scene.use_emission, the
///   emissive triangles as Lambertian area lights by stratified area sampling.
/// - One-bounce indirect irradiance E_i(p, n) = int L(w) cos dw by stratified
///   cosine-weighted Monte Carlo on the Ward-Heckbert M x N grid: each ray that hits a
///   surface q brings its outgoing radiance L = Kd(q) / pi * E_d(q) (emission seen directly
///   is not indirect light); a ray that misses brings the uniform environment radiance.
///   With pdf cos / pi, E_i ~ pi / (M N) * sum L.
/// - Per pixel of a G-buffer: direct = rho / pi * E_d, indirect = rho / pi * E_i (radiance
///   towards the camera off a Lambertian surface), combined = direct + indirect.
///
/// Every random number comes from a pcg32 seeded by derive_seed(settings.seed, stage,
/// pixel index) (or the caller's seed for per-point calls), so images do not depend on
/// the number of threads or the order in which TBB runs the rows.

#include <bounce/embree/accel.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::embree {

/// Parameters of the reference integrator (each with its unit and a typical value).
struct reference_settings {
    /// Hemisphere rays per point for one-bounce indirect irradiance, arranged as an M x N
    /// stratified grid with N ~ pi M (hemisphere_grid_for); typical: 1024 (reference
    /// images), 64-256 (irradiance cache records).
    std::uint32_t hemisphere_samples = 1024;
    /// Samples on the emissive triangles per shading point for direct light (rounded up to
    /// a square s x s grid); only used when scene.use_emission. Typical: 16-64.
    std::uint32_t area_samples = 16;
    /// Samples on the emissive triangles at each hemisphere hit (the surfaces that reflect
    /// indirect light). Typical: 1 (the hemisphere average smooths it).
    std::uint32_t secondary_area_samples = 1;
    /// At hemisphere hits (the surfaces that reflect indirect light): one shadow ray
    /// towards one of the point, spot and directional lights, chosen with probability
    /// proportional to its unshadowed irradiance there (sum of channels) and weighted by
    /// 1 / probability, instead of one shadow ray per light. Unbiased (the expectation over
    /// the choice is the sum over the lights), but noisier where several lights reach a hit
    /// and only some are shadowed, or their colours differ. Identical results where one
    /// light reaches the hit. Direct light at G-buffer points always takes every light.
    /// Typical: false (references), true where shadow rays dominate a record's cost.
    bool secondary_light_choice = false;
    /// Uniform radiance (W/(m^2 sr), RGB) of hemisphere rays that hit nothing; typical: 0
    /// (closed scenes) or a sky colour. It is indirect light only: it does not light the
    /// surfaces hemisphere rays hit (one bounce).
    glm::vec3 environment{0.f};
    /// Offset of secondary ray origins along the normal (world units); 0 selects
    /// accel::ray_epsilon() (1e-4 of the scene size).
    float ray_epsilon = 0.f;
    /// Base seed of every random stream; the same seed gives bitwise the same images.
    std::uint64_t seed = 1;
    /// Called after each row of an image with (rows done, rows total), serialized and in
    /// increasing order, from a worker thread; may be empty. Throwing from it cancels the
    /// image (the exception reaches the caller).
    std::function<void(std::size_t done, std::size_t total)> progress;
};

/// An M x N stratification of the hemisphere: M strata in theta, N in phi.
struct hemisphere_grid {
    std::uint32_t m = 1, n = 1;
    std::uint32_t count() const noexcept { return m * n; }
};

/// The grid for about `samples` rays with Ward and Heckbert's proportion N ~ pi M (strata
/// of roughly square shape in solid angle): M = max(1, round(sqrt(samples / pi))),
/// N = max(1, round(samples / M)). Throws parameter_error when samples is 0.
hemisphere_grid hemisphere_grid_for(std::uint32_t samples);

/// Seed for one stream: a SplitMix64 hash of (base, stage, index), so that streams for
/// different pixels, stages and base seeds are decorrelated and independent of scheduling.
std::uint64_t derive_seed(std::uint64_t base, std::uint64_t stage, std::uint64_t index) noexcept;

/// The stratified hemisphere samples around a point, as irradiance gradients need them
/// (Ward and Heckbert 1992; Krivanek et al. 2005). Sample (j, k), j < M, k < N, is stored
/// at index j * N + k; its direction is
///   sin(theta) (cos(phi) tangent + sin(phi) bitangent) + cos(theta) normal,
/// theta = asin(sqrt((j + u) / M)), phi = 2 pi (k + v) / N, (u, v) uniform jitter.
struct hemisphere_samples {
    hemisphere_grid grid;
    glm::vec3 origin{0.f};                   ///< the point p (world units)
    glm::vec3 normal{0.f, 0.f, 1.f};         ///< unit normal n: the frame's z
    glm::vec3 tangent{1.f, 0.f, 0.f};        ///< the frame's x (orthonormal_basis of n)
    glm::vec3 bitangent{0.f, 1.f, 0.f};      ///< the frame's y
    std::vector<float> theta, phi;           ///< jittered polar and azimuthal angles (radians)
    std::vector<glm::vec3> direction;        ///< unit world-space directions
    std::vector<glm::vec3> radiance;         ///< incoming radiance along each (W/(m^2 sr), RGB)
    /// Distance along each direction to the surface hit, measured from the ray origin
    /// p + ray_epsilon() * n (so within ray_epsilon / cos(theta) of the distance from p);
    /// +infinity on a miss.
    std::vector<float> distance;

    /// E = pi / (M N) * sum of radiance (W/m^2), the cosine-weighted estimate.
    glm::vec3 irradiance() const;
};

/// The reference integrator over one scene and its BVH. Holds references to both: they
/// must outlive it. Immutable after construction; every member is safe to call from many
/// threads at once.
class reference_integrator {
public:
    /// Validates the lights (finite, non-negative intensities, non-zero directions,
    /// cone_deg in (0, 180]) and the settings, and prepares the emissive triangles for area
    /// sampling. Throws parameter_error naming the light or setting, or when the scene does
    /// not match `bvh`.
    reference_integrator(const accel& bvh, const scene_view& scene, reference_settings settings = {});

    const reference_settings& settings() const noexcept { return settings_; }
    /// The offset of secondary ray origins along the normal (world units) in use.
    float ray_epsilon() const noexcept { return epsilon_; }
    /// Total area of the emissive triangles (0 when there are none or !use_emission).
    double emitter_area() const noexcept { return emitter_area_; }

    /// Direct irradiance (W/m^2, RGB) at `p` with unit normal `n` (the side that receives),
    /// with shadow rays, using `area_samples` samples (rounded up to a square) on emissive
    /// triangles drawn from `seed`. Throws parameter_error on a non-unit or non-finite `n`,
    /// a non-finite p or area_samples = 0.
    glm::vec3 direct_irradiance(glm::vec3 p, glm::vec3 n, std::uint32_t area_samples, std::uint64_t seed) const;
    /// Direct irradiance with settings().area_samples.
    glm::vec3 direct_irradiance(glm::vec3 p, glm::vec3 n, std::uint64_t seed) const {
        return direct_irradiance(p, n, settings_.area_samples, seed);
    }

    /// One-bounce indirect irradiance (W/m^2, RGB) at (p, n) from about `samples` stratified
    /// cosine-weighted rays (the grid of hemisphere_grid_for). Throws as direct_irradiance.
    glm::vec3 indirect_irradiance(glm::vec3 p, glm::vec3 n, std::uint32_t samples, std::uint64_t seed) const;

    /// The M x N stratified samples at (p, n) with their incoming radiance and hit
    /// distance, for estimators that need more than the mean (irradiance gradients).
    /// Sample i is bitwise incoming_radiance(ray from p + ray_epsilon() n along its
    /// direction, derive_seed(seed, 3, i)); the rays and shadow rays are traced in batches
    /// (Embree packets and streams) on the calling thread.
    hemisphere_samples sample_hemisphere(glm::vec3 p, glm::vec3 n, hemisphere_grid grid, std::uint64_t seed) const;
    /// As above, reusing the vectors of `out` (no allocation once they are large enough).
    void sample_hemisphere(glm::vec3 p, glm::vec3 n, hemisphere_grid grid, std::uint64_t seed,
                           hemisphere_samples& out) const;

    /// The rays sample_hemisphere(p, n, grid, seed) casts, traced alone: nearest hits, no
    /// shading (no shadow rays), through the same Embree queries in the same batches (on
    /// the calling thread). Returns how many hit a surface. Embree's raw rate for a
    /// record's rays, against which the shaded records are measured.
    std::size_t trace_hemisphere(glm::vec3 p, glm::vec3 n, hemisphere_grid grid, std::uint64_t seed) const;

    /// Radiance (W/(m^2 sr), RGB) arriving at r.origin from direction r.direction (unit):
    /// Kd / pi * E_d at the first surface hit, or the environment on a miss. `distance`
    /// receives the hit distance (+infinity on a miss) when not null.
    glm::vec3 incoming_radiance(const ray& r, std::uint64_t seed, float* distance = nullptr) const;
    /// incoming_radiance(rays[i], seeds[i], &distance[i]) for every i, bitwise the same, with
    /// the rays and their hits' shadow rays traced in batches (Embree stream and packet
    /// queries) on the calling thread, without allocating. Throws parameter_error when the
    /// spans' sizes differ.
    void incoming_radiance(std::span<const ray> rays, std::span<const std::uint64_t> seeds,
                           std::span<glm::vec3> radiance, std::span<float> distance) const;

    /// rho / pi * E_d per pixel of `g` (0 where g sees no geometry), rows in parallel.
    image<glm::vec3> direct_image(const gbuffer_view<float>& g) const;
    /// rho / pi * E_i per pixel of `g` with settings().hemisphere_samples rays per pixel.
    image<glm::vec3> indirect_image(const gbuffer_view<float>& g) const;

private:
    struct emitter {
        glm::vec3 p0, e1, e2;  // p = p0 + b1 e1 + b2 e2
        glm::vec3 normal;      // unit, the emitting side
        glm::vec3 radiance;    // Ke
    };
    glm::dvec3 direct_at(glm::vec3 p, glm::vec3 n, glm::vec3 offset_normal, std::uint32_t area_grid,
                         std::uint64_t seed, bool choose_light) const;
    // Calls term(unshadowed irradiance, shadow ray, from an emitter) for each term of E_d at
    // (p, n) whose unshadowed value is positive, in the order E_d sums them.
    template <class Term>
    void direct_terms(glm::vec3 p, glm::vec3 n, glm::vec3 offset_normal, std::uint32_t area_grid,
                      std::uint64_t seed, bool choose_light, Term&& term) const;
    // The batched incoming_radiance for at most shade_batch rays.
    void shade_batch(const ray* rays, const std::uint64_t* seeds, std::size_t count, glm::vec3* radiance,
                     float* distance) const;
    void check_point(glm::vec3 p, glm::vec3 n) const;
    // What shading a hit reads of its triangle, packed in one cache line per triangle (the
    // scene's arrays cost a cache miss each: indices, three positions, three normals,
    // material index, material): the unit geometric normal, whether the triangle is
    // degenerate (no plane: hits face the ray), the vertex normals and the albedo.
    struct alignas(64) shading_triangle {
        glm::vec3 geometric_normal;
        glm::vec3 n0, n1, n2;
        glm::vec3 albedo;
        std::uint32_t degenerate;
    };
    static_assert(sizeof(shading_triangle) == 64, "one cache line per triangle");
    // surface_at(scene, r, h) from the packed triangles, bitwise the same.
    surface surface_of(const ray& r, const hit& h) const;

    const accel& bvh_;
    scene_view scene_;
    reference_settings settings_;
    float epsilon_;
    std::vector<packed_light> lights_;
    std::vector<emitter> emitters_;
    std::vector<shading_triangle> shading_;  // per triangle of the scene
    std::vector<double> emitter_cdf_;  // cumulative area fractions, size emitters + 1
    double emitter_area_ = 0;
};

/// The three images of a reference render (linear radiance, W/(m^2 sr), RGB).
struct reference_images {
    image<glm::vec3> direct, indirect, combined;
    hemisphere_grid grid;  ///< the M x N grid the indirect image used per pixel
};

/// Direct, indirect and combined images over the G-buffer `g` (one reference_integrator,
/// both images in turn).
reference_images render_reference(const accel& bvh, const scene_view& scene, const gbuffer_view<float>& g,
                                  const reference_settings& settings);

}  // namespace bounce::embree
