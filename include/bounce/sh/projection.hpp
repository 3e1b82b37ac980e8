#pragma once
/// \file sh/projection.hpp
/// SH coefficients c_i = int f(w) Y_i(w) dw of a spherical function given as a cube map, a
/// latitude-longitude map or a set of samples (Monte Carlo, regularized least squares).
/// Convention: sh/basis.hpp. These are the reference implementations, one map at a time in
/// double; cpu/sh_projection.hpp projects many cube maps at once with precomputed tables.
///
/// Cube maps follow OpenGL's layout (GL 4.6 specification, Table 8.19): faces +x -x +y -y
/// +z -z in that order; texel (x, y) of a size x size face (row y as uploaded, row 0 first)
/// has face coordinates u = 2 (x + 1/2) / size - 1 (GL's s_c / |m_a|) and
/// v = 2 (y + 1/2) / size - 1 (t_c / |m_a|), and looks along
///   +x: (1, -v, -u)   -x: (-1, -v, u)   +y: (u, 1, v)   -y: (u, -1, -v)
///   +z: (u, -v, 1)    -z: (-u, -v, -1).

#include <bounce/errors.hpp>
#include <bounce/image.hpp>
#include <bounce/sh/basis.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline sh {

/// The six faces of a cube map, in OpenGL's order (GL_TEXTURE_CUBE_MAP_POSITIVE_X + i).
enum class cube_face : int { positive_x = 0, negative_x, positive_y, negative_y, positive_z, negative_z };

/// Six square faces of one size, each a view (see the file comment for the orientation).
/// `P` is the pixel type: float, double, glm::vec3, glm::dvec3 (RGB), const or not.
template <class P>
struct cube_map_view {
    std::array<image_view<P>, 6> faces;

    std::size_t size() const noexcept { return faces[0].width(); }
    const image_view<P>& face(cube_face f) const noexcept { return faces[std::size_t(f)]; }
};

/// Throws parameter_error naming `name` unless the six faces are square, non-empty and of
/// one size.
template <class P>
void require_cube_map(const cube_map_view<P>& cube, const char* name) {
    const std::size_t n = cube.size();
    require(n > 0, name, "cube-map faces are empty");
    for (const auto& f : cube.faces)
        require(f.width() == n && f.height() == n, name, "cube-map faces must be square and of one size");
}

/// The (unnormalized) direction of face coordinates (u, v) in [-1, 1]^2 on face `f`.
constexpr glm::dvec3 cube_face_direction(cube_face f, double u, double v) noexcept {
    switch (f) {
        case cube_face::positive_x: return {1, -v, -u};
        case cube_face::negative_x: return {-1, -v, u};
        case cube_face::positive_y: return {u, 1, v};
        case cube_face::negative_y: return {u, -1, -v};
        case cube_face::positive_z: return {u, -v, 1};
        case cube_face::negative_z: return {-u, -v, -1};
    }
    return {0, 0, 0};
}

/// The unit direction through the centre of texel (x, y) of face `f` of a size x size map.
inline glm::dvec3 cube_texel_direction(cube_face f, std::size_t size, std::size_t x, std::size_t y) {
    const double u = 2 * (double(x) + 0.5) / double(size) - 1, v = 2 * (double(y) + 0.5) / double(size) - 1;
    return glm::normalize(cube_face_direction(f, u, v));
}

/// Solid angle (sr) of the face rectangle [-1, u] x [-1, v] measured from its corner at the
/// face centre: dw = du dv / (1 + u^2 + v^2)^(3/2) integrates to atan(u v / sqrt(1 + u^2 + v^2))
/// over [0, u] x [0, v] (the exact texel solid angle used by e.g. Filament's libs/ibl).
inline double cube_corner_solid_angle(double u, double v) noexcept {
    return std::atan2(u * v, std::sqrt(1 + u * u + v * v));
}

/// Exact solid angle (sr) of texel (x, y) of any face of a size x size cube map (the same
/// on every face): the inclusion-exclusion of `cube_corner_solid_angle` at its four corners.
/// Over a face these sum to 2 pi / 3, over the cube to 4 pi (tests/sh).
inline double cube_texel_solid_angle(std::size_t size, std::size_t x, std::size_t y) noexcept {
    const double s = double(size);
    const double u0 = 2 * double(x) / s - 1, u1 = 2 * double(x + 1) / s - 1;
    const double v0 = 2 * double(y) / s - 1, v1 = 2 * double(y + 1) / s - 1;
    return cube_corner_solid_angle(u1, v1) - cube_corner_solid_angle(u0, v1) - cube_corner_solid_angle(u1, v0) +
           cube_corner_solid_angle(u0, v0);
}

}  // namespace bounce::sh

