#pragma once
/// \file rectangle_solid_angle.hpp
/// Exact integrals over a rectangle [u0, u1] x [v0, v1] on a plane at unit distance along
/// its normal w (d = sqrt(1 + u^2 + v^2), direction omega = (u, v, 1) / d,
/// d omega = du dv / d^3): its solid angle and the first moment int omega d omega, whose
/// normal component is the cosine-weighted solid angle. Each is a corner function F with
/// int = F(u1, v1) - F(u0, v1) - F(u1, v0) + F(u0, v0):
///  - solid angle:      F = atan(u v / d)                                     (Eq. H1)
///  - int omega_w dw:   F = (u/cu atan(v/cu) + v/cv atan(u/cv)) / 2            (Eq. H2)
///  - int omega_u dw:   F = -atan(v/cu) / (2 cu)                               (Eq. H3)
///  - int omega_v dw:   F = -atan(u/cv) / (2 cv),   cu = sqrt(1+u^2), cv = sqrt(1+v^2)
/// (each checked by differentiating: d2F/du dv is the integrand). H2 is the cosine-weighted
/// solid angle (the differential-area-to-parallel-rectangle form factor times pi), H3 the
/// in-plane moments a rotation gradient needs. Derivations: docs/hemisphere-sampling.md.
/// Kernels: instantiated on the CPU and emitted as GLSL.

#include <bounce/concepts.hpp>
#include <bounce/vocabulary.hpp>

namespace bounce {

/// Corner function of the solid angle of a rectangle on the plane at unit distance
/// (Eq. H1): atan(u v / sqrt(1 + u^2 + v^2)). Dimensionless (u, v in units of the distance).
template <real T>
T rectangle_solid_angle_corner(T u, T v) {
    return atan(u * v, sqrt(T(1) + u * u + v * v));
}

/// Solid angle (sr) subtended at the origin by the rectangle [u0, u1] x [v0, v1] on the
/// plane at unit distance (corner differences of Eq. H1; exact, unlike the midpoint rule
/// cos^3 du dv). Requires u0 <= u1, v0 <= v1.
template <real T>
T rectangle_solid_angle(T u0, T v0, T u1, T v1) {
    return rectangle_solid_angle_corner<T>(u1, v1) - rectangle_solid_angle_corner<T>(u0, v1) -
           rectangle_solid_angle_corner<T>(u1, v0) + rectangle_solid_angle_corner<T>(u0, v0);
}

/// atan(y / x) for y >= 0, x > 0, as the series t - t^3/3 + ... - t^11/11 below t = 1/8
/// (truncation under 1e-12 relative) and atan(y, x) above: the Vulkan environment allows a
/// GPU's atan 4096 ulps, where a cube map's texels need a few.
template <real T>
T small_angle_atan(T y, T x) {
    const T t = y / x, t2 = t * t;
    const T series = t * (T(1) + t2 * (T(-1.0 / 3) + t2 * (T(0.2) + t2 * (T(-1.0 / 7) + t2 * (T(1.0 / 9) + t2 * T(-1.0 / 11))))));
    return select(t < T(0.125), series, atan(y, x));
}

/// The same solid angle as `rectangle_solid_angle`, as its two spherical triangles
/// (corners a, b, c of one and a, c, d of the other on the plane z = 1), each by Van Oosterom
/// and Strackee's formula (1983): tan(Omega / 2) = a . (b x c) / (|a||b||c| + (a.b)|c| +
/// (a.c)|b| + (b.c)|a|). The triple product is (u1 - u0)(v1 - v0) for both and every term
/// of the denominators is positive, so no digits cancel: in float a small rectangle (a cube
/// map's texel) keeps a few ulps, where the corner differences lose the most significant
/// digits of the corner angles (tests/vk: over 1e-2 relative at 4096 texels a side). The
/// cube-map SH projection on the GPU (vk::sh_projector) takes its texel solid angles from it.
template <real T, vec3_of<T> V>
T rectangle_solid_angle_triangles(T u0, T v0, T u1, T v1) {
    const V a(u0, v0, T(1)), b(u1, v0, T(1)), c(u1, v1, T(1)), d(u0, v1, T(1));
    const T la = length(a), lb = length(b), lc = length(c), ld = length(d);
    const T area = (u1 - u0) * (v1 - v0);
    const T abc = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
    const T acd = la * lc * ld + dot(a, c) * ld + dot(a, d) * lc + dot(c, d) * la;
    return T(2) * (small_angle_atan<T>(area, abc) + small_angle_atan<T>(area, acd));
}

/// Corner function of the first moment int omega d omega of a rectangle on the plane at
/// unit distance (Eqs. H2, H3), as (u component, v component, normal component).
template <real T, vec3_of<T> V>
V rectangle_moment_corner(T u, T v) {
    const T cu = sqrt(T(1) + u * u), cv = sqrt(T(1) + v * v);
    const T au = atan(v, cu), av = atan(u, cv);  // atan(v / cu), atan(u / cv): cu, cv > 0
    return V(-au / (T(2) * cu), -av / (T(2) * cv), (u / cu * au + v / cv * av) / T(2));
}

/// The first moment int omega d omega over the rectangle [u0, u1] x [v0, v1] on the plane at
/// unit distance, in the plane's frame: (int omega_u, int omega_v, int omega_w) in sr. Its
/// normal component is the rectangle's cosine-weighted solid angle int cos(theta) d omega
/// (pi times the form factor from a differential area facing the plane); the in-plane
/// components give the rotation gradient's weights. Requires u0 <= u1, v0 <= v1.
template <real T, vec3_of<T> V>
V rectangle_moment(T u0, T v0, T u1, T v1) {
    return rectangle_moment_corner<T, V>(u1, v1) - rectangle_moment_corner<T, V>(u0, v1) -
           rectangle_moment_corner<T, V>(u1, v0) + rectangle_moment_corner<T, V>(u0, v0);
}

/// Cosine-weighted solid angle (sr) of the rectangle [u0, u1] x [v0, v1] on the plane at
/// unit distance: int cos(theta) d omega, theta measured from the plane's normal (Eq. H2).
template <real T, vec3_of<T> V>
T rectangle_cosine_solid_angle(T u0, T v0, T u1, T v1) {
    return rectangle_moment<T, V>(u0, v0, u1, v1).z;
}

}  // namespace bounce
