// The SH toolkit's accuracy against closed forms (sh_study).
#include <bounce/study/sh_accuracy.hpp>

#include <bounce/errors.hpp>
#include <bounce/sampling.hpp>
#include <bounce/sh/gradients.hpp>
#include <bounce/sh/irradiance.hpp>
#include <bounce/sh/lights.hpp>
#include <bounce/sh/projection.hpp>
#include <bounce/sh/quadrature.hpp>
#include <bounce/sh/windowing.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

namespace bounce::study {

namespace {

using json = nlohmann::ordered_json;
constexpr double pi = std::numbers::pi;

template <int L>
sh_coefficients<L, glm::dvec3> closed_form_coefficients(const sh_environment& env) {
    if (env.directional) return sh_project_directional_light<L, glm::dvec3>(env.axis, glm::dvec3(1.0));
    return sh_project_cone_light<L, glm::dvec3>(env.axis, env.cos_half_angle, glm::dvec3(1.0));
}

struct error_row {
    double max_rel = 0, mean_rel = 0;
};

// Max and mean |E_sh - E| over the sphere relative to the peak of E, from the profile in
// c = cos(normal, axis) (uniform in c is uniform in area), 4001 midpoints.
template <int L>
error_row irradiance_error(const sh_environment& env, const sh_coefficients<L, glm::dvec3>& c) {
    const glm::dvec3 a = env.axis,
                     t = glm::normalize(glm::cross(a, std::abs(a.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
    const double peak = sh_environment_irradiance(env, 1);
    error_row r;
    constexpr int n = 4001;
    for (int k = 0; k < n; ++k) {
        const double cz = -1 + 2 * (k + 0.5) / n, s = std::sqrt(1 - cz * cz);
        const double e = sh_irradiance<L, double, glm::dvec3>(c, cz * a + s * t).x;
        const double err = std::abs(e - sh_environment_irradiance(env, cz)) / peak;
        r.max_rel = std::max(r.max_rel, err);
        r.mean_rel += err / n;
    }
    return r;
}

// Relative L2 error of the truncated radiance (Parseval): sqrt(1 - sum c^2 / int f^2).
template <int L>
double radiance_truncation_error(const sh_environment& env, const sh_coefficients<L, glm::dvec3>& c) {
    if (env.directional) return INFINITY;  // a delta has infinite energy
    const double total = 2 * pi * (1 - env.cos_half_angle);
    double kept = 0;
    for (const auto& ci : c) kept += ci.x * ci.x;
    return std::sqrt(std::max(0.0, 1 - kept / total));
}

template <int L>
json accuracy_for_order(const sh_environment& env, const std::array<image<glm::vec3>, 6>& raster) {
    const auto c = closed_form_coefficients<L>(env);
    const auto e = irradiance_error<L>(env, c);
    cube_map_view<const glm::vec3> view;
    for (int f = 0; f < 6; ++f) view.faces[std::size_t(f)] = raster[std::size_t(f)].view();
    const auto ec = irradiance_error<L>(env, sh_project_cube_map<L>(view));
    json row = {{"order", L - 1},
                {"coefficients", sh_count(L)},
                {"irradiance_max_rel", e.max_rel},
                {"irradiance_mean_rel", e.mean_rel},
                {"cube_irradiance_max_rel", ec.max_rel},
                {"cube_irradiance_mean_rel", ec.mean_rel}};
    const double t = radiance_truncation_error<L>(env, c);
    row["radiance_rel_l2"] = std::isfinite(t) ? json(t) : json(nullptr);
    if (env.directional && L >= 3) {
        sh_coefficients<L, double> scalar{};
        for (std::size_t i = 0; i < sh_count(L); ++i) scalar[i] = c[i].x;
        const auto irradiance = sh_convolve_clamped_cosine<L, double>(scalar);
        const double w = sh_nonnegative_window_width<L>(irradiance, sh_window_family::hann, L);
        const auto h = hann_window<L>(w);
        const auto cost = sh_window_cost<L>(irradiance, h);
        sh_coefficients<L, glm::dvec3> windowed{};
        for (std::size_t i = 0; i < sh_count(L); ++i) windowed[i] = glm::dvec3(c[i].x * h[std::size_t(sh_band(i))]);
        const auto ew = irradiance_error<L>(env, windowed);
        row["hann_nonnegative"] = {{"width", w},
                                   {"energy_kept", cost.energy_kept},
                                   {"peak_kept", cost.peak_kept},
                                   {"irradiance_max_rel", ew.max_rel},
                                   {"irradiance_mean_rel", ew.mean_rel}};
    }
    return row;
}

template <std::size_t... I>
json accuracy_rows(const sh_environment& env, std::size_t cube_size, std::index_sequence<I...>) {
    const auto raster = rasterize_environment(env, cube_size);
    return json::array({accuracy_for_order<int(I) + 2>(env, raster)...});
}

}  // namespace

std::array<sh_environment, 3> sh_study_environments() {
    const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
    return {sh_environment{"directional", axis, 1.0, true}, sh_environment{"sky", axis, 0.0, false},
            sh_environment{"cone-20deg", axis, std::cos(20 * pi / 180), false}};
}

// Cone (the sky is the cone of half-angle 90 degrees): int over the cap of max(0, n . w),
// exactly in the azimuth (int_0^2pi max(0, a cos phi + b) dphi = 2 a sin phi0 + 2 b phi0,
// cos phi0 = -b / a) and by 64-node Gauss-Legendre in cos(beta) on each side of the kink
// where the horizon starts to cut the cap's rings.
double sh_environment_irradiance(const sh_environment& env, double c) {
    if (env.directional) return std::max(0.0, c);
    static const auto rule = [] {
        std::pair<std::vector<double>, std::vector<double>> xw;
        gauss_legendre(64, xw.first, xw.second);
        return xw;
    }();
    const double st = std::sqrt(std::max(0.0, 1 - c * c));
    auto ring = [&](double t) {  // int over phi at cos(beta) = t
        const double a = st * std::sqrt(std::max(0.0, 1 - t * t)), b = c * t;
        if (b >= a) return 2 * pi * b;
        if (b <= -a) return 0.0;
        const double phi0 = std::acos(-b / a);
        return 2 * a * std::sin(phi0) + 2 * b * phi0;
    };
    const double lo = env.cos_half_angle, kink = std::abs(st);  // rings with |b| = a: t = sin(theta_n)
    const auto integral = [&](double a, double b) { return gauss_legendre_integral(rule.first, rule.second, a, b, ring); };
    if (kink > lo && kink < 1) return integral(lo, kink) + integral(kink, 1);
    return integral(lo, 1);
}

std::array<image<glm::vec3>, 6> rasterize_environment(const sh_environment& env, std::size_t n) {
    require(n > 0, "cube_size", "a cube face needs at least one texel");
    std::array<image<glm::vec3>, 6> faces;
    double best = -2;
    int bf = 0;
    std::size_t bx = 0, by = 0;
    for (int f = 0; f < 6; ++f) {
        faces[std::size_t(f)] = image<glm::vec3>(n, n);
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x) {
                const double c = glm::dot(cube_texel_direction(cube_face(f), n, x, y), env.axis);
                if (c > best) std::tie(best, bf, bx, by) = std::tuple(c, f, x, y);
                if (!env.directional && c >= env.cos_half_angle) faces[std::size_t(f)](x, y) = glm::vec3(1.f);
            }
    }
    if (env.directional) faces[std::size_t(bf)](bx, by) = glm::vec3(float(1 / cube_texel_solid_angle(n, bx, by)));
    return faces;
}

json sh_accuracy_table(const sh_environment& env, std::size_t cube_size) {
    require(cube_size > 0, "cube_size", "a cube face needs at least one texel");
    return accuracy_rows(env, cube_size, std::make_index_sequence<8>{});
}

json sh_gradient_table() {
    constexpr int L = 3;
    const glm::dvec3 q(0, 0, 3);
    const double radius = 0.5, step = 0.1;
    auto probe_at = [&](const glm::dvec3& p) {
        const glm::dvec3 d = q - p;
        const double sin_alpha = radius / glm::length(d);
        return sh_project_cone_light<L, glm::dvec3>(d, std::sqrt(1 - sin_alpha * sin_alpha), glm::dvec3(1.0));
    };
    const glm::dvec3 p(0.0);
    const auto stale = probe_at(p);
    const auto g = sh_translational_gradient<L, glm::dvec3>(probe_at, p, step);
    json rows = json::array();
    for (const glm::dvec3 dir : {glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1)})
        for (const double distance : {0.25, 0.5, 1.0}) {
            const glm::dvec3 d = dir * distance;
            const auto exact = probe_at(p + d), extrapolated = sh_extrapolate<L, glm::dvec3>(stale, g, d);
            double peak = 0, err_stale = 0, err_extrapolated = 0;
            for (std::size_t j = 0; j < 4096; ++j) {
                const glm::dvec3 n = spherical_fibonacci_direction(j, 4096);
                const double e = sh_irradiance<L, double, glm::dvec3>(exact, n).x;
                peak = std::max(peak, e);
                err_stale = std::max(err_stale, std::abs(sh_irradiance<L, double, glm::dvec3>(stale, n).x - e));
                err_extrapolated =
                    std::max(err_extrapolated, std::abs(sh_irradiance<L, double, glm::dvec3>(extrapolated, n).x - e));
            }
            rows.push_back({{"direction", dir.x > 0 ? "sideways" : "towards the light"},
                            {"distance_m", distance},
                            {"step_m", step},
                            {"stale_max_rel", err_stale / peak},
                            {"extrapolated_max_rel", err_extrapolated / peak}});
        }
    return rows;
}

}  // namespace bounce::study
