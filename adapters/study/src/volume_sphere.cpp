// An irradiance volume lighting a moving sphere, against the reference integrator.
#include <bounce/study/volume_sphere.hpp>

#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/errors.hpp>
#include <bounce/luminance.hpp>
#include <bounce/sh/irradiance.hpp>
#include <bounce/sh/projection.hpp>
#include <bounce/study/stage_timer.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <span>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace bounce::study {

namespace {

float lum(const glm::vec3& c) { return rec709_luminance<float, glm::vec3>(c); }
bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

error_figures compare(const std::vector<glm::vec3>& x, const std::vector<glm::vec3>& ref) {
    double sq = 0, ref_sq = 0, max_abs = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        const double d = double(lum(x[i])) - double(lum(ref[i]));
        sq += d * d;
        ref_sq += double(lum(ref[i])) * lum(ref[i]);
        max_abs = std::max(max_abs, std::abs(d));
    }
    error_figures e;
    e.rel_rms = ref_sq > 0 ? std::sqrt(sq / ref_sq) : 0;
    e.max_abs = max_abs;
    e.sum_sq = sq;
    e.pixels = x.size();
    return e;
}

double mean_of(const std::vector<double>& v) {
    double m = 0;
    for (double x : v) m += x;
    return v.empty() ? 0 : m / double(v.size());
}

// Largest |x_{s+1} - x_s| over the mean of x.
double popping_of(const std::vector<double>& series) {
    const double mean = mean_of(series);
    double worst = 0;
    for (std::size_t s = 1; s < series.size(); ++s) worst = std::max(worst, std::abs(series[s] - series[s - 1]));
    return mean > 0 ? worst / mean : 0;
}

// Largest |(x_{s+1} - x_s) - (ref_{s+1} - ref_s)| over the mean of ref: the part of the
// step-to-step change the true field does not have (jumps at cell boundaries).
double popping_excess(const std::vector<double>& series, const std::vector<double>& ref) {
    const double mean = mean_of(ref);
    double worst = 0;
    for (std::size_t s = 1; s < series.size(); ++s)
        worst = std::max(worst, std::abs((series[s] - series[s - 1]) - (ref[s] - ref[s - 1])));
    return mean > 0 ? worst / mean : 0;
}

// The ray o + t d (d unit) clipped to the box: [t0, t1] with t0 >= 0, or t0 > t1 when it misses.
std::pair<float, float> clip_to_box(glm::vec3 o, glm::vec3 d, glm::vec3 lo, glm::vec3 hi) {
    float t0 = 0, t1 = std::numeric_limits<float>::infinity();
    for (int k = 0; k < 3; ++k) {
        if (std::abs(d[k]) < 1e-12f) {
            if (o[k] < lo[k] || o[k] > hi[k]) return {1, 0};
            continue;
        }
        float a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
    }
    return {t0, t1};
}

// Free distance (nearest hit over `dirs`) at each of `count` points from a to b.
std::vector<float> free_distances(const embree::accel& bvh, glm::vec3 a, glm::vec3 b, std::size_t count,
                                  const std::vector<glm::vec3>& dirs) {
    std::vector<float> free(count);
    tbb::parallel_for(std::size_t(0), count, [&](std::size_t k) {
        const glm::vec3 p = a + (b - a) * (float(k) / float(count - 1));
        float nearest = std::numeric_limits<float>::infinity();
        for (const auto& d : dirs) {
            embree::ray r;
            r.origin = p;
            r.direction = d;
            nearest = std::min(nearest, bvh.intersect(r).t);
        }
        free[k] = nearest;
    });
    return free;
}

}  // namespace

glm::vec3 sphere_path::centre(std::size_t s, std::size_t steps) const {
    return steps < 2 ? (a + b) * 0.5f : a + (b - a) * (float(s) / float(steps - 1));
}

