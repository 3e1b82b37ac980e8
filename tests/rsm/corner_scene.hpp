#pragma once
// A floor (z = 0, |x|, |y| <= 1, normal +z) meeting a wall (x = 1, normal -x) seen by a
// camera, as an exact ray-cast G-buffer, and a reflective shadow map of a lit wall facing
// them (x = -1, normal +x, |y| <= 1, 0 <= z <= 2) with an uneven flux, seen by an
// orthographic projection along the wall's normal (u along +y, v down z). The floor-wall
// edge gives the blur and the upsampling a discontinuity; the image sizes are not multiples
// of the patterns.
#include <bounce/camera.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/indirect/vpl_sampling.hpp>

#include <cmath>
#include <limits>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace rsm_test {

struct corner_scene {
    bounce::camera cam;
    bounce::gbuffer<float> gb;
    bounce::image<glm::vec3> map_position, map_normal, map_flux;
    glm::mat4 light_view_projection{1.f};

    corner_scene(std::size_t w, std::size_t h, std::size_t map_size = 32, bool with_wall = true)
        : gb(w, h),
          map_position(map_size, map_size),
          map_normal(map_size, map_size, glm::vec3(1, 0, 0)),
          map_flux(map_size, map_size) {
        cam.position = {-0.6f, -2.6f, 2.2f};
        cam.look_at = {0.2f, 0.1f, 0.4f};
        cam.up = {0, 0, 1};
        cam.fov_y_deg = 50.f;
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t x = 0; x < w; ++x) {
                const glm::vec3 d = cam.direction(float(x) + 0.5f, float(y) + 0.5f, w, h);
                float best = std::numeric_limits<float>::infinity();
                glm::vec3 n(0.f);
                // Floor.
                if (d.z < 0.f) {
                    const float t = -cam.position.z / d.z;
                    const glm::vec3 p = cam.position + t * d;
                    if (std::abs(p.x) <= 1.f && std::abs(p.y) <= 1.f && t < best) best = t, n = {0, 0, 1};
                }
                if (with_wall && d.x > 0.f) {
                    const float t = (1.f - cam.position.x) / d.x;
                    const glm::vec3 p = cam.position + t * d;
                    if (std::abs(p.y) <= 1.f && p.z >= 0.f && p.z <= 2.f && t < best) best = t, n = {-1, 0, 0};
                }
                if (!(best < std::numeric_limits<float>::infinity())) continue;
                gb.position(x, y) = cam.position + best * d;
                gb.normal(x, y) = n;
                gb.albedo(x, y) = {0.7f, 0.7f, 0.7f};
                gb.depth(x, y) = glm::dot(gb.position(x, y) - cam.position, cam.forward());
            }
        const float texel = 2.f / float(map_size);
        for (std::size_t j = 0; j < map_size; ++j)
            for (std::size_t i = 0; i < map_size; ++i) {
                // Row 0 at the top: z from 2 down to 0; column i: y from -1 to 1.
                const float yy = -1.f + (float(i) + 0.5f) * texel, zz = 2.f - (float(j) + 0.5f) * texel;
                map_position(i, j) = {-1.f, yy, zz};
                const float f = (0.6f + 0.4f * std::sin(3.f * yy) * std::cos(2.f * zz)) * texel * texel;
                map_flux(i, j) = glm::vec3(f, 0.8f * f, 0.5f * f);
            }
        const glm::mat4 view = glm::lookAt(glm::vec3(3, 0, 1), glm::vec3(0, 0, 1), glm::vec3(0, 0, 1));
        light_view_projection = glm::ortho(-1.f, 1.f, -1.f, 1.f, 0.1f, 10.f) * view;
    }

    bounce::rsm_view map() const {
        return {map_position.view(), map_normal.view(), map_flux.view(), light_view_projection};
    }
};

}  // namespace rsm_test
