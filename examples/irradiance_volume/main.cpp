// irradiance_volume: an irradiance volume (Oat, "Irradiance Volumes for Real-time
// Rendering", ShaderX5 2006) baked with Embree over a static scene lights a sphere moving
// along a straight path through it.
//
//   build/bin/irradiance_volume --scene sponza --mode adaptive --max-depth 5 --interp weighted
//       --b 2 --gradients on --json iv.json --out iv.png
//
// Light transport: probes hold the one-bounce indirect light (reference_integrator::
// incoming_radiance: Kd / pi times the direct irradiance at the first hit), and the
// reference on the sphere is reference_integrator::indirect_irradiance at its surface
// points, which integrates the same radiance over the hemisphere; the sphere is not in the
// BVH, so it occludes neither. Reports probes, bake_ms, lookup_ns per shaded point,
// error.rel_rms of the luminance of the irradiance over every sphere point of every frame,
// and popping: the largest change of the irradiance between consecutive steps at the
// sphere point facing down (-y), relative to its mean along the path, with the reference's
// own figure beside it (the real change per step), and popping_excess: the largest
// step-to-step change of (lookup - reference), relative to the reference's mean, the part
// of the change the true field does not have. The reference there uses 16 times the
// samples (at most 65536) with one seed for every step. Every lookup (trilinear, weighted
// without and with gradients) runs on the same bake and is reported under "lookups".
// --sh-study instead captures environments along the path and prints SH projection and
// irradiance errors per order.
#include "../common/cli_number_checks.hpp"

#include <bounce/cpu/irradiance_volume.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/probe_baker.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/irradiance_volume.hpp>
#include <bounce/luminance.hpp>
#include <bounce/sh_irradiance.hpp>
#include <bounce/sh_projection.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/study/stage_timer.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

using namespace bounce;
namespace fs = std::filesystem;

namespace {

struct options {
    std::string scene = "cornell";
    std::string mode = "adaptive";
    int max_depth = 4;
    int min_depth = -1;  // -1: 1 (adaptive) or max_depth (uniform)
    std::string interp = "weighted";
    float b = 2.f;
    float support = 1.5f;
    std::string gradients = "on";
    std::uint32_t rays = 512;
    std::uint32_t ref_samples = 1024;
    std::uint32_t frames = 16;
    std::uint32_t sphere_points = 256;
    std::uint32_t popping_steps = 128;
    float radius = 0.02f;      // fraction of the volume's diagonal
    float margin = -0.01f;     // fraction of the scene's extent added on every side
    std::vector<float> path;   // x0 y0 z0 x1 y1 z1 as fractions of the volume's box
    float distance_ratio = 1.f, neighbour_change = 0.25f, gradient_ratio = 0.3f, cull = 0.05f;
    std::uint32_t geometry_triangles = 1;
    float gradient_step = 0.1f;  // fraction of the finest cell's shortest edge
    int repeat = 5;
    int threads = 0;
    std::string json, out;
    bool sh_study = false;
};

// Fails before any long work when an output file cannot be created.
void check_writable(const std::string& file, const char* option) {
    if (file.empty()) return;
    const fs::path p(file);
    std::error_code ec;
    if (p.has_parent_path()) fs::create_directories(p.parent_path(), ec);
    const bool existed = fs::exists(p);
    {
        std::ofstream f(p, std::ios::app);
        if (!f) throw parameter_error(option, "cannot write '" + file + "'");
    }
    if (!existed) fs::remove(p, ec);
}

std::vector<glm::vec3> fibonacci_sphere(std::uint32_t n) {
    std::vector<glm::vec3> d;
    const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
    for (std::uint32_t j = 0; j < n; ++j) {
        const double z = 1 - (2.0 * j + 1) / n, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = golden * j;
        d.emplace_back(glm::normalize(glm::dvec3(r * std::cos(phi), r * std::sin(phi), z)));
    }
    return d;
}

float lum(const glm::vec3& c) { return rec709_luminance<float, glm::vec3>(c); }

study::error_figures compare(const std::vector<glm::vec3>& x, const std::vector<glm::vec3>& ref) {
    double sq = 0, ref_sq = 0, max_abs = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        const double d = double(lum(x[i])) - double(lum(ref[i]));
        sq += d * d;
        ref_sq += double(lum(ref[i])) * lum(ref[i]);
        max_abs = std::max(max_abs, std::abs(d));
    }
    study::error_figures e;
    e.rel_rms = ref_sq > 0 ? std::sqrt(sq / ref_sq) : 0;
    e.max_abs = max_abs;
    e.sum_sq = sq;
    e.pixels = x.size();
    return e;
}

