#pragma once
/// \file sh_projection_benchmark.hpp
/// The speed of cpu::cube_map_sh_projector measured as a probe bake would use it (what
/// `sh_study` reports): `maps` cube maps of 6 x size^2 RGB texels projected back to back
/// onto 3 bands, float and binary16 texels, on 1 thread and on `threads`, each beside a
/// streaming read of the same bytes in the same run (the memory ceiling the projection is
/// measured against); the projection of one map's data over and over (cache-resident:
/// compute alone); the AVX2 and the portable paths; the one-off table construction.
///
/// Each figure is the best and the median of `repeat` runs of wall-clock and of process
/// CPU time. On a shared machine the wall clock includes the time other processes held the
/// cores; CPU time counts only this process's work (TBB's brief spinning included), so
/// texels per CPU-second is what the cores this process got delivered.

#include <bounce/cpu/sh_projection.hpp>
#include <bounce/errors.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace bounce::cpu {

/// What the benchmark projects and how often.
struct sh_projection_benchmark_settings {
    std::size_t maps = 1000;  ///< cube maps projected back to back (a probe bake), >= 1
    std::size_t size = 64;    ///< texels per face edge, 1 .. 4096
    int repeat = 5;           ///< timed runs per figure (the best and the median are reported), >= 1
    int threads = 2;          ///< the most threads (figures at 1 and at this many), >= 1
    /// Refuse (parameter_error naming "maps") when sh_projection_benchmark_bytes exceeds
    /// this many bytes; 0: no limit. Programs pass the memory available.
    std::uint64_t memory_limit_bytes = 0;
};

/// Wall-clock and process CPU time of one figure over `repeat` runs (milliseconds): the
/// medians, and the fastest run (with its CPU time).
struct benchmark_timing {
    double wall_ms = 0, cpu_ms = 0, best_wall_ms = 0, best_cpu_ms = 0;
};

/// One measured figure: what ran, on how many threads, the bytes it read.
struct sh_projection_benchmark_figure {
    std::string name;  ///< read_float, read_half, project_float, project_half, project_float_resident,
                       ///< project_float_avx2, project_float_portable
    int threads = 1;
    double bytes = 0;
    benchmark_timing timing;
};

/// The figures of one run of benchmark_sh_projection.
struct sh_projection_benchmark_result {
    std::string path;  ///< the projector's code: "avx512", "avx2" or "portable"
    double texels = 0;                            ///< maps * 6 * size^2
    std::size_t table_bytes = 0;                  ///< the projector's table
    double table_ms = 0;                          ///< building the projector (once per size)
    std::vector<sh_projection_benchmark_figure> figures;
    double checksum = 0, first_coefficient = 0;   ///< keep the work observable
    double load_before = -1, load_after = -1;     ///< /proc/loadavg's 1-minute figure
};

/// Bytes the benchmark allocates for `maps` maps of `size`^2 faces: float and binary16
/// texels, views, coefficients and three projectors' tables.
inline double sh_projection_benchmark_bytes(std::size_t maps, std::size_t size) {
    const double texels = 6.0 * double(size) * double(size);
    const double per_map = texels * (12 + 6) + 3 * 6 * double(sizeof(image_view<const glm::vec3>)) + 9 * 12;
    return double(maps) * per_map + 3 * (texels / 6 * 9 * 4 + 64);
}

namespace detail {

inline double process_cpu_ms() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

template <class F>
benchmark_timing timing_of(int repeat, F&& f) {
    std::vector<double> wall, cpu;
    benchmark_timing t;
    t.best_wall_ms = 1e300;
    for (int r = 0; r < repeat; ++r) {
        const double c0 = process_cpu_ms();
        const auto t0 = std::chrono::steady_clock::now();
        f();
        wall.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        cpu.push_back(process_cpu_ms() - c0);
        if (wall.back() < t.best_wall_ms) {
            t.best_wall_ms = wall.back();
            t.best_cpu_ms = cpu.back();
        }
    }
    std::sort(wall.begin(), wall.end());
    std::sort(cpu.begin(), cpu.end());
    t.wall_ms = wall[wall.size() / 2];
    t.cpu_ms = cpu[cpu.size() / 2];
    return t;
}

inline double load_average() {
    std::ifstream in("/proc/loadavg");
    double l = -1;
    in >> l;
    return l;
}

// A streaming read of `bytes` bytes (a multiple of 64) as 64-bit words summed in 8 lanes,
// in blocks of 256 KB over the arena's threads: the memory ceiling of a pass over the data.
inline double stream_read(const unsigned char* data, std::size_t bytes) {
    constexpr std::size_t block = 256 * 1024;
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, (bytes + block - 1) / block), 0.0,
        [&](const tbb::blocked_range<std::size_t>& r, double s) {
            for (std::size_t k = r.begin(); k < r.end(); ++k) {
                const std::size_t end = std::min(bytes, (k + 1) * block);
                std::uint64_t lane[8] = {};
                for (std::size_t at = k * block; at + 64 <= end; at += 64)
                    for (std::size_t q = 0; q < 8; ++q) {
                        std::uint64_t word;
                        std::memcpy(&word, data + at + 8 * q, 8);
                        lane[q] += word;
                    }
                for (const std::uint64_t x : lane) s += double(x & 0xffff);
            }
            return s;
        },
        [](double a, double b) { return a + b; });
}

}  // namespace detail

