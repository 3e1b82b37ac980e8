#pragma once
// The half-lit ceiling as a scene, for the samplers' tests: a ceiling at height y = H
// facing down, Kd = kd_lit for x > x_edge and 0 elsewhere, 2 * extent wide, lit from
// below by a directional light travelling +y that delivers E_perp, so the lit part has
// radiance kd / pi * E_perp. Records sit at y = 0 looking up (n = +y).
#include "../core/half_lit_ceiling.hpp"

#include <bounce/cache/plane_camera.hpp>
#include "../owned_scene.hpp"

#include <cmath>
#include <cstdint>

namespace bounce::hemisphere_test {

inline test::owned_scene half_lit_ceiling_scene(float H, float x_edge, float kd_lit, float E_perp, float extent = 2000.f) {
    test::owned_scene s;
    s.name = "half-lit-ceiling";
    bounce::material lit, dark;
    lit.albedo = glm::vec3(kd_lit);
    dark.albedo = glm::vec3(0.f);
    s.materials = {lit, dark};
    const glm::vec3 down(0, -1, 0);
    const auto quad = [&](float x0, float x1, std::uint32_t m) {
        const auto base = std::uint32_t(s.positions.size());
        for (const glm::vec3 p : {glm::vec3(x0, H, -extent), glm::vec3(x1, H, -extent), glm::vec3(x1, H, extent),
                                  glm::vec3(x0, H, extent)}) {
            s.positions.push_back(p);
            s.normals.push_back(down);
        }
        s.triangles.emplace_back(base, base + 1, base + 2);
        s.triangles.emplace_back(base, base + 2, base + 3);
        s.material_of.insert(s.material_of.end(), {m, m});
    };
    quad(x_edge, extent, 0);
    quad(-extent, x_edge, 1);
    s.lights.push_back(bounce::directional_light{glm::vec3(0, 1, 0), glm::vec3(E_perp)});
    return s;
}

// That ceiling as a record at p (n = +y), whose rays or eye leave at height `offset`, sees
// it in its plane's frame (cam.frame): the core tests' half_lit_ceiling with
// h = H - offset, x0 = p.x - x_edge and rot = atan2(b.x, t.x), the angle of world +x (the
// edge's normal) in that frame ((t.x, b.x) is a unit vector, n being +y).
inline ceiling_test::half_lit_ceiling ceiling_seen_from(const plane_camera& cam, glm::vec3 p, float H, double offset,
                                                        float x_edge, double L) {
    const auto tb = cam.frame(p, glm::vec3(0, 1, 0));
    return {double(H) - offset, double(p.x) - double(x_edge), L, std::atan2(double(tb[1].x), double(tb[0].x))};
}

}  // namespace bounce::hemisphere_test
