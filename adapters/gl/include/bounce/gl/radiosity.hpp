#pragma once
/// \file radiosity.hpp
/// Progressive refinement radiosity on the GPU (Cohen et al. 1988, on textures as Coombe and
/// Harris 2005 do it, GPU Gems 2 ch. 39): `gl::progressive_radiosity`, the GL backend of the
/// solver cpu::progressive_radiosity (adapters/cpu), with the same steps, options and answers
/// (docs/radiosity-gl.md).
///
/// Elements are the texels of the lightmap atlas (include/bounce/radiosity/lightmap_atlas.hpp): the
/// radiosity and the unshot ("residual") radiosity are RGBA32F textures of the atlas's size,
/// element e at texel atlas.texel[e]. One step:
///  1. the shooter chosen by the last reduction (the largest unshot power sum dB A, channels
///     summed, ties to the lowest index, as on the CPU) is shot: its texels' unshot radiosity
///     (at most block_texels^2 texels) is read back to build its near-field quadtree and then
///     cleared;
///  2. visibility: the scene's triangles, in the shooter's frame, clipped above its plane and
///     tessellated on the CPU with the sagitta rule (radiosity/stereographic_tessellation.hpp, the same
///     code as cpu::item_buffer_visibility's), are drawn
///     by GL in the stereographic projection (stereographic_item_coords, emitted from
///     radiosity/kernels.hpp) into an item buffer holding chart id, triangle id and the exact depth at
///     each pixel centre (item_plane_depth), depth tested on a separate depth attachment;
///  3. a compute pass, one invocation per element at its texel, evaluates the shot from
///     the shooter's near-field nodes (element_form_factor, emitted), looks
///     its pixel up with item_buffer_sees (the CPU's concave-corner rule) and adds the result
///     to the radiosity and unshot textures, writing the power it intercepted;
///  4. a compute reduction (one invocation per shooter, then one group of 64) finds the next
///     shooter, the total unshot power and the shot's intercepted and absorbed power, in
///     double: the convergence fraction is known after every step.
/// Point, spot and directional lights are shot first, in the constructor, as the CPU solver
/// does (their direct irradiance from direct_light.hpp times visibility from the light: a
/// hemisphere at a time, or an orthographic buffer along a directional light).
///
/// Visibility can also come from a hemicube (five perspective faces drawn by GL, no
/// tessellation needed) or be left out. Not here (the CPU solver has them): several shooters
/// per step, grouped shooters, adaptive subdivision. Re-bakes after a light changes or an
/// object moves: rebake_light, rebake_move.
///
/// The ambient term shown before convergence (radiosity_options::ambient_shape) is the CPU
/// solver's: Cohen's uniform one, or shots or mixed (radiosity/ambient.hpp), shaped by a window
/// of recent surface shots (radiosity/ambient_window.hpp) whose irradiance per element-side
/// the solver keeps in a texture, raised by a compute pass after each shot (ambient_field).
///
/// Elements are two-sided by default, as on the CPU (radiosity/sides.hpp): a radiosity per
/// side, the backs in rows [height, 2 height) of the textures, shooter k block k % blocks on
/// side k / blocks; a receiver takes each node of a shot on the side that faces it
/// (receiving_side, emitted) and a light on the side that faces the light.
///
/// Every pass works in the context current on the calling thread, on textures and buffers the
/// solver owns, and restores the context state it touches (program, framebuffers, viewport,
/// raster state, the storage-buffer and image bindings it uses). Construct, use and destroy
/// it with the same context current.

#include <bounce/gl/errors.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/image.hpp>
#include <bounce/output.hpp>
#include <bounce/radiosity/ambient_window.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/radiosity/options.hpp>
#include <bounce/radiosity/rebake.hpp>
#include <bounce/radiosity/solve.hpp>
#include <bounce/scene_view.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::gl {

/// How visibility is found for each shot.
enum class radiosity_visibility {
    stereographic,  ///< item buffer in the stereographic projection (Coombe and Harris 2005)
    hemicube,       ///< item buffers on the five faces of a hemicube (Cohen and Greenberg 1985)
    none            ///< every element sees every shooter (open scenes, tests, the unoccluded bound)
};