/// Runs the benchmark on synthetic maps (a sky-like hemisphere of radiance 1 about
/// (0.1, 0.2, 1), scaled a little per map): the streaming read of the float and the
/// binary16 texels and their projection, each on 1 thread and on settings.threads; on the
/// most threads also the projection of one map's data over and over (cache-resident:
/// compute alone) and the AVX2 and portable paths. Throws parameter_error naming "maps",
/// "size", "repeat" or "threads" for values out of range, and "maps" (with the figure) when
/// the data would need more than settings.memory_limit_bytes.
inline sh_projection_benchmark_result benchmark_sh_projection(const sh_projection_benchmark_settings& s) {
    constexpr int L = 3;
    require(s.maps >= 1, "maps", "at least one cube map");
    require(s.size >= 1 && s.size <= 4096, "size", "cube-map size must be 1 to 4096 texels");
    require(s.repeat >= 1, "repeat", "at least one timed run");
    require(s.threads >= 1, "threads", "at least one thread");
    const double need = sh_projection_benchmark_bytes(s.maps, s.size);
    if (s.memory_limit_bytes > 0 && need > double(s.memory_limit_bytes)) {
        char text[256];
        const bool tera = need >= 1e12;
        std::snprintf(text, sizeof text, "%zu cube maps of 6 x %zu^2 texels need %.3g %s, more than the %.3g GB available: "
                      "choose fewer maps or a smaller size", s.maps, s.size, need / (tera ? 1e12 : 1e9), tera ? "TB" : "GB",
                      double(s.memory_limit_bytes) / 1e9);
        throw parameter_error("maps", text);
    }
    const std::size_t n = s.size, maps = s.maps, face_texels = n * n, map_floats = 6 * face_texels * 3;
    std::vector<float> data(maps * map_floats);
    {
        const glm::dvec3 axis = glm::normalize(glm::dvec3(0.1, 0.2, 1));
        for (int f = 0; f < 6; ++f)
            for (std::size_t t = 0; t < face_texels; ++t) {
                const bool lit = glm::dot(cube_texel_direction(cube_face(f), n, t % n, t / n), axis) >= 0;
                for (std::size_t k = 0; k < maps; ++k)
                    for (int c = 0; c < 3; ++c)
                        data[k * map_floats + (std::size_t(f) * face_texels + t) * 3 + std::size_t(c)] =
                            (lit ? 1.f : 0.f) * (1.f + 1e-3f * float(k % 97)) + 0.01f * float(c);
            }
    }
    auto views_of = [&](bool same_map) {
        std::vector<cube_map_view<const glm::vec3>> v(maps);
        for (std::size_t k = 0; k < maps; ++k)
            for (int f = 0; f < 6; ++f) {
                const float* p = data.data() + (same_map ? 0 : k) * map_floats + std::size_t(f) * face_texels * 3;
                v[k].faces[std::size_t(f)] = image_view<const glm::vec3>(reinterpret_cast<const glm::vec3*>(p), n, n);
            }
        return v;
    };
    const auto views = views_of(false), resident = views_of(true);
    // The same maps as binary16 (what an RGB16F render target reads back as): half the bytes.
    std::vector<half_rgb> half_data(maps * map_floats / 3);
    for (std::size_t t = 0; t < half_data.size(); ++t)
        for (int c = 0; c < 3; ++c) half_data[t].bits[c] = float_to_half(data[3 * t + std::size_t(c)]);
    std::vector<cube_map_view<const half_rgb>> half_views(maps);
    for (std::size_t k = 0; k < maps; ++k)
        for (int f = 0; f < 6; ++f)
            half_views[k].faces[std::size_t(f)] =
                image_view<const half_rgb>(half_data.data() + (k * 6 + std::size_t(f)) * face_texels, n, n);
    std::vector<sh_coefficients<L, glm::vec3>> out(maps);

    sh_projection_benchmark_result r;
    std::optional<cube_map_sh_projector<L>> projector;
    r.table_ms = detail::timing_of(1, [&] { projector.emplace(n); }).wall_ms;
    const cube_map_sh_projector<L> avx2(n, sh_projection_path::avx2), portable(n, sh_projection_path::portable);
    r.path = projector->path_name();
    r.table_bytes = projector->table_bytes();
    r.texels = double(maps) * 6 * double(face_texels);
    const double float_bytes = r.texels * 12, half_bytes = r.texels * 6;
    r.load_before = detail::load_average();
    auto measure = [&](const char* name, int threads, double bytes, auto&& f) {
        tbb::task_arena arena(threads);
        r.figures.push_back({name, threads, bytes, arena.execute([&] { return detail::timing_of(s.repeat, f); })});
    };
    const auto* float_data = reinterpret_cast<const unsigned char*>(data.data());
    const auto* half_bytes_data = reinterpret_cast<const unsigned char*>(half_data.data());
    for (const int threads : {1, s.threads}) {
        if (threads == 1 && s.threads == 1 && !r.figures.empty()) break;
        measure("read_float", threads, float_bytes, [&] { r.checksum += detail::stream_read(float_data, std::size_t(float_bytes)); });
        measure("project_float", threads, float_bytes, [&] { projector->project(views, out); });
        measure("read_half", threads, half_bytes, [&] { r.checksum += detail::stream_read(half_bytes_data, std::size_t(half_bytes)); });
        measure("project_half", threads, half_bytes, [&] { projector->project(half_views, out); });
    }
    r.first_coefficient = out[0][0].x;
    measure("project_float_resident", s.threads, float_bytes, [&] { projector->project(resident, out); });
    measure("project_float_avx2", s.threads, float_bytes, [&] { avx2.project(views, out); });
    measure("project_float_portable", s.threads, float_bytes, [&] { portable.project(views, out); });
    r.load_after = detail::load_average();
    return r;
}

}  // namespace bounce::cpu