std::vector<glm::vec3> fibonacci_sphere(std::uint32_t n) {
    std::vector<glm::vec3> d;
    d.reserve(n);
    const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
    for (std::uint32_t j = 0; j < n; ++j) {
        const double z = 1 - (2.0 * j + 1) / n, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = golden * j;
        d.emplace_back(glm::normalize(glm::dvec3(r * std::cos(phi), r * std::sin(phi), z)));
    }
    return d;
}

bool sphere_path_is_clear(const embree::accel& bvh, const sphere_path& path) {
    static const auto dirs = fibonacci_sphere(256);
    for (std::size_t s = 0; s < 64; ++s) {
        const glm::vec3 c = path.centre(s, 64);
        for (const auto& d : dirs) {
            embree::ray r;
            r.origin = c;
            r.direction = d;
            r.tfar = path.radius;
            if (bvh.occluded(r)) return false;
        }
    }
    return true;
}

sphere_path default_sphere_path(const embree::accel& bvh, const camera& cam, glm::vec3 lo, glm::vec3 hi, float radius) {
    require(finite3(lo) && finite3(hi) && glm::all(glm::lessThan(lo, hi)), "lo", "the volume's box must be finite and non-empty");
    require(std::isfinite(radius) && radius >= 0, "radius", "must be finite and >= 0 (0: chosen)");
    const float largest = radius > 0 ? radius : 0.02f * glm::length(hi - lo);
    const auto probe_dirs = fibonacci_sphere(64);
    constexpr std::size_t samples = 64;
    // The view axis, then eight rays through the image at half the way to its edges.
    const glm::vec3 f = cam.forward(), right = cam.right(), up = cam.true_up();
    const float ty = std::tan(0.5f * glm::radians(cam.fov_y_deg)) * 0.5f;
    std::vector<glm::vec3> view_dirs = {f};
    for (int i = -1; i <= 1; ++i)
        for (int j = -1; j <= 1; ++j)
            if (i != 0 || j != 0) view_dirs.push_back(glm::normalize(f + float(i) * ty * right + float(j) * ty * up));
    // Each ray's segment inside the box up to its first surface, and the free distances on it.
    struct candidate {
        glm::vec3 a, b;
        float from_camera;  // distance from the camera to a
        std::vector<float> free;
    };
    std::vector<candidate> candidates;
    for (const glm::vec3 d : view_dirs) {
        auto [t0, t1] = clip_to_box(cam.position, d, lo, hi);
        if (!(t0 < t1)) continue;
        embree::ray r;
        r.origin = cam.position + t0 * d;
        r.direction = d;
        r.tfar = t1 - t0;
        const embree::hit h = bvh.intersect(r);
        const float end = h.found() ? t0 + h.t : t1;
        if (!(end > t0)) continue;
        const glm::vec3 a = cam.position + t0 * d, b = cam.position + end * d;
        candidates.push_back({a, b, t0, free_distances(bvh, a, b, samples, probe_dirs)});
    }
    // The largest radius (halving from `largest`) for which some ray has a run of points
    // whose free distance is at least 1.5 radii, at least four radii from the camera, and
    // which is at least four radii long; the
    // longest such run. The sparse rays of the free distances can miss thin geometry, so
    // the path is checked with sphere_path_is_clear before it is taken.
    for (int halvings = 0; halvings <= (radius > 0 ? 0 : 6); ++halvings) {
        const float r = largest / float(1 << halvings);
        std::vector<sphere_path> found;
        for (const auto& c : candidates) {
            const float step = glm::length(c.b - c.a) / float(samples - 1);
            std::size_t begin = 0;
            for (std::size_t k = 0; k <= samples; ++k) {
                // Free, and not in the camera's face (a sphere there would fill the frame).
                if (k < samples && c.free[k] >= 1.5f * r && c.from_camera + float(k) * step >= 4 * r) continue;
                if (k > begin && float(k - 1 - begin) * step >= 4 * r) {
                    const glm::vec3 dir = (c.b - c.a) / float(samples - 1);
                    found.push_back({c.a + float(begin) * dir, c.a + float(k - 1) * dir, r});
                }
                begin = k + 1;
            }
        }
        std::sort(found.begin(), found.end(),
                  [](const sphere_path& x, const sphere_path& y) { return glm::length(x.b - x.a) > glm::length(y.b - y.a); });
        for (const auto& p : found)
            if (sphere_path_is_clear(bvh, p)) return p;
    }
    throw parameter_error("path", "no free path for the sphere along the camera's view inside the volume (radius " +
                                      std::to_string(largest) + " down to 1/64 of it); give --path and --radius");
}

