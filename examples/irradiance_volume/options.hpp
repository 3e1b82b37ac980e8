#pragma once
// irradiance_volume's options: what the command line sets and how it is spelled and checked
// (main.cpp runs and reports).
#include "../common/cli_choices.hpp"
#include "../common/cli_number_checks.hpp"

#include <bounce/cpu/irradiance_volume.hpp>
#include <bounce/embree/probe_baker.hpp>
#include <bounce/embree/probe_visibility_baker.hpp>
#include <bounce/study/volume_sphere.hpp>
#include <bounce/volume/probe_octree.hpp>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace bounce::examples {

/// --mode: a uniform grid of probes, or an octree refined where the light changes.
enum class volume_mode { uniform, adaptive };
inline const choices<volume_mode> mode_names{{"uniform", volume_mode::uniform}, {"adaptive", volume_mode::adaptive}};
inline const choices<volume_refinement> refine_names{{"merge", volume_refinement::merge}, {"split", volume_refinement::split}};
inline const choices<embree::probe_noise_estimate> noise_names{
    {"even-odd", embree::probe_noise_estimate::even_odd},
    {"independent-halves", embree::probe_noise_estimate::independent_halves},
    {"rotated-repeat", embree::probe_noise_estimate::rotated_repeat}};
inline const choices<hanging_corner_storage> hanging_names{{"stored", hanging_corner_storage::stored},
                                                           {"computed", hanging_corner_storage::computed}};
inline const choices<bias_tolerance_unit> tolerance_unit_names{{"light", bias_tolerance_unit::scene_light},
                                                               {"noise", bias_tolerance_unit::probe_noise}};
inline const choices<cpu::volume_interpolation> interp_names{{"trilinear", cpu::volume_interpolation::trilinear},
                                                                {"weighted", cpu::volume_interpolation::weighted}};

struct volume_options {
    volume_mode mode = volume_mode::adaptive;
    cpu::volume_interpolation interp = cpu::volume_interpolation::trilinear;
    std::string scene = "cornell", gradients = "on", json, out;
    int max_depth = 4, min_depth = -1;  // -1: 1 (adaptive) or max_depth (uniform)
    float b = 2.f, support = 1.5f;
    std::uint32_t rays = 512, geometry_triangles = 1;
    study::volume_sphere_settings sphere;
    float radius = 0;        // fraction of the volume's diagonal; 0: from the free space
    float margin = -0.01f;   // fraction of the scene's extent added on every side
    std::vector<float> path; // x0 y0 z0 x1 y1 z1 as fractions of the volume's box
    float distance_ratio = 1.f, neighbour_change = 0.25f, gradient_ratio = 0.3f, cull = 0.05f;
    float prediction_tolerance = 0.05f, noise_sigmas = 4.f, gradient_noise = 1.f;
    float gradient_step = 0.1f;  // fraction of the finest cell's shortest edge
    std::uint64_t seed = 1;
    int threads = 0;
    bool sh_study = false, surface = false;
    std::string refit = "on", conforming = "on", calibrate = "on";
    float bias_budget = 0.f, bias_tolerance = 0.f;
    volume_refinement refine = volume_refinement::merge;
    std::size_t surface_size = 128;
    embree::probe_visibility_settings visibility;
    float self_shadow_bias = 0.3f;
    std::string relocate = "off";
    embree::probe_noise_estimate noise = embree::probe_noise_estimate::even_odd;
    std::vector<float> sweep, sweep_sigmas, sweep_tolerances;  // merged octrees built from the same probes
    std::vector<int> sweep_depths;           // ... and uniform grids, at these finest depths
    bool sweep_surface = false;              // ... measured at the camera's surface points too
    int sweep_equal_rays = -1;               // ... and rebaked with the rays of the grid of this depth
    hanging_corner_storage hanging = hanging_corner_storage::stored;
    bias_tolerance_unit tolerance_unit = bias_tolerance_unit::scene_light;
};

