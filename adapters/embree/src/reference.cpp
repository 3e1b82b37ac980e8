// The reference integrator: direct light with shadow rays, one-bounce indirect irradiance by
// stratified cosine-weighted Monte Carlo (Ward and Heckbert 1992), per-pixel images.
#include <bounce/embree/reference.hpp>

#include "light_rays.hpp"

#include <bounce/direct_light.hpp>
#include <bounce/sampling.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
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
// The stream that picks a hit's light under secondary_light_choice (keyed by the hit's seed).
constexpr std::uint64_t stage_light_choice = 4;

// Rays shaded together: one batch of hemisphere rays is traced with one batched query, and
// its hits' shadow rays with batched queries of at most shadow_batch rays.
constexpr std::size_t shade_batch_rays = 64;
constexpr std::size_t shadow_batch = 256;

// The queries, chosen by measurement (docs/irradiance-splatting.md, "Record cost against
// Embree"): a batch of one record's hemisphere rays as packets of eight (they share their
// origin and neighbours in the batch are neighbours in direction; faster than single rays
// or streams on the Cornell box and the bunny, as fast on Sponza), shadow rays as an
// incoherent stream (their origins are scattered over the hits; packets were slower).
void trace_rays(const accel& bvh, std::span<const ray> rays, std::span<hit> hits) { bvh.intersect_packets(rays, hits); }

void trace_shadows(const accel& bvh, std::span<const ray> rays, std::span<std::uint8_t> blocked) {
    bvh.occluded(rays, blocked, /*coherent=*/false);
}

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

    shading_.resize(scene.triangles.size());
    for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
        // surface_at's geometric normal, computed as it computes it.
        const glm::uvec3 tri = scene.triangles[t];
        const glm::vec3 p0 = scene.positions[tri.x], p1 = scene.positions[tri.y], p2 = scene.positions[tri.z];
        const glm::vec3 ng = glm::cross(p1 - p0, p2 - p0);
        const float ng_len = glm::length(ng);
        shading_triangle& st = shading_[t];
        st.degenerate = ng_len > 0.f ? 0u : 1u;
        st.geometric_normal = ng_len > 0.f ? ng / ng_len : glm::vec3(0.f);
        if (!scene.normals.empty()) {
            st.n0 = scene.normals[tri.x];
            st.n1 = scene.normals[tri.y];
            st.n2 = scene.normals[tri.z];
        } else {
            st.n0 = st.n1 = st.n2 = glm::vec3(0.f);
        }
        st.albedo = scene.materials[scene.material_of[t]].albedo;
    }

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

surface reference_integrator::surface_of(const ray& r, const hit& h) const {
    // surface_at's steps, in its arithmetic, on the packed triangle.
    const shading_triangle& st = shading_[h.triangle];
    surface s;
    s.triangle = h.triangle;
    s.position = r.origin + h.t * r.direction;
    glm::vec3 ng = st.degenerate ? -glm::normalize(r.direction) : st.geometric_normal;
    if (glm::dot(ng, r.direction) > 0.f) ng = -ng;
    s.geometric_normal = ng;
    glm::vec3 n = ng;
    if (!scene_.normals.empty()) {
        const float w0 = 1.f - h.u - h.v;
        const glm::vec3 blend = w0 * st.n0 + h.u * st.n1 + h.v * st.n2;
        const float len = glm::length(blend);
        if (len > 0.f && std::isfinite(len)) n = blend / len;
    }
    if (glm::dot(n, r.direction) > 0.f) n = -n;
    s.normal = n;
    s.albedo = st.albedo;
    return s;
}

void reference_integrator::check_point(glm::vec3 p, glm::vec3 n) const {
    require(finite3(p), "p", "must be finite");
    require(finite3(n) && std::abs(glm::length(n) - 1.f) < 1e-3f, "n", "must be a finite unit vector");
}

