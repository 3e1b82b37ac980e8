#pragma once
/// \file plane_estimate.hpp
/// The CPU reduction of one rendered hemisphere plane to a record's estimate: the sums of
/// the plane_pixel_terms kernel over the plane, in double. The GL adapter's reduction sums
/// the same kernel, emitted as GLSL, on the GPU.

#include <bounce/errors.hpp>
#include <bounce/cache/gradients.hpp>
#include <bounce/cache/plane_camera.hpp>
#include <bounce/cache/plane_pixel.hpp>
#include <bounce/cache/plane_weights.hpp>

#include <cmath>
#include <cstddef>

#include <glm/glm.hpp>

namespace bounce::cpu {

/// Irradiance, rotation and translation gradients (local frame, tangent components) and
/// harmonic mean distance sum wd / sum(wd / r) from one rendered plane and a weight table:
/// the sums of plane_pixel_terms in double, irradiance and gradients times weights.scale.
/// Throws parameter_error when the views are not N x N or the table is not the camera's,
/// and on a non-finite radiance or a non-positive (or NaN) distance.
inline hemisphere_estimate estimate_plane(const plane_weights& weights, plane_view plane) {
    const std::size_t N = weights.camera.resolution;
    require(plane.radiance.width() == N && plane.radiance.height() == N && plane.distance.width() == N &&
                plane.distance.height() == N,
            "plane", "radiance and distance must be resolution x resolution");
    require(weights.irradiance.size() == N * N && weights.distance.size() == N * N && weights.rotation.size() == N * N &&
                weights.left_wall.size() == N * N && weights.up_wall.size() == N * N &&
                weights.edge_wall.size() == N * N,
            "weights", "table size does not match its camera");
    hemisphere_estimate e;
    glm::dvec3 rx(0), ry(0), tx(0), ty(0);
    double inv_distance = 0, weight = 0;
    for (std::size_t j = 0; j < N; ++j)
        for (std::size_t i = 0; i < N; ++i) {
            const glm::dvec3 L(plane.radiance(i, j));
            const double r = plane.distance(i, j);
            require(std::isfinite(L.x) && std::isfinite(L.y) && std::isfinite(L.z), "plane.radiance",
                    "non-finite radiance");
            require(r > 0.0 && !std::isnan(r), "plane.distance", "hit distance must be positive");
            const std::size_t at = j * N + i, li = i > 0 ? i - 1 : i, uj = j > 0 ? j - 1 : j;
            const auto [te, trx, tr_y, ttx, tty, tinv, tw] = plane_pixel_terms<double, glm::dvec3, glm::dvec2>(
                weights.irradiance[at], weights.distance[at], weights.rotation[at], weights.left_wall[at],
                weights.up_wall[at], weights.edge_wall[at], L, glm::dvec3(plane.radiance(li, j)),
                glm::dvec3(plane.radiance(i, uj)), r, double(plane.distance(li, j)), double(plane.distance(i, uj)));
            e.irradiance += te;
            rx += trx;
            ry += tr_y;
            tx += ttx;
            ty += tty;
            inv_distance += tinv;
            weight += tw;
        }
    const double s = weights.scale;
    e.irradiance *= s;
    for (int c = 0; c < 3; ++c) {
        e.rotation[c] = glm::dvec3(rx[c], ry[c], 0) * s;
        e.translation[c] = glm::dvec3(tx[c], ty[c], 0) * s;
    }
    if (inv_distance > 0) e.harmonic_mean_distance = weight / inv_distance;
    return e;
}

}  // namespace bounce::cpu
