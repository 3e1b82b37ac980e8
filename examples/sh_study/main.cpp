// sh_study: the SH toolkit measured.
//  1. Speed: SH projection (3 bands, RGB) of a probe bake's worth of 6 x size^2 cube maps
//     back to back with cpu::cube_map_sh_projector, beside a plain read (a sum) of the same
//     data in the same run, the same projection on cache-resident data (compute alone), the
//     portable path, and the one-off table construction.
//  2. Accuracy per order (1 .. 8): radiance truncation error (Parseval) and irradiance error
//     (max and mean over the sphere, relative to the peak) for a directional light, a uniform
//     sky and a cone light, from the closed-form coefficients and through a rasterized cube
//     map; the widest non-negative Hann window's cost on the directional light.
// --json PATH writes one object with the figures and provenance.
#include "../common/cli_number_checks.hpp"

#include <bounce/cpu/sh_projection.hpp>
#include <bounce/sh_gradients.hpp>
#include <bounce/sh_irradiance.hpp>
#include <bounce/sh_lights.hpp>
#include <bounce/sh_projection.hpp>
#include <bounce/sh_windowing.hpp>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <ctime>
#include <time.h>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

using namespace bounce;
using json = nlohmann::json;

namespace {

constexpr double pi = std::numbers::pi;

// ---- provenance --------------------------------------------------------------------------

std::string cpu_model() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
    return "unknown";
}

std::string source_commit() {
    std::string out;
    if (FILE* p = popen("git -C " BOUNCE_SOURCE_DIR " rev-parse --short HEAD 2>/dev/null", "r")) {
        char buf[64];
        while (std::fgets(buf, sizeof buf, p)) out += buf;
        pclose(p);
    }
    while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
    return out.empty() ? "unknown" : out;
}

std::string utc_now() {
    const std::time_t t = std::time(nullptr);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
    return buf;
}

// ---- environments ------------------------------------------------------------------------

// Every environment is symmetric about `axis`: a function of the cosine to it.
struct environment {
    std::string name;
    glm::dvec3 axis;
    double cos_half_angle;  // cone: radiance 1 inside; directional: unused
    bool directional;
};