template <class Term>
void reference_integrator::direct_terms(glm::vec3 p, glm::vec3 n, glm::vec3 offset_normal, std::uint32_t area_grid,
                                        std::uint64_t seed, bool choose_light, Term&& term) const {
    const glm::vec3 origin = p + epsilon_ * offset_normal;
    auto unshadowed = [&](const packed_light& l) { return light_irradiance(l, p, n); };
    auto shadow_ray = [&](const packed_light& l) { return detail::shadow_ray_towards(l, origin, epsilon_); };
    auto weight = [](glm::vec3 c) { return c.x + c.y + c.z; };

    if (choose_light && lights_.size() > 1) {
        // One light, drawn with probability w_l / W (w_l: its unshadowed irradiance summed
        // over channels, W: their total), its term divided by that probability.
        float total = 0.f;
        for (const auto& l : lights_) total += weight(unshadowed(l));
        if (total > 0.f) {
            pcg32 pick(derive_seed(seed, stage_light_choice, 0));
            const float target = pick.next_float() * total;
            float below = 0.f;
            std::size_t chosen = lights_.size();
            glm::vec3 chosen_term(0.f);
            for (std::size_t i = 0; i < lights_.size(); ++i) {
                const glm::vec3 c = unshadowed(lights_[i]);
                const float w = weight(c);
                if (!(w > 0.f)) continue;
                chosen = i;  // rounding may leave target above the last sum: the last lit light takes it
                chosen_term = c * (total / w);
                below += w;
                if (target < below) break;
            }
            term(chosen_term, shadow_ray(lights_[chosen]), false);
        }
    } else {
        for (const auto& l : lights_) {
            const glm::vec3 contribution = unshadowed(l);
            if (!(contribution.x > 0.f || contribution.y > 0.f || contribution.z > 0.f)) continue;
            term(contribution, shadow_ray(l), false);
        }
    }

    if (!emitters_.empty()) {
        // Stratified area sampling: an s x s jittered grid over [0,1)^2; u.x picks the
        // emitter by area (its stratum carries over to the rescaled coordinate), then
        // uniform_triangle places the point. pdf_A = 1 / total area.
        const std::uint32_t s = area_grid;
        pcg32 rng(seed);
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
                term(c, detail::shadow_ray_to(origin, q, epsilon_), true);
            }
    }
}

glm::dvec3 reference_integrator::direct_at(glm::vec3 p, glm::vec3 n, glm::vec3 offset_normal, std::uint32_t area_grid,
                                           std::uint64_t seed, bool choose_light) const {
    // Lights' terms summed into e, the emitters' samples into their own sum, which enters
    // as its mean (shade_batch sums the same terms in the same order).
    glm::dvec3 e(0.0), sum(0.0);
    direct_terms(p, n, offset_normal, area_grid, seed, choose_light, [&](glm::vec3 c, const ray& shadow, bool emitter) {
        if (!bvh_.occluded(shadow)) (emitter ? sum : e) += glm::dvec3(c);
    });
    if (!emitters_.empty()) e += sum / double(area_grid * area_grid);
    return e;
}

glm::vec3 reference_integrator::direct_irradiance(glm::vec3 p, glm::vec3 n, std::uint32_t area_samples,
                                                  std::uint64_t seed) const {
    check_point(p, n);
    require(area_samples > 0, "area_samples", "must be positive");
    return glm::vec3(direct_at(p, n, n, square_side(area_samples), seed, false));
}

glm::vec3 reference_integrator::incoming_radiance(const ray& r, std::uint64_t seed, float* distance) const {
    const hit h = bvh_.intersect(r);
    if (!h.found()) {
        if (distance) *distance = std::numeric_limits<float>::infinity();
        return settings_.environment;
    }
    const surface s = surface_of(r, h);
    if (distance) *distance = h.t * glm::length(r.direction);
    // Offset along the geometric normal: the shading normal may point into the surface's
    // own plane at grazing angles and let the shadow ray re-hit the triangle it left.
    const glm::dvec3 e = direct_at(s.position, s.normal, s.geometric_normal,
                                   square_side(settings_.secondary_area_samples), seed,
                                   settings_.secondary_light_choice);
    return glm::vec3(glm::dvec3(s.albedo) * (1.0 / pi) * e);
}

void reference_integrator::shade_batch(const ray* rays, const std::uint64_t* seeds, std::size_t count,
                                       glm::vec3* radiance, float* distance) const {
    // incoming_radiance for each ray, its queries batched: the rays' nearest hits in one
    // query, the hits' shadow rays queued and tested shadow_batch at a time. Each ray's
    // unblocked terms are summed in the order direct_at sums them, so the results are
    // bitwise those of incoming_radiance (Embree's batched queries return the same hits).
    hit hits[shade_batch_rays];
    trace_rays(bvh_, std::span<const ray>(rays, count), std::span<hit>(hits, count));

    glm::dvec3 lit[shade_batch_rays], emitted[shade_batch_rays];  // unblocked terms per ray
    ray shadow[shadow_batch];
    glm::vec3 term[shadow_batch];
    std::uint8_t owner[shadow_batch], from_emitter[shadow_batch], blocked[shadow_batch];
    static_assert(shade_batch_rays <= 256, "owner holds a ray's index in one byte");
    std::size_t pending = 0;
    auto flush = [&] {
        trace_shadows(bvh_, std::span<const ray>(shadow, pending), std::span<std::uint8_t>(blocked, pending));
        for (std::size_t k = 0; k < pending; ++k)
            if (!blocked[k]) (from_emitter[k] ? emitted : lit)[owner[k]] += glm::dvec3(term[k]);
        pending = 0;
    };
    // The hits' triangles are scattered in memory: ask for all of them before shading the
    // first, so their cache misses overlap instead of following one another.
#if defined(__GNUC__) || defined(__clang__)
    for (std::size_t i = 0; i < count; ++i)
        if (hits[i].found()) __builtin_prefetch(&shading_[hits[i].triangle]);
#endif
    const std::uint32_t area_grid = square_side(settings_.secondary_area_samples);
    for (std::size_t i = 0; i < count; ++i) {
        lit[i] = emitted[i] = glm::dvec3(0.0);
        if (!hits[i].found()) continue;
        const surface s = surface_of(rays[i], hits[i]);
        direct_terms(s.position, s.normal, s.geometric_normal, area_grid, seeds[i], settings_.secondary_light_choice,
                     [&](glm::vec3 c, const ray& r, bool emitter) {
                         if (pending == shadow_batch) flush();
                         shadow[pending] = r;
                         term[pending] = c;
                         owner[pending] = std::uint8_t(i);
                         from_emitter[pending] = emitter ? 1 : 0;
                         ++pending;
                     });
    }
    if (pending > 0) flush();
    for (std::size_t i = 0; i < count; ++i) {
        const hit& h = hits[i];
        if (!h.found()) {
            distance[i] = std::numeric_limits<float>::infinity();
            radiance[i] = settings_.environment;
            continue;
        }
        distance[i] = h.t * glm::length(rays[i].direction);
        glm::dvec3 e = lit[i];
        if (!emitters_.empty()) e += emitted[i] / double(area_grid * area_grid);
        radiance[i] = glm::vec3(glm::dvec3(shading_[h.triangle].albedo) * (1.0 / pi) * e);
    }
}

