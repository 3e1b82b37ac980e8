#pragma once
/// \file indirect/options.hpp
/// What an indirect renderer of the RSM / SII family does per frame, and what it reports:
/// the options, their enums and parameter structs, and the per-stage timings, shared by
/// every backend (cpu::indirect_renderer, gl::indirect_renderer), so a caller sets one
/// `bounce::indirect_options` and hands it to either (docs/rsm-sii-interleaved.md,
/// docs/rsm-sii-gl.md). The functions the options select (disc pattern, VPL selection, splat
/// rectangles) are in indirect/rsm_sampling.hpp.

#include <bounce/errors.hpp>
#include <bounce/indirect/imperfect_shadow_maps.hpp>
#include <bounce/indirect/interleaved_sampling.hpp>
#include <bounce/indirect/view_selection.hpp>
#include <bounce/indirect/visibility.hpp>
#include <bounce/scene_view.hpp>

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <cstddef>
#include <cstdint>
#include <string>

namespace bounce::inline indirect {

enum class indirect_technique {
    rsm_gather,  ///< every pixel gathers a disc of map texels (DS05)
    sii,         ///< every VPL is splatted over its screen bounds (DS06)
};

enum class vpl_selection {
    grid,          ///< texels on a regular grid (Hahn 2012, section 4.1.2)
    flux_warping,  ///< hierarchical importance warping on the flux (DS06 section 3.3)
};

/// How the disc samples of the RSM gather are weighted (indirect/rsm.hpp).
enum class disc_weighting {
    unbiased,     ///< w proportional to xi1 (rsm_disc_sample): estimates the disc's texel sum
    xi1_squared,  ///< DS05's xi1^2 (rsm_disc_sample_xi1_squared): over-weights the rim
};

/// Parameters of the pixel-light irradiance shared by the RSM gather and SII
/// (indirect/rsm.hpp's pixel_light_irradiance).
struct pixel_light_params {
    float offset = 0.f;         ///< sender moved along -n_p (m, >= 0; typical: half a texel footprint)
    float min_distance2 = 0.f;  ///< d^2 clamped below at this (m^2, >= 0; typical: texel footprint^2)
    /// SII's clamp that follows the VPLs' density (>= 0; typical 1; 0: off): when > 0, SII
    /// clamps d^2 below at footprint_scale^2 area / pi instead of min_distance2, the squared
    /// radius of the disc of the area the VPL stands for (vpl::area), so a VPL is never
    /// brighter than that disc would be, and the clamp shrinks as VPLs are added (docs,
    /// section 16). The RSM gather's disc samples carry no area: it keeps min_distance2.
    float footprint_scale = 0.f;

    bool operator==(const pixel_light_params&) const = default;

    /// The d^2 below which SII clamps a VPL standing for `vpl_area` (m^2).
    float min_distance2_for(float vpl_area) const noexcept {
        if (!(footprint_scale > 0.f)) return min_distance2;
        const float footprint = footprint_scale * footprint_scale * vpl_area * float(1.0 / std::numbers::pi);
        return std::isfinite(footprint) ? footprint : 0.f;
    }

    void validate() const {
        require(std::isfinite(offset) && offset >= 0.f, "offset", "must be finite and >= 0");
        require(std::isfinite(min_distance2) && min_distance2 >= 0.f, "min_distance2", "must be finite and >= 0");
        require(std::isfinite(footprint_scale) && footprint_scale >= 0.f, "footprint_scale",
                "must be finite and >= 0");
    }
};

/// Tolerances of the discontinuity buffer (geometry_discontinuity, visibility_discontinuity).
struct discontinuity_params {
    float relative_depth = 0.05f;  ///< depth step, relative to the nearer depth (typical: 0.02-0.1)
    float cos_normal = 0.9f;       ///< smallest cosine between normals of one surface (typical: 0.9, 25 deg)
    /// With visibility by rays, interleaved SII also cuts the blur between neighbours whose
    /// visible fractions differ by more than this many standard errors
    /// (visibility_discontinuity; docs section 15, "Issue 29, fourth session"); 0: no
    /// visibility edges (the blur of geometry alone). Typical: 3.
    float visibility_sigmas = 3.f;
    /// Interleaved SII (no imperfect shadow maps): a pixel whose blur reaches fewer than this
    /// share of the pattern's sub-buffers (edges all round it: a thin ledge, a crease) is
    /// completed with the sum of every VPL of the frame at the pixel itself, the plain
    /// estimate, instead of its few sub-buffers' share at N M times the weight
    /// (cpu::complete_isolated_pixels; docs section 15, fifth session). In [0, 1]; 0: off.
    float complete_below = 0.f;

    bool operator==(const discontinuity_params&) const = default;

