#include <bounce/embree/probe_baker.hpp>

#include <bounce/sh/gradients.hpp>
#include <bounce/sh/projection.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <mutex>
#include <numbers>

#include <glm/geometric.hpp>

namespace bounce::embree {

namespace {

constexpr std::uint64_t stage_probe = 0x70726f6265ull;  // "probe"

std::uint64_t position_hash(glm::vec3 p) {
    return (std::uint64_t(std::bit_cast<std::uint32_t>(p.x)) << 32) ^
           (std::uint64_t(std::bit_cast<std::uint32_t>(p.y)) << 16) ^ std::uint64_t(std::bit_cast<std::uint32_t>(p.z));
}

}  // namespace

struct probe_baker::cast {
    float harmonic_mean_distance = std::numeric_limits<float>::infinity();
    float nearest = std::numeric_limits<float>::infinity();
    float back_fraction = 0;
};

probe_baker::probe_baker(const reference_integrator& light, const accel& bvh, const scene_view& scene,
                         probe_baker_settings settings)
    : light_(light), bvh_(bvh), scene_(scene), settings_(std::move(settings)) {
    require(settings_.rays > 0, "rays", "a probe needs at least one ray");
    require(std::isfinite(settings_.gradient_step) && settings_.gradient_step >= 0, "gradient_step",
            "must be finite and >= 0 (0: no gradients)");
    require(settings_.nearest_fraction > 0 && settings_.nearest_fraction <= 1, "nearest_fraction", "must lie in (0, 1]");
    require(settings_.inside_fraction >= 0 && settings_.inside_fraction <= 1, "inside_fraction", "must lie in [0, 1]");
    require_match(bvh, scene);
    // Spherical Fibonacci points: z uniform in (-1, 1) at cell centres, golden-angle azimuth.
    const double n = settings_.rays, golden = std::numbers::pi * (3 - std::sqrt(5.0));
    directions_.reserve(settings_.rays);
    for (std::uint32_t j = 0; j < settings_.rays; ++j) {
        const double z = 1 - (2 * j + 1) / n, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = golden * j;
        directions_.push_back(glm::normalize(glm::dvec3(r * std::cos(phi), r * std::sin(phi), z)));
    }
}

irradiance_probe::coefficients probe_baker::project(glm::vec3 position, std::uint64_t seed, cast* details) const {
    const std::size_t n = directions_.size();
    std::vector<glm::dvec3> radiance(n);
    double inverse_distance_sum = 0;
    std::size_t back = 0;
    float nearest = std::numeric_limits<float>::infinity();
    for (std::size_t j = 0; j < n; ++j) {
        ray r;
        r.origin = position;
        r.direction = glm::vec3(directions_[j]);
        float distance = 0;
        radiance[j] = glm::dvec3(light_.incoming_radiance(r, derive_seed(seed, stage_probe, j), &distance));
        if (details && std::isfinite(distance)) {
            inverse_distance_sum += 1.0 / std::max(double(distance), 1e-30);
            nearest = std::min(nearest, distance);
            const hit h = bvh_.intersect(r);
            if (h.found()) {
                const glm::uvec3 t = scene_.triangles[h.triangle];
                const glm::vec3 a = scene_.positions[t.x], b = scene_.positions[t.y], c = scene_.positions[t.z];
                if (glm::dot(glm::cross(b - a, c - a), r.direction) > 0) ++back;
            }
        }
    }
    if (details) {
        details->harmonic_mean_distance =
            inverse_distance_sum > 0 ? float(double(n) / inverse_distance_sum) : std::numeric_limits<float>::infinity();
        details->nearest = nearest;
        details->back_fraction = float(double(back) / double(n));
    }
    const auto c = sh_project_monte_carlo<irradiance_volume_bands, glm::dvec3>(
        std::span<const glm::dvec3>(directions_), std::span<const glm::dvec3>(radiance), 1 / (4 * std::numbers::pi));
    irradiance_probe::coefficients out{};
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = glm::vec3(c[i]);
    return out;
}

irradiance_probe probe_baker::bake(glm::vec3 position) const {
    require(std::isfinite(position.x) && std::isfinite(position.y) && std::isfinite(position.z), "position",
            "probe position must be finite");
    const std::uint64_t seed = derive_seed(settings_.seed, position_hash(position), 0);
    irradiance_probe p;
    p.position = position;
    cast details;
    p.radiance = project(position, seed, &details);
    p.harmonic_mean_distance = details.harmonic_mean_distance;
    p.inside = details.back_fraction > settings_.inside_fraction;
    const float step = std::min(settings_.gradient_step, settings_.nearest_fraction * details.nearest);
    if (!p.inside && settings_.gradient_step > 0 && step > 1e-6f * bvh_.diagonal()) {
        const auto g = sh_translational_gradient<irradiance_volume_bands, glm::dvec3>(
            [&](const glm::dvec3& q) {
                const auto c = project(glm::vec3(q), seed, nullptr);
                sh_coefficients<irradiance_volume_bands, glm::dvec3> d{};
                for (std::size_t i = 0; i < d.size(); ++i) d[i] = glm::dvec3(c[i]);
                return d;
            },
            glm::dvec3(position), double(step));
        const sh_coefficients<irradiance_volume_bands, glm::dvec3>* axes[3] = {&g.x, &g.y, &g.z};
        for (int a = 0; a < 3; ++a)
            for (std::size_t i = 0; i < p.gradient[std::size_t(a)].size(); ++i)
                p.gradient[std::size_t(a)][i] = glm::vec3((*axes[a])[i]);
    }
    return p;
}

void probe_baker::bake(std::span<const glm::vec3> positions, std::span<irradiance_probe> out) const {
    require(out.size() == positions.size(), "out", "one probe per position");
    std::mutex progress_mutex;
    std::size_t done = 0;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 4), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) out[i] = bake(positions[i]);
        if (settings_.progress) {
            std::lock_guard lock(progress_mutex);
            done += r.size();
            settings_.progress(done, positions.size());
        }
    });
}

}  // namespace bounce::embree
