// The renderer's own scene for the recipes of docs/embedding.md: a closed room (walls facing
// inwards, a red and a green wall), a free-standing partition (a panel with a face on each
// side), one point light, and a camera. Plain arrays behind a bounce::scene_view: no scene
// file, nothing of bounce::io.
#pragma once

#include <bounce/camera.hpp>
#include <bounce/image.hpp>
#include <bounce/light.hpp>
#include <bounce/scene_view.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <glm/geometric.hpp>

struct room {
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::uvec3> triangles;
    std::vector<std::uint32_t> material_of;
    std::vector<bounce::material> materials{{glm::vec3(0.7f), glm::vec3(0.f)},
                                            {{0.7f, 0.1f, 0.1f}, glm::vec3(0.f)},
                                            {{0.1f, 0.6f, 0.1f}, glm::vec3(0.f)}};
    std::vector<bounce::light> lights{bounce::point_light{{0.5f, 2.2f, 0.5f}, glm::vec3(3.f)}};
    bounce::camera camera;

    room() {
        // Corners counter-clockwise seen from the side the quad faces (the room's inside).
        const auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t m) {
            const auto base = std::uint32_t(positions.size());
            const glm::vec3 n = glm::normalize(glm::cross(b - a, d - a));
            for (const glm::vec3 v : {a, b, c, d}) {
                positions.push_back(v);
                normals.push_back(n);
            }
            triangles.insert(triangles.end(), {{base, base + 1, base + 2}, {base, base + 2, base + 3}});
            material_of.insert(material_of.end(), {m, m});
        };
        const float s = 2.f, h = 2.5f;
        quad({-s, 0, -s}, {-s, 0, s}, {s, 0, s}, {s, 0, -s}, 0);  // floor
        quad({-s, h, -s}, {s, h, -s}, {s, h, s}, {-s, h, s}, 0);  // ceiling
        quad({-s, 0, -s}, {s, 0, -s}, {s, h, -s}, {-s, h, -s}, 0);  // back
        quad({-s, 0, s}, {-s, h, s}, {s, h, s}, {s, 0, s}, 0);    // front
        quad({-s, 0, -s}, {-s, h, -s}, {-s, h, s}, {-s, 0, s}, 1);  // left, red
        quad({s, 0, -s}, {s, 0, s}, {s, h, s}, {s, h, -s}, 2);    // right, green
        // The partition: a 1.6 x 1.5 panel 2 cm thick at x = -0.5, one face towards each side.
        quad({-0.5f, 0, -0.8f}, {-0.5f, 0, 0.8f}, {-0.5f, 1.5f, 0.8f}, {-0.5f, 1.5f, -0.8f}, 0);
        quad({-0.48f, 0, -0.8f}, {-0.48f, 1.5f, -0.8f}, {-0.48f, 1.5f, 0.8f}, {-0.48f, 0, 0.8f}, 0);
        camera.position = {0.f, 1.2f, 1.9f};
        camera.look_at = {0.f, 0.9f, 0.f};
        camera.fov_y_deg = 60.f;
    }

    bounce::scene_view view() const { return {positions, normals, triangles, material_of, materials, lights, false}; }
};

/// Sum of every channel of every pixel.
inline double total(const bounce::image<glm::vec3>& img) {
    double sum = 0;
    for (std::size_t i = 0; i < img.width() * img.height(); ++i) sum += double(img.data()[i].x + img.data()[i].y + img.data()[i].z);
    return sum;
}

/// Exit status of a recipe: 0 when `value` (a sum of the output) is finite and positive.
inline int report(const char* what, double value) {
    std::printf("%s: %g\n", what, value);
    return std::isfinite(value) && value > 0 ? 0 : 1;
}
