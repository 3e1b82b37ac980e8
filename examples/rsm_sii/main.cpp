// rsm_sii: one-bounce indirect light from reflective shadow maps, by the RSM gather
// (Dachsbacher and Stamminger 2005) or by splatting indirect illumination (Dachsbacher and
// Stamminger 2006), optionally interleaved (Keller and Heidrich 2001; Segovia et al. 2006)
// with energy-correct weights, through the library's cpu::indirect_renderer or
// gl::offscreen_indirect_renderer on maps that embree::rsm_ray_caster casts; errors against
// the references with and without indirect visibility, and against the same technique
// without interleaving (Hahn 2012's metric), measured by bounce::study (indirect_study.hpp).
//
//   build/bin/rsm_sii --scene cornell --technique sii --vpls 1024 --pattern 4x4 --json r.json
//   build/bin/rsm_sii --study --json build/runs/rsm_sii-cornell.json     (Hahn 2012's grid)
//
// timings_ms: rsm (casting the maps, per frame), split, shade, gather, blur, upsample and
// total = split + shade + gather + blur + upsample (the frame after the maps exist, as Hahn
// 2012 section 5.1 times it); medians of --repeat renders.
#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/near_field_rays.hpp>
#include <bounce/embree/occlusion_rays.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/rsm_ray_cast.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/frame_comparison.hpp>
#include <bounce/study/indirect_study.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/study/stage_timer.hpp>
#ifdef BOUNCE_WITH_GL
#include <bounce/gl/indirect_renderer.hpp>
#endif

#include "../common/run_program.hpp"
#include "options.hpp"

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <optional>
#include <vector>
#include <string>

using namespace bounce;
using namespace bounce::examples;
using json = nlohmann::ordered_json;