    void validate() const {
        require(std::isfinite(relative_depth) && relative_depth >= 0.f, "relative_depth", "must be finite and >= 0");
        require(std::isfinite(cos_normal) && cos_normal >= -1.f && cos_normal <= 1.f, "cos_normal",
                "must lie in [-1, 1]");
        require(std::isfinite(visibility_sigmas) && visibility_sigmas >= 0.f, "visibility_sigmas",
                "must be finite and >= 0");
        require(std::isfinite(complete_below) && complete_below >= 0.f && complete_below <= 1.f, "complete_below",
                "must lie in [0, 1]");
    }
};

/// Tolerances of the geometry-aware upsampling (geometry_aware_upsample_weights).
struct upsample_params {
    float cos_normal = 0.9f;       ///< smallest cosine between a sample's normal and the pixel's (typical: 0.9)
    float plane_footprints = 2.f;  ///< largest distance to the pixel's tangent plane, in low-resolution pixel
                                   ///< footprints at the pixel's depth (typical: 1-4)

    bool operator==(const upsample_params&) const = default;

    void validate() const {
        require(std::isfinite(cos_normal) && cos_normal >= -1.f && cos_normal <= 1.f, "upsample.cos_normal",
                "must lie in [-1, 1]");
        require(std::isfinite(plane_footprints) && plane_footprints > 0.f, "upsample.plane_footprints",
                "must be finite and > 0");
    }
};

/// What an indirect renderer does per frame.
struct indirect_options {
    indirect_technique technique = indirect_technique::sii;
    /// SII: VPLs per frame over all maps; RSM gather: disc samples per pixel and map before
    /// interleaving (each sub-buffer uses count / (N M)). Default 400, DS05's choice for the
    /// gather; typical 400-4096.
    std::size_t count = 400;
    interleave_pattern pattern{4, 4};  ///< 1 x 1: no interleaving (typical: 4 x 4, 8 x 8)
    light_assignment assignment = light_assignment::interleaved;
    int shift = 0;     ///< relabelling of the sub-buffers (assign_lights), in [0, N M); 0 normally
    bool blur = true;  ///< geometry-aware tent over the gathered buffer (only when interleaved)
    /// Interleaved lights weighted N M (docs section 5); false reproduces the thesis's
    /// weight 1 and its loss of 1 - 1/(N M) of the energy, for comparison.
    bool energy_correct = true;
    discontinuity_params discontinuity;
    vpl_selection selection = vpl_selection::flux_warping;  ///< SII only
    float r_max = 1.5f;  ///< RSM gather disc radius, map units (0, 2]; 1.5 reaches the whole map
    disc_weighting disc = disc_weighting::unbiased;  ///< RSM gather sample weights (DS05's xi1^2 to compare)
    pixel_light_params light;                        ///< singularity remedies (indirect/rsm.hpp)
    /// Receiver-sender visibility (indirect/visibility.hpp): none leaks light through walls
    /// as DS05/DS06 do; rays tests every pair the frame sums (the renderer needs an
    /// occlusion_query, CPU only).
    indirect_visibility visibility = indirect_visibility::none;
    /// The RSM gather (CPU) with visibility rays or none: cosine rays per pixel that give back
    /// the light the clamp (light.min_distance2) removes within its distance, from each ray's
    /// first surface with rays, from every surface it crosses without visibility
    /// (indirect/clamp_compensation.hpp; docs/rsm-sii-interleaved.md section 15.5); the renderer then
    /// needs a near_field_query. 0: off (the library's default); typical 16. Ignored with ism
    /// and by SII.
    std::uint32_t clamp_compensation_rays = 0;
    /// With visibility rays (CPU): SII's VPLs drawn again from a larger pool by their
    /// visible contribution to a sparse grid of pixels (indirect/view_selection.hpp; docs
    /// section 15; the RSM gather keeps its pattern). candidates 1 turns it off.
    view_selection_params view_selection;
    /// Imperfect shadow maps' parameters (visibility ism; SII only, the renderer needs an
    /// ism_point_sampler of the scene).
    ism_params ism;
    /// SII splat cutoff, W/m^2 per pixel over all VPLs (each VPL is splatted over the sphere
    /// outside which it gives less than cutoff / VPLs); 0: whole screen.
    float sii_cutoff = 0.f;
    int low_resolution = 1;  ///< RSM gather at 1/f resolution with upsampling (f in 1..8)
    upsample_params upsample;
    std::uint64_t seed = 1;  ///< disc pattern and VPL sampling

    /// Field by field: two option sets that compare equal make the same frames (a caller
    /// keeps its renderer between them; gl::offscreen_indirect_renderer does).
    bool operator==(const indirect_options&) const = default;

