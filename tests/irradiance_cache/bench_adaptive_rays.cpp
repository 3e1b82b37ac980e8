// A measurement, not a test (hidden: [.benchmark]): one frame of the CPU irradiance cache on
// a shared scene with fixed and adaptive rays per record, its indirect error against a
// reference of two independent halves (whose own noise is taken out), its records and rays.
//
//   BOUNCE_BENCH="fixed:1024 adaptive:256:4096:0.04" BOUNCE_BENCH_SCENE=sponza
//   BOUNCE_BENCH_SIZE=128 BOUNCE_BENCH_REF_SPP=2048 build/bin/test_adaptive_rays "[.benchmark]"
//
// Each entry: fixed:RAYS, or adaptive:MIN:MAX:TARGET[:FLOOR]. a = 0.15, smoothed Ward
// weight, gradients, neighbour clamping, radius in [1.5, 64] pixel footprints: the
// defaults of ic_splatting. References are kept in the system's temporary folder.
#include <bounce/cache/adaptive_hemisphere.hpp>
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/luminance.hpp>
#include <bounce/cache/weighting.hpp>

#include "../skip.hpp"

#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <filesystem>
#include <mutex>
#include <numeric>
#include <span>

#include <tbb/parallel_for.h>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace bounce;

namespace {

std::string env_or(const char* name, const char* fallback) {
    const char* v = std::getenv(name);
    return v && *v ? v : fallback;
}

image<glm::vec3> cached_indirect(const embree::accel& bvh, const io::scene& scene, const gbuffer_view<float>& g,
                                 std::uint32_t spp, std::uint64_t seed, const std::string& tag) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("bounce-adaptive-ref-" + tag + "-" + std::to_string(g.width()) + "-" + std::to_string(spp) + "-" +
                       std::to_string(seed) + ".bin");
    image<glm::vec3> out(g.width(), g.height());
    const std::size_t bytes = g.width() * g.height() * sizeof(glm::vec3);
    if (std::ifstream in(path, std::ios::binary); in && std::filesystem::file_size(path) == bytes) {
        in.read(reinterpret_cast<char*>(out.data()), std::streamsize(bytes));
        return out;
    }
    embree::reference_settings s;
    s.hemisphere_samples = spp;
    s.seed = seed;
    const embree::reference_integrator ri(bvh, scene, s);
    out = ri.indirect_image(g);
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(out.data()), std::streamsize(bytes));
    return out;
}

double lum(const glm::vec3& c) { return rec709_luminance<double, glm::dvec3>(glm::dvec3(c)); }

}  // namespace