namespace {

json parameters_json(const options& o, float clamp_distance, std::size_t maps) {
    return {{"technique", name_of(technique_names, o.technique)},
            {"vpls", o.vpls},
            {"pattern", o.pattern},
            {"assign", name_of(assignment_names, o.assign)},
            {"selection", name_of(selection_names, o.selection)},
            {"rsm_resolution", o.rsm_resolution},
            {"maps", maps},
            {"r_max", o.r_max},
            {"clamp", clamp_distance},
            {"offset", o.offset},
            {"blur", o.blur},
            {"energy_correct", !o.thesis_weights},
            {"seed", o.seed},
            {"reference_spp", o.ref_spp}};
}

/// Every flag and output checked before the scene is loaded: nothing below fails for a
/// reason the command line already showed.
void check_arguments(const options& o) {
    check_backend_built(o.backend);
    if (o.backend == backend::gl)
        require(o.visibility != indirect_visibility::rays, "--visibility",
                "'rays' runs on the CPU backend only (GL offers 'ism', imperfect shadow maps)");
    if (o.study) require(!o.json.empty(), "--study", "needs --json for the study's report");
    if (o.study)
        require(o.out.empty() && o.indirect_out.empty(), "--out/--indirect-out",
                "write one run's images; --study makes many (run the configuration without --study)");
    if (!o.json.empty()) io::check_output_file("--json", o.json);
    if (!o.out.empty()) io::check_image_output("--out", o.out);
    if (!o.indirect_out.empty()) io::check_image_output("--indirect-out", o.indirect_out);
    study::check_indirect_reference_spp(o.ref_spp, "--ref-spp");
}

/// --indirect-out: the run's indirect light beside the reference of what it computes, one
/// exposure (the reference's). With visibility the same frame without it stands between
/// them: [no visibility | rays or ism | occluded reference], the leak and its fix side by side.
void write_indirect_pictures(const options& o, const study::indirect_frame& frame, const indirect_options& chosen,
                             const image<glm::vec3>& radiance, const study::indirect_references& refs,
                             const gbuffer_view<float>& g, image_view<const float> mask) {
    std::vector<image_view<const glm::vec3>> panels;
    image<glm::vec3> leaking;
    const bool visible = o.visibility != indirect_visibility::none;
    if (visible) {
        indirect_options none = chosen;
        none.visibility = indirect_visibility::none;
        image<glm::vec3> e(o.width, o.height);
        frame(none, e.view());
        leaking = study::radiance_image(g, e.view());
        panels.push_back(leaking.view());
    }
    panels.push_back(radiance.view());
    const image_view<const glm::vec3> reference = visible ? refs.occluded.indirect.view() : refs.unoccluded.view();
    panels.push_back(reference);
    image<glm::vec3> row(panels.size() * o.width, o.height);
    for (std::size_t k = 0; k < panels.size(); ++k)
        for (std::size_t y = 0; y < o.height; ++y)
            for (std::size_t x = 0; x < o.width; ++x) row(k * o.width + x, y) = panels[k](x, y);
    io::write_png(o.indirect_out, row.view(), io::auto_exposure(reference, mask));
}

int run(const options& o) {
    const interleave_pattern pattern = parse_pattern(o.pattern);
    check_arguments(o);
    // The scene first, validated whole (magnitudes, lights), so that its own error is the
    // one shown, not one of a quantity derived from it.
    const io::scene scene = io::load_scene_arg(o.scene);
    scene.view().validate();
    for (const auto& w : scene.warnings) fmt::print(stderr, "{}: {}\n", scene.name, w);
    require(!scene.lights.empty(), "--scene",
            "has no point, spot or directional light: reflective shadow maps need one");
    const float clamp_distance = o.clamp >= 0.f ? o.clamp : scene_clamp_distance(scene.view());
    // The options the runs use, checked before the maps and references take minutes.
    const indirect_options chosen = indirect_options_for(o, o.technique, o.vpls, pattern, clamp_distance);
    study::check_cache_dir();

    const embree::accel bvh(scene);
    const camera& cam = scene.camera;
    gbuffer<float> g = embree::ray_cast_gbuffer(bvh, scene, cam, o.width, o.height);
    embree::rsm_ray_cast_settings rs;
    rs.resolution = o.rsm_resolution;
    embree::rsm_ray_caster caster(bvh, scene, rs);
    study::stage_timer rsm_timer;
    for (int i = 0; i < std::max(3, o.repeat); ++i) rsm_timer.time("rsm", [&] { caster.render(); });
    fmt::print(stderr, "{} maps of {}^2 texels cast in {:.1f} ms\n", caster.maps().size(), o.rsm_resolution,
               rsm_timer.median_ms("rsm"));

    // The backend: both renderers take the same call.
    const embree::occlusion_rays rays(bvh);
    std::optional<ism_point_sampler> points;
    if (o.visibility == indirect_visibility::ism) points.emplace(scene.view());
    const embree::near_field_rays near(bvh, scene.view());  // the gather's clamp compensation
    cpu::indirect_renderer cpu_renderer({}, &rays, points ? &*points : nullptr, &near);
    study::indirect_frame frame = [&](const indirect_options& opts, image_view<glm::vec3> out) {
        return cpu_renderer.render(opts, g.view(), cam, caster.views(), out);
    };
    std::string gl_name;
#ifdef BOUNCE_WITH_GL
    std::optional<gl::offscreen_indirect_renderer> gl_renderer;
    if (o.backend == backend::gl) {
        gl_renderer.emplace();
        gl_renderer->set_point_sampler(points ? &*points : nullptr);
        gl_name = gl_renderer->gl_renderer();
        frame = [&](const indirect_options& opts, image_view<glm::vec3> out) {
            return gl_renderer->render(opts, g.view(), cam, caster.views(), out);
        };
    }
#endif

    const study::indirect_references refs = study::cached_indirect_references(bvh, scene, cam, g.view(), o.ref_spp);
    fmt::print(stderr, "reference {}x{} at {} spp: {}\n", o.width, o.height, o.ref_spp,
               refs.occluded_from_cache ? "from cache" : fmt::format("computed in {:.1f} s", refs.occluded_ms / 1e3));
    fmt::print(stderr, "unoccluded reference at {} spp: {} (noise {:.4f})\n", o.ref_spp,
               refs.unoccluded_from_cache ? "from cache" : fmt::format("computed in {:.1f} s", refs.unoccluded_ms / 1e3),
               refs.unoccluded_noise);
    const image<float> mask = study::coverage_mask(g.view());
    const study::indirect_bench bench{frame, g.view(), &refs, mask.view(), rsm_timer.median_ms("rsm"), o.repeat};

    study::run_report report;
    report.technique = o.study ? "rsm_sii_study" : "rsm_sii";
    report.scene = scene.name;
    report.width = o.width;
    report.height = o.height;
    report.backend = name_of(backend_names, o.backend);
    report.gl_renderer = gl_name;
    report.parameters = parameters_json(o, clamp_distance, caster.maps().size());
    report.parameters["footprint_clamp"] = chosen.light.footprint_scale;
    report.parameters["embree_config"] = bvh.owner().config();
    json extra = json::object();
    extra["references"] = {
        {"spp", refs.spp},
        {"unoccluded_noise_rel_rms", refs.unoccluded_noise},
        {"occluded_vs_unoccluded_rel_rms",
         study::compare_luminance(refs.occluded.indirect.view(), refs.unoccluded.view(), mask.view()).rel_rms}};

    std::optional<study::indirect_run> single;
    if (o.study) {
        report.repeat = std::size_t(o.repeat);
        extra.update(study::interleaving_study(bench, chosen,
                                               [](const study::indirect_run& r) { fmt::print("{}\n", r.summary()); }));
    } else {
        std::optional<study::indirect_run> plain;
        if (pattern.cells() > 1) {
            indirect_options p = chosen;
            p.pattern = {1, 1};
            p.energy_correct = true;
            plain = study::measure_indirect(bench, p);
            fmt::print("{}\n", plain->summary());
        }
        single = study::measure_indirect(bench, chosen, plain ? &*plain : nullptr);
        fmt::print("{}\n", single->summary());
        const double removed = study::clamp_removed_fraction(bench, chosen);
        fmt::print("the 1/d^2 clamp removes {:.2f}% of the frame's light\n", 100.0 * removed);
        extra["clamp_removed_fraction"] = removed;
        report.set_timings(single->timer);
        // The error against the reference of what the frame computes: with visibility the
        // occluded one-bounce light, without it the unoccluded one (the other beside it).
        report.error = o.visibility != indirect_visibility::none ? single->vs_occluded : single->vs_unoccluded;
        report.set_count("vpls", single->last.vpls);
        report.set_count("maps", caster.maps().size());
        const json r = single->to_json();
        if (r.contains("speedup_vs_plain")) extra["speedup_vs_plain"] = r["speedup_vs_plain"];
    }

    if (single && !o.out.empty()) {
        image<glm::vec3> combined(o.width, o.height);
        for (std::size_t y = 0; y < o.height; ++y)
            for (std::size_t x = 0; x < o.width; ++x) combined(x, y) = refs.occluded.direct(x, y) + single->radiance(x, y);
        io::write_png(o.out, combined.view(), io::auto_exposure(combined.view(), mask.view()));
    }
    if (single && !o.indirect_out.empty())
        write_indirect_pictures(o, frame, chosen, single->radiance, refs, g.view(), mask.view());

    if (!o.json.empty()) {
        json j = report.to_json();
        if (single && j.contains("error")) {
            const json r = single->to_json();
            j["error"]["rel_rms_occluded"] = r["error"]["rel_rms_occluded"];
            if (r["error"].contains("vs_plain")) j["error"]["vs_plain"] = r["error"]["vs_plain"];
        }
        j.update(extra);
        io::write_text_file(o.json, j.dump(2) + "\n");
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce: reflective shadow maps, splatting indirect illumination and interleaved sampling (Hahn 2012)"};
    options o;
    add_options(app, o);
    CLI11_PARSE(app, argc, argv);
    return run_program("rsm_sii", [&] { return run(o); });
}
