#pragma once
// Scenes built by hand for the closed-form tests: quads, boxes and a subdivided icosahedron,
// and Lambert's exact irradiance from a uniformly bright polygon.
#include "../owned_scene.hpp"

#include <glm/glm.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace hand_built {

using scene = bounce::test::owned_scene;

template <class Scene>
std::uint32_t add_material(Scene& s, glm::vec3 kd, glm::vec3 ke = glm::vec3(0.f)) {
    s.materials.push_back({kd, ke});
    return std::uint32_t(s.materials.size() - 1);
}

template <class Scene>
void add_triangle(Scene& s, std::array<glm::vec3, 3> p, std::array<glm::vec3, 3> n, std::uint32_t material) {
    const auto base = std::uint32_t(s.positions.size());
    for (int i = 0; i < 3; ++i) {
        s.positions.push_back(p[i]);
        s.normals.push_back(n[i]);
    }
    s.triangles.emplace_back(base, base + 1, base + 2);
    s.material_of.push_back(material);
}

// Quad a b c d (counter-clockwise seen from the side `normal` points to), two triangles
// sharing the diagonal a-c, every vertex normal equal to `normal`.
template <class Scene>
void add_quad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec3 normal,
                     std::uint32_t material) {
    add_triangle(s, {a, b, c}, {normal, normal, normal}, material);
    add_triangle(s, {a, c, d}, {normal, normal, normal}, material);
}

// Axis-aligned square of half-size h in the plane z = z0, normal +z or -z.
template <class Scene>
void add_square_z(Scene& s, float z0, float h, bool faces_up, std::uint32_t material, glm::vec2 centre = {0, 0}) {
    const glm::vec3 a(centre.x - h, centre.y - h, z0), b(centre.x + h, centre.y - h, z0), c(centre.x + h, centre.y + h, z0),
        d(centre.x - h, centre.y + h, z0);
    if (faces_up) add_quad(s, a, b, c, d, {0, 0, 1}, material);
    else add_quad(s, a, d, c, b, {0, 0, -1}, material);
}

// Irradiance at height h above the centre of a Lambertian square of half-side a and exitance
// M, facing it: M square_factor(a / h), with
// F(X) = 4/pi X / sqrt(1 + X^2) atan(X / sqrt(1 + X^2)) (four corner rectangles of the
// parallel differential-area-to-rectangle factor).
inline double square_factor(double x) {
    const double s = x / std::sqrt(1 + x * x);
    return 4 / std::numbers::pi * s * std::atan(s);
}

// A lit floor (half-side 1, z = 0, albedo rho) under a lit occluder (half-side 0.3, z = 0.5,
// which shadows the floor's centre), a directional light of irradiance e0 straight down.
// Seen from (0, 0, 1) facing down, the receiver the RSM tests use: without visibility it
// sees the floor less its shadow plus the occluder, M (F(1) - F(0.3) + F(0.6)); with it the
// occluder hides exactly the floor's |x|, |y| <= 0.6 and replaces it with the same radiance,
// M F(1) (M = rho e0, F = square_factor).
inline scene lit_floor_under_occluder(float rho, float e0) {
    scene s;
    const auto mat = add_material(s, glm::vec3(rho));
    add_square_z(s, 0.f, 1.f, true, mat);
    add_square_z(s, 0.5f, 0.3f, true, mat);
    s.lights.push_back(bounce::directional_light{{0, 0, -1}, glm::vec3(e0)});
    return s;
}

// An icosahedron subdivided `levels` times and projected onto the sphere of radius r around
// `centre`: shared vertices (watertight), unit radial vertex normals, 20 * 4^levels triangles.
template <class Scene>
void add_icosphere(Scene& s, glm::dvec3 centre, double r, int levels, std::uint32_t material) {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<glm::dvec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (auto& p : v) p = glm::normalize(p);
    std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},   {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<unsigned, unsigned>, unsigned> mid;
        auto midpoint = [&](unsigned a, unsigned b) {
            const auto key = std::minmax(a, b);
            if (auto it = mid.find(key); it != mid.end()) return it->second;
            v.push_back(glm::normalize(v[a] + v[b]));
            return mid[key] = unsigned(v.size() - 1);
        };
        std::vector<glm::uvec3> g;
        for (const auto& tri : f) {
            const unsigned ab = midpoint(tri.x, tri.y), bc = midpoint(tri.y, tri.z), ca = midpoint(tri.z, tri.x);
            g.insert(g.end(), {{tri.x, ab, ca}, {tri.y, bc, ab}, {tri.z, ca, bc}, {ab, bc, ca}});
        }
        f = std::move(g);
    }
    const auto base = std::uint32_t(s.positions.size());
    for (const auto& p : v) {
        s.positions.push_back(glm::vec3(centre + r * p));
        s.normals.push_back(glm::vec3(p));
    }
    for (const auto& tri : f) {
        s.triangles.push_back(tri + glm::uvec3(base));
        s.material_of.push_back(material);
    }
}

// Irradiance at p (unit normal n) from a polygon of uniform unit radiance that lies wholly
// above p's tangent plane: Lambert's formula E = 1/2 sum_i beta_i (n . gamma_i), beta_i the
// angle the edge (v_i, v_i+1) subtends at p and gamma_i the unit normal of the plane through
// p and that edge (Arvo 1995, "Applications of irradiance tensors", Eq. 1). Exact; the full
// hemisphere gives pi. Evaluated in double.
inline double lambert_polygon(glm::dvec3 p, glm::dvec3 n, const std::vector<glm::dvec3>& polygon) {
    double sum = 0;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
        const glm::dvec3 a = glm::normalize(polygon[i] - p), b = glm::normalize(polygon[(i + 1) % polygon.size()] - p);
        const double beta = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
        sum += beta * glm::dot(n, glm::normalize(glm::cross(a, b)));
    }
    return 0.5 * std::abs(sum);
}

}  // namespace hand_built
