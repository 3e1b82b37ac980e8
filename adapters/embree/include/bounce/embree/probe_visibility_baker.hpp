#pragma once
/// \file probe_visibility_baker.hpp
/// The distance moments of an irradiance volume's probes, ray-cast with Embree
/// (volume/probe_visibility.hpp; DDGI, Majercik et al. 2019): each probe casts `rays` rays
/// along a spherical Fibonacci set (the probe baker's directions), clamps each first-hit
/// distance (a miss counts as the maximum) to `max_distance_ratio` times the diagonal of
/// the largest leaf the probe is a corner of, and filters the distances into its N x N
/// octahedral map with cosine-power weights (filter_ray_distances). Intersections only: no
/// shading, so far cheaper than the probes' light.

#include <bounce/embree/accel.hpp>
#include <bounce/errors.hpp>
#include <bounce/volume/probe_visibility.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::embree {

/// `n` unit directions of a spherical Fibonacci set (Gonzalez 2010): z uniform in (-1, 1) at
/// cell centres, golden-angle azimuth; near-equal areas.
inline std::vector<glm::dvec3> spherical_fibonacci_directions(std::uint32_t n) {
    const double count = n, golden = std::numbers::pi * (3 - std::sqrt(5.0));
    std::vector<glm::dvec3> out;
    out.reserve(n);
    for (std::uint32_t j = 0; j < n; ++j) {
        const double z = 1 - (2 * j + 1) / count, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = golden * j;
        out.push_back(glm::normalize(glm::dvec3(r * std::cos(phi), r * std::sin(phi), z)));
    }
    return out;
}

/// Parameters of the distance-moment bake (unit and typical value with each).
struct probe_visibility_settings {
    /// Texels per side of each probe's octahedral map, 1 .. 64. Typical: 8-16 (DDGI: 16).
    std::uint32_t resolution = 16;
    /// Rays per probe. Typical: 4 N^2 or more, so that each texel's lobe holds several.
    std::uint32_t rays = 1024;
    /// Exponent of the cosine-power filter (DDGI: 50: a lobe of about 10 degrees).
    float sharpness = 50.f;
    /// Distances clamp to this times the diagonal of the largest leaf the probe is a corner
    /// of (misses count as that). Typical: 1-2.
    float max_distance_ratio = 1.5f;
};

/// The distance moments of every probe of `volume` over the scene `bvh` holds (in parallel,
/// TBB; probes inside geometry get maps of zeros, as lookups skip them), cast from
/// `positions` (one per probe: where relocated probes were baked,
/// relocating_probe_source::positions_of; empty: the probes' lattice positions), which the
/// result keeps. Throws parameter_error naming the setting: resolution outside 1 .. 64,
/// rays = 0, sharpness or max_distance_ratio not positive and finite, "positions" of
/// another size.
inline probe_visibility bake_probe_visibility(const accel& bvh, const irradiance_volume& volume,
                                              const probe_visibility_settings& s = {},
                                              std::span<const glm::vec3> positions = {}) {
    require(s.resolution >= 1 && s.resolution <= 64, "resolution", "must lie in 1 .. 64");
    require(s.rays > 0, "rays", "a probe needs at least one ray");
    require(std::isfinite(s.sharpness) && s.sharpness > 0, "sharpness", "must be finite and > 0");
    require(std::isfinite(s.max_distance_ratio) && s.max_distance_ratio > 0, "max_distance_ratio",
            "must be finite and > 0");
    require(positions.empty() || positions.size() == volume.probes().size(), "positions", "one position per probe");
    std::vector<glm::vec3> directions;
    for (const glm::dvec3& d : spherical_fibonacci_directions(s.rays)) directions.push_back(glm::vec3(d));
    const std::size_t floats = 2 * std::size_t(s.resolution) * s.resolution;
    const auto& probes = volume.probes();
    std::vector<float> moments(probes.size() * floats, 0.f);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, probes.size(), 4), [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<ray> rays(directions.size());
        std::vector<hit> hits(directions.size());
        std::vector<float> distances(directions.size());
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const irradiance_probe& p = probes[i];
            if (p.inside) continue;
            const float max_distance = s.max_distance_ratio * 2 * p.reach;  // reach: half the diagonal
            const glm::vec3 from = positions.empty() ? p.position : positions[i];
            for (std::size_t j = 0; j < rays.size(); ++j) rays[j] = ray{from, directions[j], 0.f, max_distance};
            bvh.intersect(std::span<const ray>(rays), std::span<hit>(hits));
            for (std::size_t j = 0; j < rays.size(); ++j) distances[j] = hits[j].found() ? hits[j].t : max_distance;
            filter_ray_distances(directions, distances, s.resolution, s.sharpness,
                                 std::span<float>(moments.data() + i * floats, floats));
        }
    });
    return probe_visibility(s.resolution, std::move(moments), std::vector<glm::vec3>(positions.begin(), positions.end()));
}

}  // namespace bounce::embree