// Exact irradiance at a normal whose cosine to the axis is `c`. Directional: max(0, c).
// Cone (the sky is the cone of half-angle 90 degrees): int over the cap of max(0, n . w),
// exactly in the azimuth (int_0^2pi max(0, a cos phi + b) dphi = 2 a sin phi0 + 2 b phi0,
// cos phi0 = -b / a) and by 64-node Gauss-Legendre in cos(beta) on each side of the kink
// where the horizon starts to cut the cap's rings.
double exact_irradiance(const environment& env, double c) {
    if (env.directional) return std::max(0.0, c);
    static const auto nodes = [] {
        std::vector<std::pair<double, double>> xw;
        const int n = 64;
        for (int i = 0; i < n; ++i) {
            double t = std::cos(pi * (i + 0.75) / (n + 0.5));
            for (int it = 0; it < 100; ++it) {
                double p0 = 1, p1 = t;
                for (int k = 2; k <= n; ++k) std::tie(p0, p1) = std::pair(p1, ((2 * k - 1) * t * p1 - (k - 1) * p0) / k);
                const double dp = n * (t * p1 - p0) / (t * t - 1);
                t -= p1 / dp;
                if (it > 5 && std::abs(p1 / dp) < 1e-16) break;
            }
            double p0 = 1, p1 = t;
            for (int k = 2; k <= n; ++k) std::tie(p0, p1) = std::pair(p1, ((2 * k - 1) * t * p1 - (k - 1) * p0) / k);
            const double dp = n * (t * p1 - p0) / (t * t - 1);
            xw.emplace_back(t, 2 / ((1 - t * t) * dp * dp));
        }
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
    auto integrate = [&](double lo, double hi) {
        double s = 0;
        for (const auto& [x, w] : nodes) s += 0.5 * (hi - lo) * w * ring(0.5 * (hi - lo) * x + 0.5 * (hi + lo));
        return s;
    };
    const double lo = env.cos_half_angle, kink = std::abs(st);  // rings with |b| = a: t = sin(theta_n)
    if (kink > lo && kink < 1) return integrate(lo, kink) + integrate(kink, 1);
    return integrate(lo, 1);
}

template <int L>
sh_coefficients<L, glm::dvec3> closed_form_coefficients(const environment& env) {
    if (env.directional) return sh_project_directional_light<L, glm::dvec3>(env.axis, glm::dvec3(1.0));
    return sh_project_cone_light<L, glm::dvec3>(env.axis, env.cos_half_angle, glm::dvec3(1.0));
}

// The environment rasterized into a size^2 cube map: radiance at each texel centre; the
// directional light goes into the texel that contains it, as irradiance / texel solid angle.
std::array<image<glm::vec3>, 6> rasterize(const environment& env, std::size_t n) {
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

struct error_row {
    double max_rel = 0, mean_rel = 0;
};

// Max and mean |E_sh - E| over the sphere relative to the peak of E, from the profile in
// c = cos(normal, axis) (uniform in c is uniform in area), 4001 midpoints.
template <int L>
error_row irradiance_error(const environment& env, const sh_coefficients<L, glm::dvec3>& c) {
    const glm::dvec3 a = env.axis, t = glm::normalize(glm::cross(a, std::abs(a.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
    const double peak = exact_irradiance(env, 1);
    error_row r;
    constexpr int n = 4001;
    for (int k = 0; k < n; ++k) {
        const double cz = -1 + 2 * (k + 0.5) / n, s = std::sqrt(1 - cz * cz);
        const double e = sh_irradiance<L, double, glm::dvec3>(c, cz * a + s * t).x;
        const double err = std::abs(e - exact_irradiance(env, cz)) / peak;
        r.max_rel = std::max(r.max_rel, err);
        r.mean_rel += err / n;
    }
    return r;
}

// Relative L2 error of the truncated radiance (Parseval): sqrt(1 - sum c^2 / int f^2).
template <int L>
double radiance_truncation_error(const environment& env, const sh_coefficients<L, glm::dvec3>& c) {
    if (env.directional) return INFINITY;  // a delta has infinite energy
    const double total = 2 * pi * (1 - env.cos_half_angle);
    double kept = 0;
    for (const auto& ci : c) kept += ci.x * ci.x;
    return std::sqrt(std::max(0.0, 1 - kept / total));
}

template <int L>
json accuracy_for_order(const environment& env, const std::array<image<glm::vec3>, 6>& raster) {
    const auto c = closed_form_coefficients<L>(env);
    const auto e = irradiance_error<L>(env, c);
    cube_map_view<const glm::vec3> view;
    for (int f = 0; f < 6; ++f) view.faces[std::size_t(f)] = raster[std::size_t(f)].view();
    const auto from_cube = sh_project_cube_map<L>(view);
    const auto ec = irradiance_error<L>(env, from_cube);
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
json accuracy_table(const environment& env, std::size_t cube_size, std::index_sequence<I...>) {
    const auto raster = rasterize(env, cube_size);
    return json::array({accuracy_for_order<int(I) + 2>(env, raster)...});
}

// ---- gradients ---------------------------------------------------------------------------

// Oat's extrapolation I + grad I . d against the probe re-projected at p + d, for a sphere
// light of radius 0.5 m whose centre is 3 m above the probe (order 2). Errors are the largest
// irradiance difference over 4096 normals, relative to the peak irradiance at p + d, for the
// stale probe (no gradient) and the extrapolated one.
json gradient_table() {
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
                err_extrapolated = std::max(err_extrapolated, std::abs(sh_irradiance<L, double, glm::dvec3>(extrapolated, n).x - e));
            }
            rows.push_back({{"direction", dir.x > 0 ? "sideways" : "towards the light"},
                            {"distance_m", distance},
                            {"step_m", step},
                            {"stale_max_rel", err_stale / peak},
                            {"extrapolated_max_rel", err_extrapolated / peak}});
        }
    return rows;
}

// ---- timing ------------------------------------------------------------------------------

// Wall-clock and process CPU time of one run. On a shared machine the wall clock includes
// the time other processes held the cores; CPU time counts only this process's work (TBB's
// brief spinning included), so texels per CPU-second is what one core delivers.
struct timing {
    double wall_ms = 0, cpu_ms = 0;
};

double process_cpu_ms() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

// The medians of `repeat` runs (wall and CPU separately).
template <class F>
timing median_timing(int repeat, F&& f) {
    std::vector<double> wall, cpu;
    for (int r = 0; r < repeat; ++r) {
        const double c0 = process_cpu_ms();
        const auto t0 = std::chrono::steady_clock::now();
        f();
        wall.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        cpu.push_back(process_cpu_ms() - c0);
    }
    std::sort(wall.begin(), wall.end());
    std::sort(cpu.begin(), cpu.end());
    return {wall[wall.size() / 2], cpu[cpu.size() / 2]};
}

double load_average() {
    std::ifstream in("/proc/loadavg");
    double l = -1;
    in >> l;
    return l;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"sh_study: speed and accuracy of the SH toolkit (projection, irradiance, windowing)"};
    std::size_t maps = 1000, size = 64;
    int repeat = 5, threads = 0;
    std::string json_path;
    app.add_option("--maps", maps, "cube maps projected back to back (a probe bake)")->check(CLI::Range(1, 100000));
    app.add_option("--size", size, "texels per cube-face edge")->check(CLI::Range(1, 1024));
    app.add_option("--repeat", repeat, "timed runs per figure (the median is reported)")->check(CLI::Range(1, 1000));
    app.add_option("--threads", threads, "TBB threads (0: all)")->check(CLI::Range(0, 1024));
    app.add_option("--json", json_path, "write the figures and provenance to this file");
    CLI11_PARSE(app, argc, argv);

    const int used_threads = threads > 0 ? threads : tbb::info::default_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(used_threads));

    // ---- speed ----
    constexpr int L = 3;
    const std::size_t face_texels = size * size, map_floats = 6 * face_texels * 3;
    std::vector<float> data(maps * map_floats);
    {
        const environment sky{"sky", glm::normalize(glm::dvec3(0.1, 0.2, 1)), 0.0, false};
        const auto faces = rasterize(sky, size);
        for (std::size_t k = 0; k < maps; ++k)
            for (int f = 0; f < 6; ++f)
                for (std::size_t t = 0; t < face_texels; ++t)
                    for (int c = 0; c < 3; ++c)
                        data[k * map_floats + (std::size_t(f) * face_texels + t) * 3 + std::size_t(c)] =
                            faces[std::size_t(f)].data()[t][c] * (1.f + 1e-3f * float(k % 97)) + 0.01f * float(c);
    }
    auto views_of = [&](bool same_map) {
        std::vector<cube_map_view<const glm::vec3>> v(maps);
        for (std::size_t k = 0; k < maps; ++k)
            for (int f = 0; f < 6; ++f) {
                const float* p = data.data() + (same_map ? 0 : k) * map_floats + std::size_t(f) * face_texels * 3;
                v[k].faces[std::size_t(f)] = image_view<const glm::vec3>(reinterpret_cast<const glm::vec3*>(p), size, size);
            }
        return v;
    };
    const auto views = views_of(false), resident = views_of(true);
    // The same maps as binary16 (what an RGB16F render target reads back as): half the bytes.
    std::vector<cpu::half_rgb> half_data(maps * map_floats / 3);
    for (std::size_t t = 0; t < half_data.size(); ++t)
        for (int c = 0; c < 3; ++c) half_data[t].bits[c] = cpu::float_to_half(data[3 * t + std::size_t(c)]);
    std::vector<cube_map_view<const cpu::half_rgb>> half_views(maps);
    for (std::size_t k = 0; k < maps; ++k)
        for (int f = 0; f < 6; ++f)
            half_views[k].faces[std::size_t(f)] =
                image_view<const cpu::half_rgb>(half_data.data() + (k * 6 + std::size_t(f)) * face_texels, size, size);
    std::vector<sh_coefficients<L, glm::vec3>> out(maps);

    std::optional<cpu::cube_map_sh_projector<L>> projector;
    const timing table = median_timing(1, [&] { projector.emplace(size); });
    const cpu::cube_map_sh_projector<L> portable(size, cpu::sh_projection_path::portable);

    double checksum = 0;
    const double load_before = load_average();
    const timing read = median_timing(repeat, [&] {
        checksum = tbb::parallel_reduce(
            tbb::blocked_range<std::size_t>(0, maps, cpu::cube_map_sh_projector<L>::maps_per_task), 0.0,
            [&](const tbb::blocked_range<std::size_t>& r, double s) {
                for (std::size_t k = r.begin(); k < r.end(); ++k) {
                    const float* p = data.data() + k * map_floats;
                    float lane[16] = {};
                    for (std::size_t j = 0; j + 16 <= map_floats; j += 16)
                        for (int q = 0; q < 16; ++q) lane[q] += p[j + std::size_t(q)];
                    for (float x : lane) s += x;
                }
                return s;
            },
            [](double a, double b) { return a + b; });
    });
    const timing project = median_timing(repeat, [&] { projector->project(views, out); });
    const double first_coefficient = out[0][0].x;
    const timing resident_run = median_timing(repeat, [&] { projector->project(resident, out); });
    const timing portable_run = median_timing(repeat, [&] { portable.project(views, out); });
    const timing half_run = median_timing(repeat, [&] { projector->project(half_views, out); });
    double half_checksum = 0;
    const timing half_read = median_timing(repeat, [&] {
        half_checksum = tbb::parallel_reduce(
            tbb::blocked_range<std::size_t>(0, maps, cpu::cube_map_sh_projector<L>::maps_per_task), 0.0,
            [&](const tbb::blocked_range<std::size_t>& r, double s) {
                const std::size_t per_map = map_floats;  // 16-bit words per map
                for (std::size_t k = r.begin(); k < r.end(); ++k) {
                    const auto* p = reinterpret_cast<const std::uint16_t*>(half_data.data()) + k * per_map;
                    std::uint32_t lane[16] = {};
                    for (std::size_t j = 0; j + 16 <= per_map; j += 16)
                        for (int q = 0; q < 16; ++q) lane[q] += p[j + std::size_t(q)];
                    for (auto x : lane) s += double(x);
                }
                return s;
            },
            [](double a, double b) { return a + b; });
    });
    const double load_after = load_average();

    const double texels = double(maps) * 6 * double(face_texels);
    double bytes = texels * 12;
    auto per_s = [](double count, double ms) { return count / (ms * 1e-3); };
    fmt::print("SH projection, {} bands RGB, {} maps of 6 x {}^2 texels ({:.0f} MB), {} threads, {} path\n", L, maps, size,
               bytes / 1e6, used_threads, projector->path_name());
    fmt::print("  load average {:.2f} before, {:.2f} after (other processes share the cores: compare CPU time)\n", load_before,
               load_after);
    fmt::print("  {:<32} {:>9} {:>9} {:>9} {:>7} {:>13}\n", "", "wall ms", "Gtexel/s", "GB/s", "CPU ms", "Gtexel/CPU-s");
    auto line = [&](const char* what, const timing& t) {
        fmt::print("  {:<32} {:>9.2f} {:>9.3f} {:>9.2f} {:>7.1f} {:>13.3f}\n", what, t.wall_ms, per_s(texels, t.wall_ms) / 1e9,
                   per_s(bytes, t.wall_ms) / 1e9, t.cpu_ms, per_s(texels, t.cpu_ms) / 1e9);
    };
    line("plain read (sum)", read);
    line("SH projection", project);
    line("SH projection, data in cache", resident_run);
    line("SH projection, portable path", portable_run);
    const double float_bytes = bytes;
    bytes = texels * 6;
    line("plain read, half texels (sum)", half_read);
    line("SH projection, half texels", half_run);
    bytes = float_bytes;
    fmt::print("  table construction (once per size): {:.2f} ms, {:.1f} MB\n", table.wall_ms, double(projector->table_bytes()) / 1e6);
    fmt::print("  checksums: sum {:.6g}, half sum {:.6g}, c00 of map 0 {:.6g}\n\n", checksum, half_checksum, first_coefficient);

    // ---- accuracy ----
    const std::vector<environment> envs = {
        {"directional", glm::normalize(glm::dvec3(0.3, -0.5, 0.8)), 1.0, true},
        {"sky", glm::normalize(glm::dvec3(0.3, -0.5, 0.8)), 0.0, false},
        {"cone-20deg", glm::normalize(glm::dvec3(0.3, -0.5, 0.8)), std::cos(20 * pi / 180), false},
    };
    json accuracy = json::object();
    for (const auto& env : envs) {
        const json rows = accuracy_table(env, size, std::make_index_sequence<8>{});
        accuracy[env.name] = rows;
        fmt::print("{}: irradiance error relative to the peak (closed-form coefficients | via a {}^2 cube map)\n", env.name, size);
        fmt::print("  order coeffs   max      mean   |   max      mean   | radiance L2\n");
        for (const auto& r : rows) {
            fmt::print("  {:>5} {:>6} {:>8.5f} {:>8.5f} | {:>8.5f} {:>8.5f} | {}\n", r["order"].get<int>(),
                       r["coefficients"].get<int>(), r["irradiance_max_rel"].get<double>(), r["irradiance_mean_rel"].get<double>(),
                       r["cube_irradiance_max_rel"].get<double>(), r["cube_irradiance_mean_rel"].get<double>(),
                       r["radiance_rel_l2"].is_null() ? std::string("-") : fmt::format("{:.4f}", r["radiance_rel_l2"].get<double>()));
            if (r.contains("hann_nonnegative")) {
                const auto& h = r["hann_nonnegative"];
                fmt::print("        widest non-negative Hann: w = {:.3f}, energy kept {:.3f}, peak kept {:.3f}, max {:.5f}, mean {:.5f}\n",
                           h["width"].get<double>(), h["energy_kept"].get<double>(), h["peak_kept"].get<double>(),
                           h["irradiance_max_rel"].get<double>(), h["irradiance_mean_rel"].get<double>());
            }
        }
    }

    const json gradients = gradient_table();
    fmt::print("gradients: sphere light r = 0.5 m, 3 m above the probe, order 2, step 0.1 m; max irradiance error / peak\n");
    for (const auto& r : gradients)
        fmt::print("  {:<18} d = {:.2f} m: stale probe {:.4f}, extrapolated {:.4f}\n", r["direction"].get<std::string>(),
                   r["distance_m"].get<double>(), r["stale_max_rel"].get<double>(), r["extrapolated_max_rel"].get<double>());

    if (!json_path.empty()) {
        json report = {
            {"technique", "sh"},
            {"backend", "cpu"},
            {"parameters", {{"bands", L}, {"maps", maps}, {"size", size}, {"repeat", repeat}, {"threads", used_threads},
                            {"path", projector->path_name()}}},
            {"timings_ms", {{"table", table.wall_ms}, {"plain_read", read.wall_ms}, {"projection", project.wall_ms},
                            {"projection_cache_resident", resident_run.wall_ms}, {"projection_portable", portable_run.wall_ms},
                            {"plain_read_half", half_read.wall_ms}, {"projection_half", half_run.wall_ms}}},
            {"cpu_ms", {{"plain_read", read.cpu_ms}, {"projection", project.cpu_ms},
                        {"projection_cache_resident", resident_run.cpu_ms}, {"projection_portable", portable_run.cpu_ms},
                        {"plain_read_half", half_read.cpu_ms}, {"projection_half", half_run.cpu_ms}}},
            {"throughput", {{"projection_texels_per_s", per_s(texels, project.wall_ms)},
                            {"projection_gb_per_s", per_s(bytes, project.wall_ms) / 1e9},
                            {"plain_read_texels_per_s", per_s(texels, read.wall_ms)},
                            {"plain_read_gb_per_s", per_s(bytes, read.wall_ms) / 1e9},
                            {"cache_resident_texels_per_s", per_s(texels, resident_run.wall_ms)},
                            {"portable_texels_per_s", per_s(texels, portable_run.wall_ms)},
                            {"projection_texels_per_cpu_s", per_s(texels, project.cpu_ms)},
                            {"plain_read_texels_per_cpu_s", per_s(texels, read.cpu_ms)},
                            {"cache_resident_texels_per_cpu_s", per_s(texels, resident_run.cpu_ms)},
                            {"half_projection_texels_per_s", per_s(texels, half_run.wall_ms)},
                            {"half_plain_read_texels_per_s", per_s(texels, half_read.wall_ms)},
                            {"half_projection_texels_per_cpu_s", per_s(texels, half_run.cpu_ms)}}},
            {"load_average", {{"before", load_before}, {"after", load_after}}},
            {"error", accuracy},
            {"gradients", gradients},
            {"provenance", {{"cpu", cpu_model()}, {"cores", std::thread::hardware_concurrency()}, {"date", utc_now()},
                            {"commit", source_commit()}}},
        };
        std::ofstream(json_path) << report.dump(2) << '\n';
    }
    return 0;
}
