// The benchmark's reflective-shadow-map techniques: the RSM gather, SII and SII interleaved
// through cpu::indirect_renderer on maps embree::rsm_ray_caster casts.
#include <bounce/study/benchmark_parts.hpp>

#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/embree/near_field_rays.hpp>
#include <bounce/embree/occlusion_rays.hpp>
#include <bounce/embree/rsm_ray_cast.hpp>
#include <bounce/output.hpp>
#include <bounce/study/stage_timer.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

namespace bounce::study::bench {

namespace {

// rsm_sii's defaults (examples/rsm_sii/options.hpp): the settings' lights a frame (1,024 by
// default; SII: VPLs by flux warping; the gather: disc samples per pixel and map over a disc
// of radius 1.5 map units), 256^2 texels per map, d^2 clamped at each VPL's footprint (plain SII) or at
// scene_clamp_distance (interleaved SII, the gather; default_pixel_light), the geometry-aware blur after interleaving, energy-correct weights, seed 1;
// the gather's clamp compensated by 16 rays a pixel with visibility rays or none.
constexpr std::size_t map_resolution = 256;
// The gather's clamp compensation with visibility rays or none (rsm_sii's --compensation-rays).
constexpr std::uint32_t compensation_rays = 16;

indirect_options options_for(bench_technique t, std::size_t lights, const pixel_light_params& light,
                             indirect_visibility visibility) {
    indirect_options o;
    o.technique = t == bench_technique::rsm_gather ? indirect_technique::rsm_gather : indirect_technique::sii;
    o.count = lights;
    o.pattern = t == bench_technique::sii_interleaved ? interleave_pattern{4, 4} : interleave_pattern{1, 1};
    o.light = light;
    o.visibility = visibility;
    if (t == bench_technique::rsm_gather && visibility != indirect_visibility::ism)
        o.clamp_compensation_rays = compensation_rays;
    o.validate();
    return o;
}

}  // namespace

technique_run run_rsm_sii(const scene_setup& s, bench_technique t, indirect_visibility visibility) {
    require(t == bench_technique::rsm_gather || t == bench_technique::sii || t == bench_technique::sii_interleaved,
            "technique", "is not an RSM technique");
    require(!s.scene.lights.empty(), "scene", "has no point, spot or directional light: reflective shadow maps need one");
    // Built by append: "+" + std::string trips GCC 12's -Wrestrict false positive at -O3.
    std::string name(technique_name(t));
    if (visibility != indirect_visibility::none) {
        name += '+';
        name += visibility_name(visibility);
    }
    const pixel_light_params light = default_pixel_light(
        s.scene, t == bench_technique::sii_interleaved ? interleave_pattern{4, 4} : interleave_pattern{1, 1});
    const indirect_options options = options_for(t, s.settings.rsm_lights, light, visibility);

    // The maps are part of every frame's cost (the lights may move); cast once timed.
    s.clock.report(name, "maps");
    embree::rsm_ray_cast_settings rs;
    rs.resolution = map_resolution;
    embree::rsm_ray_caster caster(s.bvh, s.scene, rs);
    const auto t0 = std::chrono::steady_clock::now();
    caster.render();
    const double maps_ms = ms_since(t0);

    s.clock.report(name, "frames");
    const embree::occlusion_rays rays(s.bvh);
    std::optional<ism_point_sampler> points;
    if (visibility == indirect_visibility::ism) points.emplace(s.scene.view());
    const embree::near_field_rays near(s.bvh, s.scene.view());  // the gather's clamp compensation
    cpu::indirect_renderer renderer(options, &rays, points ? &*points : nullptr, &near);
    image<glm::vec3> e(s.g.width(), s.g.height());
    // ISM: the scene's point set is made once (a static scene's), outside the timed frames.
    if (points) renderer.render(s.g.view(), s.scene.camera, caster.views(), e.view());
    stage_timer timer;
    indirect_timings last;
    for (int i = 0; i < std::max(1, s.settings.repeat); ++i) {
        last = renderer.render(s.g.view(), s.scene.camera, caster.views(), e.view());
        timer.add_sample("split", last.split_ms);
        timer.add_sample("shade", last.shade_ms);
        timer.add_sample("gather", last.gather_ms);
        timer.add_sample("blur", last.blur_ms);
        timer.add_sample("frame", last.total_ms());
    }

    technique_run r;
    r.technique = t;
    r.visibility = visibility;
    r.quantity = bench_quantity::one_bounce;
    r.ms = maps_ms + timer.median_ms("frame");
    r.timings_ms = {{"maps", maps_ms}};
    for (const auto& stage : timer.stages()) r.timings_ms[stage] = timer.median_ms(stage);
    r.timings_ms["total"] = r.ms;
    // The frames give irradiance (timed as a renderer runs them); the references hold
    // radiance rho / pi E, made as the renderer makes it when asked (output.hpp).
    r.radiance = std::move(e);
    apply_output(output_quantity::radiance, image_view<const glm::vec3>(s.g.view().albedo), r.radiance.view());
    r.counts = {{"vpls", last.vpls}, {"maps", caster.maps().size()}};
    r.parameters = {{"count", s.settings.rsm_lights},
                    {"pattern", t == bench_technique::sii_interleaved ? "4x4" : "1x1"},
                    {"rsm_resolution", map_resolution},
                    {"clamp", std::sqrt(light.min_distance2)},
                    {"footprint_clamp", light.footprint_scale},
                    {"r_max", options.r_max},
                    {"blur", options.blur},
                    {"visibility", visibility_name(visibility)},
                    {"compensation_rays", options.clamp_compensation_rays},
                    {"selection", "warping"},
                    {"repeat", std::max(1, s.settings.repeat)}};
    if (points) {
        r.parameters["ism_map_size"] = options.ism.map_size;
        r.parameters["ism_points_per_vpl"] = options.ism.points_per_vpl;
    }
    return r;
}

}  // namespace bounce::study::bench
