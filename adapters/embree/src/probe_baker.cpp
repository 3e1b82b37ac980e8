#include <bounce/embree/probe_baker.hpp>
#include <bounce/embree/probe_relocation.hpp>
#include <bounce/embree/probe_visibility_baker.hpp>

#include <bounce/luminance.hpp>
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
#include <glm/gtc/quaternion.hpp>

namespace bounce::embree {

namespace {

constexpr std::uint64_t stage_probe = 0x70726f6265ull;  // "probe"

constexpr std::uint64_t stage_rotation = 0x726f74ull;  // "rot"

std::uint64_t position_hash(glm::vec3 p) {
    return (std::uint64_t(std::bit_cast<std::uint32_t>(p.x)) << 32) ^
           (std::uint64_t(std::bit_cast<std::uint32_t>(p.y)) << 16) ^ std::uint64_t(std::bit_cast<std::uint32_t>(p.z));
}

/// A uniformly random rotation (Shoemake 1992, "Uniform random rotations": a unit
/// quaternion from three uniform numbers) drawn from `seed`.
glm::dmat3 random_rotation(std::uint64_t seed) {
    const auto u = [&](std::uint64_t k) { return double(derive_seed(seed, stage_rotation, k) >> 11) * 0x1p-53; };
    const double u1 = u(0), u2 = 2 * std::numbers::pi * u(1), u3 = 2 * std::numbers::pi * u(2);
    const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
    return glm::mat3_cast(glm::dquat(b * std::cos(u3), a * std::sin(u2), a * std::cos(u2), b * std::sin(u3)));
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
    require(std::isfinite(settings_.gradient_noise_ratio) && settings_.gradient_noise_ratio >= 0, "gradient_noise_ratio",
            "must be finite and >= 0 (0: keep every gradient)");
    require(settings_.inside_fraction >= 0 && settings_.inside_fraction <= 1, "inside_fraction", "must lie in [0, 1]");
    require_match(bvh, scene);
    if (settings_.noise == probe_noise_estimate::independent_halves && settings_.rays >= 2) {
        directions_ = spherical_fibonacci_directions(settings_.rays / 2);
        const auto second = spherical_fibonacci_directions(settings_.rays - settings_.rays / 2);
        directions_.insert(directions_.end(), second.begin(), second.end());
    } else {
        directions_ = spherical_fibonacci_directions(settings_.rays);
    }
}

std::vector<glm::dvec3> probe_baker::directions_at(glm::vec3 position) const {
    std::vector<glm::dvec3> dirs = directions_;
    if (settings_.noise != probe_noise_estimate::independent_halves || dirs.size() < 2) return dirs;
    const std::uint64_t seed = derive_seed(settings_.seed, position_hash(position), 0);
    const std::size_t first = dirs.size() / 2;
    for (std::size_t h = 0; h < 2; ++h) {
        const glm::dmat3 r = random_rotation(derive_seed(seed, stage_rotation, 16 + h));
        for (std::size_t j = h ? first : 0; j < (h ? dirs.size() : first); ++j) dirs[j] = r * dirs[j];
    }
    return dirs;
}

probe_baker::estimate probe_baker::project(glm::vec3 position, std::uint64_t seed, std::span<const glm::dvec3> directions,
                                          cast* details) const {
    const std::size_t n = directions.size();
    std::vector<glm::dvec3> radiance(n);
    double inverse_distance_sum = 0;
    std::size_t back = 0;
    float nearest = std::numeric_limits<float>::infinity();
    for (std::size_t j = 0; j < n; ++j) {
        ray r;
        r.origin = position;
        r.direction = glm::vec3(directions[j]);
        float distance = 0;
        radiance[j] = glm::dvec3(light_.incoming_radiance(r, derive_seed(seed, stage_probe, j), &distance));
        if (details && std::isfinite(distance)) {
            inverse_distance_sum += 1.0 / std::max(double(distance), 1e-30);
            nearest = std::min(nearest, distance);
            const hit h = bvh_.intersect(r);
            if (h.found() && hits_back_face(scene_, h, r.direction)) ++back;
        }
    }
    if (details) {
        details->harmonic_mean_distance =
            inverse_distance_sum > 0 ? float(double(n) / inverse_distance_sum) : std::numeric_limits<float>::infinity();
        details->nearest = nearest;
        details->back_fraction = float(double(back) / double(n));
    }
    const auto to_float = [](const sh_coefficients<irradiance_volume_bands, glm::dvec3>& c) {
        irradiance_probe::coefficients out{};
        for (std::size_t i = 0; i < out.size(); ++i) out[i] = glm::vec3(c[i]);
        return out;
    };
    estimate e;
    e.all = to_float(sh_project_monte_carlo<irradiance_volume_bands, glm::dvec3>(
        directions, std::span<const glm::dvec3>(radiance), 1 / (4 * std::numbers::pi)));
    // The two halves: the two turned sets (independent_halves), else the even and the odd
    // rays (each a Fibonacci set of half the density).
    const bool independent = settings_.noise == probe_noise_estimate::independent_halves;
    for (std::size_t h = 0; h < 2 && n >= 2; ++h) {
        std::vector<glm::dvec3> dirs, values;
        const std::size_t begin = independent ? (h ? n / 2 : 0) : h, end = independent && !h ? n / 2 : n;
        for (std::size_t j = begin; j < end; j += independent ? 1 : 2) dirs.push_back(directions[j]), values.push_back(radiance[j]);
        e.half[h] = to_float(sh_project_monte_carlo<irradiance_volume_bands, glm::dvec3>(
            std::span<const glm::dvec3>(dirs), std::span<const glm::dvec3>(values), 1 / (4 * std::numbers::pi)));
    }
    return e;
}

namespace {

/// Half the difference of two estimates' irradiance luminance at the axis normals: the
/// largest (`worst`), or the root mean square over the six (independent halves: its square
/// is an unbiased estimate of the mean's variance there).
float probe_noise(const irradiance_probe::coefficients& a, const irradiance_probe::coefficients& b, bool worst) {
    const auto ea = bounce::detail::axis_irradiance(a), eb = bounce::detail::axis_irradiance(b);
    double largest = 0, sum2 = 0;
    for (std::size_t k = 0; k < ea.size(); ++k) {
        const double d = 0.5 * std::abs(double(ea[k]) - double(eb[k]));
        largest = std::max(largest, d), sum2 += d * d;
    }
    return float(worst ? largest : std::sqrt(sum2 / double(ea.size())));
}

/// Central-difference gradients from the six shifted estimates (+x -x +y -y +z -z), each
/// axis set to 0 where its signal is at most noise_ratio times its noise (the halves').
std::array<irradiance_probe::coefficients, 3> gated_gradient(const std::array<probe_baker::estimate, 6>& shifted, float step,
                                                              float noise_ratio) {
    std::array<irradiance_probe::coefficients, 3> g{};
    for (std::size_t a = 0; a < 3; ++a) {
        const auto& plus = shifted[2 * a];
        const auto& minus = shifted[2 * a + 1];
        double signal2 = 0, noise2 = 0;
        for (std::size_t i = 0; i < g[a].size(); ++i) {
            g[a][i] = (plus.all[i] - minus.all[i]) / (2 * step);
            const glm::vec3 h0 = (plus.half[0][i] - minus.half[0][i]) / (2 * step);
            const glm::vec3 h1 = (plus.half[1][i] - minus.half[1][i]) / (2 * step);
            const double s = rec709_luminance<float, glm::vec3>(g[a][i]), d = 0.5 * rec709_luminance<float, glm::vec3>(h0 - h1);
            signal2 += s * s;
            noise2 += d * d;
        }
        if (noise_ratio > 0 && signal2 <= double(noise_ratio) * double(noise_ratio) * noise2) g[a] = {};
    }
    return g;
}

}  // namespace

irradiance_probe probe_baker::bake(glm::vec3 position) const {
    require(std::isfinite(position.x) && std::isfinite(position.y) && std::isfinite(position.z), "position",
            "probe position must be finite");
    const std::uint64_t seed = derive_seed(settings_.seed, position_hash(position), 0);
    irradiance_probe p;
    p.position = position;
    cast details;
    const std::vector<glm::dvec3> dirs = directions_at(position);
    const estimate centre = project(position, seed, dirs, &details);
    p.radiance = centre.all;
    switch (settings_.noise) {
    case probe_noise_estimate::even_odd: p.noise = probe_noise(centre.half[0], centre.half[1], true); break;
    case probe_noise_estimate::independent_halves: p.noise = probe_noise(centre.half[0], centre.half[1], false); break;
    case probe_noise_estimate::rotated_repeat: {  // the same set turned at random: (a - b) / sqrt 2
        std::vector<glm::dvec3> turned = dirs;
        const glm::dmat3 r = random_rotation(derive_seed(seed, stage_rotation, 32));
        for (auto& d : turned) d = r * d;
        const estimate repeat = project(position, derive_seed(seed, stage_rotation, 33), turned, nullptr);
        p.noise = std::sqrt(2.f) * probe_noise(centre.all, repeat.all, false);
        break;
    }
    }
    p.harmonic_mean_distance = details.harmonic_mean_distance;
    p.inside = details.back_fraction > settings_.inside_fraction;
    const float step = std::min(settings_.gradient_step, settings_.nearest_fraction * details.nearest);
    if (!p.inside && settings_.gradient_step > 0 && step > 1e-6f * bvh_.diagonal()) {
        // Central differences (sh_translational_gradient's, +x -x +y -y +z -z), on all rays
        // and on each half, so that each axis's noise is known.
        std::array<estimate, 6> shifted;
        for (int k = 0; k < 6; ++k) {
            glm::vec3 q = position;
            q[k / 2] += (k % 2 ? -step : step);
            shifted[std::size_t(k)] = project(q, seed, dirs, nullptr);
        }
        p.gradient = gated_gradient(shifted, step, settings_.gradient_noise_ratio);
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
