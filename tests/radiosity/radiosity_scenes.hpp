#pragma once
// Scenes built by hand for the radiosity tests: quads (two triangles each) in owned arrays
// that hand out a scene_view.
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace bounce::radiosity_test {

struct owned_scene {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;
    std::vector<std::uint32_t> material_of;
    std::vector<material> materials;
    std::vector<light> lights;
    bool use_emission = true;

    std::uint32_t add_material(glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.f)) {
        materials.push_back({albedo, emission});
        return std::uint32_t(materials.size() - 1);
    }
    // The quad a b c d (counter-clockwise seen from its front) as triangles abc, acd.
    void add_quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t m) {
        const auto base = std::uint32_t(positions.size());
        positions.insert(positions.end(), {a, b, c, d});
        triangles.emplace_back(base, base + 1, base + 2);
        triangles.emplace_back(base, base + 2, base + 3);
        material_of.insert(material_of.end(), {m, m});
    }
    scene_view view() const {
        scene_view v;
        v.positions = positions;
        v.triangles = triangles;
        v.material_of = material_of;
        v.materials = materials;
        v.lights = lights;
        v.use_emission = use_emission;
        return v;
    }
};

// Two parallel squares of side `side` a distance `gap` apart, facing each other: the lower
// one (z = 0, facing +z) emits radiance `radiance`, the upper one (z = gap, facing -z)
// reflects `albedo`; the lower one reflects `albedo` too.
inline owned_scene facing_squares(float side, float gap, float albedo, float radiance) {
    owned_scene s;
    const auto lower = s.add_material(glm::vec3(albedo), glm::vec3(radiance));
    const auto upper = s.add_material(glm::vec3(albedo));
    const float h = side / 2;
    s.add_quad({-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}, lower);
    s.add_quad({-h, -h, gap}, {-h, h, gap}, {h, h, gap}, {h, -h, gap}, upper);
    return s;
}

// The inside of the cube [0, size]^3 (walls face inwards), albedo `albedo` (per channel
// 0.5, 0.6, 0.7 times it, so channels differ), with the ceiling's middle third an emitting
// quad of radiance `radiance` just below the ceiling.
inline owned_scene closed_box(float size, float albedo, float radiance) {
    owned_scene s;
    const auto wall = s.add_material(albedo * glm::vec3(0.5f, 0.6f, 0.7f) / 0.7f);
    const auto lamp = s.add_material(glm::vec3(0.5f), glm::vec3(radiance));
    const float a = size;
    s.add_quad({0, 0, 0}, {0, 0, a}, {a, 0, a}, {a, 0, 0}, wall);   // floor, y = 0, +y
    s.add_quad({0, a, 0}, {a, a, 0}, {a, a, a}, {0, a, a}, wall);   // ceiling, -y
    s.add_quad({0, 0, 0}, {a, 0, 0}, {a, a, 0}, {0, a, 0}, wall);   // back, z = 0, +z
    s.add_quad({0, 0, a}, {0, a, a}, {a, a, a}, {a, 0, a}, wall);   // front, -z
    s.add_quad({0, 0, 0}, {0, a, 0}, {0, a, a}, {0, 0, a}, wall);   // left, x = 0, +x
    s.add_quad({a, 0, 0}, {a, 0, a}, {a, a, a}, {a, a, 0}, wall);   // right, -x
    const float l0 = a / 3, l1 = 2 * a / 3, y = a * 0.999f;
    s.add_quad({l0, y, l0}, {l1, y, l0}, {l1, y, l1}, {l0, y, l1}, lamp);  // faces -y
    return s;
}

