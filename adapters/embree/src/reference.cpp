// The reference integrator: direct light with shadow rays, one-bounce indirect irradiance by
// stratified cosine-weighted Monte Carlo (Ward and Heckbert 1992), per-pixel images.
#include <bounce/embree/reference.hpp>

#include <bounce/lights.hpp>
#include <bounce/sampling.hpp>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numbers>
#include <string>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bounce::embree {

namespace {

constexpr double pi = std::numbers::pi;

// Stage tags for derive_seed: the direct and indirect images use unrelated streams.
constexpr std::uint64_t stage_direct = 1, stage_indirect = 2, stage_secondary = 3;

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool non_negative3(glm::vec3 v) { return finite3(v) && v.x >= 0.f && v.y >= 0.f && v.z >= 0.f; }

// Side length s of the s x s area-sampling grid for `samples` samples.
std::uint32_t square_side(std::uint32_t samples) {
    auto s = std::uint32_t(std::ceil(std::sqrt(double(samples))));
    while (std::uint64_t(s) * s < samples) ++s;
    return std::max<std::uint32_t>(1, s);
}

// Runs body(y) for every row in parallel and reports finished rows in increasing order.
template <class Body>
void for_each_row(std::size_t height, const reference_settings& settings, Body body) {
    std::mutex progress_mutex;
    std::size_t done = 0;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, height), [&](const tbb::blocked_range<std::size_t>& rows) {
        for (std::size_t y = rows.begin(); y != rows.end(); ++y) {
            body(y);
            if (settings.progress) {
                const std::lock_guard lock(progress_mutex);
                settings.progress(++done, height);
            }
        }
    });
}

void require_gbuffer(const gbuffer_view<float>& g) {
    const std::size_t w = g.depth.width(), h = g.depth.height();
    require(w > 0 && h > 0, "gbuffer", "the G-buffer is empty");
    const bool same = g.position.width() == w && g.position.height() == h && g.normal.width() == w &&
                      g.normal.height() == h && g.albedo.width() == w && g.albedo.height() == h;
    require(same, "gbuffer", "position, normal, albedo and depth views differ in size");
}

// A covered G-buffer pixel must carry a finite position and a unit normal.
void require_pixel(const gbuffer_view<float>& g, std::size_t x, std::size_t y) {
    const glm::vec3 p = g.position(x, y), n = g.normal(x, y);
    const float len = glm::length(n);
    if (!finite3(p) || !finite3(n) || !(std::abs(len - 1.f) < 1e-3f) || !non_negative3(g.albedo(x, y)))
        throw parameter_error("gbuffer", "pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                                             ") has a non-finite position, a non-unit normal or a negative albedo");
}

}  // namespace

std::uint64_t derive_seed(std::uint64_t base, std::uint64_t stage, std::uint64_t index) noexcept {
    return splitmix64(splitmix64(splitmix64(base) ^ stage) ^ index);
}

hemisphere_grid hemisphere_grid_for(std::uint32_t samples) {
    require(samples > 0, "hemisphere_samples", "must be positive");
    const auto m = std::max<std::uint32_t>(1, std::uint32_t(std::lround(std::sqrt(double(samples) / pi))));
    const auto n = std::max<std::uint32_t>(1, std::uint32_t(std::lround(double(samples) / m)));
    return {m, n};
}

glm::vec3 hemisphere_samples::irradiance() const {
    glm::dvec3 sum(0.0);
    for (const auto& l : radiance) sum += glm::dvec3(l);
    return radiance.empty() ? glm::vec3(0.f) : glm::vec3(sum * (pi / double(radiance.size())));
}