TEST_CASE("adaptive rays per record against fixed ones: error, records and rays of one frame", "[.benchmark]") {
    const std::string name = env_or("BOUNCE_BENCH_SCENE", "sponza");
    const std::size_t size = std::stoul(env_or("BOUNCE_BENCH_SIZE", "128"));
    const std::uint32_t ref_spp = std::uint32_t(std::stoul(env_or("BOUNCE_BENCH_REF_SPP", "2048")));
    const float a = std::stof(env_or("BOUNCE_BENCH_A", "0.15"));
    std::optional<io::scene> loaded;
    try {
        loaded.emplace(io::load_scene_arg(name));
    } catch (const std::exception& e) {
        test::skip(std::string("scene not found: ") + e.what());
        return;
    }
    const io::scene& scene = *loaded;
    const embree::accel bvh(scene);
    embree::reference_settings rs;
    rs.hemisphere_samples = 64;
    const embree::reference_integrator integrator(bvh, scene, rs);
    gbuffer<float> g = embree::ray_cast_gbuffer(bvh, scene, scene.camera, size, size);
    // Two independent halves: R = (A + B) / 2, whose own squared error is mean |A - B|^2 / 4.
    const image<glm::vec3> ra = cached_indirect(bvh, scene, g.view(), ref_spp / 2, 11, name);
    const image<glm::vec3> rb = cached_indirect(bvh, scene, g.view(), ref_spp / 2, 12, name);
    double ref2 = 0, half_diff2 = 0;
    std::size_t pixels = 0;
    for (std::size_t y = 0; y < size; ++y)
        for (std::size_t x = 0; x < size; ++x) {
            if (!g.view().covered(x, y)) continue;
            const double r = 0.5 * (lum(ra(x, y)) + lum(rb(x, y)));
            ref2 += r * r;
            half_diff2 += (lum(ra(x, y)) - lum(rb(x, y))) * (lum(ra(x, y)) - lum(rb(x, y)));
            ++pixels;
        }
    const double ref_own2 = half_diff2 / 4 / ref2;  // relative, squared
    std::printf("%s %zux%zu, reference %u spp: own rel_rms %.4f over %zu pixels; a = %.2f\n", name.c_str(), size, size,
                ref_spp, std::sqrt(ref_own2), pixels, a);

    std::istringstream configs(env_or("BOUNCE_BENCH", "fixed:1024 adaptive:256:4096:0.04"));
    for (std::string entry; configs >> entry;) {
        std::vector<std::string> f;
        std::stringstream ss(entry);
        for (std::string part; std::getline(ss, part, ':');) f.push_back(part);
        radius_limits limits;
        limits.min_pixels = 1.5f;
        limits.max_pixels = 64.f;
        std::optional<embree::record_sampler> sampler;
        if (f.at(0) == "fixed") {
            sampler.emplace(integrator, embree::hemisphere_grid_for(std::uint32_t(std::stoul(f.at(1)))), limits);
        } else {
            adaptive_rays ar;
            ar.enabled = true;
            ar.min_rays = std::uint32_t(std::stoul(f.at(1)));
            ar.max_rays = std::uint32_t(std::stoul(f.at(2)));
            ar.target = std::stod(f.at(3));
            if (f.size() > 4) ar.irradiance_floor = std::stod(f.at(4));
            sampler.emplace(integrator, ar, limits);
        }
        cpu::irradiance_cache_options o;
        o.splat.a = a;
        o.neighbour_clamp = true;
        const auto [lo, hi] = scene.bounds();
        cpu::irradiance_cache<ward_smooth_weight> cache(lo, hi, o);
        image<glm::vec3> indirect(size, size);
        const auto t0 = std::chrono::steady_clock::now();
        // Every record's irradiance and rays, for their distribution.
        std::mutex mutex;
        std::vector<std::pair<double, std::uint32_t>> seen;
        auto measuring = [&](std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                             std::span<const double> footprints, std::span<std::optional<irradiance_record>> out) {
            tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t k) {
                std::uint32_t r = 0;
                out[k] = sampler->measure(points[k], normals[k], footprints[k], &r);
                const std::lock_guard lock(mutex);
                seen.emplace_back(out[k] ? lum(out[k]->irradiance) : 0.0, r);
            });
        };
        const cpu::cache_frame_stats st = cache.render(g.view(), scene.camera, measuring, indirect.view());
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        double err2 = 0;
        for (std::size_t y = 0; y < size; ++y)
            for (std::size_t x = 0; x < size; ++x) {
                if (!g.view().covered(x, y)) continue;
                const double r = 0.5 * (lum(ra(x, y)) + lum(rb(x, y)));
                const double d = lum(indirect(x, y)) - r;
                err2 += d * d;
            }
        const double rel = std::sqrt(err2 / ref2);
        const auto t = sampler->rays_cast();
        std::printf("%-28s records %6zu  rays/record %7.1f (min %u, max %u)  total rays %9llu  records %8.1f ms  "
                    "frame %8.1f ms  rel_rms %.4f  without the reference's noise %.4f\n",
                    entry.c_str(), cache.records().size(), t.mean(), t.fewest, t.most,
                    static_cast<unsigned long long>(t.rays), st.records_ms, ms, rel,
                    std::sqrt(std::max(0.0, rel * rel - ref_own2)));
        std::fflush(stdout);
        // Rays against irradiance: quartiles of E, and the mean rays in each quarter.
        std::sort(seen.begin(), seen.end());
        const std::size_t q = seen.size() / 4;
        std::printf("    E quartiles %.3g %.3g %.3g (mean %.3g); mean rays per quarter of E:", seen[q].first,
                    seen[2 * q].first, seen[3 * q].first,
                    std::accumulate(seen.begin(), seen.end(), 0.0, [](double t, const auto& e) { return t + e.first; }) /
                        double(seen.size()));
        for (int k = 0; k < 4; ++k) {
            double sum = 0;
            for (std::size_t i = std::size_t(k) * q; i < std::size_t(k + 1) * q; ++i) sum += seen[i].second;
            std::printf(" %.0f", sum / double(q));
        }
        std::size_t early = 0;
        double early_e = 0;
        for (const auto& [e, r] : seen)
            if (r < t.most / 2) {
                ++early;
                early_e += e;
            }
        std::printf("; %zu stopped below half the most (mean E %.3g)\n", early, early ? early_e / double(early) : 0.0);
        CHECK(std::isfinite(rel));
    }
}

