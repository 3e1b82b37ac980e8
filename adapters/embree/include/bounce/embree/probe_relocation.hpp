#pragma once
/// \file probe_relocation.hpp
/// Probe relocation (Majercik et al. 2021, "Scaling Probe-Based Real-Time Dynamic Global
/// Illumination for Production", section 5.2), as a `probe_source` around the probe baker:
/// a lattice point whose rays hit the backs of triangles in more than `back_fraction` of
/// the cases lies inside geometry; it is moved through the nearest back face it sees, by
/// that distance plus `clearance` of a cell, up to `iterations` times, and kept only
/// where every axis of the move stays within `max_offset` of a cell (the finest cell's
/// shortest edge, so the probe stays in its cell). The probe is baked where it ends up and
/// handed to the build at its lattice point (trilinear weights keep the lattice); its
/// actual position is kept for the visibility test (`positions_of`, then
/// embree::bake_probe_visibility), as DDGI's probe offsets are. A probe that finds no free
/// place stays where it was and the baker flags it inside, as without relocation.

#include <bounce/embree/accel.hpp>
#include <bounce/embree/probe_baker.hpp>
#include <bounce/embree/probe_visibility_baker.hpp>
#include <bounce/errors.hpp>
#include <bounce/scene_view.hpp>
#include <bounce/volume/probe_octree.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <span>
#include <tuple>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::embree {

/// Whether `h` (a hit of a ray along `direction`) is on the back of its triangle: the side
/// opposite its counter-clockwise normal (the probe baker's inside test).
inline bool hits_back_face(const scene_view& scene, const hit& h, glm::vec3 direction) {
    const glm::uvec3 t = scene.triangles[h.triangle];
    const glm::vec3 a = scene.positions[t.x], b = scene.positions[t.y], c = scene.positions[t.z];
    return glm::dot(glm::cross(b - a, c - a), direction) > 0;
}

/// Parameters of probe relocation (unit and typical value with each).
struct probe_relocation_settings {
    std::uint32_t rays = 128;    ///< rays per try. Typical: 64-256
    float back_fraction = 0.25f; ///< inside above this fraction of back-face hits (DDGI: 0.25)
    float clearance = 0.1f;      ///< past the back face by this fraction of a cell
    float max_offset = 0.45f;    ///< largest move per axis, fraction of a cell (DDGI: 0.45)
    int iterations = 4;          ///< tries per probe
};

/// A probe_source: `baker`'s probes, each baked at its relocated position and returned at its
/// lattice point. Holds references to the baker, the BVH and the scene. Not thread-safe to
/// call concurrently (the build calls it one batch at a time).
class relocating_probe_source {
public:
    /// `cell`: the finest cell's shortest edge (world units). Throws parameter_error naming
    /// "cell" when not positive and finite, the setting for rays = 0, fractions outside
    /// [0, 1] (max_offset in [0, 0.5]) or iterations < 1.
    relocating_probe_source(const probe_baker& baker, const accel& bvh, const scene_view& scene, float cell,
                            probe_relocation_settings s = {})
        : baker_(baker), bvh_(bvh), scene_(scene), cell_(cell), s_(s) {
        require(std::isfinite(cell) && cell > 0, "cell", "must be finite and > 0");
        require(s.rays > 0, "rays", "at least one ray");
        require(s.back_fraction >= 0 && s.back_fraction <= 1, "back_fraction", "must lie in [0, 1]");
        require(s.clearance >= 0 && s.clearance <= 1, "clearance", "must lie in [0, 1]");
        require(s.max_offset >= 0 && s.max_offset <= 0.5f, "max_offset", "must lie in [0, 0.5]");
        require(s.iterations >= 1, "iterations", "at least one");
        for (const glm::dvec3& d : spherical_fibonacci_directions(s.rays)) directions_.push_back(glm::vec3(d));
    }

    /// Where a probe at lattice point `p` is baked: p, or p moved out of geometry.
    glm::vec3 relocate(glm::vec3 p) const {
        glm::vec3 offset(0.f);
        for (int it = 0; it < s_.iterations; ++it) {
            std::size_t back = 0;
            float nearest_back = std::numeric_limits<float>::infinity();
            glm::vec3 towards(0.f);
            for (const glm::vec3& d : directions_) {
                const hit h = bvh_.intersect(ray{p + offset, d, 0.f, std::numeric_limits<float>::infinity()});
                if (!h.found() || !hits_back_face(scene_, h, d)) continue;
                ++back;
                if (h.t < nearest_back) nearest_back = h.t, towards = d;
            }
            if (float(back) <= s_.back_fraction * float(directions_.size())) break;  // outside geometry
            const glm::vec3 moved = offset + towards * (nearest_back + s_.clearance * cell_);
            if (glm::any(glm::greaterThan(glm::abs(moved), glm::vec3(s_.max_offset * cell_)))) break;  // leaves its cell
            offset = moved;
        }
        return p + offset;
    }

    /// Bakes each position's probe at its relocated position (in parallel) and returns it at
    /// the lattice position; remembers where each was baked.
    void operator()(std::span<const glm::vec3> positions, std::span<irradiance_probe> out) {
        std::vector<glm::vec3> at(positions.size());
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) at[i] = relocate(positions[i]);
        });
        baker_.bake(at, out);
        for (std::size_t i = 0; i < positions.size(); ++i) {
            out[i].position = positions[i];
            baked_at_[key(positions[i])] = at[i];
            moved_ += at[i] != positions[i];
        }
    }

    /// Where each probe of `volume` (built from this source) was baked, in probes() order.
    std::vector<glm::vec3> positions_of(const irradiance_volume& volume) const {
        std::vector<glm::vec3> out;
        out.reserve(volume.probes().size());
        for (const irradiance_probe& p : volume.probes()) {
            const auto it = baked_at_.find(key(p.position));
            out.push_back(it == baked_at_.end() ? p.position : it->second);
        }
        return out;
    }
    std::size_t moved() const noexcept { return moved_; }  ///< probes moved so far

private:
    static std::tuple<std::uint32_t, std::uint32_t, std::uint32_t> key(glm::vec3 p) {
        return {std::bit_cast<std::uint32_t>(p.x), std::bit_cast<std::uint32_t>(p.y), std::bit_cast<std::uint32_t>(p.z)};
    }

    const probe_baker& baker_;
    const accel& bvh_;
    scene_view scene_;
    float cell_;
    probe_relocation_settings s_;
    std::vector<glm::vec3> directions_;
    std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>, glm::vec3> baked_at_;
    std::size_t moved_ = 0;
};

}  // namespace bounce::embree