/// Options of gl::progressive_radiosity: the shooting options shared with the CPU solver
/// (radiosity/options.hpp; shooters_per_step must be 1 here) and the item-buffer options of
/// cpu::item_buffer_visibility::options, with the same meanings and defaults.
struct radiosity_options {
    bounce::radiosity_options shooting{};  ///< as cpu::progressive_radiosity takes them (two-sided by default)
    radiosity_visibility visibility = radiosity_visibility::stereographic;
    int resolution = 256;            ///< item buffer side, pixels (hemicube: per face, even; typical: 128-512)
    float tolerance_px = 0.25f;      ///< largest sagitta of a tessellated edge, pixels
    int max_tessellation_depth = 10; ///< cap on the halvings of one triangle's edges
    int parallel_resolution = 1024;  ///< side of a directional light's buffer, pixels
    bool timed_stages = true;  ///< end visibility and distribution with glFinish so that timings()
                               ///< splits the GPU's time by stage; false leaves one wait per step
                               ///< (the reduction's read-back), which then carries the GPU's time

    /// Throws parameter_error naming the option ("radiosity_options.resolution" ...).
    void validate() const;
};

/// The core's timings and progress (radiosity/options.hpp); subdivision_ms stays 0 here.
using bounce::radiosity_progress;
using bounce::radiosity_timings;

/// The GL solver. Move-only; owns its GL objects (create, use and destroy it with one context
/// current).
class progressive_radiosity {
public:
    /// Uploads `atlas` (copied: base blocks only, as build_lightmap_atlas makes them; a
    /// subdivided atlas is refused) and the scene's triangles, compiles the passes, shoots the
    /// scene's lights and runs the first reduction. `scene` is read only here. Throws
    /// parameter_error on bad options (tolerance_px below stereographic_tolerance_floor
    /// included), an atlas not built from `scene`, a subdivided atlas, or blocks wider than
    /// 16 texels; radiosity_error when the scene's lights reach no surface (no front side,
    /// one-sided: check_lights_reach_surfaces); gl_error when GL cannot run it (the textures
    /// are sides() times the atlas's height: GL_MAX_TEXTURE_SIZE bounds it).
    progressive_radiosity(const scene_view& scene, const lightmap_atlas& atlas, radiosity_options options = {});
    ~progressive_radiosity();
    progressive_radiosity(progressive_radiosity&&) noexcept;
    progressive_radiosity& operator=(progressive_radiosity&&) noexcept;
    progressive_radiosity(const progressive_radiosity&) = delete;
    progressive_radiosity& operator=(const progressive_radiosity&) = delete;

    /// One step: shoot the shooter with the largest unshot power. Returns false (and does
    /// nothing) when no unshot power is left.
    bool step();
    /// Steps until the unshot fraction is at most `fraction` (in [0, 1)) or nothing is left to
    /// shoot, calling `progress` after each step (return false from it to stop early).
    /// Returns the steps taken.
    std::size_t solve(double fraction, const std::function<bool(const radiosity_progress&)>& progress = {});
    /// The solve of radiosity/solve.hpp (the CPU solver's): to `options.converge`, within
    /// `options.max_seconds`, with its progress and checkpoint callbacks (the clock paused
    /// during checkpoints). Throws radiosity_error when energy is created or every shot
    /// escapes without reaching a surface's front side, parameter_error on bad options.
    radiosity_solve_report solve(const radiosity_solve_options& options);

