// The multi-bounce diffuse reference: path tracing with next-event estimation
// (see multi_bounce_reference.hpp).
#include <bounce/embree/multi_bounce_reference.hpp>

#include <bounce/errors.hpp>
#include <bounce/sampling.hpp>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bounce::embree {

void multi_bounce_settings::validate() const {
    require(paths > 0, "paths", "must be positive");
    require(max_bounces <= 1024, "max_bounces", "must be at most 1024");
    require(area_samples > 0, "area_samples", "must be positive");
}

namespace {

reference_settings direct_settings(const multi_bounce_settings& s) {
    s.validate();
    reference_settings r;
    r.area_samples = s.area_samples;
    r.secondary_area_samples = s.area_samples;
    r.hemisphere_samples = 1;
    r.seed = s.seed;
    return r;
}

// Stage numbers of derive_seed, distinct from the one-bounce reference's.
constexpr std::uint64_t stage_paths = 11;

// The geometric normal of triangle t, on the side facing `towards` (a direction from the
// surface).
glm::vec3 facing_normal(const scene_view& scene, std::uint32_t t, glm::vec3 towards) {
    const glm::uvec3 tri = scene.triangles[t];
    const glm::vec3 c = glm::cross(scene.positions[tri.y] - scene.positions[tri.x], scene.positions[tri.z] - scene.positions[tri.x]);
    const float l = glm::length(c);
    if (!(l > 0.f)) return glm::vec3(0.f);
    const glm::vec3 n = c / l;
    return glm::dot(n, towards) < 0.f ? -n : n;
}

// Whether the emitting side of triangle t (as reference_integrator decides it: the winding's
// normal, flipped to the vertex normals' side when the scene has them) faces `towards`.
bool emits_towards(const scene_view& scene, std::uint32_t t, glm::vec3 towards) {
    const glm::uvec3 tri = scene.triangles[t];
    glm::vec3 n = glm::cross(scene.positions[tri.y] - scene.positions[tri.x], scene.positions[tri.z] - scene.positions[tri.x]);
    if (!scene.normals.empty()) {
        const glm::vec3 sum = scene.normals[tri.x] + scene.normals[tri.y] + scene.normals[tri.z];
        if (glm::dot(sum, n) < 0.f) n = -n;
    }
    return glm::dot(n, towards) > 0.f;
}

}  // namespace

multi_bounce_reference::multi_bounce_reference(const accel& bvh, const scene_view& scene, multi_bounce_settings settings)
    : bvh_(bvh), scene_(scene), settings_(std::move(settings)), direct_(bvh, scene, direct_settings(settings_)),
      epsilon_(direct_.ray_epsilon()) {}

glm::vec3 multi_bounce_reference::radiance(glm::vec3 p, glm::vec3 n, std::uint32_t triangle, std::uint64_t seed,
                                           std::vector<glm::dvec3>* per_bounce) const {
    require(triangle < scene_.triangles.size(), "triangle", "is not a triangle of the scene");
    constexpr double pi = std::numbers::pi;
    const material& m0 = scene_.materials[scene_.material_of[triangle]];
    const glm::dvec3 rho0(m0.albedo);
    glm::dvec3 emitted(0.0);
    if (scene_.use_emission && emits_towards(scene_, triangle, n)) emitted = glm::dvec3(m0.emission);
    pcg32 rng(seed);
    const std::uint32_t area = settings_.area_samples;
    // The point's own direct light with as many emitter samples as all its paths take.
    const glm::dvec3 direct =
        glm::dvec3(direct_.direct_irradiance(p, n, area * settings_.paths, derive_seed(seed, 0, 0)));
    if (per_bounce) {
        if (per_bounce->empty()) per_bounce->resize(1, glm::dvec3(0.0));
        (*per_bounce)[0] += emitted + rho0 / pi * direct;
    }
    glm::dvec3 indirect(0.0);
    const double inv_paths = 1.0 / double(settings_.paths);
    for (std::uint32_t path = 0; path < settings_.paths; ++path) {
        glm::vec3 x = p, nx = n;
        glm::dvec3 beta(1.0);  // product of the albedos met so far (roulette-weighted)
        for (std::uint32_t bounce = 1; bounce <= settings_.max_bounces; ++bounce) {
            const auto tb = orthonormal_basis<float, glm::vec3>(nx);
            const glm::vec3 local =
                cosine_hemisphere<float, glm::vec3, glm::vec2>(glm::vec2(rng.next_float(), rng.next_float()));
            ray r;
            r.origin = x + epsilon_ * nx;
            r.direction = tb[0] * local.x + tb[1] * local.y + nx * local.z;
            const hit h = bvh_.intersect(r);
            if (!h.found()) break;
            const glm::vec3 q = r.origin + h.t * r.direction;
            const glm::vec3 nq = facing_normal(scene_, h.triangle, -r.direction);
            if (!(glm::dot(nq, nq) > 0.f)) break;
            const glm::dvec3 rho(scene_.materials[scene_.material_of[h.triangle]].albedo);
            beta *= rho;
            const glm::dvec3 e = glm::dvec3(direct_.direct_irradiance(q, nq, area, rng.next_u32() | (std::uint64_t(path) << 32)));
            const glm::dvec3 term = beta * e * inv_paths;
            indirect += term;
            if (per_bounce) {
                if (per_bounce->size() <= bounce) per_bounce->resize(bounce + 1, glm::dvec3(0.0));
                (*per_bounce)[bounce] += rho0 / pi * term;
            }
            if (bounce >= settings_.roulette_after) {
                const double survive = std::min(1.0, std::max({beta.x, beta.y, beta.z}));
                if (!(double(rng.next_float()) < survive)) break;
                beta /= survive;
            }
            x = q;
            nx = nq;
        }
    }
    return glm::vec3(emitted + rho0 / pi * (direct + indirect));
}

multi_bounce_image multi_bounce_reference::render(const bounce::camera& cam, std::size_t width, std::size_t height) const {
    cam.validate();
    require(width > 0 && height > 0, "width/height", "must be positive");
    multi_bounce_image out;
    out.radiance = image<glm::vec3>(width, height, glm::vec3(0.f));
    std::mutex mutex;
    std::size_t done = 0;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, height, 1), [&](const tbb::blocked_range<std::size_t>& rows) {
        std::vector<glm::dvec3> bounces;
        for (std::size_t y = rows.begin(); y != rows.end(); ++y) {
            for (std::size_t x = 0; x < width; ++x) {
                ray r;
                r.origin = cam.position;
                r.direction = cam.direction(float(x) + 0.5f, float(y) + 0.5f, width, height);
                r.tnear = cam.near_plane;
                r.tfar = cam.far_plane;
                const hit h = bvh_.intersect(r);
                if (!h.found()) continue;
                const glm::vec3 n = facing_normal(scene_, h.triangle, -r.direction);
                if (!(glm::dot(n, n) > 0.f)) continue;
                const glm::vec3 p = r.origin + h.t * r.direction;
                out.radiance(x, y) =
                    radiance(p, n, h.triangle, derive_seed(settings_.seed, stage_paths, y * width + x), &bounces);
            }
            const std::lock_guard lock(mutex);
            if (out.per_bounce.size() < bounces.size()) out.per_bounce.resize(bounces.size(), glm::dvec3(0.0));
            for (std::size_t k = 0; k < bounces.size(); ++k) out.per_bounce[k] += bounces[k];
            bounces.assign(bounces.size(), glm::dvec3(0.0));
            ++done;
            if (settings_.progress) settings_.progress(done, height);
        }
    });
    return out;
}

}  // namespace bounce::embree
