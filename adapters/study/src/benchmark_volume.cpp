// The benchmark's irradiance volume: an adaptive octree of SH probes baked by
// embree::probe_baker, looked up at the volume's points off the view's surfaces.
#include <bounce/study/benchmark_parts.hpp>

#include <bounce/cpu/irradiance_volume.hpp>
#include <bounce/embree/probe_baker.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/volume/probe_octree.hpp>
#include <bounce/direct_light.hpp>
#include <bounce/study/stage_timer.hpp>

#include <fmt/core.h>

#include <algorithm>
#include <vector>

namespace bounce::study::bench {

technique_run run_irradiance_volume(const scene_setup& s, const gbuffer_view<float>& points) {
    // irradiance_volume's defaults (examples/irradiance_volume/main.cpp): an adaptive octree
    // of depth 1 to 4 with Oat's heuristics as irradiance_volume_settings has them, over the
    // scene's bounds shrunk by 1% of their extent per side, 512 rays per probe, gradients by
    // central differences a tenth of the finest cell's shortest edge apart (kept where they
    // stand out of their noise), looked up trilinearly.
    constexpr int max_depth = 4;
    constexpr float margin = -0.01f, gradient_step = 0.1f;
    constexpr std::uint32_t rays = 512;
    const std::string name(technique_name(bench_technique::irradiance_volume));

    auto [lo, hi] = s.scene.bounds();
    const glm::vec3 extent = hi - lo;
    lo -= margin * extent;
    hi += margin * extent;
    irradiance_volume_settings vs;
    vs.max_depth = max_depth;
    vs.min_depth = 1;
    const glm::vec3 finest = (hi - lo) / float(1 << max_depth);
    embree::reference_settings rs;
    rs.seed = 1;
    const embree::reference_integrator light(s.bvh, s.scene, rs);
    embree::probe_baker_settings bs;
    bs.rays = rays;
    bs.gradient_step = gradient_step * std::min({finest.x, finest.y, finest.z});
    std::size_t batch = 0;
    auto last_report = std::chrono::steady_clock::now();
    bs.progress = [&](std::size_t done, std::size_t total) {  // serialized by the baker
        if (done == total) ++batch;
        if (ms_since(last_report) < 2000) return;
        last_report = std::chrono::steady_clock::now();
        s.clock.report(name, fmt::format("bake: level batch {}, {} of {} probes", batch, done, total));
    };
    s.clock.report(name, "bake");
    const embree::probe_baker baker(light, s.bvh, s.scene, bs);
    irradiance_volume_build_stats stats;
    const auto t0 = std::chrono::steady_clock::now();
    const irradiance_volume volume = irradiance_volume::build(s.scene, lo, hi, vs, baker, &stats);
    const double bake_ms = ms_since(t0);

    s.clock.report(name, "lookups");
    std::vector<glm::vec3> p, n, e;
    std::vector<std::size_t> pixel;
    for (std::size_t y = 0; y < points.height(); ++y)
        for (std::size_t x = 0; x < points.width(); ++x)
            if (points.covered(x, y)) {
                p.push_back(points.position(x, y));
                n.push_back(points.normal(x, y));
                pixel.push_back(y * points.width() + x);
            }
    e.resize(p.size());
    const auto t1 = std::chrono::steady_clock::now();
    cpu::light_points(volume, p, n, e, cpu::volume_lookup{cpu::volume_interpolation::trilinear, {}});
    const double lookup_ms = ms_since(t1);

    technique_run r;
    r.technique = bench_technique::irradiance_volume;
    r.quantity = bench_quantity::volume_points;
    // The bake is view-independent and done once for a static scene; both are counted, the
    // lookups alone are in timings_ms.
    r.ms = bake_ms + lookup_ms;
    r.timings_ms = {{"bake", bake_ms}, {"lookup", lookup_ms}, {"total", r.ms}};
    r.radiance = image<glm::vec3>(points.width(), points.height(), glm::vec3(0.f));
    for (std::size_t k = 0; k < p.size(); ++k) {
        const std::size_t x = pixel[k] % points.width(), y = pixel[k] / points.width();
        // Negative irradiance (SH ringing) is clamped to 0, as a renderer shades.
        r.radiance(x, y) = lambertian_radiance<float, glm::vec3>(points.albedo(x, y), glm::max(e[k], glm::vec3(0.f)));
    }
    r.counts = {{"probes", volume.probes().size()},
                {"probes_baked", stats.probes_baked},
                {"probes_inside", stats.probes_inside},
                {"leaves", volume.leaf_count()},
                {"points", p.size()}};
    r.parameters = {{"mode", "adaptive"},
                    {"max_depth", max_depth},
                    {"min_depth", vs.min_depth},
                    {"rays", rays},
                    {"gradient_step", bs.gradient_step},
                    {"margin", margin},
                    {"interp", "trilinear"},
                    {"volume_offset", s.settings.volume_offset}};
    return r;
}

}  // namespace bounce::study::bench
