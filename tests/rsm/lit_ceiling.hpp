// A lit ceiling for the SII tests with rays (test_view_selection, test_visibility_edges): an
// RSM of 16 x 16 texels at y = 1 over [-1, 1]^2, facing down, its flux rising along x.
#pragma once

#include <bounce/image.hpp>

#include <glm/vec3.hpp>

namespace bounce::test {

struct lit_ceiling {
    image<glm::vec3> position{16, 16}, normal{16, 16}, flux{16, 16};

    lit_ceiling() {
        for (std::size_t y = 0; y < 16; ++y)
            for (std::size_t x = 0; x < 16; ++x) {
                const float u = (float(x) + 0.5f) / 8.f - 1.f, v = (float(y) + 0.5f) / 8.f - 1.f;
                position(x, y) = {u, 1.f, v};
                normal(x, y) = {0.f, -1.f, 0.f};
                flux(x, y) = glm::vec3(0.01f * (1.5f + u), 0.01f, 0.005f);
            }
    }
};

}  // namespace bounce::test