void reference_integrator::incoming_radiance(std::span<const ray> rays, std::span<const std::uint64_t> seeds,
                                             std::span<glm::vec3> radiance, std::span<float> distance) const {
    require(seeds.size() == rays.size() && radiance.size() == rays.size() && distance.size() == rays.size(), "rays",
            "rays, seeds, radiance and distance must have one entry per ray");
    for (std::size_t b = 0; b < rays.size(); b += shade_batch_rays) {
        const std::size_t count = std::min(shade_batch_rays, rays.size() - b);
        shade_batch(rays.data() + b, seeds.data() + b, count, radiance.data() + b, distance.data() + b);
    }
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
    // Each ray has its own stream, so the batches' order changes no bit. One record's rays
    // run on the calling thread: the irradiance cache measures records in parallel, and a
    // parallel loop per record measured no faster there (the 64-ray batches are small).
    const glm::vec3 origin = p + epsilon_ * n;
    ray rays[shade_batch_rays];
    std::uint64_t seeds[shade_batch_rays];
    for (std::size_t b = 0; b < count; b += shade_batch_rays) {
        const std::size_t batch = std::min(shade_batch_rays, count - b);
        for (std::size_t i = 0; i < batch; ++i) {
            rays[i].origin = origin;
            rays[i].direction = out.direction[b + i];
            seeds[i] = derive_seed(seed, stage_secondary, b + i);
        }
        shade_batch(rays, seeds, batch, &out.radiance[b], &out.distance[b]);
    }
}

std::size_t reference_integrator::trace_hemisphere(glm::vec3 p, glm::vec3 n, hemisphere_grid grid,
                                                  std::uint64_t seed) const {
    check_point(p, n);
    require(grid.m > 0 && grid.n > 0, "grid", "needs at least one stratum in theta and in phi");
    // The directions of sample_hemisphere: the same stream, drawn in the same order, and
    // traced in the same batches with the same query.
    const auto tb = orthonormal_basis<float, glm::vec3>(n);
    pcg32 rng(seed);
    const float m = float(grid.m), nn = float(grid.n);
    const glm::vec3 origin = p + epsilon_ * n;
    const std::size_t count = std::size_t(grid.m) * grid.n;
    ray rays[shade_batch_rays];
    hit hits[shade_batch_rays];
    std::size_t found = 0;
    for (std::size_t b = 0; b < count; b += shade_batch_rays) {
        const std::size_t batch = std::min(shade_batch_rays, count - b);
        for (std::size_t i = 0; i < batch; ++i) {
            const std::size_t index = b + i;
            const auto j = std::uint32_t(index / grid.n), k = std::uint32_t(index % grid.n);
            const float u = rng.next_float(), v = rng.next_float();
            const glm::vec3 local = stratified_cosine_direction<float, glm::vec3>(float(j), float(k), m, nn, u, v);
            rays[i].origin = origin;
            rays[i].direction = glm::normalize(local.x * tb[0] + local.y * tb[1] + local.z * n);
        }
        trace_rays(bvh_, std::span<const ray>(rays, batch), std::span<hit>(hits, batch));
        for (std::size_t i = 0; i < batch; ++i) found += hits[i].found() ? 1 : 0;
    }
    return found;
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
            const glm::dvec3 e = direct_at(p, n, n, side, derive_seed(settings_.seed, stage_direct, y * w + x), false);
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
