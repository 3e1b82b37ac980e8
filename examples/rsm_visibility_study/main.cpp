// rsm_visibility_study: where the error that indirect visibility adds comes from (issue 29).
// For each scene, at the benchmark's settings (256x256, rsm_sii's defaults, references of
// 1024 rays a pixel with visibility and 512 without, each in two halves, from the cache), it
// renders SII with and without occlusion rays plain, interleaved 4x4 before the blur and
// after it, and measures each frame's debiased rel_rms against the reference of what it
// computes (with rays the occluded one-bounce light, without it the unoccluded one), the same
// bench::measure_error as the benchmark. It also blurs each reference itself with the 4x4
// geometry-aware tent (the blur's bias on the true light: what the blurred frame averages to
// over the VPLs' draws). --dump DIR writes every image as raw float32 (W H 3, row-major) for
// per-pixel analysis. Each frame with rays also reports how its error splits against the frame
// without visibility ("split"), and --occlusion swaps the occlusion query for diagnostic ones.
//
//   build/bin/rsm_visibility_study --scenes cornell-box,conference --vpls 4096 [--dump DIR]
#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/near_field_rays.hpp>
#include <bounce/embree/rsm_ray_cast.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/output.hpp>
#include <bounce/study/benchmark_parts.hpp>
#include <bounce/study/indirect_diagnostics.hpp>

#include "../common/run_program.hpp"

#include <bounce/io/output_files.hpp>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

using namespace bounce;
namespace bench = bounce::study::bench;