/// Every option of the program, with its checks, on `app`, setting `o`.
inline void add_volume_options(CLI::App& app, volume_options& o) {
    app.add_option("--scene", o.scene, "cornell, a scene folder name under BOUNCE_SCENES, or a path");
    add_choice(app, "--mode", o.mode, mode_names, "uniform or adaptive");
    app.add_option("--max-depth", o.max_depth, "deepest octree level (uniform: the grid's depth), 0..10")
        ->check(CLI::Range(0, irradiance_volume::depth_limit));
    app.add_option("--min-depth", o.min_depth, "shallowest leaf level of an adaptive octree (default 1)")
        ->check(CLI::Range(0, irradiance_volume::depth_limit));
    add_choice(app, "--interp", o.interp, interp_names, "trilinear or weighted");
    app.add_option("--b", o.b, "distance exponent of the weighted average, (0, 4]")->check(detail::number_in(0, 4, true, "an exponent", /*lo_included=*/false));
    app.add_option("--support", o.support, "a probe's weight reaches 0 at support * half the diagonal of its largest leaf, > 1")
        ->check(detail::number_in(1, 16, true, "a support", /*lo_included=*/false));
    app.add_option("--gradients", o.gradients, "on or off (weighted interpolation)")->check(CLI::IsMember({"on", "off"}));
    app.add_option("--rays", o.rays, "rays per probe")->check(CLI::Range(1u, 1u << 20));
    app.add_option("--ref-samples", o.sphere.reference_samples, "reference hemisphere samples per sphere point")
        ->check(CLI::Range(1u, 1u << 20));
    app.add_option("--frames", o.sphere.frames, "sphere positions along the path for the error")->check(CLI::Range(1u, 4096u));
    app.add_option("--sphere-points", o.sphere.sphere_points, "surface points per sphere")->check(CLI::Range(1u, 65536u));
    app.add_option("--popping-steps", o.sphere.popping_steps, "steps along the path for popping")->check(CLI::Range(2u, 65536u));
    app.add_option("--radius", o.radius, "sphere radius, fraction of the volume's diagonal (default: the largest up to 0.02 "
                                         "that the free space along the view holds)")->check(detail::number_in(1e-6, 0.5, true, "a fraction"));
    app.add_option("--margin", o.margin, "volume box = scene bounds grown by this fraction of their extent per side")
        ->check(detail::number_in(-0.4, 4, true, "a fraction"));
    app.add_option("--path", o.path, "x0 y0 z0 x1 y1 z1: the sphere's path in fractions of the volume's box (default: from the "
                                     "free space along the camera's view)")->expected(6)->check(detail::number_in(0, 1, true, "a fraction"));
    app.add_option("--distance-ratio", o.distance_ratio, "split: harmonic mean distance < ratio * cell diagonal (0 off)")
        ->check(finite_non_negative);
    app.add_option("--neighbour-change", o.neighbour_change, "split: relative change between corners (0 off)")
        ->check(finite_non_negative);
    app.add_option("--geometry-triangles", o.geometry_triangles, "split: triangles in the cell (0 off)");
    app.add_option("--gradient-ratio", o.gradient_ratio, "split: |grad E| * edge / E (0 off)")->check(finite_non_negative);
    app.add_option("--cull", o.cull, "cull children within this fraction of the parent's interpolation (0 off)")
        ->check(finite_non_negative);
    app.add_option("--prediction-tolerance", o.prediction_tolerance,
                   "adaptive: split where a new probe differs from its parent's prediction by more than this fraction "
                   "and noise-sigmas standard errors (0: Oat's heuristics above)")
        ->check(finite_non_negative);
    app.add_option("--noise-sigmas", o.noise_sigmas, "differences within this many standard errors of the probes are noise")
        ->check(finite_non_negative);
    app.add_option("--refit", o.refit, "on: the samples of culled splits refit the kept probes (least squares)")
        ->check(CLI::IsMember({"on", "off"}));
    add_choice(app, "--refine", o.refine, refine_names,
                         "adaptive: merge cells from the finest grid up, or split them from the root down");
    app.add_option("--conforming", o.conforming, "on: corners at level boundaries take the coarser leaf's interpolation")
        ->check(CLI::IsMember({"on", "off"}));
    app.add_option("--bias-budget", o.bias_budget, "merge: the bias a merge may add, fraction of the noise it removes "
                                                   "(0: the per-probe test)")->check(finite_non_negative);
    app.add_option("--bias-tolerance", o.bias_tolerance, "merge: the bias a merge may add, fraction of the finest grid's mean "
                                                         "light, in place of --bias-budget (0: off)")->check(finite_non_negative);
    app.add_option("--calibrate-noise", o.calibrate, "on: scale the probes' noise to the finest grid's second differences")
        ->check(CLI::IsMember({"on", "off"}));
    app.add_option("--gradient-noise", o.gradient_noise, "keep a probe's gradient only where it exceeds this times its noise "
                                                         "(0: keep all)")->check(finite_non_negative);
    add_choice(app, "--noise-estimate", o.noise, noise_names, "a probe's noise: from its rays' even and odd halves, "
                         "from two independently turned halves, or from a repeat of its rays turned at random");
    app.add_option("--sweep-bias-budget", o.sweep, "also build merged octrees from the same probes at these bias budgets and "
                                                   "report their trilinear lookups under \"sweep\"")->check(finite_positive);
    app.add_option("--sweep-noise-sigmas", o.sweep_sigmas, "the sweep's octrees at each of these --noise-sigmas too")
        ->check(finite_non_negative);
    app.add_option("--sweep-bias-tolerance", o.sweep_tolerances, "the sweep's octrees at these --bias-tolerance values too "
                                                                 "(with --sweep-depths)")->check(finite_positive);
    app.add_option("--sweep-depths", o.sweep_depths, "also the uniform grid of each of these depths (<= --max-depth: from the "
                                                     "same probes), and the sweep's octrees merged from each of them")
        ->check(CLI::Range(0, irradiance_volume::depth_limit));
    app.add_flag("--sweep-surface", o.sweep_surface, "also measure the sweep's octrees at the camera's surface points "
                                                     "(--surface-size, --ref-samples)");
    app.add_option("--sweep-equal-rays", o.sweep_equal_rays, "also measure each of the sweep's octrees with its probes baked "
                                                             "again with the total rays of the uniform grid of this depth, "
                                                             "and with --rays each (needs --hanging-corners computed)")
        ->check(CLI::Range(0, irradiance_volume::depth_limit));
    add_choice(app, "--hanging-corners", o.hanging, hanging_names,
               "adaptive: a probe at each T-junction corner (stored), or none, interpolated by the trilinear lookup");
    add_choice(app, "--bias-tolerance-unit", o.tolerance_unit, tolerance_unit_names,
               "--bias-tolerance in units of the finest grid's mean light or of its probes' median noise");
    app.add_option("--gradient-step", o.gradient_step, "central-difference step, fraction of the finest cell edge (0: no "
                                                       "gradients; trilinear lookups and merging do not use them)")
        ->check(finite_non_negative);
    app.add_option("--seed", o.seed, "seed of the probes' and the reference's light samples, 0 .. 2^64 - 1")
        ->check(seed_u64);
    app.add_option("--repeat", o.sphere.repeat, "lookup timing repeats (median)")->check(CLI::Range(1, 1000));
    app.add_option("--threads", o.threads, "TBB threads (0: all)")->check(CLI::Range(0, 1024));
    app.add_option("--json", o.json, "write the run report here");
    app.add_option("--out", o.out, "write a strip of four frames here (.exr: linear; else 8-bit sRGB, auto exposure)");
    app.add_flag("--sh-study", o.sh_study, "SH projection and irradiance errors per order of environments along the path");
    app.add_flag("--surface", o.surface, "light the camera's G-buffer with and without visibility, against the reference");
    app.add_option("--surface-size", o.surface_size, "G-buffer width and height of --surface")->check(CLI::Range(1, 4096));
    app.add_option("--visibility-resolution", o.visibility.resolution, "texels per side of each probe's distance map")
        ->check(CLI::Range(1u, 64u));
    app.add_option("--visibility-rays", o.visibility.rays, "rays per probe for its distance map")->check(CLI::Range(1u, 1u << 20));
    app.add_option("--relocate", o.relocate, "on: probes inside geometry are baked moved into free space within their cell")
        ->check(CLI::IsMember({"on", "off"}));
    app.add_option("--self-shadow-bias", o.self_shadow_bias, "visibility test's self-shadow bias (fraction of 0.75 cell)")
        ->check(detail::number_in(0, 4, true, "a bias"));
}