    /// Re-baking what changed (radiosity/rebake.hpp; cpu::rebake_light and cpu::rebake_move on
    /// the CPU, the same correction): the state is corrected from the previous solution so
    /// that solve() again converges to the changed scene's answer; the unshot power may turn
    /// negative, and is shot by magnitude. Light `index` of the scene's point, spot and
    /// directional lights (in its order) becomes `changed`: its old light is shot again with
    /// -1 times its intensity (the same passes, so exactly what it delivered is taken away),
    /// then the new one. Throws parameter_error ("index", "changed").
    radiosity_rebake_report rebake_light(std::size_t index, const light& changed);
    /// The triangles `moved` of the scene moved by `move`; `moved_scene` is the scene after the
    /// move (those vertices moved), which the solver draws from then on. Every block-side that
    /// has shot re-shoots what it shot from (its shots' radiosity times their scales) with -1
    /// before the move and +1 after, each time to the receivers whose visibility segment meets
    /// the object's box before or after it (rebake_filter) and the moved elements: one item
    /// buffer and one masked distribution per re-shot, the moved object's own shooters with
    /// the old geometry only (what they shot goes back to their unshot radiosity). The lights
    /// are shot again (-1 before, +1 after). `share` < 1 re-shoots only the block-sides that
    /// hold that share of the shot power, the largest first (the report's `uncorrected`).
    /// Throws parameter_error as cpu::rebake_move ("moved_triangles", "moved_scene",
    /// "rigid_move.*", "share").
    radiosity_rebake_report rebake_move(const scene_view& moved_scene, std::span<const std::uint32_t> moved,
                                        const rigid_move& move, double share = 1.0);

    /// Unshot power in magnitude (|dB| A per channel, summed: a re-bake's may be negative) /
    /// emitted power (from the last reduction), as cpu::progressive_radiosity counts it; 0 for a
    /// scene that emits nothing.
    double unshot_fraction() const noexcept;
    /// Of the power the surfaces reflect, the share still to shoot, its bounces to come
    /// included (radiosity/options.hpp), as cpu::progressive_radiosity gives it.
    double indirect_unshot_fraction() const noexcept;
    radiosity_progress progress() const noexcept;
    /// The shooter the next step will shoot (the last reduction's choice) and its unshot
    /// power (W, channels summed); power 0 when nothing is left.
    std::uint32_t next_shooter() const noexcept;
    double next_shooter_power() const noexcept;
    /// Number of shooters: blocks (or elements without shoot_blocks) times sides(); shooter k
    /// is block b = k % (shooters() / sides()) on side k / (shooters() / sides()), the elements
    /// [shooter_first(b), shooter_first(b + 1)).
    std::size_t shooters() const noexcept;
    /// The first element of block `block` (in [0, shooters() / sides()]).
    std::uint32_t shooter_first(std::size_t block) const;
    /// Shots whose form factors summed above 1 and were scaled down to deliver their power
    /// (shot_scale, radiosity/shooters.hpp), as cpu::progressive_radiosity counts them.
    std::size_t clamped_shots() const noexcept;

    /// Power per channel, W, as cpu::progressive_radiosity keeps them: emitted (surfaces and
    /// the direct light that reached elements), absorbed, escaped, and unshot (read back and
    /// summed in double).
    glm::dvec3 emitted_power() const noexcept;
    glm::dvec3 absorbed_power() const noexcept;
    glm::dvec3 escaped_power() const noexcept;
    /// Power that reached elements since construction (lights' direct light and every shot's
    /// interception), W per channel.
    glm::dvec3 intercepted_power() const noexcept;
    glm::dvec3 unshot_power() const;

