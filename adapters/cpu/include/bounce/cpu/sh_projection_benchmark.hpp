#pragma once
/// \file sh_projection_benchmark.hpp
/// The speed of cpu::cube_map_sh_projector measured as a probe bake would use it (what
/// `sh_study` reports): `maps` cube maps of 6 x size^2 RGB texels projected back to back
/// onto 3 bands, beside a plain read (a sum) of the same data in the same run, the same
/// projection on one map's data over and over (cache-resident: compute alone), the portable
/// path, the binary16 texels with their own plain read, and the one-off table construction.
///
/// Each figure is the median of `repeat` runs of wall-clock and of process CPU time. On a
/// shared machine the wall clock includes the time other processes held the cores; CPU time
/// counts only this process's work (TBB's brief spinning included), so texels per
/// CPU-second is what the cores this process got delivered.

#include <bounce/cpu/sh_projection.hpp>
#include <bounce/errors.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace bounce::cpu {

/// What the benchmark projects and how often.
struct sh_projection_benchmark_settings {
    std::size_t maps = 1000;  ///< cube maps projected back to back (a probe bake), >= 1
    std::size_t size = 64;    ///< texels per face edge, 1 .. 4096
    int repeat = 5;           ///< timed runs per figure (the median is reported), >= 1
    /// Refuse (parameter_error naming "maps") when sh_projection_benchmark_bytes exceeds
    /// this many bytes; 0: no limit. Programs pass the memory available.
    std::uint64_t memory_limit_bytes = 0;
};

/// Wall-clock and process CPU time of one figure (medians, milliseconds).
struct benchmark_timing {
    double wall_ms = 0, cpu_ms = 0;
};

/// The figures of one run of benchmark_sh_projection.
struct sh_projection_benchmark_result {
    std::string path;  ///< the projector's row product: "avx2" or "portable"
    double texels = 0;                            ///< maps * 6 * size^2
    double float_bytes = 0, half_bytes = 0;       ///< the data read per projection
    std::size_t table_bytes = 0;                  ///< the projector's table
    benchmark_timing table, read, project, resident, portable, half_read, half_project;
    double checksum = 0, half_checksum = 0, first_coefficient = 0;  ///< keep the work observable
    double load_before = -1, load_after = -1;     ///< /proc/loadavg's 1-minute figure
};

/// Bytes the benchmark allocates for `maps` maps of `size`^2 faces: float and binary16
/// texels, views, coefficients and two projectors' tables.
inline double sh_projection_benchmark_bytes(std::size_t maps, std::size_t size) {
    const double texels = 6.0 * double(size) * double(size);
    const double per_map = texels * (12 + 6) + 3 * 6 * double(sizeof(image_view<const glm::vec3>)) + 9 * 12;
    return double(maps) * per_map + 2 * (texels * 9 * 4 + 32);
}

namespace detail {

inline double process_cpu_ms() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

template <class F>
benchmark_timing median_timing(int repeat, F&& f) {
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

inline double load_average() {
    std::ifstream in("/proc/loadavg");
    double l = -1;
    in >> l;
    return l;
}

// A sum over `maps` blocks of `words` values of type T each, 16 lanes wide (a plain read).
template <class Acc, class T>
double plain_read(const T* data, std::size_t maps, std::size_t words) {
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, maps, cube_map_sh_projector<3>::maps_per_task), 0.0,
        [&](const tbb::blocked_range<std::size_t>& r, double s) {
            for (std::size_t k = r.begin(); k < r.end(); ++k) {
                const T* p = data + k * words;
                Acc lane[16] = {};
                for (std::size_t j = 0; j + 16 <= words; j += 16)
                    for (std::size_t q = 0; q < 16; ++q) lane[q] += p[j + q];
                for (Acc x : lane) s += double(x);
            }
            return s;
        },
        [](double a, double b) { return a + b; });
}

}  // namespace detail

/// Runs the benchmark on synthetic maps (a sky-like hemisphere of radiance 1 about
/// (0.1, 0.2, 1), scaled a little per map). Throws parameter_error naming "maps", "size" or
/// "repeat" for values out of range, and "maps" (with the figure) when the data would need
/// more than settings.memory_limit_bytes.
inline sh_projection_benchmark_result benchmark_sh_projection(const sh_projection_benchmark_settings& s) {
    constexpr int L = 3;
    require(s.maps >= 1, "maps", "at least one cube map");
    require(s.size >= 1 && s.size <= 4096, "size", "cube-map size must be 1 to 4096 texels");
    require(s.repeat >= 1, "repeat", "at least one timed run");
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
    r.table = detail::median_timing(1, [&] { projector.emplace(n); });
    const cube_map_sh_projector<L> portable(n, sh_projection_path::portable);
    r.path = projector->path_name();
    r.table_bytes = projector->table_bytes();
    r.texels = double(maps) * 6 * double(face_texels);
    r.float_bytes = r.texels * 12;
    r.half_bytes = r.texels * 6;
    r.load_before = detail::load_average();
    r.read = detail::median_timing(s.repeat, [&] { r.checksum = detail::plain_read<float>(data.data(), maps, map_floats); });
    r.project = detail::median_timing(s.repeat, [&] { projector->project(views, out); });
    r.first_coefficient = out[0][0].x;
    r.resident = detail::median_timing(s.repeat, [&] { projector->project(resident, out); });
    r.portable = detail::median_timing(s.repeat, [&] { portable.project(views, out); });
    r.half_project = detail::median_timing(s.repeat, [&] { projector->project(half_views, out); });
    r.half_read = detail::median_timing(s.repeat, [&] {
        r.half_checksum =
            detail::plain_read<std::uint32_t>(reinterpret_cast<const std::uint16_t*>(half_data.data()), maps, map_floats);
    });
    r.load_after = detail::load_average();
    return r;
}

}  // namespace bounce::cpu
