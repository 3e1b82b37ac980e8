#pragma once
/// \file gbuffer.hpp
/// The G-buffer as a struct of views: every backend fills one, every technique reads one.

#include <bounce/image.hpp>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <cmath>
#include <limits>

namespace bounce {

/// Per-pixel surface attributes of the first visible surface, in world space.
/// A pixel that sees no geometry has `depth` = +infinity (and unspecified attributes).
template <class T = float>
struct gbuffer_view {
    image_view<glm::vec<3, T>> position;  ///< world-space hit point
    image_view<glm::vec<3, T>> normal;    ///< unit shading normal, facing the camera
    image_view<glm::vec<3, T>> albedo;    ///< diffuse reflectance rho_d in [0,1]^3
    image_view<T> depth;                  ///< distance from the eye along the view axis

    std::size_t width() const noexcept { return depth.width(); }
    std::size_t height() const noexcept { return depth.height(); }
    bool covered(std::size_t x, std::size_t y) const noexcept {
        return depth(x, y) < std::numeric_limits<T>::infinity();
    }
};

/// Whether two G-buffers of one size see the same surface at (x, y): both covered, their
/// points within 1e-4 `scale` (the scene's size) of each other and their normals within
/// 2.6 degrees (dot >= 0.999). A raster and a ray-cast G-buffer differ at silhouettes, where
/// they see different surfaces and their images are not comparable.
template <class T>
bool same_surface(const gbuffer_view<T>& a, const gbuffer_view<T>& b, std::size_t x, std::size_t y, T scale) {
    return std::isfinite(a.depth(x, y)) && std::isfinite(b.depth(x, y)) &&
           glm::length(a.position(x, y) - b.position(x, y)) <= T(1e-4) * scale &&
           glm::dot(a.normal(x, y), b.normal(x, y)) >= T(0.999);
}

/// Owning storage behind a `gbuffer_view`.
template <class T = float>
struct gbuffer {
    image<glm::vec<3, T>> position, normal, albedo;
    image<T> depth;

    gbuffer() = default;
    gbuffer(std::size_t width, std::size_t height)
        : position(width, height), normal(width, height), albedo(width, height),
          depth(width, height, std::numeric_limits<T>::infinity()) {}

    gbuffer_view<T> view() noexcept { return {position.view(), normal.view(), albedo.view(), depth.view()}; }
    std::size_t width() const noexcept { return depth.width(); }
    std::size_t height() const noexcept { return depth.height(); }
};

}  // namespace bounce