    /// Radiosity B and unshot radiosity per element of `side` (0 the front, counter-clockwise;
    /// 1 the back, two-sided only), read back, W/m^2 per channel.
    std::vector<glm::vec3> radiosity(int side = 0) const;
    std::vector<glm::vec3> unshot(int side = 0) const;
    /// Cohen et al. 1988's uniform ambient term (W/m^2 per channel), as
    /// cpu::progressive_radiosity::ambient() gives it.
    glm::dvec3 ambient() const;
    /// The ambient irradiance per element of `side` that display_radiosity, output, the
    /// lightmaps and update_lightmap_texture show (W/m^2 per channel), as the CPU solver
    /// shows it: 0 without radiosity_options::ambient; with ambient_shape uniform (and before
    /// the first surface shot) ambient() everywhere; shots or mixed (radiosity/ambient.hpp)
    /// shaped by a window of recent surface shots (radiosity/ambient_window.hpp) whose
    /// irradiance per element-side the solver keeps in a texture, raised after each shot.
    std::vector<glm::vec3> ambient_field(int side = 0) const;
    /// That window's sums and weight (empty unless the options ask for shots or mixed).
    const shot_ambient_window& ambient_window() const noexcept;
    /// B plus rho times ambient_field(side).
    std::vector<glm::vec3> display_radiosity(int side = 0) const;
    /// Per element, the light of `paths` as `quantity` (output.hpp), as
    /// cpu::progressive_radiosity::output gives it. The parts come from B and the B read back
    /// after the lights were shot (direct radiosity B_e + rho E_d): irradiance is a part's
    /// reflected radiosity divided by rho per channel, so a channel whose albedo is 0 reports
    /// 0 here (the CPU solver, which keeps irradiance itself, reports the light that arrived).
    /// `side` as cpu::progressive_radiosity takes it (the emission counted on the side that
    /// emits); so the direct part, times rho, is the lights' direct deposit that
    /// embree::lightmap_direct_view replaces by its own direct light (bounced_radiosity_lightmap).
    std::vector<glm::vec3> output(output_quantity quantity = output_quantity::irradiance,
                                  light_paths paths = light_paths::indirect, int side = 0) const;
    /// output(quantity, paths, side) laid out as the atlas (lightmap_atlas::to_fine_texels;
    /// level 0: to_texels, padding filled), as cpu::progressive_radiosity::lightmap gives it.
    image<glm::vec3> lightmap(output_quantity quantity = output_quantity::irradiance,
                              light_paths paths = light_paths::indirect, int level = 0, int side = 0) const;
    /// display_radiosity(side) (B, W/m^2) laid out the same way: what embree::lightmap_view
    /// takes (the back's for the views of back sides). parameter_error for a side it lacks.
    image<glm::vec3> radiosity_lightmap(int level = 0, int side = 0) const;
    /// 2 when elements are two-sided (radiosity_options::two_sided, the default), else 1.
    int sides() const noexcept;
    bool two_sided() const noexcept { return sides() == 2; }
    /// Writes display_radiosity(side) laid out as the atlas into the solver's lightmap texture
    /// (RGBA32F, atlas size, alpha 1 on charts, 0 elsewhere) on the GPU, padding texels
    /// filled from their element as radiosity_lightmap() fills them, so a renderer can sample it
    /// bilinearly with the atlas's corner_uvs; returns it (valid while the solver lives; one
    /// texture for either side, the next call overwrites it).
    texture_ref update_lightmap_texture(int side = 0);
    /// lightmap(quantity, paths, 0, side) in a texture of the solver's (RGBA32F, atlas size,
    /// alpha 1 on charts and their padding, 0 elsewhere), uploaded from the host: what a
    /// renderer with its own light pass samples with the atlas's corner_uvs (by default the
    /// indirect irradiance, so its direct light is not counted twice). Returns it (valid
    /// while the solver lives; the next call overwrites it).
    texture_ref update_output_texture(output_quantity quantity = output_quantity::irradiance,
                                      light_paths paths = light_paths::indirect, int side = 0);
    /// The solver's radiosity and unshot textures (RGBA32F, the atlas's width and sides()
    /// times its height: the fronts' rows, then the backs'; element texels only, padding
    /// texels hold 0); valid while the solver lives.
    texture_ref radiosity_texture() const noexcept;
    texture_ref unshot_texture() const noexcept;

    const radiosity_timings& timings() const noexcept;
    const lightmap_atlas& atlas() const noexcept;
    const radiosity_options& options() const noexcept;
    /// Pieces drawn into the item buffer in the last shot (tessellation included; hemicube:
    /// triangles times five faces).
    std::size_t drawn_triangles() const noexcept;

private:
    struct state;
    std::unique_ptr<state> s_;
    std::vector<glm::vec3> direct_;  // B once the lights were shot (emission + rho E_d), per side and element (side-major)
    std::optional<texture> output_texture_;  // update_output_texture's
    // ambient_field(side) for the side's radiosity `b`, already read back by the caller.
    std::vector<glm::vec3> ambient_field(int side, const std::vector<glm::vec3>& b) const;
};

}  // namespace bounce::gl
