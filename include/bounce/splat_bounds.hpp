#pragma once
/// \file splat_bounds.hpp
/// The screen-space bounding box of a record's sphere of influence under a perspective
/// camera (Gautron 2008, section 8.1: "determine the bounding box of I_k on the image plane").
///
/// Exact and conservative, including spheres that cross the near plane or contain the eye
/// (where Gautron 2008's box of the sphere's silhouette square is wrong). Per axis, the sphere
/// projects onto the plane spanned by that axis and the view axis as a disc; the slopes
/// (lateral / depth) of the part of the disc in front of the near plane form an interval
/// whose ends are either tangent points of lines through the eye or the ends of the chord
/// cut by the near plane (the set is convex and the slope's level sets are lines through
/// the eye, so no other point can be extreme). Cf. Mara and McGuire 2013.
///
/// On the host, sphere_pixel_rect rounds that box to the pixels a splat visits: the records
/// of irradiance splatting (cpu/splatting.hpp) and the VPLs of splatting indirect
/// illumination (indirect/rsm_sampling.hpp) both take their rectangles from it.

#include <bounce/camera.hpp>
#include <bounce/vocabulary.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include <glm/glm.hpp>

namespace bounce {

/// Interval [lo, hi] of slopes a/d over the disc centred at (a, d) with radius r, restricted
/// to depth d >= near_depth > 0 (d is the distance along the view axis). Returns lo > hi
/// (both 2e30 apart) when nothing of the disc lies in front of the near plane.
template <real T>
std::array<T, 2> disc_slope_interval(T a, T d, T r, T near_depth) {
    const T big = T(1e30);
    const T c2 = a * a + d * d;
    const T t2 = c2 - r * r;  // squared length of the tangents from the eye
    const auto eye_outside = t2 > T(0);
    const T t = sqrt(max(t2, T(0)));
    const T inv_c2 = T(1) / max(c2, T(1e-30));
    // Tangent points: the centre turned by +-alpha (sin alpha = r/|c|) and scaled to length t.
    const T pa = t * (a * t - d * r) * inv_c2, pd = t * (a * r + d * t) * inv_c2;
    const T ma = t * (a * t + d * r) * inv_c2, md = t * (d * t - a * r) * inv_c2;
    const auto p_ok = eye_outside && pd >= near_depth;
    const auto m_ok = eye_outside && md >= near_depth;
    const T ps = pa / select(p_ok, pd, T(1)), ms = ma / select(m_ok, md, T(1));
    // Chord cut by the near plane.
    const T dn = near_depth - d;
    const T h2 = r * r - dn * dn;
    const auto crosses = h2 >= T(0);
    const T h = sqrt(max(h2, T(0)));
    const T c_lo = (a - h) / near_depth, c_hi = (a + h) / near_depth;

    const T lo = min(min(select(p_ok, ps, big), select(m_ok, ms, big)), select(crosses, c_lo, big));
    const T hi = max(max(select(p_ok, ps, -big), select(m_ok, ms, -big)), select(crosses, c_hi, -big));
    return {lo, hi};
}

/// Normalized-device-coordinate box {x_min, y_min, x_max, y_max} (y up, [-1, 1] is the
/// screen) of the sphere with view-space centre `c` (the camera looks down -z) and radius
/// r, for a camera with tan(fov_y / 2) = tan_half_fov_y and the given aspect (width /
/// height), clipped by the near plane at distance near_depth. An invisible sphere gets the
/// zero-area box at x = y = 2, off screen, so a rasterized quad built from it covers nothing.
template <real T, vec3_of<T> V>
std::array<T, 4> sphere_ndc_bounds(const V& c, T r, T near_depth, T tan_half_fov_y, T aspect) {
    const T d = -c.z;
    const auto x = disc_slope_interval<T>(c.x, d, r, near_depth);
    const auto y = disc_slope_interval<T>(c.y, d, r, near_depth);
    const auto visible = x[0] <= x[1];
    const T sx = T(1) / (tan_half_fov_y * aspect), sy = T(1) / tan_half_fov_y;
    return {select(visible, x[0] * sx, T(2)), select(visible, y[0] * sy, T(2)),
            select(visible, x[1] * sx, T(2)), select(visible, y[1] * sy, T(2))};
}

/// Inclusive pixel rectangle, rows counted from the top; empty when x0 > x1 or y0 > y1.
struct pixel_rect {
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
    bool empty() const noexcept { return x0 > x1 || y0 > y1; }
};

/// Pixels of a width x height image (seen by `cam`, `view` its view matrix) whose centres
/// the sphere (`centre`, `radius`) can cover: sphere_ndc_bounds clipped to the image. The
/// box is widened by 1/8 pixel so that no pixel is lost to rounding: a point inside the
/// sphere lies on its pixel's centre ray up to float rounding of its position, some 1e-6 of
/// its distance, and the box's corners are exact to a few ulps; 1/8 pixel is far above both.
/// (A wider margin costs: a sphere a few pixels across would visit twice the pixels.)
inline pixel_rect sphere_pixel_rect(const camera& cam, const glm::mat4& view, const glm::vec3& centre, float radius,
                                    std::size_t width, std::size_t height) {
    const glm::vec3 c = glm::vec3(view * glm::vec4(centre, 1.f));
    const auto b =
        sphere_ndc_bounds<float, glm::vec3>(c, radius, cam.near_plane, cam.tan_half_fov(), float(width) / float(height));
    if (!(b[0] <= b[2]) || b[0] >= 2.f) return {};
    // Pixel x covers ndc [2x/W - 1, 2(x+1)/W - 1]; row 0 is the top (ndc y = +1).
    auto px = [&](float ndc) { return double(ndc + 1.f) * 0.5 * double(width); };
    auto py = [&](float ndc) { return double(1.f - ndc) * 0.5 * double(height); };
    constexpr double m = 0.125;  // margin, pixels
    pixel_rect r;
    r.x0 = int(std::max(0.0, std::ceil(px(b[0]) - 0.5 - m)));
    r.x1 = int(std::min(double(width) - 1, std::floor(px(b[2]) - 0.5 + m)));
    r.y0 = int(std::max(0.0, std::ceil(py(b[3]) - 0.5 - m)));
    r.y1 = int(std::min(double(height) - 1, std::floor(py(b[1]) - 0.5 + m)));
    return r;
}

}  // namespace bounce