reference_integrator::reference_integrator(const accel& bvh, const scene_view& scene, reference_settings settings)
    : bvh_(bvh), scene_(scene), settings_(std::move(settings)) {
    require_match(bvh, scene);
    require(settings_.hemisphere_samples > 0, "hemisphere_samples", "must be positive");
    require(settings_.area_samples > 0, "area_samples", "must be positive");
    require(settings_.secondary_area_samples > 0, "secondary_area_samples", "must be positive");
    require(non_negative3(settings_.environment), "environment", "must be finite and non-negative");
    require(std::isfinite(settings_.ray_epsilon) && settings_.ray_epsilon >= 0.f, "ray_epsilon",
            "must be finite and non-negative");
    epsilon_ = settings_.ray_epsilon > 0.f ? settings_.ray_epsilon : bvh.ray_epsilon();

    validate_lights(scene.lights);
    for (const light& l : scene.lights) lights_.push_back(pack(l));

    if (scene.use_emission) {
        for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
            const auto& mat = scene.materials[scene.material_of[t]];
            if (!(mat.emission.x > 0.f || mat.emission.y > 0.f || mat.emission.z > 0.f)) continue;
            const glm::uvec3 tri = scene.triangles[t];
            const glm::vec3 p0 = scene.positions[tri.x], e1 = scene.positions[tri.y] - p0,
                            e2 = scene.positions[tri.z] - p0;
            const glm::vec3 c = glm::cross(e1, e2);
            const double area = 0.5 * double(glm::length(c));
            if (!(area > 0.0)) continue;  // a degenerate emitter emits nothing
            glm::vec3 normal = glm::normalize(c);
            // Emit on the side the vertex normals point to (the loader's smoothing normals
            // follow the winding, authored normals may not).
            if (!scene.normals.empty()) {
                const glm::vec3 sum = scene.normals[tri.x] + scene.normals[tri.y] + scene.normals[tri.z];
                if (glm::dot(sum, normal) < 0.f) normal = -normal;
            }
            emitters_.push_back({p0, e1, e2, normal, mat.emission});
            emitter_cdf_.push_back(area);
        }
        // Area-proportional choice: prefix sums normalized to [0, 1].
        double total = 0;
        for (double& a : emitter_cdf_) {
            const double area = a;
            a = total;
            total += area;
        }
        emitter_cdf_.push_back(total);
        for (double& c : emitter_cdf_) c /= total > 0 ? total : 1.0;
        emitter_area_ = total;
        if (emitters_.empty()) emitter_cdf_.clear();
    }
}

void reference_integrator::check_point(glm::vec3 p, glm::vec3 n) const {
    require(finite3(p), "p", "must be finite");
    require(finite3(n) && std::abs(glm::length(n) - 1.f) < 1e-3f, "n", "must be a finite unit vector");
}

glm::dvec3 reference_integrator::direct_at(glm::vec3 p, glm::vec3 n, glm::vec3 offset_normal, std::uint32_t area_grid,
                                           std::uint64_t seed) const {
    const glm::vec3 origin = p + epsilon_ * offset_normal;
    glm::dvec3 e(0.0);
    for (const auto& l : lights_) {
        glm::vec3 contribution(0.f);
        ray shadow;
        shadow.origin = origin;
        const light_kind kind = l.kind();
        if (kind == light_kind::point) {
            contribution = point_light_irradiance<float, glm::vec3>(p, n, l.position(), l.intensity());
        } else if (kind == light_kind::spot) {
            contribution = spot_light_irradiance<float, glm::vec3>(p, n, l.position(), l.direction(), l.intensity(),
                                                                    l.cos_cone(), l.cosine_falloff());
        } else {
            contribution = directional_light_irradiance<float, glm::vec3>(n, l.direction(), l.intensity());
        }
        if (!(contribution.x > 0.f || contribution.y > 0.f || contribution.z > 0.f)) continue;
        if (kind == light_kind::directional) {
            shadow.direction = -l.direction();
        } else {
            // Towards the light; stop short of it by epsilon so geometry at the light's
            // own position does not shadow it.
            shadow.direction = l.position() - origin;
            const float d = glm::length(shadow.direction);
            shadow.tfar = std::max(0.f, 1.f - epsilon_ / std::max(d, epsilon_));
        }
        if (!bvh_.occluded(shadow)) e += glm::dvec3(contribution);
    }

    if (!emitters_.empty()) {
        // Stratified area sampling: an s x s jittered grid over [0,1)^2; u.x picks the
        // emitter by area (its stratum carries over to the rescaled coordinate), then
        // uniform_triangle places the point. pdf_A = 1 / total area.
        const std::uint32_t s = area_grid;
        pcg32 rng(seed);
        glm::dvec3 sum(0.0);
        const float inv_pdf = float(emitter_area_);
        for (std::uint32_t j = 0; j < s; ++j)
            for (std::uint32_t i = 0; i < s; ++i) {
                const double ux = (i + rng.next_double()) / s, uy = (j + rng.next_double()) / s;
                const auto it = std::upper_bound(emitter_cdf_.begin(), emitter_cdf_.end(), ux);
                const std::size_t k =
                    std::min<std::size_t>(emitters_.size() - 1, std::size_t(std::max<std::ptrdiff_t>(0, it - emitter_cdf_.begin() - 1)));
                const double width = emitter_cdf_[k + 1] - emitter_cdf_[k];
                const double rescaled = std::clamp((ux - emitter_cdf_[k]) / width, 0.0, 0x1.fffffffffffffp-1);
                const glm::vec2 b = uniform_triangle<float, glm::vec2>(glm::vec2(float(rescaled), float(uy)));
                const emitter& em = emitters_[k];
                const glm::vec3 q = em.p0 + b.x * em.e1 + b.y * em.e2;
                const glm::vec3 c =
                    area_light_irradiance_sample<float, glm::vec3>(p, n, q, em.normal, em.radiance, inv_pdf);
                if (!(c.x > 0.f || c.y > 0.f || c.z > 0.f)) continue;
                ray shadow;
                shadow.origin = origin;
                shadow.direction = q - origin;
                const float d = glm::length(shadow.direction);
                shadow.tfar = std::max(0.f, 1.f - epsilon_ / std::max(d, epsilon_));
                if (!bvh_.occluded(shadow)) sum += glm::dvec3(c);
            }
        e += sum / double(s * s);
    }
    return e;
}