volume_sphere_study::volume_sphere_study(const embree::reference_integrator& light, const sphere_path& path,
                                         const volume_sphere_settings& s)
    : path_(path), settings_(s) {
    require(s.frames > 0, "frames", "at least one frame");
    require(s.sphere_points > 0, "sphere_points", "at least one point per sphere");
    require(s.popping_steps >= 2, "popping_steps", "at least two steps");
    require(s.reference_samples > 0, "reference_samples", "at least one sample");
    require(s.repeat > 0, "repeat", "at least one timed repeat");
    require(finite3(s.popping_normal) && std::abs(glm::length(s.popping_normal) - 1.f) < 1e-4f, "popping_normal",
            "must be a unit vector");
    require(finite3(path.a) && finite3(path.b) && std::isfinite(path.radius) && path.radius > 0, "path",
            "the path must be finite with a radius > 0");
    const auto dirs = fibonacci_sphere(s.sphere_points);
    const std::size_t m = dirs.size();
    points_.resize(s.frames * m);
    normals_.resize(s.frames * m);
    reference_.resize(s.frames * m);
    for (std::size_t f = 0; f < s.frames; ++f)
        for (std::size_t k = 0; k < m; ++k) {
            normals_[f * m + k] = dirs[k];
            points_[f * m + k] = path.centre(f, s.frames) + path.radius * dirs[k];
        }
    const auto t0 = std::chrono::steady_clock::now();
    tbb::parallel_for(std::size_t(0), points_.size(), [&](std::size_t i) {
        reference_[i] = light.indirect_irradiance(points_[i], normals_[i], s.reference_samples, embree::derive_seed(s.seed, 1, i));
    });
    reference_ms_ = ms_since(t0);
    const std::size_t steps = s.popping_steps;
    pop_points_.resize(steps);
    pop_normals_.assign(steps, s.popping_normal);
    pop_reference_.resize(steps);
    for (std::size_t k = 0; k < steps; ++k) pop_points_[k] = path.centre(k, steps) + path.radius * s.popping_normal;
    const std::uint32_t pop_samples = std::min<std::uint32_t>(16 * s.reference_samples, 1u << 16);
    tbb::parallel_for(std::size_t(0), steps, [&](std::size_t k) {
        pop_reference_[k] = light.indirect_irradiance(pop_points_[k], pop_normals_[k], pop_samples, s.seed + 92);
    });
    for (const auto& x : pop_reference_) pop_reference_lum_.push_back(lum(x));
    reference_popping_ = popping_of(pop_reference_lum_);
}

volume_lookup_figures volume_sphere_study::measure(const irradiance_volume& volume, std::string name,
                                                    const cpu::volume_lookup& how) const {
    volume_lookup_figures out;
    out.name = std::move(name);
    std::vector<glm::vec3> lit(points_.size()), pop(pop_points_.size());
    std::vector<double> ns;
    for (int r = 0; r < settings_.repeat; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        cpu::light_points(volume, points_, normals_, lit, how);
        ns.push_back(ms_since(t0) * 1e6 / double(points_.size()));
    }
    std::sort(ns.begin(), ns.end());
    out.lookup_ns = ns[ns.size() / 2];
    cpu::light_points(volume, pop_points_, pop_normals_, pop, how);
    out.error = compare(lit, reference_);
    for (const auto& x : pop) out.popping_series.push_back(lum(x));
    out.popping = popping_of(out.popping_series);
    out.popping_excess = popping_excess(out.popping_series, pop_reference_lum_);
    return out;
}