namespace bounce::detail {

/// The double accumulator of a pixel type: double for scalars, glm::dvec3 for RGB.
template <class P>
struct sh_accumulator {
    using type = double;
};
template <class T, glm::qualifier Q>
struct sh_accumulator<glm::vec<3, T, Q>> {
    using type = glm::dvec3;
};

template <class A>
bool finite_value(const A& v) {
    if constexpr (std::is_floating_point_v<A>) return std::isfinite(v);
    else return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace bounce::detail

namespace bounce::inline sh {

/// The double-precision coefficient type of pixels of type `P`.
template <class P>
using sh_accumulator_t = typename detail::sh_accumulator<std::remove_const_t<P>>::type;

/// SH projection of a cube map: c_i = sum over texels of f(texel) Y_i(texel centre) dw_texel,
/// with the exact texel solid angle dw_texel (a constant map gives c_00 = f sqrt(4 pi) to
/// rounding). Midpoint quadrature: the error of the other coefficients is that of sampling
/// f Y_i at texel centres, O(1/size^2) for smooth f. Throws parameter_error on an
/// ill-formed cube.
template <int L, class P>
sh_coefficients<L, sh_accumulator_t<P>> sh_project_cube_map(const cube_map_view<P>& cube) {
    using A = sh_accumulator_t<P>;
    require_cube_map(cube, "cube");
    const std::size_t n = cube.size();
    sh_coefficients<L, A> c{};
    for (int f = 0; f < 6; ++f)
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x) {
                const auto basis = sh_basis<L, double, glm::dvec3>(cube_texel_direction(cube_face(f), n, x, y));
                const A value = A(cube.faces[std::size_t(f)](x, y)) * cube_texel_solid_angle(n, x, y);
                for (std::size_t i = 0; i < sh_count(L); ++i) c[i] += value * basis[i];
            }
    return c;
}

/// Unit direction through the centre of pixel (x, y) of a width x height
/// latitude-longitude map: longitude phi = 2 pi (x + 1/2) / width from +x towards +y,
/// polar angle theta = pi (y + 1/2) / height from +z (row 0 touches the +z pole).
inline glm::dvec3 latlong_direction(std::size_t width, std::size_t height, std::size_t x, std::size_t y) {
    const double phi = 2 * std::numbers::pi * (double(x) + 0.5) / double(width);
    const double theta = std::numbers::pi * (double(y) + 0.5) / double(height);
    return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

/// Exact solid angle (sr) of a pixel in row y of a width x height latitude-longitude map:
/// (2 pi / width) (cos theta_y - cos theta_(y+1)). Rows sum to 4 pi / width exactly.
inline double latlong_pixel_solid_angle(std::size_t width, std::size_t height, std::size_t y) {
    const double t0 = std::numbers::pi * double(y) / double(height), t1 = std::numbers::pi * double(y + 1) / double(height);
    return 2 * std::numbers::pi / double(width) * (std::cos(t0) - std::cos(t1));
}

/// SH projection of a latitude-longitude map (layout of `latlong_direction`), each pixel
/// weighted by its exact solid angle. Throws parameter_error on an empty map.
template <int L, class P>
sh_coefficients<L, sh_accumulator_t<P>> sh_project_latlong(image_view<P> map) {
    using A = sh_accumulator_t<P>;
    require(!map.empty(), "map", "latitude-longitude map is empty");
    sh_coefficients<L, A> c{};
    for (std::size_t y = 0; y < map.height(); ++y) {
        const double dw = latlong_pixel_solid_angle(map.width(), map.height(), y);
        for (std::size_t x = 0; x < map.width(); ++x) {
            const auto basis = sh_basis<L, double, glm::dvec3>(latlong_direction(map.width(), map.height(), x, y));
            const A value = A(map(x, y)) * dw;
            for (std::size_t i = 0; i < sh_count(L); ++i) c[i] += value * basis[i];
        }
    }
    return c;
}

/// Monte Carlo projection of samples f_j = values[j] at unit directions[j] drawn with
/// solid-angle densities pdfs[j] (1/sr): c_i = (1/N) sum_j f_j Y_i(w_j) / pdf_j, unbiased
/// with variance O(1/N). `C` is double or glm::dvec3. Throws parameter_error on empty or
/// mismatched spans, a non-positive pdf, or a direction that is not unit length (1e-6).
template <int L, class C>
sh_coefficients<L, C> sh_project_monte_carlo(std::span<const glm::dvec3> directions, std::span<const C> values,
                                             std::span<const double> pdfs) {
    require(!directions.empty(), "directions", "no samples");
    require(values.size() == directions.size(), "values", "one value per direction");
    require(pdfs.size() == directions.size(), "pdfs", "one pdf per direction");
    sh_coefficients<L, C> c{};
    for (std::size_t j = 0; j < directions.size(); ++j) {
        require(pdfs[j] > 0 && std::isfinite(pdfs[j]), "pdfs", "densities must be positive and finite");
        require(std::abs(glm::dot(directions[j], directions[j]) - 1) < 1e-6, "directions", "directions must be unit vectors");
        const auto y = sh_basis<L, double, glm::dvec3>(directions[j]);
        const C w = values[j] / pdfs[j];
        for (std::size_t i = 0; i < sh_count(L); ++i) c[i] += w * y[i];
    }
    for (auto& ci : c) ci = ci / double(directions.size());
    return c;
}

/// `sh_project_monte_carlo` with one density for every sample, e.g. 1 / (4 pi) for
/// directions uniform on the sphere.
template <int L, class C>
sh_coefficients<L, C> sh_project_monte_carlo(std::span<const glm::dvec3> directions, std::span<const C> values, double pdf) {
    const std::vector<double> pdfs(directions.size(), pdf);
    return sh_project_monte_carlo<L, C>(directions, values, std::span<const double>(pdfs));
}

/// Regularized least-squares fit of samples f_j at unit directions w_j: the coefficients c
/// minimizing
///   (4 pi / N) sum_j (sum_i c_i Y_i(w_j) - f_j)^2 + lambda sum_i (l_i (l_i + 1))^2 c_i^2,
/// Tikhonov regularization by the squared Laplace-Beltrami eigenvalue of each band
/// (the Laplace-Beltrami regularization of Descoteaux et al. 2007, "Regularized, fast, and
/// robust analytical Q-ball imaging"), which penalizes roughness and leaves band 0 free. The 4 pi / N scaling makes the
/// data term approximate int (f_L - f)^2 dw for well-spread samples, so `lambda` does not
/// depend on N and, on such samples, the fit is about c_i / (1 + lambda (l (l + 1))^2):
/// lambda = 0 is plain least squares (exact for a band-limited f sampled at >= L^2 generic
/// directions); typical lambda 1e-4 to 1e-2 (dimensionless). Solved through the normal
/// equations by Cholesky's method in double. Throws parameter_error on empty or mismatched
/// spans, lambda < 0, directions that are not unit, or samples too few or too clustered
/// for the system to be positive definite.
template <int L, class C>
sh_coefficients<L, C> sh_fit_least_squares(std::span<const glm::dvec3> directions, std::span<const C> values,
                                           double lambda) {
    constexpr std::size_t n = sh_count(L);
    require(!directions.empty(), "directions", "no samples");
    require(values.size() == directions.size(), "values", "one value per direction");
    require(lambda >= 0 && std::isfinite(lambda), "lambda", "the regularization weight must be >= 0 and finite");
    const double scale = 4 * std::numbers::pi / double(directions.size());
    std::vector<double> a(n * n, 0.0);  // normal matrix, row-major
    sh_coefficients<L, C> b{};
    for (std::size_t j = 0; j < directions.size(); ++j) {
        require(std::abs(glm::dot(directions[j], directions[j]) - 1) < 1e-6, "directions", "directions must be unit vectors");
        require(detail::finite_value(values[j]), "values", "non-finite sample value");
        const auto y = sh_basis<L, double, glm::dvec3>(directions[j]);
        for (std::size_t r = 0; r < n; ++r) {
            b[r] += values[j] * (scale * y[r]);
            for (std::size_t k = 0; k <= r; ++k) a[r * n + k] += scale * y[r] * y[k];
        }
    }
    for (std::size_t r = 0; r < n; ++r) {
        const double l = sh_band(r), eigen = l * (l + 1);
        a[r * n + r] += lambda * eigen * eigen;
    }
    // Cholesky A = G G^T in the lower triangle. A pivot below 1e-12 of the diagonal it
    // came from means the samples do not determine some combination of the basis.
    for (std::size_t r = 0; r < n; ++r) {
        for (std::size_t k = 0; k <= r; ++k) {
            double s = a[r * n + k];
            for (std::size_t q = 0; q < k; ++q) s -= a[r * n + q] * a[k * n + q];
            if (k == r) {
                require(s > 1e-12 * a[r * n + r] && s > 0, "directions",
                        "samples too few or too clustered to determine the coefficients (raise lambda or add samples)");
                a[r * n + r] = std::sqrt(s);
            } else {
                a[r * n + k] = s / a[k * n + k];
            }
        }
    }
    // G z = b, then G^T c = z.
    sh_coefficients<L, C> z{}, c{};
    for (std::size_t r = 0; r < n; ++r) {
        C s = b[r];
        for (std::size_t q = 0; q < r; ++q) s -= z[q] * a[r * n + q];
        z[r] = s / a[r * n + r];
    }
    for (std::size_t r = n; r-- > 0;) {
        C s = z[r];
        for (std::size_t q = r + 1; q < n; ++q) s -= c[q] * a[q * n + r];
        c[r] = s / a[r * n + r];
    }
    return c;
}

}  // namespace bounce::sh
