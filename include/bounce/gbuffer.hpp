#pragma once
/// \file gbuffer.hpp
/// The G-buffer as a struct of views: every backend fills one, every technique reads one.

#include <bounce/image.hpp>

#include <glm/vec3.hpp>

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
