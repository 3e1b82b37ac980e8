#pragma once
/// \file radiosity/options.hpp
/// What the progressive radiosity solvers share whatever their backend: how they shoot
/// (radiosity_options), the time they spent per stage (radiosity_timings) and where a solve
/// stands (radiosity_progress), and the finest stereographic tolerance worth asking for
/// (stereographic_tolerance_floor). cpu::progressive_radiosity takes these as they are;
/// gl::radiosity_options extends radiosity_options with its item-buffer options. A solve to
/// a target with checkpoints: radiosity/solve.hpp.

#include <bounce/errors.hpp>
#include <bounce/scene_view.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline radiosity {

/// The ambient term's amount and shape (radiosity_options::ambient_shape): Cohen et al. 1988's
/// uniform one, the one measured from the solve's recent shots, or mixed: the shots' amount in
/// their shape above an even floor of its reflected share (radiosity/ambient.hpp).
enum class radiosity_ambient { uniform, shots, mixed };

/// How a solver shoots.
struct radiosity_options {
    bool shoot_blocks = true;      ///< substructuring: shoot per atlas block (true) or per element
    int shooters_per_step = 1;     ///< shooters taken from one choice, shot in turn (typical: 1-16;
                                   ///< the GL solver shoots one)
    bool ambient = true;           ///< display_radiosity adds the ambient term (Cohen et al. 1988)
    radiosity_ambient ambient_shape = radiosity_ambient::uniform;  ///< with ambient: uniform (as in
                                   ///< re-bakes), shaped by the recent shots, or mixed (the radiosity
                                   ///< program's default; radiosity/ambient.hpp). Both solvers, CPU and GL
    double near_field = 4;         ///< a block shoots as one disc to receivers farther than this many
                                   ///< times its side (sqrt of its area), else as its quadrants,
                                   ///< recursively; 0: always one disc (typical: 2-4)
    bool two_sided = true;         ///< every element receives and shoots on both sides, a radiosity
                                   ///< per side (the reference integrator's convention, issue 30);
                                   ///< false: only the front (counter-clockwise) side. Both
                                   ///< solvers, CPU and GL
    int light_samples = 1;         ///< point, spot and directional lights are taken at k x k points of
                                   ///< each whole texel (light_sample_point), not only at its element's
                                   ///< point, so light narrower than a texel (the sun through a slit) is
                                   ///< not missed; 1: the element's point (CPU solver; typical: 1-4)
    int shooter_groups = 0;        ///< grouped shooters (radiosity/shooter_groups.hpp, issue 30): the
                                   ///< block-sides gathered into at most this many groups of nearby,
                                   ///< similarly oriented blocks across charts, each shooting as one
                                   ///< with visibility sampled per receiver from a member element; needs
                                   ///< a visibility with visible_from (ray casts). 0: every block-side
                                   ///< shoots alone; -1: as many as the scene's shape and blocks make
                                   ///< worth it (the budget derived in shooter_groups.hpp; CPU solver)
    double group_near_field = 4;   ///< grouped shots: a node above the blocks (several blocks) shoots as
                                   ///< one disc to receivers farther than this many times its half
                                   ///< diagonal, else as its two halves (typical: 1-4)
    int group_visibility_samples = 1;  ///< grouped shots: rays per receiver, each from an element drawn
                                       ///< in proportion to its share of the receiver's light (1-16)
    double group_discs = 2;        ///< the derived budget (shooter_groups -1): groups are split while a
                                   ///< receiver takes more discs than this per group shot on average
                                   ///< (group_cut::discs; > 0, typical: 2-8)

    /// Throws parameter_error naming the option ("radiosity_options.near_field" ...).
    void validate() const {
        require(shooters_per_step >= 1 && shooters_per_step <= 4096, "radiosity_options.shooters_per_step",
                "must lie in [1, 4096]");
        require(near_field >= 0 && std::isfinite(near_field), "radiosity_options.near_field",
                "must be finite and non-negative");
        require(light_samples >= 1 && light_samples <= 16, "radiosity_options.light_samples", "must lie in [1, 16]");
        require(shooter_groups >= -1, "radiosity_options.shooter_groups", "must be -1 (derived), 0 (off) or a budget");
        require(group_near_field >= 0 && std::isfinite(group_near_field), "radiosity_options.group_near_field",
                "must be finite and non-negative");
        require(group_discs > 0 && std::isfinite(group_discs), "radiosity_options.group_discs", "must be finite and positive");
        require(group_visibility_samples >= 1 && group_visibility_samples <= 16,
                "radiosity_options.group_visibility_samples", "must lie in [1, 16]");
    }
};

