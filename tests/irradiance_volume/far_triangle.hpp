#pragma once
// A scene of one triangle far outside the volumes of the irradiance-volume tests: one the
// build accepts (it needs triangles) whose geometry touches no cell.
#include "../owned_scene.hpp"

namespace bounce::test {

inline owned_scene far_triangle() {
    owned_scene s;
    s.positions = {{100, 100, 100}, {101, 100, 100}, {100, 101, 100}};
    s.triangles = {{0, 1, 2}};
    s.material_of = {0};
    s.materials = {material{glm::vec3(0.5f), glm::vec3(0.f)}};
    return s;
}

}  // namespace bounce::test