// Largest |x_{s+1} - x_s| over the mean of x (luminance).
double popping_of(const std::vector<glm::vec3>& series) {
    double mean = 0, worst = 0;
    for (const auto& v : series) mean += lum(v);
    mean /= double(series.size());
    for (std::size_t s = 1; s < series.size(); ++s) worst = std::max(worst, double(std::abs(lum(series[s]) - lum(series[s - 1]))));
    return mean > 0 ? worst / mean : 0;
}

// Largest |(x_{s+1} - x_s) - (ref_{s+1} - ref_s)| over the mean of ref: the part of the
// step-to-step change the true field does not have (jumps at cell boundaries).
double popping_excess(const std::vector<glm::vec3>& series, const std::vector<glm::vec3>& ref) {
    double mean = 0, worst = 0;
    for (const auto& v : ref) mean += lum(v);
    mean /= double(ref.size());
    for (std::size_t s = 1; s < series.size(); ++s)
        worst = std::max(worst, std::abs(double(lum(series[s]) - lum(series[s - 1])) - double(lum(ref[s]) - lum(ref[s - 1]))));
    return mean > 0 ? worst / mean : 0;
}

// ---- --sh-study: SH of environments captured in the scene ---------------------------------

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
                    {"radiance_rel_l2", std::sqrt(std::max(0.0, f2 - c2) / f2)},
                    {"irradiance_max_rel_peak", max_err / peak},
                    {"irradiance_mean_rel_peak", mean_err / peak}});
    if constexpr (L < 9) sh_study_order<L + 1>(dirs, radiance, normals, exact_e, f2, rows);
}

// Radiance over 16384 directions at each point, projected at orders 0..8: relative L2 error
// of the radiance (luminance, Parseval) and of the irradiance at 256 normals against the
// irradiance integrated from the same samples, relative to its peak.
nlohmann::ordered_json sh_study(const embree::reference_integrator& light, const std::vector<glm::vec3>& points) {
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
        std::printf("environment at (%.3f, %.3f, %.3f)\n  order  radiance L2  irradiance max/peak  mean/peak\n", p.x, p.y, p.z);
        for (const auto& r : rows)
            std::printf("  %5d  %11.4f  %19.4f  %9.4f\n", r["order"].get<int>(), r["radiance_rel_l2"].get<double>(),
                        r["irradiance_max_rel_peak"].get<double>(), r["irradiance_mean_rel_peak"].get<double>());
    }
    return all;
}

// ---- pictures -----------------------------------------------------------------------------

// One frame: the scene from its camera, shaded rho / pi (direct + volume irradiance), with
// the sphere (albedo 0.8) at `centre` shaded the same way.
image<glm::vec3> render_frame(const embree::accel& bvh, const io::scene& scene, const embree::reference_integrator& light,
                              const irradiance_volume& volume, const cpu::volume_lookup& how, glm::vec3 centre,
                              float radius, std::size_t w, std::size_t h) {
    const auto g = embree::ray_cast_gbuffer(bvh, scene, scene.camera, w, h);
    image<glm::vec3> img(w, h);
    tbb::parallel_for(std::size_t(0), h, [&](std::size_t y) {
        for (std::size_t x = 0; x < w; ++x) {
            const glm::vec3 d = scene.camera.direction(float(x) + 0.5f, float(y) + 0.5f, w, h);
            // Ray-sphere: |o + t d - c|^2 = r^2, d not unit (forward component 1, t = depth).
            const glm::vec3 oc = scene.camera.position - centre;
            const float a = glm::dot(d, d), bq = glm::dot(oc, d), c = glm::dot(oc, oc) - radius * radius;
            const float disc = bq * bq - a * c;
            float t_sphere = std::numeric_limits<float>::infinity();
            if (disc >= 0) t_sphere = (-bq - std::sqrt(disc)) / a;
            glm::vec3 p, n, albedo;
            if (t_sphere > 0 && t_sphere < g.depth(x, y)) {
                p = scene.camera.position + t_sphere * d;
                n = glm::normalize(p - centre);
                albedo = glm::vec3(0.8f);
            } else if (std::isfinite(g.depth(x, y))) {
                p = g.position(x, y);
                n = g.normal(x, y);
                albedo = g.albedo(x, y);
            } else {
                continue;
            }
            const glm::vec3 e_direct = light.direct_irradiance(p, n, 1);
            const glm::vec3 e_volume = how.interpolation == cpu::volume_interpolation::trilinear
                                           ? volume.trilinear(p + n * (0.01f * radius), n)
                                           : volume.weighted(p + n * (0.01f * radius), n, how.weighted);
            img(x, y) = albedo / std::numbers::pi_v<float> * (e_direct + glm::max(e_volume, glm::vec3(0.f)));
        }
    });
    return img;
}

