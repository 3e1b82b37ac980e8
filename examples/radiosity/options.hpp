#pragma once
// radiosity's options: what the command line sets, how it is spelled and checked, the
// library settings it makes, and how the report lists them (main.cpp runs and reports).
#include <bounce/cpu/radiosity.hpp>
#include <bounce/embree/multi_bounce_reference.hpp>
#include <bounce/errors.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/radiosity/options.hpp>
#include <bounce/radiosity/subdivision.hpp>

#ifdef BOUNCE_WITH_GL
#include <bounce/gl/radiosity.hpp>
#endif

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include "../common/cli_choices.hpp"
#include "../common/cli_number_checks.hpp"
#include "view.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

namespace bounce::examples {

/// Where a shot's visibility comes from: a stereographic or hemicube item buffer, or rays.
enum class visibility_kind { stereo, hemicube, rays };
inline const choices<visibility_kind> visibility_names{
    {"stereo", visibility_kind::stereo}, {"hemicube", visibility_kind::hemicube}, {"rays", visibility_kind::rays}};

/// What --converge is a fraction of (radiosity_measure): the power surfaces reflect, bounces
/// to come included (indirect), or the emitted power, lights' direct light included (emitted).
inline const choices<radiosity_measure> measure_names{{"indirect", radiosity_measure::indirect},
                                                      {"emitted", radiosity_measure::emitted}};

struct options {
    std::string scene = "cornell";
    std::size_t elements = 10000;     // target element count of the atlas (before subdivision)
    int block = 8;                    // shooting block side, texels (substructuring)
    double chart_cone = atlas_options{}.cone_degrees;  // charts' cone half-angle, degrees (0: planar charts)
    tiny_chart_clusters clusters = atlas_options{}.clusters;  // charts smaller than a texel sharing one element
    visibility_kind visibility = visibility_kind::stereo;
    int resolution = 128;             // item buffer side (hemicube: per face)
    float tolerance_px = 0.25f;       // stereographic tessellation: largest edge sagitta, pixels
    bool adaptive = false;
    int max_level = 2;                // adaptive: deepest level
    double threshold = 0.25;          // adaptive: second-difference threshold
    int subdivide_steps = 200;        // adaptive: subdivide after each of the first N steps
    examples::backend backend = backend::cpu;
    double converge = 0.9;            // stop when this fraction of converge_on's power is shot
    radiosity_measure converge_on = radiosity_measure::indirect;
    double max_seconds = 0;           // also stop after this much solving (0: no limit)
    int shooters_per_step = 1;
    double near_field = 4;
    bool ambient = true;  // the ambient term (ambient_shape_for: the mixed one, Cohen's in re-bakes)
    radiosity_ambient ambient_shape = radiosity_ambient::mixed;  // with ambient: Cohen's, the shots', or mixed
    bool ambient_given = false;       // --ambient was given (else ambient_shape_for chooses by backend)
    bool one_sided = false;           // only the front (counter-clockwise) side receives and shoots
    int light_samples = 4;            // the lights' shot at k x k points of each whole texel (CPU)
    int shooter_groups = 0;           // grouped shooters: at most N groups of blocks (0: off; rays only)
    int group_rays = 1;               // grouped shots: visibility rays per receiver
    double group_near_field = 4;      // grouped shots: a group's node opens within this many half-diagonals
    int repeat = 1;                   // solves timed (medians reported)
    std::size_t width = 256, height = 256;
    bool reference = true;
    std::uint32_t reference_paths = 256;
    std::uint64_t seed = 1;           // the reference's base seed
    int curve_points = 16;            // error checkpoints along the solve (0: none)
    bool quiet = false;
    view_kind view = view_kind::automatic;  // the camera's view: the lightmap, or the lights' direct light per pixel
    std::filesystem::path json, out, lightmaps, versus, reference_out, holes_out, oracle_out;
    std::string rebake_light, rebake_move;  // re-bakes (rebake.hpp): K,SCALE and MATERIAL[#N],DX,DY,DZ
    double rebake_check = 0.99;             // re-bakes: the converged fraction both solves are then taken to
};

inline void add_options(CLI::App& app, options& o) {
    const auto on_off = [&app](const char* name, bool& flag, const char* what) {
        app.add_option_function<std::string>(name, [&flag](const std::string& v) { flag = v == "on"; }, what)
            ->check(CLI::IsMember({"on", "off"}))
            ->default_str(flag ? "on" : "off");
    };
    app.add_option("--scene", o.scene, "cornell, a scene.json, its folder, an .obj, a .gltf or .glb, or a name under the scenes folder")
        ->capture_default_str();
    app.add_option("--elements", o.elements, "target number of elements (lightmap texels)")
        ->check(CLI::Range(std::size_t(16), std::size_t(50000000)))->capture_default_str();
    app.add_option("--chart-cone", o.chart_cone,
                   "charts follow surfaces within this cone of their normal, degrees (0: planar charts only)")
        ->check(CLI::Range(0.0, 89.9));
    app.add_option("--clusters", o.clusters,
                   "charts smaller than a texel share one element: never, when-needed (the count missed by >10%), always")
        ->transform(CLI::CheckedTransformer(std::map<std::string, tiny_chart_clusters>{
            {"never", tiny_chart_clusters::never}, {"when-needed", tiny_chart_clusters::when_needed},
            {"always", tiny_chart_clusters::always}}));
    app.add_option("--block", o.block, "side of a shooting block in texels (substructuring; 1: shoot elements)")
        ->check(CLI::Range(1, 256))->capture_default_str();
    add_choice(app, "--visibility", o.visibility, visibility_names, "stereo | hemicube | rays")->capture_default_str();
    app.add_option("--resolution", o.resolution, "item buffer side in pixels (hemicube: per face, even)")
        ->check(CLI::Range(8, 8192))->capture_default_str();
    app.add_option("--tolerance-px", o.tolerance_px, "stereographic tessellation: largest edge sagitta, pixels")
        ->check(examples::finite_positive)->capture_default_str();
    on_off("--adaptive", o.adaptive, "adaptive subdivision: on | off");
    app.add_option("--max-level", o.max_level, "adaptive: deepest quadtree level")->check(CLI::Range(0, 8))
        ->capture_default_str();
    app.add_option("--threshold", o.threshold, "adaptive: second-difference threshold (times the leaf's mean)")
        ->check(examples::finite_positive)->capture_default_str();
    app.add_option("--subdivide-steps", o.subdivide_steps, "adaptive: subdivide after each of the first N steps")
        ->check(CLI::Range(0, 1000000))->capture_default_str();
    add_choice(app, "--backend", o.backend, backend_names, "cpu | gl")->capture_default_str();
    app.add_option("--converge", o.converge, "stop when this fraction of --converge-on's power has been shot, in [0, 1)")
        ->check(examples::detail::number_in(0, 1, false, "a fraction"))->capture_default_str();
    add_choice(app, "--converge-on", o.converge_on, measure_names,
               "indirect (the power surfaces reflect, bounces to come included) | emitted (lights' direct light included)")
        ->capture_default_str();
    app.add_option("--max-seconds", o.max_seconds, "also stop after this many seconds of shooting (0: no limit)")
        ->check(examples::finite_non_negative)->capture_default_str();
    app.add_option("--shooters-per-step", o.shooters_per_step, "shooters taken from one choice")
        ->check(CLI::Range(1, 4096))->capture_default_str();
    app.add_option("--near-field", o.near_field, "a block shoots as its quadrants within this many sides (0: one disc)")
        ->check(examples::finite_non_negative)->capture_default_str();
    app.add_option_function<std::string>(
           "--ambient",
           [&o](const std::string& v) {
               o.ambient = v != "off";
               o.ambient_given = true;
               o.ambient_shape = v == "shots"   ? radiosity_ambient::shots
                                 : v == "mixed" ? radiosity_ambient::mixed
                                                : radiosity_ambient::uniform;
           },
           "show the ambient term: off | on (= uniform, Cohen et al. 1988) | uniform | shots (amount and shape "
           "measured from the recent shots, radiosity/ambient.hpp) | mixed (the shots' amount, their shape above "
           "an even floor of its reflected share)")
        ->check(CLI::IsMember({"off", "on", "uniform", "shots", "mixed"}))
        ->default_str("mixed; uniform in re-bakes");
    app.add_option("--light-samples", o.light_samples,
                   "point, spot and directional lights taken at k x k points of each whole texel (1: its element's point)")
        ->check(CLI::Range(1, 16))->capture_default_str();
    app.add_option("--shooter-groups", o.shooter_groups,
                   "shoot groups of nearby, similarly oriented blocks across charts, at most N (0: each block; -1: as "
                   "many as the scene makes worth it; rays only)")
        ->check(CLI::Range(-1, 1 << 24))->capture_default_str();
    app.add_option("--group-near-field", o.group_near_field,
                   "grouped shots: a node of several blocks shoots as one disc beyond this many half-diagonals")
        ->check(examples::finite_non_negative)->capture_default_str();
    app.add_option("--group-rays", o.group_rays, "grouped shots: visibility rays per receiver, from members drawn by their light")
        ->check(CLI::Range(1, 16))->capture_default_str();
    app.add_flag("--one-sided", o.one_sided,
                 "only the front (counter-clockwise) side of a surface receives and shoots (default: both sides, "
                 "as the reference)");
    app.add_option("--repeat", o.repeat, "solve N times; timings are medians")->check(CLI::Range(1, 100))
        ->capture_default_str();
    app.add_option("--width", o.width, "view width")->check(CLI::Range(1, 16384))->capture_default_str();
    app.add_option("--height", o.height, "view height")->check(CLI::Range(1, 16384))->capture_default_str();
    on_off("--reference", o.reference, "compare with the multi-bounce reference: on | off");
    app.add_option("--reference-paths", o.reference_paths, "reference paths per pixel")
        ->check(CLI::Range(1u, 1u << 20))->capture_default_str();
    app.add_option("--seed", o.seed, "base seed of the reference's paths, 0 .. 2^64 - 1")->check(seed_u64)
        ->capture_default_str();
    app.add_option("--curve-points", o.curve_points, "error checkpoints along the solve (0: none)")
        ->check(CLI::Range(0, 1000))->capture_default_str();
    app.add_flag("--quiet", o.quiet, "no progress line");
    app.add_option("--json", o.json, "write the run report (JSON) here");
    app.add_option("--out", o.out, "write the rendered view here (.png or .exr)");
    app.add_option("--lightmaps", o.lightmaps, "write the lightmaps (EXR) into this folder");
    app.add_option("--holes-out", o.holes_out, "write a CSV of the view's black pixels where the reference is lit (holes.hpp)");
    add_choice(app, "--view", o.view, view_names,
               "lightmap (B / pi looked up) | direct+indirect (the lights' direct light per pixel, the rest looked up) | "
               "auto (direct+indirect)")
        ->capture_default_str();
    app.add_option("--oracle-out", o.oracle_out, "write the error's split and the best lightmap's error (JSON, oracle.hpp)");
    app.add_option("--reference-out", o.reference_out, "write the reference view here (.png or .exr)");
    app.add_option("--versus", o.versus, "also compare the view with this EXR view of another run (same size)");
    // The re-bakes (rebake.hpp).
    app.add_option("--rebake-light", o.rebake_light,
                   "bake, scale light K's intensity by SCALE (K,SCALE), re-bake from the solution and compare with a fresh solve");
    app.add_option("--rebake-move", o.rebake_move,
                   "bake, move an object (MATERIAL[#N],DX,DY,DZ: the material's N-th group of connected triangles) by "
                   "DX, DY, DZ, re-bake from the solution and compare with a fresh solve");
    app.add_option("--rebake-check", o.rebake_check, "re-bakes: the converged fraction both solves are then taken to")
        ->check(CLI::Range(0.0, 0.99999))
        ->capture_default_str();
}

/// The settings of the atlas the options ask for.
inline atlas_options atlas_options_for(const options& o) {
    atlas_options a;
    a.elements = o.elements;
    a.block_texels = o.block;
    a.cone_degrees = o.chart_cone;
    a.clusters = o.clusters;
    a.padding = 1;
    return a;
}

/// The ambient term's shape the solver gets: --ambient's when given; else the mixed term (both
/// backends), Cohen's uniform one in re-bakes (a negative unshot power has no shaped amount,
/// Cohen's term is signed).
inline radiosity_ambient ambient_shape_for(const options& o) {
    const bool rebake = !o.rebake_light.empty() || !o.rebake_move.empty();
    return o.ambient_given || !rebake ? o.ambient_shape : radiosity_ambient::uniform;
}

// The shooting options, the same for both backends (include/bounce/radiosity/options.hpp).
inline radiosity_options solver_options_for(const options& o) {
    radiosity_options r;
    r.shoot_blocks = o.block > 1;
    r.shooters_per_step = o.shooters_per_step;
    r.ambient = o.ambient;
    r.ambient_shape = ambient_shape_for(o);
    r.near_field = o.near_field;
    r.two_sided = !o.one_sided;
    r.light_samples = o.light_samples;
    r.shooter_groups = o.shooter_groups;
    r.group_visibility_samples = o.group_rays;
    r.group_near_field = o.group_near_field;
    return r;
}

inline subdivision_options subdivision_options_for(const options& o) {
    subdivision_options s;
    s.threshold = o.threshold;
    s.max_level = o.max_level;
    return s;
}

inline embree::multi_bounce_settings reference_settings_for(const options& o) {
    embree::multi_bounce_settings s;
    s.paths = o.reference_paths;
    s.seed = o.seed;
    return s;
}

/// What the chosen backend and visibility do not offer, refused before any work.
inline void check_options(const options& o) {
    if (o.visibility == visibility_kind::hemicube && o.resolution % 2 != 0)
        throw parameter_error("--resolution", "a hemicube needs an even resolution");
    check_backend_built(o.backend);
    if (o.shooter_groups != 0 && o.visibility != visibility_kind::rays)
        throw parameter_error("--shooter-groups", "needs --visibility rays: a group's rays leave from its members, and "
                                                  "an item buffer renders from one point per shot");
    if (!o.oracle_out.empty() && o.adaptive)
        throw parameter_error("--oracle-out", "needs base texels: not with --adaptive");
    if (o.backend != backend::gl) return;
    // What the GL solver does not offer (docs/radiosity-gl.md).
    if (o.visibility == visibility_kind::rays)
        throw parameter_error("--visibility", "'rays' runs on the CPU backend only");
    if (o.adaptive) throw parameter_error("--adaptive", "'on' runs on the CPU backend only");
    if (o.shooters_per_step != 1) throw parameter_error("--shooters-per-step", "must be 1 on the GL backend");
}

inline cpu::item_buffer_visibility::options item_options_for(const options& o) {
    cpu::item_buffer_visibility::options v;
    v.projection = o.visibility == visibility_kind::hemicube ? cpu::item_projection::hemicube
                                                              : cpu::item_projection::stereographic;
    v.resolution = o.resolution;
    v.tolerance_px = o.tolerance_px;
    return v;
}

#ifdef BOUNCE_WITH_GL
inline gl::radiosity_options gl_options_for(const options& o) {
    gl::radiosity_options g;
    g.shooting = solver_options_for(o);  // --shooters-per-step is refused unless 1
    g.shooting.light_samples = 1;        // the GL solver takes lights at element points (--light-samples: CPU)
    g.visibility = o.visibility == visibility_kind::hemicube ? gl::radiosity_visibility::hemicube
                                                              : gl::radiosity_visibility::stereographic;
    g.resolution = o.resolution;
    g.tolerance_px = o.tolerance_px;
    return g;
}
#endif

/// The run's parameters as the report lists them.
inline nlohmann::ordered_json parameters_json(const options& o) {
    return {{"elements", o.elements}, {"block", o.block}, {"chart_cone", o.chart_cone}, {"visibility", name_of(visibility_names, o.visibility)},
            {"resolution", o.resolution}, {"tolerance_px", o.tolerance_px},
            {"adaptive", o.adaptive ? "on" : "off"}, {"max_level", o.max_level},
            {"threshold", o.threshold}, {"subdivide_steps", o.subdivide_steps},
            {"converge", o.converge}, {"converge_on", name_of(measure_names, o.converge_on)}, {"max_seconds", o.max_seconds},
            {"shooters_per_step", o.shooters_per_step}, {"near_field", o.near_field},
            {"ambient", !o.ambient ? "off" : std::array{"on", "shots", "mixed"}[int(ambient_shape_for(o))]}, {"sides", o.one_sided ? 1 : 2}, {"light_samples", o.light_samples},
            {"shooter_groups", o.shooter_groups}, {"group_rays", o.group_rays},
            {"group_near_field", o.group_near_field},
            {"view", name_of(view_names, o.view != view_kind::automatic ? o.view : view_kind::direct_indirect)},
            {"reference_paths", o.reference_paths}, {"seed", o.seed}};
}

}  // namespace bounce::examples