glm::vec3 reference_integrator::direct_irradiance(glm::vec3 p, glm::vec3 n, std::uint32_t area_samples,
                                                  std::uint64_t seed) const {
    check_point(p, n);
    require(area_samples > 0, "area_samples", "must be positive");
    return glm::vec3(direct_at(p, n, n, square_side(area_samples), seed));
}

glm::vec3 reference_integrator::incoming_radiance(const ray& r, std::uint64_t seed, float* distance) const {
    const hit h = bvh_.intersect(r);
    if (!h.found()) {
        if (distance) *distance = std::numeric_limits<float>::infinity();
        return settings_.environment;
    }
    const surface s = surface_at(scene_, r, h);
    if (distance) *distance = h.t * glm::length(r.direction);
    // Offset along the geometric normal: the shading normal may point into the surface's
    // own plane at grazing angles and let the shadow ray re-hit the triangle it left.
    const glm::dvec3 e = direct_at(s.position, s.normal, s.geometric_normal,
                                   square_side(settings_.secondary_area_samples), seed);
    return glm::vec3(glm::dvec3(s.albedo) * (1.0 / pi) * e);
}

void reference_integrator::sample_hemisphere(glm::vec3 p, glm::vec3 n, hemisphere_grid grid, std::uint64_t seed,
                                             hemisphere_samples& out) const {
    check_point(p, n);
    require(grid.m > 0 && grid.n > 0, "grid", "needs at least one stratum in theta and in phi");
    const std::size_t count = std::size_t(grid.m) * grid.n;
    out.grid = grid;
    out.origin = p;
    out.normal = n;
    const auto tb = orthonormal_basis<float, glm::vec3>(n);
    out.tangent = tb[0];
    out.bitangent = tb[1];
    out.theta.resize(count);
    out.phi.resize(count);
    out.direction.resize(count);
    out.radiance.resize(count);
    out.distance.resize(count);

    pcg32 rng(seed);
    const float m = float(grid.m), nn = float(grid.n);
    for (std::uint32_t j = 0; j < grid.m; ++j)
        for (std::uint32_t k = 0; k < grid.n; ++k) {
            const std::size_t i = std::size_t(j) * grid.n + k;
            const float u = rng.next_float(), v = rng.next_float();
            const glm::vec3 local = stratified_cosine_direction<float, glm::vec3>(float(j), float(k), m, nn, u, v);
            out.theta[i] = std::asin(std::min(1.f, std::sqrt((float(j) + u) / m)));
            out.phi[i] = float(2 * pi) * (float(k) + v) / nn;
            out.direction[i] = glm::normalize(local.x * out.tangent + local.y * out.bitangent + local.z * n);
        }
    // Each ray has its own stream, so splitting them across threads (one record's rays are
    // the unit of work of the irradiance cache's sequential scan) changes no bit. Nested
    // in an image pass it only adds tasks to the same TBB pool.
    const glm::vec3 origin = p + epsilon_ * n;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 64), [&](const tbb::blocked_range<std::size_t>& b) {
        ray r;
        r.origin = origin;
        for (std::size_t i = b.begin(); i != b.end(); ++i) {
            r.direction = out.direction[i];
            out.radiance[i] = incoming_radiance(r, derive_seed(seed, stage_secondary, i), &out.distance[i]);
        }
    });
}

