#pragma once
// rsm_sii's options: what the command line sets, how it is spelled and checked, and the
// library settings (bounce::indirect_options) they make. main.cpp runs and reports.
#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/errors.hpp>

#include <CLI/CLI.hpp>
#include "../common/cli_choices.hpp"
#include "../common/cli_number_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>

namespace bounce::examples {

// The spellings of the library's choices on the command line and in the reports.
inline const choices<indirect_technique> technique_names{{"rsm", indirect_technique::rsm_gather},
                                                         {"sii", indirect_technique::sii}};
inline const choices<light_assignment> assignment_names{{"interleaved", light_assignment::interleaved},
                                                        {"blocked", light_assignment::blocked},
                                                        {"similar", light_assignment::similarity}};
inline const choices<vpl_selection> selection_names{{"warping", vpl_selection::flux_warping},
                                                    {"grid", vpl_selection::grid}};
inline const choices<indirect_visibility> visibility_names{
    {std::string(visibility_name(indirect_visibility::none)), indirect_visibility::none},
    {std::string(visibility_name(indirect_visibility::rays)), indirect_visibility::rays},
    {std::string(visibility_name(indirect_visibility::ism)), indirect_visibility::ism}};

struct options {
    indirect_technique technique = indirect_technique::sii;  // rsm (the gather, DS05) | sii (splatting, DS06)
    std::size_t vpls = 1024;           // SII: VPLs; RSM: disc samples per pixel and map
    std::string pattern = "4x4";       // N x M interleave pattern; 1x1: none
    light_assignment assign = light_assignment::interleaved;
    examples::backend backend = backend::cpu;
    indirect_visibility visibility = indirect_visibility::none;  // none (DS05/DS06: leaks) | rays (exact, CPU) | ism
    ism_params ism;  // imperfect shadow maps (--visibility ism): --ism-map-size, --ism-points, --ism-bias
    std::string scene = "cornell";
    std::size_t width = 512, height = 384;
    std::size_t rsm_resolution = 256;  // texels per side of each map (cube face)
    vpl_selection selection = vpl_selection::flux_warping;  // SII VPLs: warping (DS06 section 3.3) | grid
    float r_max = 1.5f;                // RSM gather disc radius, map units
    float clamp = -1.f;                // d^2 clamped at clamp^2 (scene units); unset (< 0): scene_clamp_distance
    float footprint_clamp = -1.f;      // SII: d^2 clamped at the disc of each VPL's area times this^2; 0: --clamp;
                                       // unset (< 0): default_pixel_light's (1 plain, 0 interleaved)
    float offset = 0.f;                // sender moved along -n_p (m), DS05's remedy
    std::uint32_t compensation_rays = 16;  // RSM gather (CPU), rays or none: rays per pixel giving back the clamp's light
    bool blur = true;
    bool thesis_weights = false;       // interleaved lights at weight 1 (Hahn 2012), not N M
    std::uint64_t seed = 1;
    std::uint32_t ref_spp = 1024;      // rays per pixel of both references
    int repeat = 1;
    bool study = false;
    std::filesystem::path json, out, indirect_out;
};

/// "NxM" -> pattern; throws parameter_error naming --pattern.
inline interleave_pattern parse_pattern(const std::string& s) {
    const auto x = s.find('x');
    const auto digits = [](const std::string& t) {
        return !t.empty() && t.size() <= 4 && std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
    };
    if (x == std::string::npos || !digits(s.substr(0, x)) || !digits(s.substr(x + 1)))
        throw parameter_error("--pattern", "'" + s + "' is not of the form NxM (e.g. 4x4)");
    interleave_pattern p{std::stoi(s.substr(0, x)), std::stoi(s.substr(x + 1))};
    try {
        p.validate();
    } catch (const parameter_error&) {
        throw parameter_error("--pattern", "'" + s + "': N and M must lie in [1, 64]");
    }
    return p;
}

/// The renderer's options for a run of `technique` with `count` lights and `pattern`,
/// validated; a refusal names the flag that set the field (--vpls, --pattern, --r-max,
/// --clamp, --offset, --seed) rather than the library's field.
inline indirect_options indirect_options_for(const options& o, indirect_technique technique, std::size_t count,
                                             interleave_pattern pattern, float clamp_distance) {
    indirect_options c;
    c.technique = technique;
    c.count = count;
    c.pattern = pattern;
    c.assignment = o.assign;
    c.blur = o.blur;
    c.energy_correct = !o.thesis_weights;
    c.selection = o.selection;
    c.r_max = o.r_max;
    c.light.offset = o.offset;
    c.light.min_distance2 = clamp_distance * clamp_distance;
    c.light.footprint_scale = o.footprint_clamp >= 0.f ? o.footprint_clamp : (pattern.cells() == 1 ? 1.f : 0.f);
    c.seed = o.seed;
    c.visibility = o.visibility;
    c.ism = o.ism;
    c.clamp_compensation_rays = o.backend == backend::gl ? 0 : o.compensation_rays;  // the GL gather has none
    try {
        c.validate();
    } catch (const parameter_error& e) {
        const std::string& f = e.parameter();
        const std::string flag = f == "count"                      ? "--vpls"
                                 : f.rfind("pattern", 0) == 0      ? "--pattern"
                                 : f == "r_max"                    ? "--r-max"
                                 : f == "min_distance2"            ? "--clamp"
                                 : f == "footprint_scale"          ? "--footprint-clamp"
                                 : f == "offset"                   ? "--offset"
                                 : f == "clamp_compensation_rays"  ? "--compensation-rays"
                                 : f == "visibility"               ? "--visibility"
                                 : f == "ism.map_size"             ? "--ism-map-size"
                                 : f == "ism.points_per_vpl"       ? "--ism-points"
                                 : f == "ism.bias_scale"           ? "--ism-bias"
                                                                   : f;
        const std::string what = e.what();
        const auto at = what.find("': ");
        throw parameter_error(flag, at == std::string::npos ? what : what.substr(at + 3));
    }
    return c;
}

/// An even number of rays per pixel in [4, 2^20] (the unoccluded reference is two halves of
/// at least 2 rays each).
inline const CLI::Validator even_ref_spp = CLI::Validator(
    [](std::string& s) -> std::string {
        const double v = examples::detail::parse_number(s);
        if (v >= 4 && v <= double(1u << 20) && v == std::floor(v) && std::fmod(v, 2.0) == 0) return {};
        return "'" + s + "' is not an even number of rays in [4, 1048576] (the unoccluded reference is two halves of "
               "equal size)";
    },
    "EVEN IN [4, 1048576]");

inline void add_options(CLI::App& app, options& o) {
    add_choice(app, "--technique", o.technique, technique_names,
               "rsm (the RSM gather, DS05) | sii (splatting indirect illumination, DS06)")
        ->capture_default_str();
    app.add_option("--vpls", o.vpls, "SII: VPLs per frame; RSM: disc samples per pixel and map")
        ->check(CLI::Range(std::size_t(1), std::size_t(1) << 24))
        ->capture_default_str();
    app.add_option("--pattern", o.pattern, "interleave pattern NxM: 1x1 (none), 2x2, 2x4, 4x4, 8x8 ...")->capture_default_str();
    add_choice(app, "--assign", o.assign, assignment_names, "VPLs to sub-buffers: interleaved | blocked | similar")
        ->capture_default_str();
    add_choice(app, "--backend", o.backend, backend_names, "cpu | gl")->capture_default_str();
    add_choice(app, "--visibility", o.visibility, visibility_names,
               "receiver-sender visibility: none (as published: light leaks through walls) | rays (an Embree "
               "occlusion ray per pair the frame sums; CPU backend) | ism (imperfect shadow maps, SII only; CPU or GL)")
        ->capture_default_str();
    app.add_option("--ism-map-size", o.ism.map_size, "--visibility ism: texels per side of each VPL's paraboloid map "
                                                     "(a power of two in [4, 256])")
        ->capture_default_str();
    app.add_option("--ism-points", o.ism.points_per_vpl, "--visibility ism: points splatted into each VPL's map")
        ->capture_default_str();
    app.add_option("--ism-bias", o.ism.bias_scale, "--visibility ism: scale of the depth test's bias")
        ->capture_default_str();
    app.add_option("--scene", o.scene, "cornell, a scene.json, its folder, an .obj, a .gltf or .glb, or a name under the scenes folder")
        ->capture_default_str();
    app.add_option("--width", o.width, "image width")->check(CLI::Range(1, 16384))->capture_default_str();
    app.add_option("--height", o.height, "image height")->check(CLI::Range(1, 16384))->capture_default_str();
    app.add_option("--rsm-resolution", o.rsm_resolution, "texels per side of each reflective shadow map (cube face)")
        ->check(CLI::Range(1, 8192))
        ->capture_default_str();
    add_choice(app, "--selection", o.selection, selection_names, "SII's VPLs: warping (importance on the flux) | grid")
        ->capture_default_str();
    app.add_option("--r-max", o.r_max, "RSM gather disc radius in map units, (0, 2]; 1.5 reaches the whole map")
        ->check(examples::detail::number_in(0, 2, true, "a radius", /*lo_included=*/false))
        ->capture_default_str();
    app.add_option("--clamp", o.clamp,
                   "sender-receiver distance below which 1/d^2 is clamped (scene units, >= 0; 0: no clamp); "
                   "default 1% of the scene's bounding-box diagonal (scene_clamp_distance); SII uses it only "
                   "with --footprint-clamp 0")
        ->check(examples::finite_non_negative);
    app.add_option("--footprint-clamp", o.footprint_clamp,
                   "SII: 1/d^2 clamped inside the disc of the area each VPL stands for, its radius scaled by this "
                   "(>= 0; 0: the fixed --clamp instead); default 1 without interleaving, 0 with it")
        ->check(examples::finite_non_negative);
    app.add_option("--offset", o.offset, "senders moved this far along -n_p (scene units; DS05's remedy)")
        ->check(examples::finite_non_negative)
        ->capture_default_str();
    app.add_option("--compensation-rays", o.compensation_rays,
                   "--technique rsm (CPU), --visibility rays or none: cosine rays a pixel that give back the light the "
                   "clamp removes, from the first surface or every one (docs/rsm-sii-interleaved.md section 15; 0: off)")
        ->check(CLI::Range(0, 4096))
        ->capture_default_str();
    app.add_flag("!--no-blur", o.blur, "skip the geometry-aware blur after interleaving");
    app.add_flag("--thesis-weights", o.thesis_weights,
                 "interleaved lights at weight 1 as in Hahn 2012 (loses 1 - 1/(N M) of the energy), not N M");
    app.add_option("--seed", o.seed, "seed of the VPLs and of the disc pattern")->check(seed_u64)->capture_default_str();
    app.add_option("--ref-spp", o.ref_spp, "rays per pixel of the references (with and without indirect visibility)")
        ->check(even_ref_spp)
        ->capture_default_str();
    app.add_option("--repeat", o.repeat, "renders per run (timings are medians)")->check(CLI::Range(1, 1000))->capture_default_str();
    app.add_flag("--study", o.study,
                 "run Hahn 2012's grid (VPLs 64..1024 x patterns none, 2x2, 2x4, 4x4, 8x8, both techniques) and more, "
                 "into the --json file");
    app.add_option("--json", o.json, "write the run report (or the study's) here");
    app.add_option("--out", o.out, "write direct + indirect radiance as PNG");
    app.add_option("--indirect-out", o.indirect_out, "write the indirect radiance beside the reference of what it computes as PNG (with "
                   "--visibility rays: the frame without visibility, this one, the occluded reference)");
}

}  // namespace bounce::examples