// A floor 2 x 2 m (y = 0, facing +y) running around the base of a column 0.4 m square and
// `height` tall standing in the middle (the column's four sides and its top; the floor has a
// hole where the column stands, as published scenes model it), lit by a sun from above:
// the floor is one chart of four trapezoids whose texels' overlap is not convex.
inline owned_scene floor_around_column(float height) {
    owned_scene s;
    s.use_emission = false;
    const auto m = s.add_material(glm::vec3(0.6f));
    const glm::vec2 outer[4] = {{0, 0}, {0, 2}, {2, 2}, {2, 0}}, inner[4] = {{0.8f, 0.8f}, {0.8f, 1.2f}, {1.2f, 1.2f}, {1.2f, 0.8f}};
    const auto at = [](glm::vec2 p, float y) { return glm::vec3(p.x, y, p.y); };
    for (int k = 0; k < 4; ++k)  // the floor's trapezoids, counter-clockwise from +y
        s.add_quad(at(outer[k], 0), at(outer[(k + 1) % 4], 0), at(inner[(k + 1) % 4], 0), at(inner[k], 0), m);
    for (int k = 0; k < 4; ++k)  // the column's sides, facing outwards
        s.add_quad(at(inner[k], 0), at(inner[k], height), at(inner[(k + 1) % 4], height), at(inner[(k + 1) % 4], 0), m);
    s.add_quad(at(inner[0], height), at(inner[1], height), at(inner[2], height), at(inner[3], height), m);
    s.lights.push_back(directional_light{glm::normalize(glm::vec3(0.3f, -1.f, 0.2f)), glm::vec3(20.f)});
    return s;
}

// The Cornell box of ../shared/scenes/cornell-box (Goral et al. 1984; the Williams College
// OBJ, public domain), copied by hand: five walls, the two boxes (without their hidden bottom
// faces) and the ceiling light as an emitting quad (Ke 17 12 4), or, with `spot`, the spot
// light of its scene.json instead of the emitting quad.
inline owned_scene cornell_box(bool spot = false) {
    owned_scene s;
    const auto white = s.add_material({0.725f, 0.71f, 0.68f});
    const auto red = s.add_material({0.63f, 0.065f, 0.05f});
    const auto green = s.add_material({0.14f, 0.45f, 0.091f});
    const auto lamp = s.add_material({0.78f, 0.78f, 0.78f}, spot ? glm::vec3(0.f) : glm::vec3(17.f, 12.f, 4.f));
    s.add_quad({-1.01f, 0, 0.99f}, {1.00f, 0, 0.99f}, {1.00f, 0, -1.04f}, {-0.99f, 0, -1.04f}, white);
    s.add_quad({-1.02f, 1.99f, 0.99f}, {-1.02f, 1.99f, -1.04f}, {1.00f, 1.99f, -1.04f}, {1.00f, 1.99f, 0.99f}, white);
    s.add_quad({-0.99f, 0, -1.04f}, {1.00f, 0, -1.04f}, {1.00f, 1.99f, -1.04f}, {-1.02f, 1.99f, -1.04f}, white);
    s.add_quad({1.00f, 0, -1.04f}, {1.00f, 0, 0.99f}, {1.00f, 1.99f, 0.99f}, {1.00f, 1.99f, -1.04f}, green);
    s.add_quad({-1.01f, 0, 0.99f}, {-0.99f, 0, -1.04f}, {-1.02f, 1.99f, -1.04f}, {-1.02f, 1.99f, 0.99f}, red);
    // Short box.
    s.add_quad({0.53f, 0.60f, 0.75f}, {0.70f, 0.60f, 0.17f}, {0.13f, 0.60f, 0.00f}, {-0.05f, 0.60f, 0.57f}, white);
    s.add_quad({-0.05f, 0, 0.57f}, {-0.05f, 0.60f, 0.57f}, {0.13f, 0.60f, 0.00f}, {0.13f, 0, 0.00f}, white);
    s.add_quad({0.53f, 0, 0.75f}, {0.53f, 0.60f, 0.75f}, {-0.05f, 0.60f, 0.57f}, {-0.05f, 0, 0.57f}, white);
    s.add_quad({0.70f, 0, 0.17f}, {0.70f, 0.60f, 0.17f}, {0.53f, 0.60f, 0.75f}, {0.53f, 0, 0.75f}, white);
    s.add_quad({0.13f, 0, 0.00f}, {0.13f, 0.60f, 0.00f}, {0.70f, 0.60f, 0.17f}, {0.70f, 0, 0.17f}, white);
    // Tall box.
    s.add_quad({-0.53f, 1.20f, 0.09f}, {0.04f, 1.20f, -0.09f}, {-0.14f, 1.20f, -0.67f}, {-0.71f, 1.20f, -0.49f}, white);
    s.add_quad({-0.53f, 0, 0.09f}, {-0.53f, 1.20f, 0.09f}, {-0.71f, 1.20f, -0.49f}, {-0.71f, 0, -0.49f}, white);
    s.add_quad({-0.71f, 0, -0.49f}, {-0.71f, 1.20f, -0.49f}, {-0.14f, 1.20f, -0.67f}, {-0.14f, 0, -0.67f}, white);
    s.add_quad({-0.14f, 0, -0.67f}, {-0.14f, 1.20f, -0.67f}, {0.04f, 1.20f, -0.09f}, {0.04f, 0, -0.09f}, white);
    s.add_quad({0.04f, 0, -0.09f}, {0.04f, 1.20f, -0.09f}, {-0.53f, 1.20f, 0.09f}, {-0.53f, 0, 0.09f}, white);
    // Light (faces down).
    s.add_quad({-0.24f, 1.98f, 0.16f}, {-0.24f, 1.98f, -0.22f}, {0.23f, 1.98f, -0.22f}, {0.23f, 1.98f, 0.16f}, lamp);
    if (spot) {
        spot_light l;
        l.position = {0.0f, 1.97f, -0.03f};
        l.direction = {0, -1, 0};
        l.intensity = {3.04f, 2.14f, 0.71f};
        l.cone_deg = 89.f;
        l.falloff = spot_light::falloff_kind::cosine;
        s.lights.push_back(l);
    }
    return s;
}