image<glm::vec3> render_sphere_strip(const embree::accel& bvh, const scene_view& scene, const camera& cam,
                                     const embree::reference_integrator& light, const irradiance_volume& volume,
                                     const cpu::volume_lookup& how, const sphere_path& path, std::size_t frames,
                                     std::size_t w, std::size_t h) {
    require(frames > 0 && w > 0 && h > 0, "frames", "a strip needs at least one frame of at least one pixel");
    const auto g = embree::ray_cast_gbuffer(bvh, scene, cam, w, h);
    image<glm::vec3> strip(frames * w, h);
    for (std::size_t f = 0; f < frames; ++f) {
        const glm::vec3 centre = path.centre(f, frames);
        const float radius = path.radius;
        tbb::parallel_for(std::size_t(0), h, [&](std::size_t y) {
            for (std::size_t x = 0; x < w; ++x) {
                const glm::vec3 d = cam.direction(float(x) + 0.5f, float(y) + 0.5f, w, h);
                // Ray-sphere: |o + t d - c|^2 = r^2, d not unit (forward component 1, t = depth).
                const glm::vec3 oc = cam.position - centre;
                const float a = glm::dot(d, d), bq = glm::dot(oc, d), c = glm::dot(oc, oc) - radius * radius;
                const float disc = bq * bq - a * c;
                const float t_sphere = disc >= 0 ? (-bq - std::sqrt(disc)) / a : std::numeric_limits<float>::infinity();
                glm::vec3 p, n, albedo;
                if (t_sphere > 0 && t_sphere < g.depth(x, y)) {
                    p = cam.position + t_sphere * d;
                    n = glm::normalize(p - centre);
                    albedo = glm::vec3(0.8f);
                } else if (std::isfinite(g.depth(x, y))) {
                    p = g.position(x, y);
                    n = g.normal(x, y);
                    albedo = g.albedo(x, y);
                } else {
                    continue;
                }
                const glm::vec3 q = p + n * (0.01f * radius);
                const glm::vec3 e_volume = how.interpolation == cpu::volume_interpolation::trilinear
                                               ? volume.trilinear(q, n)
                                               : volume.weighted(q, n, how.weighted);
                strip(f * w + x, y) = albedo / std::numbers::pi_v<float> *
                                      (light.direct_irradiance(p, n, 1) + glm::max(e_volume, glm::vec3(0.f)));
            }
        });
    }
    return strip;
}

namespace {

template <int L>
void sh_study_order(const std::vector<glm::dvec3>& dirs, const std::vector<glm::dvec3>& radiance,
                    const std::vector<glm::vec3>& normals, const std::vector<double>& exact_e, double f2,
                    nlohmann::ordered_json& rows) {
    const auto c = sh_project_monte_carlo<L, glm::dvec3>(std::span<const glm::dvec3>(dirs),
                                                         std::span<const glm::dvec3>(radiance), 1 / (4 * std::numbers::pi));
    double c2 = 0;
    for (const auto& ci : c) c2 += std::pow(rec709_luminance<double, glm::dvec3>(ci), 2);
    std::array<glm::vec3, sh_count(L)> cf{};
    for (std::size_t i = 0; i < cf.size(); ++i) cf[i] = glm::vec3(c[i]);
    double peak = 0, max_err = 0, mean_err = 0;
    for (double e : exact_e) peak = std::max(peak, e);
    for (std::size_t k = 0; k < normals.size(); ++k) {
        const double e = lum(sh_irradiance<L, float, glm::vec3>(cf, normals[k]));
        max_err = std::max(max_err, std::abs(e - exact_e[k]));
        mean_err += std::abs(e - exact_e[k]) / double(normals.size());
    }
    rows.push_back({{"order", L - 1},
                    {"radiance_rel_l2", f2 > 0 ? std::sqrt(std::max(0.0, f2 - c2) / f2) : 0.0},
                    {"irradiance_max_rel_peak", peak > 0 ? max_err / peak : 0.0},
                    {"irradiance_mean_rel_peak", peak > 0 ? mean_err / peak : 0.0}});
    if constexpr (L < 9) sh_study_order<L + 1>(dirs, radiance, normals, exact_e, f2, rows);
}

}  // namespace