    /// Throws parameter_error naming the first bad field. `count` must be at least the
    /// pattern's N M sub-buffers: each sub-buffer shades with count / (N M) lights or disc
    /// samples, so fewer would leave sub-buffers (and the whole image, after the gather)
    /// without light.
    void validate() const {
        require(count > 0 && count <= (std::size_t(1) << 24), "count", "must lie in [1, 2^24]");
        pattern.validate();
        if (count < std::size_t(pattern.cells()))
            throw parameter_error("count", std::to_string(count) + (technique == indirect_technique::sii
                                                                        ? " VPLs are fewer than the "
                                                                        : " disc samples are fewer than the ") +
                                               std::to_string(pattern.cells()) + " sub-buffers of the " +
                                               std::to_string(pattern.n) + "x" + std::to_string(pattern.m) +
                                               " interleave pattern: each sub-buffer needs at least one");
        require(shift >= 0 && shift < pattern.cells(), "shift", "must lie in [0, N M)");
        discontinuity.validate();
        require(std::isfinite(r_max) && r_max > 0.f && r_max <= 2.f, "r_max", "must lie in (0, 2]");
        light.validate();
        require(std::isfinite(sii_cutoff) && sii_cutoff >= 0.f, "sii_cutoff", "must be finite and >= 0");
        require(clamp_compensation_rays <= 4096, "clamp_compensation_rays", "must lie in [0, 4096]");
        require(low_resolution >= 1 && low_resolution <= 8, "low_resolution", "must lie in [1, 8]");
        require(low_resolution == 1 || technique == indirect_technique::rsm_gather, "low_resolution",
                "applies to the RSM gather only");
        upsample.validate();
        view_selection.validate();
        require(discontinuity.complete_below == 0.f || visibility != indirect_visibility::ism,
                "discontinuity.complete_below", "completes with none or rays, not with ism");
        if (visibility == indirect_visibility::ism) {
            require(technique == indirect_technique::sii, "visibility",
                    "ism applies to SII only (the RSM gather's disc samples have no maps of their own)");
            ism.validate(count);
        }
    }
};

/// The default distance below which the pixel-light irradiance's 1/d^2 is clamped for a
/// scene (pixel_light_params::min_distance2 = its square): 1% of the diagonal of the scene's
/// bounding box, so that the clamp scales with the scene (the same in millimetres as in
/// metres); 0 for an empty scene. rsm_sii's default and the benchmark's.
inline float scene_clamp_distance(const scene_view& scene) {
    if (scene.positions.empty()) return 0.f;
    const auto [lo, hi] = scene.bounds();
    return 0.01f * float(glm::length(glm::dvec3(hi) - glm::dvec3(lo)));
}

/// The singularity remedies rsm_sii and the benchmark use on `scene` for `pattern` unless
/// told otherwise: plain SII clamps each VPL at the disc of its own area (footprint_scale
/// 1); interleaved SII and the RSM gather at scene_clamp_distance. Interleaved, neither
/// footprint is right everywhere: a pixel whose blur covers the pattern sees all the VPLs'
/// density, one at an edge only its sub-buffer's (docs, section 16).
inline pixel_light_params default_pixel_light(const scene_view& scene, const interleave_pattern& pattern) {
    pixel_light_params p;
    const float d = scene_clamp_distance(scene);
    p.min_distance2 = d * d;
    p.footprint_scale = pattern.cells() == 1 ? 1.f : 0.f;
    return p;
}

/// Per-stage wall-clock times of one frame (milliseconds) and its counts. On GL the times
/// are the GPU's only when the renderer finishes after each stage (gl::indirect_renderer's
/// time_stages); there the SII shade stage also reads the maps back to select the VPLs.
struct indirect_timings {
    double split_ms = 0;              ///< G-buffer split into sub-buffers (and downsampling)
    double shade_ms = 0;              ///< VPL selection and the gather or splat on the sub-buffers
    double gather_ms = 0;             ///< sub-buffers back to image order
    double blur_ms = 0;               ///< discontinuity buffer and geometry-aware blur
    double upsample_ms = 0;           ///< low-resolution upsampling with full-resolution fallback
    std::size_t vpls = 0;             ///< SII: VPLs splatted; RSM gather: disc samples per pixel and map
    std::size_t fallback_pixels = 0;  ///< pixels the upsampling gathered at full resolution
    std::size_t compensation_rays = 0;  ///< RSM gather with rays: rays of the clamp's compensation
    /// RSM gather with rays: the share of the frame's irradiance (channels summed over the
    /// shaded pixels) the clamp's compensation added.
    double compensation_share = 0;
    double total_ms() const noexcept { return split_ms + shade_ms + gather_ms + blur_ms + upsample_ms; }
};

}  // namespace bounce::indirect
