#pragma once
/// \file camera.hpp
/// The pinhole camera every backend shares, so that a raster G-buffer and a ray-cast
/// G-buffer see the same pixels.
///
/// Conventions: right-handed world; the camera looks along `forward`; pixel (x, y) has
/// row 0 at the top of the image; the centre of pixel (x, y) is at
/// ndc = (2 (x + 0.5) / W - 1, 1 - 2 (y + 0.5) / H). Depth is the distance along `forward`
/// (view-space -z), not the distance to the eye.

#include <bounce/errors.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace bounce {

struct camera {
    glm::vec3 position{0, 0, 1};  ///< eye, world units
    glm::vec3 look_at{0, 0, 0};   ///< a point on the view axis
    glm::vec3 up{0, 1, 0};        ///< approximate up; need not be orthogonal to the view axis
    float fov_y_deg = 45.f;       ///< vertical field of view in degrees, in (0, 180); typical: 40-60
    float near_plane = 0.01f;     ///< near clipping distance for raster backends (world units)
    float far_plane = 1000.f;     ///< far clipping distance for raster backends

    /// Throws `parameter_error` when the camera cannot form an image.
    void validate() const {
        require(std::isfinite(fov_y_deg) && fov_y_deg > 0.f && fov_y_deg < 180.f, "fov_y_deg",
                "must lie in (0, 180)");
        const auto bounded = [](glm::vec3 v) {
            return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::abs(v.x) <= 1e18f &&
                   std::abs(v.y) <= 1e18f && std::abs(v.z) <= 1e18f;
        };
        // 1e18: max_world_coordinate (light.hpp), what float32 rays carry.
        require(bounded(position), "camera.position", "must be finite with coordinates within +-1e18");
        require(bounded(look_at), "camera.look_at", "must be finite with coordinates within +-1e18");
        require(glm::length(look_at - position) > 0.f, "look_at", "coincides with the camera position");
        require(glm::length(glm::cross(look_at - position, up)) > 0.f, "up", "parallel to the view axis");
        require(near_plane > 0.f && far_plane > near_plane, "near_plane/far_plane", "need 0 < near < far");
    }

    glm::vec3 forward() const { return glm::normalize(look_at - position); }
    glm::vec3 right() const { return glm::normalize(glm::cross(forward(), up)); }
    glm::vec3 true_up() const { return glm::cross(right(), forward()); }
    /// tan(fov_y / 2).
    float tan_half_fov() const { return std::tan(glm::radians(fov_y_deg) * 0.5f); }

    /// World-space direction (not normalized; its component along `forward` is 1) through
    /// the image point (px, py) in pixel units, for an image of `width` x `height`.
    glm::vec3 direction(float px, float py, std::size_t width, std::size_t height) const {
        const float t = tan_half_fov(), aspect = float(width) / float(height);
        const float sx = (2.f * px / float(width) - 1.f) * t * aspect;
        const float sy = (1.f - 2.f * py / float(height)) * t;
        return forward() + sx * right() + sy * true_up();
    }

    /// World size of one pixel at distance `depth` along the view axis, for an image
    /// `height` pixels tall (the footprint used to clamp record radii in pixels).
    float pixel_footprint(float depth, std::size_t height) const {
        return 2.f * depth * tan_half_fov() / float(height);
    }

    glm::mat4 view_matrix() const { return glm::lookAt(position, look_at, up); }
    /// OpenGL projection (clip z in [-1, 1]).
    glm::mat4 projection_matrix(std::size_t width, std::size_t height) const {
        return glm::perspective(glm::radians(fov_y_deg), float(width) / float(height), near_plane, far_plane);
    }
};

/// Sets the camera's far plane to twice the distance from the eye to the farthest corner of
/// `bounds` and the near plane to 1e-4 of that, so that a raster depth buffer keeps its
/// precision for the scene at hand whatever its units. Keeps the camera's planes where the
/// scene's scale leaves float's normal range.
inline void fit_clip_planes(camera& cam, const std::pair<glm::vec3, glm::vec3>& bounds) {
    float farthest = 0.f;
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 corner((i & 1) ? bounds.second.x : bounds.first.x, (i & 2) ? bounds.second.y : bounds.first.y,
                               (i & 4) ? bounds.second.z : bounds.first.z);
        farthest = std::max(farthest, glm::length(corner - cam.position));
    }
    const float far_plane = 2.f * farthest, near_plane = 1e-4f * far_plane;
    if (!std::isfinite(far_plane) || !(near_plane >= std::numeric_limits<float>::min())) return;
    cam.far_plane = far_plane;
    cam.near_plane = near_plane;
}

}  // namespace bounce