/// Refuses options that need another: --sweep-equal-rays bakes the octrees' stored probes
/// again, which needs their hanging corners computed (a stored one would keep the old light).
inline void check_volume_options(const volume_options& o) {
    if (o.sweep_equal_rays >= 0 && o.hanging != hanging_corner_storage::computed)
        throw parameter_error("--sweep-equal-rays", "bakes the sweep's stored probes again, which needs --hanging-corners computed");
}

/// The build's settings from the options (memory_limit_bytes left to the caller).
inline irradiance_volume_settings volume_settings(const volume_options& o) {
    irradiance_volume_settings vs;
    vs.max_depth = o.max_depth;
    vs.min_depth = o.mode == volume_mode::uniform ? o.max_depth
                   : o.min_depth >= 0            ? o.min_depth
                                                 : std::min(1, o.max_depth);
    vs.distance_ratio = o.distance_ratio;
    vs.neighbour_change = o.neighbour_change;
    vs.geometry_triangles = o.geometry_triangles;
    vs.gradient_ratio = o.gradient_ratio;
    vs.cull_tolerance = o.cull;
    vs.prediction_tolerance = o.prediction_tolerance;
    vs.noise_sigmas = o.noise_sigmas;
    vs.refit_culled = o.refit == "on";
    vs.refinement = o.refine;
    vs.conforming_corners = o.conforming == "on";
    vs.bias_budget = o.bias_budget;
    vs.bias_tolerance = o.bias_tolerance;
    vs.tolerance_unit = o.tolerance_unit;
    vs.hanging_corners = o.hanging;
    vs.calibrate_noise = o.calibrate == "on";
    return vs;
}

}  // namespace bounce::examples
