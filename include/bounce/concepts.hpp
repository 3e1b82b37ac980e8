#pragma once
/// \file concepts.hpp
/// The number and vector types a kernel accepts.
///
/// A kernel in bounce is a function template written once and instantiated twice:
/// with plain numbers / GLM vectors on the CPU, and with the expression types of
/// `bounce::glsl` to print GLSL. These concepts state what a kernel may ask of its
/// types, so that both instantiations type-check against the same contract.

#include <concepts>
#include <type_traits>

namespace bounce {

/// A plain floating-point number (float, double, long double).
template <class T>
concept floating = std::is_floating_point_v<T>;

/// A scalar a kernel can compute with: closed under + - * /, constructible from a
/// double literal (`T(0.5)`), and comparable (the comparison result may be a symbolic
/// boolean, so only its existence is required).
template <class T>
concept real = std::copy_constructible<T> && std::constructible_from<T, double> &&
    requires(T a, T b) {
        { a + b } -> std::convertible_to<T>;
        { a - b } -> std::convertible_to<T>;
        { a * b } -> std::convertible_to<T>;
        { a / b } -> std::convertible_to<T>;
        { -a } -> std::convertible_to<T>;
        a < b;
        a > b;
    };

/// A three-component vector over scalar `T`: component access by `.x .y .z`,
/// arithmetic with itself and with `T`, and the GLSL geometric functions found by
/// argument-dependent lookup (GLM for GLM vectors, `bounce::glsl` for expressions).
template <class V, class T>
concept vec3_of = real<T> && std::copy_constructible<V> && requires(V a, V b, T s) {
    { a.x } -> std::convertible_to<T>;
    { a.y } -> std::convertible_to<T>;
    { a.z } -> std::convertible_to<T>;
    { a + b } -> std::convertible_to<V>;
    { a - b } -> std::convertible_to<V>;
    { a * s } -> std::convertible_to<V>;
    { s * a } -> std::convertible_to<V>;
    { a / s } -> std::convertible_to<V>;
    { dot(a, b) } -> std::convertible_to<T>;
    { cross(a, b) } -> std::convertible_to<V>;
    { length(a) } -> std::convertible_to<T>;
    { normalize(a) } -> std::convertible_to<V>;
};

/// A two-component vector over scalar `T`.
template <class V, class T>
concept vec2_of = real<T> && std::copy_constructible<V> && requires(V a, V b, T s) {
    { a.x } -> std::convertible_to<T>;
    { a.y } -> std::convertible_to<T>;
    { a + b } -> std::convertible_to<V>;
    { a - b } -> std::convertible_to<V>;
    { a * s } -> std::convertible_to<V>;
    { dot(a, b) } -> std::convertible_to<T>;
};

}  // namespace bounce
