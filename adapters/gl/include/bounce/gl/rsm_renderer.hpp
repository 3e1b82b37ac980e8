#pragma once
/// \file rsm_renderer.hpp
/// `gl::rsm_renderer`: reflective shadow maps (Dachsbacher and Stamminger 2005, section 3.1)
/// rasterized from a scene_view's lights into RGBA32F textures (world position, unit
/// normal, reflected flux), the flux computed per fragment by the emitted texel-flux kernels
/// of indirect/rsm.hpp, so a GL renderer gets the maps embree::rsm_ray_caster casts on the CPU.
///
/// Map layouts: those of bounce::rsm_layout (bounce/indirect/rsm_layout.hpp), which
/// embree::rsm_ray_caster also follows, with the same light_view_projection matrices (every
/// map square, `resolution` texels per side):
/// - point light: the six faces of a cube (90-degree perspective maps along +x, -x, +y, -y,
///   +z, -z, with the up vectors of bounce::rsm_cube_faces);
/// - spot light with a cone half-angle up to `max_single_map_cone_deg`: one perspective map
///   of field of view twice the cone; a wider cone gets the cube faces its cone can reach
///   (a face is left out when the angle between the axis and the face's direction exceeds
///   the cone by more than the face's half-diagonal, 54.7 degrees; the ray caster also
///   drops cube faces that happen to see no lit surface, which hold flux 0 here);
/// - directional light: an orthographic map across the beam covering the scene's bounding
///   sphere.
/// Normals face the light (two-sided surfaces, surface.hpp's facing_normal), as the ray
/// caster's; a texel that sees nothing holds position 0, normal -(view direction), flux 0.
///
/// A renderer with its own vertex buffers builds the renderer with a draw callback
/// (rsm_renderer(scene, rsm_drawer, options)), as hemisphere_raster takes a plane_drawer:
/// per map the pass binds its program and target and calls the callback, which binds the
/// renderer's vertex array and albedo buffer and draws. The scene_mesh constructor is the
/// same pass with a callback that draws the mesh.
/// A texel's solid angle is exact: rectangle_solid_angle evaluated in double on the CPU
/// once per map shape and read from a table, as the ray caster evaluates it.
///
/// Rasterization samples texel centres, as the ray caster's rays do; the two differ where a
/// texel centre lies within rounding of a triangle edge, and where geometry lies closer to
/// a spot or point light than 1/10000 of its farthest distance to the scene bounds (clipped
/// by the near plane here). The render restores the GL state it changes (framebuffers,
/// viewport, program, vertex array, storage binding 0, texture unit 0, depth and blend
/// state, masks, polygon mode, clip control).

#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/gl/rsm_textures.hpp>
#include <bounce/light.hpp>
#include <bounce/indirect/rsm_layout.hpp>
#include <bounce/scene_view.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace bounce::gl {

/// Settings of rsm_renderer (resolution, widest single-map spot cone): those of the shared
/// layout, as embree::rsm_ray_cast_settings.
using rsm_render_options = bounce::rsm_layout_settings;

/// One map a light needs: which light, how the map sees it (bounce::rsm_map_layout).
using rsm_map_layout = bounce::rsm_map_layout;

/// What an rsm_drawer is given for one map.
struct rsm_draw {
    rsm_map_layout map;              ///< the map drawn (map.light indexes the lights rendered)
    glm::mat4 view_projection{1.f};  ///< world to the raster's clip space, as the bound program applies it
    object_id program = 0;           ///< the pass's program, bound

    /// Where the next draw's triangles start in the albedo buffer: the fragment stage reads
    /// kd[first + gl_PrimitiveID] (gl_PrimitiveID restarts at 0 with every draw call). It is
    /// 0 when the callback is called.
    void set_first_triangle(std::uint32_t first) const;
};

/// The caller's geometry drawer: draws the scene's triangles, seen from one map's light,
/// with the pass's program.
///
/// Contract. Before each call the pass sets, and the callback may rely on: the map's
/// framebuffer bound as GL_DRAW_FRAMEBUFFER (outputs 0-2 position, normal, flux), cleared,
/// its viewport, depth test GL_LESS with writes on, no blending, culling or scissor test
/// (two-sided, as the ray caster sees surfaces), the program bound with every
/// uniform set and texture unit 0 holding its solid-angle table. The callback binds its own
/// vertex array, whose attribute 0 is the world position (vec3, float) and attribute 1 the
/// surface normal (vec3, float; any length and either side: the pass normalizes it and
/// turns it towards the light), and at shader-storage binding 0 a std430 buffer of one vec4
/// per triangle whose rgb is the diffuse albedo (scene_mesh::albedo_per_triangle's layout),
/// then draws triangles (any number of draws; `set_first_triangle` before a draw whose
/// triangles do not start the buffer). It must not change the program, its uniforms,
/// texture unit 0, the framebuffer, the viewport or the depth state. The pass restores the
/// vertex array and storage binding 0 it saved, as the rest of its state (rsm_renderer).
using rsm_drawer = std::function<void(const rsm_draw&)>;

class rsm_renderer {
public:
    /// Keeps references to `scene` (for its bounds and lights) and `mesh` (its geometry,
    /// uploaded by the caller); both must outlive the renderer. A context must be current.
    /// Throws parameter_error for bad options. The mesh is drawn by an rsm_drawer of the
    /// pass's own, as a caller's would be.
    rsm_renderer(const scene_view& scene, const scene_mesh& mesh, const rsm_render_options& options = {});
    /// The caller's geometry: `draw` draws it for each map (the contract is rsm_drawer's).
    /// `scene` gives the bounds and lights (a view of positions and lights alone will do) and
    /// must outlive the renderer. Throws parameter_error naming "draw" when it is empty, and
    /// for bad options.
    rsm_renderer(const scene_view& scene, rsm_drawer draw, const rsm_render_options& options = {});

    const rsm_render_options& options() const noexcept { return options_; }

    /// The maps `lights` need, in order (validated as validate_lights does, naming
    /// "lights[i]").
    std::vector<rsm_map_layout> layout(std::span<const light> lights) const;

    /// Rasterizes the maps of `lights` into the caller's textures: `targets` must hold one
    /// entry per map of layout(lights), each three RGBA32F textures of resolution^2 texels;
    /// their light_view_projection is set. Throws parameter_error naming "targets".
    void render(std::span<const light> lights, std::span<rsm_textures> targets);
    /// Rasterizes into textures of the renderer's own (kept between frames), see maps().
    void render(std::span<const light> lights);
    /// The scene's own lights.
    void render() { render(scene_.lights); }
    /// The maps of the last render(lights) into the renderer's own textures.
    std::span<const rsm_textures> maps() const noexcept { return refs_; }

private:
    void render_map(const rsm_map_layout& m, const packed_light& l, const rsm_textures& target);
    const texture& solid_angles(float fov_deg);

    scene_view scene_;
    rsm_drawer draw_;
    rsm_render_options options_;
    program program_;
    framebuffer fbo_;
    std::optional<texture> depth_;
    std::map<float, texture> solid_angles_;  // per field of view: the texels' exact solid angles (R32F)
    struct owned {
        texture position, normal, flux;
    };
    std::vector<owned> owned_;
    std::vector<rsm_textures> refs_;
};

}  // namespace bounce::gl