std::size_t reference_integrator::trace_hemisphere(glm::vec3 p, glm::vec3 n, hemisphere_grid grid,
                                                  std::uint64_t seed) const {
    check_point(p, n);
    require(grid.m > 0 && grid.n > 0, "grid", "needs at least one stratum in theta and in phi");
    // The directions of sample_hemisphere: the same stream, drawn in the same order.
    const auto tb = orthonormal_basis<float, glm::vec3>(n);
    pcg32 rng(seed);
    const float m = float(grid.m), nn = float(grid.n);
    ray r;
    r.origin = p + epsilon_ * n;
    std::size_t hits = 0;
    for (std::uint32_t j = 0; j < grid.m; ++j)
        for (std::uint32_t k = 0; k < grid.n; ++k) {
            const float u = rng.next_float(), v = rng.next_float();
            const glm::vec3 local = stratified_cosine_direction<float, glm::vec3>(float(j), float(k), m, nn, u, v);
            r.direction = glm::normalize(local.x * tb[0] + local.y * tb[1] + local.z * n);
            hits += bvh_.intersect(r).found() ? 1 : 0;
        }
    return hits;
}

hemisphere_samples reference_integrator::sample_hemisphere(glm::vec3 p, glm::vec3 n, hemisphere_grid grid,
                                                           std::uint64_t seed) const {
    hemisphere_samples s;
    sample_hemisphere(p, n, grid, seed, s);
    return s;
}

glm::vec3 reference_integrator::indirect_irradiance(glm::vec3 p, glm::vec3 n, std::uint32_t samples,
                                                    std::uint64_t seed) const {
    return sample_hemisphere(p, n, hemisphere_grid_for(samples), seed).irradiance();
}

image<glm::vec3> reference_integrator::direct_image(const gbuffer_view<float>& g) const {
    require_gbuffer(g);
    const std::size_t w = g.width(), h = g.height();
    image<glm::vec3> out(w, h, glm::vec3(0.f));
    const std::uint32_t side = square_side(settings_.area_samples);
    for_each_row(h, settings_, [&](std::size_t y) {
        for (std::size_t x = 0; x < w; ++x) {
            if (!g.covered(x, y)) continue;
            require_pixel(g, x, y);
            const glm::vec3 p = g.position(x, y), n = g.normal(x, y);
            const glm::dvec3 e = direct_at(p, n, n, side, derive_seed(settings_.seed, stage_direct, y * w + x));
            out(x, y) = glm::vec3(glm::dvec3(g.albedo(x, y)) * (1.0 / pi) * e);
        }
    });
    return out;
}

image<glm::vec3> reference_integrator::indirect_image(const gbuffer_view<float>& g) const {
    require_gbuffer(g);
    const std::size_t w = g.width(), h = g.height();
    image<glm::vec3> out(w, h, glm::vec3(0.f));
    const hemisphere_grid grid = hemisphere_grid_for(settings_.hemisphere_samples);
    for_each_row(h, settings_, [&](std::size_t y) {
        hemisphere_samples samples;  // reused across the row
        for (std::size_t x = 0; x < w; ++x) {
            if (!g.covered(x, y)) continue;
            require_pixel(g, x, y);
            sample_hemisphere(g.position(x, y), g.normal(x, y), grid,
                              derive_seed(settings_.seed, stage_indirect, y * w + x), samples);
            out(x, y) = glm::vec3(glm::dvec3(g.albedo(x, y)) * (1.0 / pi) * glm::dvec3(samples.irradiance()));
        }
    });
    return out;
}

reference_images render_reference(const accel& bvh, const scene_view& scene, const gbuffer_view<float>& g,
                                  const reference_settings& settings) {
    const reference_integrator integrator(bvh, scene, settings);
    reference_images r;
    r.direct = integrator.direct_image(g);
    r.indirect = integrator.indirect_image(g);
    r.combined = image<glm::vec3>(g.width(), g.height());
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x) r.combined(x, y) = r.direct(x, y) + r.indirect(x, y);
    r.grid = hemisphere_grid_for(settings.hemisphere_samples);
    return r;
}

}  // namespace bounce::embree
