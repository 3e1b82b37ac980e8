// The benchmark's irradiance cache: cpu::irradiance_cache over Embree's record sampler, one
// frame from an empty cache, against the one-bounce reference.
#include <bounce/study/benchmark_parts.hpp>

#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/embree/irradiance_probe.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/study/stage_timer.hpp>
#include <bounce/cache/weighting.hpp>

namespace bounce::study::bench {

technique_run run_irradiance_cache(const scene_setup& s) {
    // ic_splatting's defaults (examples/ic_splatting/options.hpp, chosen in issue 19 as the
    // best speed at equal error on Sponza and the Cornell box): a = 0.4, Ward's smooth
    // weight, gradients, split-sphere records of 1,024 rays with radii between 1.5 and 64
    // pixel footprints and the gradient limit, neighbour clamping, the batched linear scan
    // and splatting, and since issue 28 two rounds of the verification pass with 8-ray probes
    // (docs/irradiance-splatting.md, "Error the records cannot see").
    constexpr float a = 0.4f, min_pixels = 1.5f, max_pixels = 64.f;
    constexpr std::uint32_t record_rays = 1024, verify_rounds = 2, probe_rays = 8;
    s.clock.report("irradiance_cache", "records and splats");
    const auto t0 = std::chrono::steady_clock::now();
    embree::reference_settings rs;
    rs.seed = 1;  // the records' rays follow the sampler's grid, not hemisphere_samples
    const embree::reference_integrator integrator(s.bvh, s.scene, rs);
    radius_limits limits;
    limits.min_pixels = min_pixels;
    limits.max_pixels = max_pixels;
    limits.gradient_limit = true;
    embree::record_sampler sampler(integrator, embree::hemisphere_grid_for(record_rays), limits);
    cpu::irradiance_cache_options o;
    o.splat.a = a;
    o.splat.gradients = true;
    o.neighbour_clamp = true;
    o.verify.rounds = verify_rounds;
    const auto [lo, hi] = s.scene.bounds();
    cpu::irradiance_cache<ward_smooth_weight> cache(lo, hi, o);
    const embree::irradiance_probe probe(integrator, probe_rays);
    cache.set_probe(std::cref(probe));

    technique_run r;
    r.technique = bench_technique::irradiance_cache;
    r.quantity = bench_quantity::one_bounce;
    r.radiance = image<glm::vec3>(s.g.width(), s.g.height());
    const cpu::cache_frame_stats st = cache.render(s.g.view(), s.scene.camera, sampler, r.radiance.view(),
                                                   output_quantity::radiance);
    r.ms = ms_since(t0);
    r.timings_ms = {{"splat_existing", st.splat_existing_ms}, {"scan", st.scan_ms},
                    {"compute_records", st.records_ms},       {"interpolate", st.interpolate_ms},
                    {"normalize", st.normalize_ms},           {"verify", st.verify_ms},
                    {"total", r.ms}};
    r.counts = {{"records", cache.records().size()},
                {"records_measured", st.measured},
                {"records_wasted", st.wasted},
                {"verify_disagreed", st.verify_disagreed}};
    r.parameters = {{"a", a},
                    {"weight", ward_smooth_weight::name},
                    {"gradients", true},
                    {"record_samples", record_rays},
                    {"radius", "split-sphere"},
                    {"min_pixels", min_pixels},
                    {"max_pixels", max_pixels},
                    {"neighbour_clamp", true},
                    {"verify_rounds", verify_rounds},
                    {"verify_rays", probe_rays},
                    {"scan", "batched"},
                    {"interpolation", "splat-cpu"}};
    return r;
}

}  // namespace bounce::study::bench
