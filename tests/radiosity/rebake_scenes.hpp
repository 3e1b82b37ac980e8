#pragma once
// What the re-bake tests share (CPU and GL solvers): the box with a block that moves, and the
// measures of how far two solves lie apart and how far their unshot power lets them.
#include "radiosity_scenes.hpp"

#include <bounce/radiosity/rebake.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

namespace bounce::radiosity_test {

constexpr float rebake_albedo = 0.7f;

// A closed box 2 m wide with a glowing lamp under its ceiling, a point light and a block
// 0.4 m on the floor (its top and four sides: triangles 14-23, the last ones).
inline owned_scene box_with_block() {
    owned_scene s = closed_box(2.f, rebake_albedo, 3.f);
    const auto m = s.add_material(glm::vec3(0.6f, 0.7f, 0.5f));
    const glm::vec3 lo(0.5f, 0.f, 0.5f), hi(0.9f, 0.4f, 0.9f);
    const auto p = [&](int x, int y, int z) { return glm::vec3(x ? hi.x : lo.x, y ? hi.y : lo.y, z ? hi.z : lo.z); };
    s.add_quad(p(0, 1, 0), p(0, 1, 1), p(1, 1, 1), p(1, 1, 0), m);  // top, +y
    s.add_quad(p(0, 0, 0), p(1, 0, 0), p(1, 1, 0), p(0, 1, 0), m);  // -z
    s.add_quad(p(0, 0, 1), p(0, 1, 1), p(1, 1, 1), p(1, 0, 1), m);  // +z
    s.add_quad(p(0, 0, 0), p(0, 1, 0), p(0, 1, 1), p(0, 0, 1), m);  // -x
    s.add_quad(p(1, 0, 0), p(1, 0, 1), p(1, 1, 1), p(1, 1, 0), m);  // +x
    s.lights.push_back(point_light{glm::vec3(1.3f, 1.5f, 1.2f), glm::vec3(2.f)});
    return s;
}

inline std::vector<std::uint32_t> block_triangles() {
    std::vector<std::uint32_t> t(10);
    std::iota(t.begin(), t.end(), 14u);
    return t;
}

// `s` with the triangles `tris` moved by `move` (add_quad's triangles share no vertex with
// another quad's).
inline owned_scene moved_scene(const owned_scene& s, const std::vector<std::uint32_t>& tris, const rigid_move& move) {
    owned_scene moved = s;
    for (const std::uint32_t t : tris)
        for (int k = 0; k < 3; ++k) moved.positions[s.triangles[t][k]] = move.point(s.positions[s.triangles[t][k]]);
    return moved;
}

// |B_a - B_b| summed over elements, sides and channels, times area, over the same of |B_b|.
template <class A, class B>
double relative_l1(const A& a, const B& b) {
    double diff = 0, total = 0;
    for (int side = 0; side < a.sides(); ++side) {
        const auto ra = a.radiosity(side), rb = b.radiosity(side);
        for (std::size_t i = 0; i < ra.size(); ++i) {
            const double area = a.atlas().area[i];
            const glm::dvec3 d = glm::abs(glm::dvec3(ra[i]) - glm::dvec3(rb[i]));
            diff += (d.x + d.y + d.z) * area;
            total += (std::abs(rb[i].x) + std::abs(rb[i].y) + std::abs(rb[i].z)) * area;
        }
    }
    return diff / total;
}

// How far two solves that each left `u` of the emitted power unshot (in magnitude) may lie
// apart: the unshot power dB of a solve is what separates it from the converged answer,
// which it would raise by (I - rho F)^-1 rho F dB, at most rho / (1 - rho) |dB| in power.
template <class A, class B>
double convergence_bound(const A& a, const B& b) {
    double total = 0;
    for (int side = 0; side < b.sides(); ++side) {
        const auto rb = b.radiosity(side);
        for (std::size_t i = 0; i < rb.size(); ++i) total += (rb[i].x + rb[i].y + rb[i].z) * b.atlas().area[i];
    }
    const double e = a.emitted_power().x + a.emitted_power().y + a.emitted_power().z;
    const double f = b.emitted_power().x + b.emitted_power().y + b.emitted_power().z;
    return rebake_albedo / (1 - rebake_albedo) * (a.unshot_fraction() * e + b.unshot_fraction() * f) / total;
}

template <class S>
double negative_unshot(const S& s) {
    double neg = 0;
    for (int side = 0; side < s.sides(); ++side)
        for (const auto& u : s.unshot(side)) neg += std::min(0.f, u.x) + std::min(0.f, u.y) + std::min(0.f, u.z);
    return neg;
}

}  // namespace bounce::radiosity_test
