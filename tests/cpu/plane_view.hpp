#pragma once
// A camera looking down from height 4 at the plane through the origin with unit normal `n`
// (z = 0 by default), and the exact G-buffer of that plane; `hole` leaves a block of pixels
// uncovered, as a gap in the geometry would.
#include <bounce/camera.hpp>
#include <bounce/gbuffer.hpp>

#include <glm/glm.hpp>

namespace cpu_test {

struct plane_view {
    bounce::camera cam;
    bounce::gbuffer<float> gb;
    plane_view(std::size_t w, std::size_t h, glm::vec3 n = {0, 0, 1}, bool hole = false) : gb(w, h) {
        cam.position = {0.3f, -0.2f, 4.f};
        cam.look_at = {0.f, 0.f, 0.f};
        cam.up = {0, 1, 0};
        cam.fov_y_deg = 60.f;
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t x = 0; x < w; ++x) {
                if (hole && x > w / 3 && x < w / 2 && y > h / 4 && y < h / 2) continue;
                const glm::vec3 d = cam.direction(float(x) + 0.5f, float(y) + 0.5f, w, h);
                const float t = -glm::dot(cam.position, n) / glm::dot(d, n);
                if (!(t > 0.f)) continue;  // the ray misses the plane
                gb.position(x, y) = cam.position + t * d;
                gb.normal(x, y) = n;
                gb.albedo(x, y) = {0.5f, 0.25f, 1.f};
                gb.depth(x, y) = glm::dot(gb.position(x, y) - cam.position, cam.forward());
            }
    }
};

}  // namespace cpu_test