nlohmann::ordered_json sh_environment_study(const embree::reference_integrator& light, const std::vector<glm::vec3>& points) {
    const auto dirs_f = fibonacci_sphere(16384);
    const std::vector<glm::dvec3> dirs(dirs_f.begin(), dirs_f.end());
    const auto normals = fibonacci_sphere(256);
    nlohmann::ordered_json all = nlohmann::ordered_json::array();
    for (const auto& p : points) {
        std::vector<glm::dvec3> radiance(dirs.size());
        tbb::parallel_for(std::size_t(0), dirs.size(), [&](std::size_t j) {
            embree::ray r;
            r.origin = p;
            r.direction = glm::vec3(dirs[j]);
            radiance[j] = glm::dvec3(light.incoming_radiance(r, j));
        });
        double f2 = 0;
        for (const auto& v : radiance) f2 += std::pow(rec709_luminance<double, glm::dvec3>(v), 2);
        f2 *= 4 * std::numbers::pi / double(dirs.size());
        std::vector<double> exact(normals.size());
        for (std::size_t k = 0; k < normals.size(); ++k) {
            double e = 0;
            for (std::size_t j = 0; j < dirs.size(); ++j)
                e += rec709_luminance<double, glm::dvec3>(radiance[j]) * std::max(0.0, glm::dot(dirs[j], glm::dvec3(normals[k])));
            exact[k] = e * 4 * std::numbers::pi / double(dirs.size());
        }
        nlohmann::ordered_json rows = nlohmann::ordered_json::array();
        sh_study_order<1>(dirs, radiance, normals, exact, f2, rows);
        all.push_back({{"position", {p.x, p.y, p.z}}, {"orders", rows}});
    }
    return all;
}

nlohmann::ordered_json volume_lookup_figures::to_json() const {
    return {{"rel_rms", error.rel_rms}, {"max_abs", error.max_abs},       {"popping", popping},
            {"popping_excess", popping_excess}, {"lookup_ns", lookup_ns}, {"popping_series", popping_series}};
}

nlohmann::ordered_json build_stats_json(const irradiance_volume_build_stats& stats) {
    return {{"split_min_depth", stats.split_min_depth}, {"split_distance", stats.split_distance},
            {"split_neighbour", stats.split_neighbour}, {"split_geometry", stats.split_geometry},
            {"split_gradient", stats.split_gradient},   {"split_prediction", stats.split_prediction},
            {"culled", stats.culled},                   {"inside_cells", stats.inside_cells},
            {"merged", stats.merged},                   {"hanging_corners", stats.hanging_corners},
            {"noise_scale", stats.noise_scale}};
}

void print_sh_environments(const nlohmann::ordered_json& environments) {
    for (const auto& e : environments) {
        std::printf("environment at (%.3f, %.3f, %.3f)\n  order  radiance L2  irradiance max/peak  mean/peak\n",
                    e["position"][0].get<double>(), e["position"][1].get<double>(), e["position"][2].get<double>());
        for (const auto& r : e["orders"])
            std::printf("  %5d  %11.4f  %19.4f  %9.4f\n", r["order"].get<int>(), r["radiance_rel_l2"].get<double>(),
                        r["irradiance_max_rel_peak"].get<double>(), r["irradiance_mean_rel_peak"].get<double>());
    }
}

}  // namespace bounce::study
