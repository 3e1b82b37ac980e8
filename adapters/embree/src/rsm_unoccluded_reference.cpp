// One-bounce indirect irradiance without receiver-sender visibility: the ground truth of
// reflective shadow maps and splatting indirect illumination (Dachsbacher and Stamminger
// 2005, 2006), by cosine-weighted rays that sum every surface they cross.
#include <bounce/embree/rsm_unoccluded_reference.hpp>

#include <bounce/embree/reference.hpp>

#include "light_rays.hpp"
#include <bounce/direct_light.hpp>
#include <bounce/luminance.hpp>
#include <bounce/sampling.hpp>

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bounce::embree {

namespace {
constexpr double pi = std::numbers::pi;
// Stream numbers of derive_seed, apart from reference.cpp's (they only need to differ
// within one image).
constexpr std::uint64_t stage_unoccluded = 0x756e6f63;  // "unoc"

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
}  // namespace

void unoccluded_reference_settings::validate() const {
    require(hemisphere_samples >= 2, "hemisphere_samples", "must be at least 2 (two halves)");
    require(max_surfaces >= 1, "max_surfaces", "must be positive");
    require(std::isfinite(ray_epsilon) && ray_epsilon >= 0.f, "ray_epsilon", "must be finite and >= 0");
}

unoccluded_reference::unoccluded_reference(const accel& bvh, const scene_view& scene,
                                           unoccluded_reference_settings settings)
    : bvh_(bvh), scene_(scene), settings_(settings) {
    settings_.validate();
    require_match(bvh_, scene_);
    validate_lights(scene_.lights);
    epsilon_ = settings_.ray_epsilon > 0.f ? settings_.ray_epsilon : bvh_.ray_epsilon();
    for (const light& l : scene_.lights) lights_.push_back(pack(l));
}

glm::vec3 unoccluded_reference::direct_irradiance(glm::vec3 p, glm::vec3 n, glm::vec3 offset_normal) const {
    const glm::vec3 origin = p + epsilon_ * offset_normal;
    glm::dvec3 e(0.0);
    for (const packed_light& l : lights_) {
        const glm::vec3 c = light_irradiance(l, p, n);
        if (!(c.x > 0.f || c.y > 0.f || c.z > 0.f)) continue;
        if (!bvh_.occluded(detail::shadow_ray_towards(l, origin, epsilon_))) e += glm::dvec3(c);
    }
    return glm::vec3(e);
}

glm::vec3 unoccluded_reference::indirect_irradiance(glm::vec3 p, glm::vec3 n, std::uint32_t samples,
                                                    std::uint64_t seed) const {
    require(finite3(p), "p", "must be finite");
    require(finite3(n) && std::abs(glm::length(n) - 1.f) < 1e-3f, "n", "must be a finite unit vector");
    const hemisphere_grid grid = hemisphere_grid_for(samples);
    const auto tb = orthonormal_basis<float, glm::vec3>(n);
    pcg32 rng(seed);
    const float m = float(grid.m), nn = float(grid.n);
    glm::dvec3 sum(0.0);
    for (std::uint32_t j = 0; j < grid.m; ++j)
        for (std::uint32_t k = 0; k < grid.n; ++k) {
            const float u = rng.next_float(), v = rng.next_float();
            const glm::vec3 local = stratified_cosine_direction<float, glm::vec3>(float(j), float(k), m, nn, u, v);
            ray r;
            r.origin = p + epsilon_ * n;
            r.direction = glm::normalize(local.x * tb[0] + local.y * tb[1] + local.z * n);
            r.tnear = 0.f;
            // Every surface along the ray sends its reflected light to p: no visibility.
            for_each_sender(r, [&](float, const glm::dvec3& l) { sum += l; });
        }
    return glm::vec3(sum * (pi / double(grid.count())));
}

image<glm::vec3> unoccluded_reference::indirect_image(const gbuffer_view<float>& g) const {
    const std::size_t w = g.width(), h = g.height();
    require(w > 0 && h > 0, "g", "the G-buffer is empty");
    image<glm::vec3> out(w, h, glm::vec3(0.f));
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, h, 1), [&](const tbb::blocked_range<std::size_t>& rows) {
        for (std::size_t y = rows.begin(); y != rows.end(); ++y)
            for (std::size_t x = 0; x < w; ++x) {
                if (!g.covered(x, y)) continue;
                const glm::vec3 e = indirect_irradiance(g.position(x, y), g.normal(x, y), settings_.hemisphere_samples,
                                                        derive_seed(settings_.seed, stage_unoccluded, y * w + x));
                out(x, y) = glm::vec3(glm::dvec3(g.albedo(x, y)) * (1.0 / pi) * glm::dvec3(e));
            }
    });
    return out;
}

unoccluded_reference_image render_unoccluded_reference(const accel& bvh, const scene_view& scene,
                                                       const gbuffer_view<float>& g,
                                                       const unoccluded_reference_settings& settings) {
    settings.validate();
    require(settings.hemisphere_samples >= 4 && settings.hemisphere_samples % 2 == 0, "hemisphere_samples",
            "must be even and at least 4: two halves of equal size, each of at least 2 rays");
    unoccluded_reference_settings half = settings;
    half.hemisphere_samples = settings.hemisphere_samples / 2;
    const image<glm::vec3> a = unoccluded_reference(bvh, scene, half).indirect_image(g);
    half.seed = settings.seed + 1;
    const image<glm::vec3> b = unoccluded_reference(bvh, scene, half).indirect_image(g);
    unoccluded_reference_image out;
    out.indirect = image<glm::vec3>(g.width(), g.height());
    out.samples = 2 * half.hemisphere_samples;
    double diff2 = 0, ref2 = 0;
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x) {
            out.indirect(x, y) = 0.5f * (a(x, y) + b(x, y));
            if (!g.covered(x, y)) continue;
            const double la = rec709_luminance<double, glm::dvec3>(glm::dvec3(a(x, y)));
            const double lb = rec709_luminance<double, glm::dvec3>(glm::dvec3(b(x, y)));
            diff2 += (la - lb) * (la - lb);
            ref2 += 0.25 * (la + lb) * (la + lb);
        }
    out.noise_rel_rms = ref2 > 0 ? 0.5 * std::sqrt(diff2 / ref2) : 0.0;
    return out;
}

}  // namespace bounce::embree