int run(const options& o) {
    check_writable(o.json, "--json");
    check_writable(o.out, "--out");
    if (o.mode != "uniform" && o.mode != "adaptive") throw parameter_error("--mode", "uniform or adaptive");
    if (o.interp != "trilinear" && o.interp != "weighted") throw parameter_error("--interp", "trilinear or weighted");
    if (o.gradients != "on" && o.gradients != "off") throw parameter_error("--gradients", "on or off");
    if (!o.path.empty() && o.path.size() != 6) throw parameter_error("--path", "six numbers: x0 y0 z0 x1 y1 z1");
    std::optional<tbb::global_control> threads;
    if (o.threads > 0) threads.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(o.threads));

    study::stage_timer timer;
    const io::scene scene = io::load_scene_arg(o.scene);
    const embree::accel bvh(scene);
    embree::reference_settings rs;
    rs.hemisphere_samples = o.ref_samples;
    rs.seed = 1;
    const embree::reference_integrator light(bvh, scene, rs);

    auto [lo, hi] = scene.bounds();
    const glm::vec3 scene_extent = hi - lo;
    lo -= o.margin * scene_extent;
    hi += o.margin * scene_extent;
    const glm::vec3 extent = hi - lo;

    // The path, in fractions of the volume's box: stated per scene unless --path gives one.
    std::vector<float> path = o.path;
    if (path.empty())
        path = scene.name == "cornell" ? std::vector<float>{0.2f, 0.75f, 0.55f, 0.8f, 0.75f, 0.55f}
                                       : std::vector<float>{0.15f, 0.2f, 0.5f, 0.85f, 0.2f, 0.5f};
    const glm::vec3 a = lo + extent * glm::vec3(path[0], path[1], path[2]);
    const glm::vec3 b = lo + extent * glm::vec3(path[3], path[4], path[5]);
    const float radius = o.radius * glm::length(extent);
    const auto sphere_dirs = fibonacci_sphere(o.sphere_points);
    const auto centre_at = [&](std::size_t s, std::size_t count) {
        return count < 2 ? (a + b) * 0.5f : a + (b - a) * (float(s) / float(count - 1));
    };
    // The sphere must not cut the scene anywhere along the path.
    for (std::size_t s = 0; s < 64; ++s) {
        const glm::vec3 c = centre_at(s, 64);
        for (const auto& d : sphere_dirs) {
            embree::ray r;
            r.origin = c;
            r.direction = d;
            r.tfar = radius;
            if (bvh.occluded(r))
                throw parameter_error("--path", "the sphere (radius " + std::to_string(radius) +
                                                    ") intersects the scene along the path; choose another --path or --radius");
        }
    }

    if (o.sh_study) {
        std::vector<glm::vec3> points;
        for (std::size_t s = 0; s < 4; ++s) points.push_back(centre_at(s, 4));
        const auto result = sh_study(light, points);
        if (!o.json.empty()) {
            nlohmann::ordered_json j;
            j["technique"] = "irradiance_volume_sh_study";
            j["scene"] = scene.name;
            j["environments"] = result;
            std::ofstream(o.json) << j.dump(2) << "\n";
        }
        return 0;
    }

    // Bake.
    irradiance_volume_settings vs;
    const bool uniform = o.mode == "uniform";
    vs.max_depth = o.max_depth;
    vs.min_depth = uniform ? o.max_depth : (o.min_depth >= 0 ? o.min_depth : std::min(1, o.max_depth));
    vs.distance_ratio = o.distance_ratio;
    vs.neighbour_change = o.neighbour_change;
    vs.geometry_triangles = o.geometry_triangles;
    vs.gradient_ratio = o.gradient_ratio;
    vs.cull_tolerance = o.cull;
    const glm::vec3 finest = extent / float(1 << std::clamp(o.max_depth, 0, irradiance_volume::depth_limit));
    embree::probe_baker_settings bs;
    bs.rays = o.rays;
    bs.gradient_step = o.gradient_step * std::min({finest.x, finest.y, finest.z});
    std::size_t batch = 0;
    bs.progress = [&](std::size_t done, std::size_t total) {
        if (done == total || done % 64 < 4) std::fprintf(stderr, "\rbake: batch %zu, %zu / %zu probes   ", batch, done, total);
        if (done == total) ++batch;
    };
    const embree::probe_baker baker(light, bvh, scene, bs);
    irradiance_volume_build_stats stats;
    std::optional<irradiance_volume> volume_storage;
    const auto bake_start = std::chrono::steady_clock::now();
    volume_storage.emplace(irradiance_volume::build(scene, lo, hi, vs, baker, &stats));
    const double bake_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - bake_start).count();
    std::fprintf(stderr, "\n");
    const irradiance_volume& volume = *volume_storage;

    // The sphere's surface points in every frame, and the reference there.
    const std::size_t frames = o.frames, m = sphere_dirs.size();
    std::vector<glm::vec3> points(frames * m), normals(frames * m), reference(frames * m);
    for (std::size_t f = 0; f < frames; ++f)
        for (std::size_t k = 0; k < m; ++k) {
            normals[f * m + k] = sphere_dirs[k];
            points[f * m + k] = centre_at(f, frames) + radius * sphere_dirs[k];
        }
    const auto ref_start = std::chrono::steady_clock::now();
    tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t i) {
        reference[i] = light.indirect_irradiance(points[i], normals[i], o.ref_samples, embree::derive_seed(7, 1, i));
    });
    const double reference_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - ref_start).count();
    // Popping: the point facing down, at many steps; the reference with one seed for every
    // step (its noise is then the same pattern at each step, so its changes are real).
    const std::size_t steps = std::max<std::size_t>(o.popping_steps, 2);
    std::vector<glm::vec3> pop_points(steps), pop_normals(steps, glm::vec3(0, -1, 0)), pop_reference(steps);
    for (std::size_t s = 0; s < steps; ++s) pop_points[s] = centre_at(s, steps) + radius * glm::vec3(0, -1, 0);
    const std::uint32_t pop_samples = std::min<std::uint32_t>(16 * o.ref_samples, 1u << 16);
    tbb::parallel_for(std::size_t(0), steps, [&](std::size_t s) {
        pop_reference[s] = light.indirect_irradiance(pop_points[s], pop_normals[s], pop_samples, 99);
    });

    // Every lookup on the same volume.
    struct variant {
        std::string name;
        cpu::volume_lookup how;
    };
    const float exponent = o.b;
    std::vector<variant> variants = {
        {"trilinear", {cpu::volume_interpolation::trilinear, {exponent, false, o.support}}},
        {"weighted", {cpu::volume_interpolation::weighted, {exponent, false, o.support}}},
        {"weighted_gradients", {cpu::volume_interpolation::weighted, {exponent, true, o.support}}},
    };
    const std::string chosen = o.interp == "trilinear" ? "trilinear" : (o.gradients == "on" ? "weighted_gradients" : "weighted");
    nlohmann::ordered_json lookups = nlohmann::ordered_json::object();
    study::error_figures chosen_error;
    double chosen_popping = 0, chosen_excess = 0, chosen_lookup_ns = 0;
    cpu::volume_lookup chosen_how;
    for (const auto& v : variants) {
        std::vector<glm::vec3> lit(points.size()), pop(steps);
        std::vector<double> ns;
        for (int r = 0; r < std::max(1, o.repeat); ++r) {
            const auto t0 = std::chrono::steady_clock::now();
            cpu::light_points(volume, points, normals, lit, v.how);
            ns.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() /
                         double(points.size()));
        }
        std::sort(ns.begin(), ns.end());
        cpu::light_points(volume, pop_points, pop_normals, pop, v.how);
        const auto e = compare(lit, reference);
        const double popping = popping_of(pop), lookup_ns = ns[ns.size() / 2];
        const double excess = popping_excess(pop, pop_reference);
        nlohmann::ordered_json series = nlohmann::ordered_json::array();
        for (const auto& x : pop) series.push_back(lum(x));
        lookups[v.name] = {{"rel_rms", e.rel_rms},     {"max_abs", e.max_abs},       {"popping", popping},
                           {"popping_excess", excess},   {"lookup_ns", lookup_ns}, {"popping_series", series}};
        std::printf("%-20s rel_rms %.4f  popping %.4f (excess %.4f)  lookup %.0f ns\n", v.name.c_str(), e.rel_rms, popping,
                    excess, lookup_ns);
        if (v.name == chosen)
            chosen_error = e, chosen_popping = popping, chosen_excess = excess, chosen_lookup_ns = lookup_ns,
            chosen_how = v.how;
    }
    const double reference_popping = popping_of(pop_reference);
    std::printf("%s %s depth %d: %zu probes (%zu inside), %zu leaves, bake %.0f ms; reference popping %.4f\n",
                scene.name.c_str(), o.mode.c_str(), volume.depth(), volume.probes().size(), stats.probes_inside,
                volume.leaf_count(), bake_ms, reference_popping);

    // A strip of four frames along the path.
    std::size_t strip_w = 0, strip_h = 0;
    if (!o.out.empty()) {
        const std::size_t w = 192, h = 144;
        image<glm::vec3> strip(4 * w, h);
        for (std::size_t f = 0; f < 4; ++f) {
            const auto frame = render_frame(bvh, scene, light, volume, chosen_how, centre_at(f, 4), radius, w, h);
            for (std::size_t y = 0; y < h; ++y)
                for (std::size_t x = 0; x < w; ++x) strip(f * w + x, y) = frame(x, y);
        }
        io::write_png(o.out, strip.view(), io::auto_exposure(strip.view()));
        strip_w = strip.width(), strip_h = strip.height();
    }

    if (!o.json.empty()) {
        study::run_report report;
        report.technique = "irradiance_volume";
        report.scene = scene.name;
        report.width = strip_w ? strip_w : m;       // the strip, or the sphere's points per frame
        report.height = strip_h ? strip_h : frames;  // the strip, or the frames
        report.backend = "cpu";
        auto& p = report.parameters;
        p["mode"] = o.mode;
        p["max_depth"] = o.max_depth;
        p["min_depth"] = vs.min_depth;
        p["interp"] = o.interp;
        p["b"] = o.b;
        p["gradients"] = o.gradients;
        p["support"] = o.support;
        p["rays"] = o.rays;
        p["gradient_step"] = bs.gradient_step;
        p["reference_samples"] = o.ref_samples;
        p["frames"] = o.frames;
        p["sphere_points"] = o.sphere_points;
        p["sphere_radius"] = radius;
        p["path"] = {{a.x, a.y, a.z}, {b.x, b.y, b.z}};
        p["volume_lo"] = {lo.x, lo.y, lo.z};
        p["volume_hi"] = {hi.x, hi.y, hi.z};
        p["distance_ratio"] = o.distance_ratio;
        p["neighbour_change"] = o.neighbour_change;
        p["geometry_triangles"] = o.geometry_triangles;
        p["gradient_ratio"] = o.gradient_ratio;
        p["cull_tolerance"] = o.cull;
        p["threads"] = o.threads;
        report.timings_ms = {{"bake", bake_ms}, {"reference", reference_ms}};
        report.error = chosen_error;
        report.set_count("probes", volume.probes().size());
        report.set_count("probes_inside", stats.probes_inside);
        report.set_count("probes_baked", stats.probes_baked);
        report.set_count("leaves", volume.leaf_count());
        report.set_count("nodes", volume.nodes().size());
        auto j = report.to_json();
        j["bake_ms"] = bake_ms;
        j["lookup_ns"] = chosen_lookup_ns;
        j["popping"] = chosen_popping;
        j["popping_excess"] = chosen_excess;
        j["popping_reference"] = reference_popping;
        nlohmann::ordered_json series = nlohmann::ordered_json::array();
        for (const auto& x : pop_reference) series.push_back(lum(x));
        j["popping_reference_series"] = series;
        j["lookups"] = lookups;
        j["build"] = {{"split_min_depth", stats.split_min_depth}, {"split_distance", stats.split_distance},
                      {"split_neighbour", stats.split_neighbour}, {"split_geometry", stats.split_geometry},
                      {"split_gradient", stats.split_gradient},   {"culled", stats.culled},
                      {"inside_cells", stats.inside_cells}};
        j["light_transport"] =
            "one-bounce indirect: probes and reference integrate Kd/pi * direct irradiance at the first hit";
        std::ofstream(o.json) << j.dump(2) << "\n";
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    options o;
    CLI::App app{"Irradiance volume lighting a moving sphere (Oat 2006), against the reference integrator"};
    using examples::finite_non_negative;
    using examples::finite_positive;
    app.add_option("--scene", o.scene, "cornell, a scene folder name under BOUNCE_SCENES, or a path");
    app.add_option("--mode", o.mode, "uniform or adaptive")->check(CLI::IsMember({"uniform", "adaptive"}));
    app.add_option("--max-depth", o.max_depth, "deepest octree level (uniform: the grid's depth), 0..10")
        ->check(CLI::Range(0, irradiance_volume::depth_limit));
    app.add_option("--min-depth", o.min_depth, "shallowest leaf level of an adaptive octree (default 1)")
        ->check(CLI::Range(0, irradiance_volume::depth_limit));
    app.add_option("--interp", o.interp, "trilinear or weighted")->check(CLI::IsMember({"trilinear", "weighted"}));
    app.add_option("--b", o.b, "distance exponent of the weighted average, (0, 4]")
        ->check(examples::detail::number_in(1e-6, 4, true, "an exponent"));
    app.add_option("--support", o.support, "a probe's weight reaches 0 at support * half the diagonal of its largest leaf, > 1")
        ->check(examples::detail::number_in(1.000001, 16, true, "a support"));
    app.add_option("--gradients", o.gradients, "on or off (weighted interpolation)")->check(CLI::IsMember({"on", "off"}));
    app.add_option("--rays", o.rays, "rays per probe")->check(CLI::Range(1u, 1u << 20));
    app.add_option("--ref-samples", o.ref_samples, "reference hemisphere samples per sphere point")->check(CLI::Range(1u, 1u << 20));
    app.add_option("--frames", o.frames, "sphere positions along the path for the error")->check(CLI::Range(1u, 4096u));
    app.add_option("--sphere-points", o.sphere_points, "surface points per sphere")->check(CLI::Range(1u, 65536u));
    app.add_option("--popping-steps", o.popping_steps, "steps along the path for popping")->check(CLI::Range(2u, 65536u));
    app.add_option("--radius", o.radius, "sphere radius, fraction of the volume's diagonal")->check(finite_positive);
    app.add_option("--margin", o.margin, "volume box = scene bounds grown by this fraction of their extent per side")
        ->check(examples::detail::number_in(-0.4, 4, true, "a fraction"));
    app.add_option("--path", o.path, "x0 y0 z0 x1 y1 z1: the sphere's path in fractions of the volume's box")
        ->expected(6)
        ->check(examples::detail::number_in(0, 1, true, "a fraction"));
    app.add_option("--distance-ratio", o.distance_ratio, "split: harmonic mean distance < ratio * cell diagonal (0 off)")
        ->check(finite_non_negative);
    app.add_option("--neighbour-change", o.neighbour_change, "split: relative change between corners (0 off)")
        ->check(finite_non_negative);
    app.add_option("--geometry-triangles", o.geometry_triangles, "split: triangles in the cell (0 off)");
    app.add_option("--gradient-ratio", o.gradient_ratio, "split: |grad E| * edge / E (0 off)")->check(finite_non_negative);
    app.add_option("--cull", o.cull, "cull children within this fraction of the parent's interpolation (0 off)")
        ->check(finite_non_negative);
    app.add_option("--gradient-step", o.gradient_step, "central-difference step, fraction of the finest cell edge")
        ->check(finite_positive);
    app.add_option("--repeat", o.repeat, "lookup timing repeats (median)")->check(CLI::Range(1, 1000));
    app.add_option("--threads", o.threads, "TBB threads (0: all)")->check(CLI::Range(0, 1024));
    app.add_option("--json", o.json, "write the run report here");
    app.add_option("--out", o.out, "write a PNG strip of four frames here");
    app.add_flag("--sh-study", o.sh_study, "SH projection and irradiance errors per order of environments along the path");
    CLI11_PARSE(app, argc, argv);
    try {
        return run(o);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "irradiance_volume: %s\n", e.what());
        return 1;
    }
}