// A small lamp (5 cm square, facing down) over 3,750 separate 1 mm triangles, 4 mm apart:
// 2,500 on a floor facing up and 1,250 on a wall facing +x, each triangle its own chart.
inline owned_scene tiny_triangles_under_a_lamp() {
    owned_scene s;
    const auto floor = s.add_material(glm::vec3(0.6f)), wall = s.add_material(glm::vec3(0.4f, 0.5f, 0.6f));
    const auto lamp = s.add_material(glm::vec3(0.f), glm::vec3(20.f));
    s.add_quad({0.10f, 0.10f, 0.10f}, {0.10f, 0.15f, 0.10f}, {0.15f, 0.15f, 0.10f}, {0.15f, 0.10f, 0.10f}, lamp);
    const auto triangle = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, std::uint32_t m) {
        const auto base = std::uint32_t(s.positions.size());
        s.positions.insert(s.positions.end(), {a, b, c});
        s.triangles.emplace_back(base, base + 1, base + 2);
        s.material_of.push_back(m);
    };
    const float mm = 0.001f, step = 0.004f;
    for (int i = 0; i < 50; ++i)
        for (int j = 0; j < 50; ++j) {
            const glm::vec3 p(step * float(i), step * float(j), 0.f);
            triangle(p, p + glm::vec3(mm, 0, 0), p + glm::vec3(0, mm, 0), floor);
        }
    for (int j = 0; j < 50; ++j)
        for (int k = 0; k < 25; ++k) {
            const glm::vec3 p(0.f, step * float(j), 0.002f + step * float(k));
            triangle(p, p + glm::vec3(0, mm, 0), p + glm::vec3(0, 0, mm), wall);
        }
    return s;
}

// The triangles from `first` on whose element (the texel their centroid's lightmap
// coordinates fall in) has no radiosity in `b` (one value per element): what a view shows black.
inline std::size_t unlit_triangles(const owned_scene& s, const lightmap_atlas& atlas, const std::vector<glm::vec3>& b,
                                   std::size_t first) {
    const glm::vec2 size(float(atlas.width), float(atlas.height));
    const auto uv = atlas.corner_uvs(s.view());
    std::size_t dark = 0;
    for (std::size_t t = first; t < s.triangles.size(); ++t) {
        const glm::vec2 p = (uv[3 * t] + uv[3 * t + 1] + uv[3 * t + 2]) / 3.f * size;
        const std::int32_t e = atlas.element_at(std::uint32_t(p.x), std::uint32_t(p.y));
        dark += e >= 0 && atlas.chart[std::size_t(e)] == atlas.chart_of_triangle[t] &&
                        b[std::size_t(e)].x + b[std::size_t(e)].y + b[std::size_t(e)].z > 0.f
                    ? 0
                    : 1;
    }
    return dark;
}

}  // namespace bounce::radiosity_test
