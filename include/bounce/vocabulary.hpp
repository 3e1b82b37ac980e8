#pragma once
/// \file vocabulary.hpp
/// The kernel vocabulary for plain numbers and GLM vectors.
///
/// Kernels call `sqrt`, `inversesqrt`, `min`, `max`, `clamp`, `mix`, `abs`, `select`,
/// `dot`, `cross`, `length`, `normalize` unqualified. Inside namespace `bounce` ordinary
/// lookup finds the scalar overloads below; argument-dependent lookup adds GLM's
/// functions for GLM vectors and `bounce::glsl`'s for expression types. The names and
/// meanings are GLSL's, so a kernel reads like the shader it prints.

#include <bounce/concepts.hpp>

#include <cmath>
#include <glm/geometric.hpp>
#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce {

template <floating T> constexpr T sqrt(T x) noexcept { return std::sqrt(x); }
/// GLSL `inversesqrt`: 1 / sqrt(x).
template <floating T> constexpr T inversesqrt(T x) noexcept { return T(1) / std::sqrt(x); }
template <floating T> constexpr T abs(T x) noexcept { return std::fabs(x); }
template <floating T> constexpr T min(T a, T b) noexcept { return b < a ? b : a; }
template <floating T> constexpr T max(T a, T b) noexcept { return a < b ? b : a; }
/// GLSL `clamp`: min(max(x, lo), hi).
template <floating T> constexpr T clamp(T x, T lo, T hi) noexcept { return min(max(x, lo), hi); }
/// GLSL `mix`: a * (1 - t) + b * t.
template <floating T> constexpr T mix(T a, T b, T t) noexcept { return a * (T(1) - t) + b * t; }
template <floating T> T exp(T x) noexcept { return std::exp(x); }
template <floating T> T log(T x) noexcept { return std::log(x); }
template <floating T> T pow(T x, T y) noexcept { return std::pow(x, y); }
template <floating T> T sin(T x) noexcept { return std::sin(x); }
template <floating T> T cos(T x) noexcept { return std::cos(x); }
template <floating T> T atan(T y, T x) noexcept { return std::atan2(y, x); }
/// GLSL `floor`: the largest integer not above x (index arithmetic of interleave maps).
template <floating T> T floor(T x) noexcept { return std::floor(x); }

/// `select(c, a, b)`: `a` where `c` holds, else `b`, with no data-dependent branch in the
/// generated code (GLSL prints it as a ternary). For plain booleans it is the obvious
/// conditional; both operands have already been evaluated by the caller.
template <class T>
    requires(!std::same_as<T, bool>)
constexpr T select(std::same_as<bool> auto c, const T& a, const T& b) noexcept {
    return c ? a : b;
}

/// Scalar `dot` so that kernels generic over the dimension also accept plain numbers.
template <floating T> constexpr T dot(T a, T b) noexcept { return a * b; }

}  // namespace bounce
