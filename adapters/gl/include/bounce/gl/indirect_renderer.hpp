#pragma once
/// \file indirect_renderer.hpp
/// `gl::indirect_renderer`: one frame of one-bounce indirect irradiance from reflective
/// shadow maps on OpenGL, by the RSM gather (Dachsbacher and Stamminger 2005) or by
/// splatting indirect illumination (Dachsbacher and Stamminger 2006), optionally
/// interleaved (Keller and Heidrich 2001, in the deferred form of Segovia et al. 2006) and
/// energy-correct (docs/rsm-sii-interleaved.md, section 5), on the caller's G-buffer and
/// RSM textures in the caller's context, into the caller's output texture:
///
///   split G-buffer (fragment pass, index maps of interleaved_sampling.hpp)
///   -> shade each sub-buffer with its light subset
///        RSM gather: a fragment pass reading the disc pattern from a storage buffer
///        SII: one instanced quad per VPL on its split-buffer rectangle, additive blending
///   -> gather (fragment pass) -> discontinuity buffer -> separable geometry-aware tent
///   (the RSM gather may also run at 1/f resolution: a downsampling pass, the frame above at
///   low resolution, then the geometry-aware upsampling with the full-resolution fallback
///   gather of DS05 section 3.3, as the CPU renderer does)
///
/// It is the GL twin of cpu::indirect_renderer: the same options (mirrored here, since the
/// GL adapter does not include the CPU adapter), the same disc pattern and light groups,
/// the same VPLs (selected on the CPU from the read-back RSM with vpl_sampling.hpp, as the
/// CPU renderer selects them), the same pixel rectangles, and every formula an emitted
/// kernel of rsm.hpp and interleaved_sampling.hpp, so its image agrees with the CPU's to
/// float rounding (tests/gl_rsm). Each pixel sums its terms in the CPU's order (blending
/// adds in primitive order).
///
/// Textures are in GL row order (row 0 at the bottom); the index maps are applied to the
/// rows counted from the top, as on the CPU, so both backends put a pixel in the same
/// sub-buffer. The renderer restores the GL state it changes (framebuffers, viewport,
/// program, vertex array, storage bindings 0-1, texture units 0-5 and their samplers,
/// blend, depth and dither state).

#include <bounce/camera.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/gl/rsm_textures.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/interleaved_sampling.hpp>
#include <bounce/vpl_sampling.hpp>

#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce::gl {

// ---- the options: cpu::indirect_options mirrored field by field --------------------------

enum class indirect_technique {
    rsm_gather,  ///< every pixel gathers a disc of map texels (DS05)
    sii,         ///< every VPL is splatted over its screen bounds (DS06)
};

enum class vpl_selection {
    grid,          ///< texels on a regular grid (Hahn 2012, section 4.1.2)
    flux_warping,  ///< hierarchical importance warping on the flux (DS06 section 3.3)
};

/// How the disc samples are weighted (rsm.hpp).
enum class disc_weighting {
    unbiased,     ///< w proportional to xi1 (rsm_disc_sample)
    xi1_squared,  ///< DS05's xi1^2 (rsm_disc_sample_xi1_squared)
};

/// Singularity remedies of the pixel-light irradiance (rsm.hpp's pixel_light_irradiance).
struct pixel_light_params {
    float offset = 0.f;         ///< sender moved along -n_p (m, >= 0; typical: half a texel footprint)
    float min_distance2 = 0.f;  ///< d^2 clamped below at this (m^2, >= 0; typical: texel footprint^2)
    void validate() const;
};

/// Tolerances of the discontinuity buffer (geometry_discontinuity).
struct discontinuity_params {
    float relative_depth = 0.05f;  ///< depth step, relative to the nearer depth (typical: 0.02-0.1)
    float cos_normal = 0.9f;       ///< smallest cosine between normals of one surface (typical: 0.9)
    void validate() const;
};

/// Tolerances of the geometry-aware upsampling (geometry_aware_upsample_weights).
struct upsample_params {
    float cos_normal = 0.9f;       ///< smallest cosine between a sample's normal and the pixel's (typical: 0.9)
    float plane_footprints = 2.f;  ///< largest distance to the pixel's tangent plane, in low-resolution pixel
                                   ///< footprints at the pixel's depth (typical: 1-4)
};