/// Time spent per stage since construction, milliseconds. The GL solver ends visibility and
/// distribution with glFinish when gl::radiosity_options::timed_stages is set (so the figures
/// are the GPU's time, not the driver's queueing); otherwise the GPU's work is counted where
/// the step waits for it, in choice_ms.
struct radiosity_timings {
    double lights_ms = 0;        ///< shooting point, spot and directional lights, their visibility included (construction)
    double visibility_ms = 0;    ///< visibility of the surface shots: item buffers (GL: reading the
                                 ///< shooter back, tessellating, drawing), ray casts
    double choice_ms = 0;        ///< choosing shooters (reduction; GL: it also sums the powers)
    double distribution_ms = 0;  ///< form factors and updates over the elements
    double subdivision_ms = 0;   ///< adaptive subdivision: the test and the refined atlas (CPU only)
};

/// What the last shot of a solver did, for the energy check of radiosity/solve.hpp and its
/// error message.
struct radiosity_shot_record {
    std::size_t shot = 0;              ///< the shot's number (0: the first)
    std::size_t shooter = 0;           ///< the shooter (block or element) that shot
    std::uint32_t first_element = 0;   ///< the shooter's first element
    std::uint32_t top_receiver = 0;    ///< the element that intercepted the most of it
    double top_share = 0;              ///< that element's intercepted power / the shot's power
    glm::dvec3 scale{1.0};             ///< per channel, the factor that kept the shot's delivered
                                       ///< power within its own (shot_scale; 1 when it was)
};

/// Where a solve stands after a step.
struct radiosity_progress {
    std::size_t steps = 0, shots = 0;
    double unshot_fraction = 1;  ///< unshot power / emitted power (channel sums)
    double elapsed_ms = 0;       ///< time of the running solve(radiosity_solve_options) so far,
                                 ///< its checkpoints excluded (radiosity/solve.hpp); 0 outside one
    double indirect_unshot_fraction = 1;  ///< of the power surfaces reflect, the share still to
                                          ///< shoot (indirect_unshot_fraction below)
};

/// The convergence measure that counts bounced light (issue 30): of the power the surfaces
/// reflect (the emitters' emission, the reflected part of the lights' direct light and of
/// every shot), the fraction still to shoot, its own future bounces included:
///   r / (shot + r),  r = unshot / (1 - rho_avg),
/// `unshot` the unshot power, `shot` the power shot so far, `rho_avg` the area-weighted mean
/// albedo (channels averaged, at most 0.999): r is the unshot power with the interreflections
/// it will cause (Cohen et al. 1988's ambient factor). It starts at 1 and falls to 0 as the
/// solve converges. unshot / emitted, the older measure, counts the lights' direct light as
/// emitted power: a scene lit mostly by direct light was "90% converged" before any bounce
/// (the absorbed part of the direct light counted as done).
inline double indirect_unshot_fraction(double unshot, double shot, double rho_avg) {
    const double r = std::max(0.0, unshot) / (1.0 - std::clamp(rho_avg, 0.0, 0.999));
    return r + shot > 0 ? r / (r + shot) : 0.0;
}

}  // namespace bounce::radiosity

namespace bounce::detail {
/// `v` with 4 significant digits (%.4g), for messages: std::to_string(1e-7f) reads 0.000000.
inline std::string radiosity_number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", v);
    return text;
}
}  // namespace bounce::detail

namespace bounce::inline radiosity {

/// The smallest `tolerance_px` (the sagitta rule of radiosity/stereographic_tessellation.hpp) that can
/// still change a stereographic item buffer of `resolution` pixels over `scene` cut into
/// about `elements` elements: the larger of
///  - 1/256 pixel, the scan converter's vertex snap (cpu::scan_triangle_with keeps 8
///    sub-pixel bits; GL rasterizers keep at least 4), below which a tessellated vertex lands
///    on the same snapped position as the chord's, and
///  - what float32 positions resolve at the scene's scale: a coordinate of magnitude M (the
///    scene's largest) carries 2^-24 M of rounding, which, seen from a shooter one element
///    side s away (sqrt of the scene's area / elements), moves its projection by about
///    resolution * 2^-24 M / s pixels.
/// Below it the tessellation only splits deeper (4^depth pieces, up to its depth cap)
/// without changing what is drawn: `--tolerance-px 1e-7` took a minute for 63 elements.
inline float stereographic_tolerance_floor(const scene_view& scene, std::size_t elements, int resolution) {
    double magnitude = 0, area = 0;
    for (const glm::vec3& p : scene.positions)
        magnitude = std::max({magnitude, double(std::abs(p.x)), double(std::abs(p.y)), double(std::abs(p.z))});
    for (const glm::uvec3& t : scene.triangles) {
        if (t.x >= scene.positions.size() || t.y >= scene.positions.size() || t.z >= scene.positions.size()) continue;
        const glm::dvec3 a(scene.positions[t.x]), b(scene.positions[t.y]), c(scene.positions[t.z]);
        area += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    const double side = std::sqrt(area / double(std::max<std::size_t>(elements, 1)));
    const double position_px = side > 0 ? double(resolution) * std::ldexp(magnitude, -24) / side : 0.0;
    return float(std::max(1.0 / 256.0, position_px));
}

}  // namespace bounce::radiosity