namespace {

struct options {
    std::vector<std::string> scenes{"cornell-box"};
    std::size_t vpls = 4096;
    std::uint64_t seed = 1;
    std::size_t width = 256, height = 256;
    std::string dump;
    std::string json;
    std::vector<std::string> configs;
    bool flat_normals = false;
    float sigmas = discontinuity_params{}.visibility_sigmas;
    float complete_below = 0.5f;  // the 4x4-blur-complete configs
    view_selection_params view;    // with rays: the view's choice of VPLs (candidates 1: off)
    std::string occlusion = "rays";
    std::uint32_t compensation_rays = 16;  // the gather with rays: the clamp's compensation (0: off)
};

void dump_image(const options& o, const std::string& scene, const std::string& name, image_view<const glm::vec3> img) {
    if (!o.dump.empty()) study::write_raw_f32(std::filesystem::path(o.dump) / (scene + "." + name + ".f32"), img, "--dump");
}

int run(const options& o) {
    if (!o.json.empty()) io::check_output_file("--json", o.json);
    nlohmann::ordered_json report = {{"technique", "rsm_visibility_study"},
                                     {"parameters",
                                      {{"vpls", o.vpls}, {"seed", o.seed}, {"width", o.width}, {"height", o.height},
                                       {"flat_normals", o.flat_normals}, {"occlusion", o.occlusion},
                                       {"compensation_rays", o.compensation_rays}, {"rsm_resolution", 256},
                                       {"view_candidates", o.view.candidates}, {"view_receivers", o.view.receivers},
                                       {"view_defensive", o.view.defensive}, {"view_near_field", o.view.near_field},
                                       {"visibility_sigmas", o.sigmas}}},
                                     {"frames", nlohmann::ordered_json::array()},
                                     {"blurred_references", nlohmann::ordered_json::array()}};
    const study::benchmark_settings settings = study::benchmark_settings::defaults(false, o.width, o.height);
    bench::run_clock clock({}, o.scenes.size(), 1.0);
    for (std::size_t si = 0; si < o.scenes.size(); ++si) {
        const io::scene loaded = io::load_scene_arg(o.scenes[si]);
        const io::scene scene = o.flat_normals ? study::flat_shaded(loaded) : loaded;
        const embree::accel bvh(scene);
        clock.begin_scene(scene.name, si);
        const bench::scene_setup s = bench::make_scene_setup(scene, bvh, settings, clock);
        const auto t0 = std::chrono::steady_clock::now();
        const bench::halves_reference occluded = bench::one_bounce_reference(s);
        const bench::halves_reference unoccluded = bench::unoccluded_reference(s);
        fmt::print("{}: references {} / {} ({:.0f} s), noise {:.4f} / {:.4f}\n", scene.name,
                   occluded.cached ? "cached" : "computed", unoccluded.cached ? "cached" : "computed",
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                   occluded.noise_rel_rms, unoccluded.noise_rel_rms);
        std::fflush(stdout);
        dump_image(o, scene.name, "ref_occluded", occluded.mean.view());
        dump_image(o, scene.name, "ref_occluded_a", occluded.a.view());
        dump_image(o, scene.name, "ref_occluded_b", occluded.b.view());
        dump_image(o, scene.name, "ref_unoccluded", unoccluded.mean.view());
        dump_image(o, scene.name, "ref_unoccluded_a", unoccluded.a.view());
        dump_image(o, scene.name, "ref_unoccluded_b", unoccluded.b.view());
        dump_image(o, scene.name, "albedo", image_view<const glm::vec3>(s.g.view().albedo));
        dump_image(o, scene.name, "normal", image_view<const glm::vec3>(s.g.view().normal));
        dump_image(o, scene.name, "position", image_view<const glm::vec3>(s.g.view().position));

        embree::rsm_ray_cast_settings rs;
        rs.resolution = 256;
        embree::rsm_ray_caster caster(bvh, scene, rs);
        caster.render();
        const study::diagnostic_occlusion rays(bvh, scene, o.occlusion);
        const embree::near_field_rays near(bvh, scene.view());
        cpu::indirect_renderer renderer({}, &rays, nullptr, &near);

        indirect_options base;
        base.technique = indirect_technique::sii;
        base.count = o.vpls;
        base.seed = o.seed;
        const interleave_pattern p44{4, 4}, p11{1, 1};

        {  // The blur's bias on the true light.
            indirect_options b = base;
            b.pattern = p44;
            if (!o.dump.empty())
                dump_image(o, scene.name, "reached_sub_buffers", study::reached_sub_buffers_image(s.g.view(), b).view());
            for (const bool vis : {false, true}) {
                const bench::halves_reference& ref = vis ? occluded : unoccluded;
                const image<glm::vec3> blurred = study::blurred_reference(s.g.view(), ref.mean.view(), b);
                const bench::measured_error e = bench::measure_error(blurred.view(), ref, s.mask.view());
                fmt::print("{} reference {} blurred 4x4: raw {:.4f} debiased {:.4f}\n", scene.name,
                           vis ? "occluded" : "unoccluded", e.rel_rms, e.rel_rms_debiased);
                report["blurred_references"].push_back({{"scene", scene.name},
                                                        {"reference", vis ? "occluded" : "unoccluded"},
                                                        {"rel_rms", e.rel_rms},
                                                        {"rel_rms_debiased", e.rel_rms_debiased}});
                dump_image(o, scene.name, vis ? "ref_occluded_blurred" : "ref_unoccluded_blurred", blurred.view());
            }
        }

        struct config {
            std::string name;
            interleave_pattern pattern;
            bool blur;
            bool footprint;
            bool view = true;  // with rays: VPLs chosen by the view (the library's default)
            indirect_technique technique = indirect_technique::sii;
            float sigmas = -1.f;  // visibility edges of the blur; -1: --sigmas
            bool complete = false;  // isolated pixels completed (discontinuity_params::complete_below)
        };
        const std::vector<config> configs = {{"plain-footprint", p11, false, true},
                                             {"plain-fixed", p11, false, false},
                                             {"4x4-noblur", p44, false, false},
                                             {"4x4-blur", p44, true, false},
                                             {"plain-fixed-noview", p11, false, false, false},
                                             {"4x4-noblur-noview", p44, false, false, false},
                                             {"4x4-blur-noview", p44, true, false, false},
                                             {"gather", p11, false, false, true, indirect_technique::rsm_gather},
                                             {"4x4-blur-geometry-edges", p44, true, false, true,
                                              indirect_technique::sii, 0.f},
                                             {"4x4-blur-complete", p44, true, false, true, indirect_technique::sii,
                                              -1.f, true}};
        for (const auto& c : configs) {
            if (!o.configs.empty() && std::find(o.configs.begin(), o.configs.end(), c.name) == o.configs.end())
                continue;
            image<glm::vec3> without, with_rays;
            for (const indirect_visibility vis : {indirect_visibility::none, indirect_visibility::rays}) {
                if (!c.view && vis == indirect_visibility::none) continue;  // the same frames as with the view
                indirect_options opt = base;
                opt.pattern = c.pattern;
                opt.technique = c.technique;
                opt.blur = c.blur;
                opt.visibility = vis;
                opt.light = default_pixel_light(scene.view(), c.pattern);
                opt.light.footprint_scale = c.footprint ? 1.f : 0.f;
                opt.view_selection = o.view;
                opt.clamp_compensation_rays = o.compensation_rays;
                if (!c.view) opt.view_selection.candidates = 1;
                opt.discontinuity.visibility_sigmas = c.sigmas < 0.f ? o.sigmas : c.sigmas;
                if (c.complete) opt.discontinuity.complete_below = o.complete_below;
                image<glm::vec3>& e = vis == indirect_visibility::rays ? with_rays : without;
                e = image<glm::vec3>(s.g.width(), s.g.height());
                const auto f0 = std::chrono::steady_clock::now();
                const indirect_timings t =
                    renderer.render(opt, s.g.view(), scene.camera, caster.views(), e.view(), output_quantity::radiance);
                const double ms =
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - f0).count();
                const bool rays_on = vis == indirect_visibility::rays;
                const bench::measured_error err =
                    bench::measure_error(e.view(), rays_on ? occluded : unoccluded, s.mask.view());
                fmt::print("{} {} {} vpls {}: raw {:.4f} debiased {:.4f} (se {:.4f}) {:.0f} ms, compensation {} rays "
                           "{:.4f} of the light\n", scene.name, c.name, rays_on ? "rays" : "none", o.vpls, err.rel_rms,
                           err.rel_rms_debiased, err.rel_rms_debiased_se, ms, t.compensation_rays, t.compensation_share);
                std::fflush(stdout);
                report["frames"].push_back({{"scene", scene.name}, {"config", c.name},
                                            {"visibility", rays_on ? "rays" : "none"}, {"vpls", o.vpls},
                                            {"pattern", c.pattern.cells() > 1 ? "4x4" : "1x1"},
                                            {"blur", c.blur},
                                            {"complete_below", opt.discontinuity.complete_below},
                                            {"view_selection", rays_on && c.view},
                                            {"visibility_sigmas",
                                             rays_on && c.blur ? opt.discontinuity.visibility_sigmas : 0.f},
                                            {"reference", rays_on ? "occluded" : "unoccluded"},
                                            {"rel_rms", err.rel_rms},
                                            {"rel_rms_debiased", err.rel_rms_debiased},
                                            {"rel_rms_debiased_se", err.rel_rms_debiased_se},
                                            {"ms_loaded_machine", ms}, {"compensation_rays", t.compensation_rays},
                                            {"compensation_share", t.compensation_share}});
                dump_image(o, scene.name, c.name + (rays_on ? "-rays" : "-none"), e.view());
                if (!rays_on || without.empty()) continue;
                auto split = bench::visibility_error_split(with_rays.view(), without.view(), occluded, unoccluded, s.mask.view());
                fmt::print("{} {} vpls {}: none's error in the occluded reference's units {:.4f}, visibility's change "
                           "{:.4f}, references' rms ratio {:.3f}\n",
                           scene.name, c.name, o.vpls, split["none_error_in_occluded_units"].get<double>(),
                           split["visibility_change"].get<double>(), split["references_rms_ratio"].get<double>());
                report["frames"].back()["split"] = std::move(split);
            }
        }
        fmt::print("{} {}\n", scene.name, rays.summary());
    }
    if (!o.json.empty()) io::write_text_file(o.json, report.dump(2) + "\n");
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce: where indirect visibility's error comes from in SII (issue 29)"};
    options o;
    app.add_option("--scenes", o.scenes, "cornell, or names under the scenes folder")->delimiter(',');
    app.add_option("--vpls", o.vpls, "VPLs a frame")->check(CLI::Range(16, 1 << 20));
    app.add_option("--seed", o.seed, "seed of the VPLs");
    app.add_option("--width", o.width, "image width")->check(CLI::Range(1, 4096));
    app.add_option("--height", o.height, "image height")->check(CLI::Range(1, 4096));
    app.add_option("--configs", o.configs,
                   "only these: plain-footprint, plain-fixed, 4x4-noblur, 4x4-blur, 4x4-blur-complete, gather, ...")
        ->delimiter(',');
    app.add_option("--sigmas", o.sigmas, "the blur's visibility edges (discontinuity_params::visibility_sigmas)")
        ->check(CLI::Range(0.f, 100.f));
    app.add_option("--complete-below", o.complete_below,
                   "4x4-blur-complete: share of sub-buffers below which a pixel gets every VPL")
        ->check(CLI::Range(0.f, 1.f));
    app.add_option("--candidates", o.view.candidates, "view_selection.candidates (1: VPLs by flux alone)")
        ->check(CLI::Range(1, 64));
    app.add_option("--receivers", o.view.receivers, "view_selection.receivers")->check(CLI::Range(1, 1 << 20));
    app.add_option("--defensive", o.view.defensive, "view_selection.defensive")->check(CLI::Range(0.001f, 1.f));
    app.add_option("--near-field", o.view.near_field, "view_selection.near_field (0: off)")->check(CLI::Range(0.f, 64.f));
    app.add_option("--compensation-rays", o.compensation_rays, "gather with rays: the clamp's compensation (0: off)")
        ->check(CLI::Range(0, 4096));
    app.add_option("--occlusion", o.occlusion, "diagnostic occlusion query: rays (the library's), geometric, shortened");
    app.add_flag("--flat-normals", o.flat_normals, "every triangle shaded with its own geometric normal");
    app.add_option("--json", o.json, "write the frames' errors here (docs/studies/results.py adds it)");
    app.add_option("--dump", o.dump, "write every image as raw float32 into this folder");
    CLI11_PARSE(app, argc, argv);
    return bounce::examples::run_program("rsm_visibility_study", [&] { return run(o); });
}