/// What `indirect_renderer` does per frame; the fields, defaults and meanings of
/// cpu::indirect_options (adapters/cpu/include/bounce/cpu/indirect_renderer.hpp).
struct indirect_options {
    indirect_technique technique = indirect_technique::sii;
    /// SII: VPLs per frame over all maps; RSM gather: disc samples per pixel and map before
    /// interleaving (each sub-buffer uses count / (N M)). Typical 400-4096.
    std::size_t count = 400;
    interleave_pattern pattern{4, 4};  ///< 1 x 1: no interleaving (typical: 4 x 4, 8 x 8)
    light_assignment assignment = light_assignment::interleaved;
    int shift = 0;     ///< relabelling of the sub-buffers (assign_lights), in [0, N M); 0 normally
    bool blur = true;  ///< geometry-aware tent over the gathered buffer (only when interleaved)
    bool energy_correct = true;  ///< interleaved lights weighted N M (false: the thesis's weight 1)
    discontinuity_params discontinuity;
    vpl_selection selection = vpl_selection::flux_warping;  ///< SII only
    float r_max = 1.5f;  ///< RSM gather disc radius, map units (0, 2]; 1.5 reaches the whole map
    disc_weighting disc = disc_weighting::unbiased;
    pixel_light_params light;
    float sii_cutoff = 0.f;  ///< SII splat cutoff, W/m^2 per pixel over all VPLs; 0: whole screen
    int low_resolution = 1;  ///< RSM gather at 1/f resolution with upsampling (f in 1..8)
    upsample_params upsample;
    std::uint64_t seed = 1;  ///< disc pattern and VPL sampling
    /// GL only: glFinish after every stage, so the stage times are the GPU's (wall clock
    /// between finishes). Off, the times measure only the issuing of commands.
    bool time_stages = false;

    /// Throws parameter_error naming the first bad field.
    void validate() const;
};

/// Per-stage wall-clock times of one frame (ms; the GPU's when time_stages) and counts,
/// as cpu::indirect_timings.
struct indirect_timings {
    double split_ms = 0;    ///< G-buffer split into sub-buffers (and downsampling)
    double shade_ms = 0;    ///< RSM read-back and VPL selection (SII), upload, the gather or splat passes
    double gather_ms = 0;   ///< sub-buffers back to image order
    double blur_ms = 0;     ///< discontinuity buffer and the two tent passes
    double upsample_ms = 0; ///< low-resolution upsampling with full-resolution fallback
    std::size_t vpls = 0;   ///< SII: VPLs splatted; RSM gather: disc samples per pixel and map
    std::size_t fallback_pixels = 0;  ///< pixels the upsampling gathered at full resolution (an occlusion query)
    double total_ms() const noexcept { return split_ms + shade_ms + gather_ms + blur_ms + upsample_ms; }
};

/// The disc pattern of the RSM gather (DS05 section 3.2): `count` samples (du, dv, w) of
/// rsm_disc_sample (or rsm_disc_sample_xi1_squared) on the shifted Halton points, listed in
/// a seeded shuffled order; the sequence cpu::rsm_disc_pattern makes (tested equal).
std::vector<glm::vec3> rsm_disc_pattern(std::size_t count, float r_max, std::size_t texel_count, std::uint64_t seed = 1,
                                        disc_weighting weighting = disc_weighting::unbiased);

/// The VPLs of one frame from `maps`, shared between maps in proportion to their flux and
/// taken by `selection` (the CPU renderer's selection).
std::vector<vpl> select_vpls(std::span<const rsm_view> maps, const indirect_options& options);

class indirect_renderer {
public:
    /// Compiles the passes' programs (a context must be current; it must outlive the
    /// renderer). Throws parameter_error for bad options.
    explicit indirect_renderer(const indirect_options& options = {});
    ~indirect_renderer();
    indirect_renderer(const indirect_renderer&) = delete;
    indirect_renderer& operator=(const indirect_renderer&) = delete;

    const indirect_options& options() const noexcept { return options_; }

    /// Writes into `irradiance` (RGBA32F, the G-buffer's size; rgb = W/m^2, a = 0) the
    /// one-bounce indirect irradiance `maps` (one per spot or directional light, six per
    /// point light, one size for the gather) reflect onto the G-buffer `g` seen by `cam`,
    /// unoccluded; 0 where the G-buffer sees nothing. Throws parameter_error naming the
    /// texture or map at fault (sizes, formats, zero-sized textures).
    indirect_timings render(const gbuffer_textures& g, const camera& cam, std::span<const rsm_textures> maps,
                            const texture_ref& irradiance);

    /// The last frame's VPLs (SII), in the order of their light groups (sub-buffer 0's
    /// first), each with its interleaving weight already applied to the flux.
    const std::vector<vpl>& splatted_vpls() const noexcept { return splatted_; }

private:
    struct passes;
    using clock = std::chrono::steady_clock;
    double lap(clock::time_point& t) const;
    void frame(const gbuffer_textures& g, std::size_t w, std::size_t h, const camera& cam,
               std::span<const rsm_textures> maps, object_id out, indirect_timings& t, clock::time_point& start);

    indirect_options options_;
    std::unique_ptr<passes> passes_;
    std::vector<vpl> splatted_;
};

}  // namespace bounce::gl
