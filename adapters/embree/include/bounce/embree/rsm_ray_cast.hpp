#pragma once
/// \file rsm_ray_cast.hpp
/// Reflective shadow maps (Dachsbacher and Stamminger 2005) by ray casting from the light:
/// one ray through each texel centre finds the surface the light sees there (so the map
/// carries the light's own shadows), and indirect/rsm.hpp's texel-flux kernels give the flux it
/// reflects. A renderer without a rasterizer, or a test that needs exact maps, calls this
/// where a GL renderer would rasterize the maps; both fill the same `rsm_view`s.
///
/// Map layouts: those of bounce::rsm_layout (bounce/indirect/rsm_layout.hpp), shared with
/// gl::rsm_renderer (every map square, `resolution` texels per side, row 0 at the top):
/// - point light: the six faces of a cube (90-degree perspective maps along +-x, +-y, +-z),
///   less those that see no lit surface;
/// - spot light: one perspective map whose field of view is twice the cone when the cone's
///   half-angle is at most `max_single_map_cone_deg`; a wider cone (the Cornell box's
///   89-degree ceiling spot) would squeeze the centre of the beam into a few texels, so it
///   gets the faces of a cube like a point light, less the faces its cone cannot reach
///   (left out by the layout) and those that see no lit surface (dropped after casting);
/// - directional light: an orthographic map across the beam covering the scene's bounding
///   sphere.
/// A texel whose ray finds nothing, or a surface the light reaches from behind or outside
/// the cone, has flux 0. Texel solid angles are exact (rectangle_solid_angle in double).

#include <bounce/embree/accel.hpp>
#include <bounce/image.hpp>
#include <bounce/light.hpp>
#include <bounce/indirect/rsm_layout.hpp>
#include <bounce/scene_view.hpp>
#include <bounce/indirect/vpl_sampling.hpp>

#include <cstddef>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>

namespace bounce::embree {

/// One reflective shadow map owning its buffers (positions in world units, unit normals
/// facing the light, flux in W per channel).
struct reflective_shadow_map {
    image<glm::vec3> position, normal, flux;
    glm::mat4 light_view_projection{1.f};  ///< world to the map's clip space (OpenGL conventions)
    std::size_t light = 0;                 ///< index of the light it belongs to
    /// World size of a texel's side where the map's rays travel one world unit (perspective
    /// maps: 2 tan(fov/2) / resolution, per unit distance from the light) or everywhere
    /// (orthographic maps: the texel's width); used to size the singularity remedies.
    float texel_size = 0.f;
    bool orthographic = false;

    rsm_view view() const { return {position.view(), normal.view(), flux.view(), light_view_projection}; }
};

/// Settings of rsm_ray_caster (resolution, widest single-map spot cone): those of the shared
/// layout, as gl::rsm_render_options.
using rsm_ray_cast_settings = rsm_layout_settings;

/// Renders the reflective shadow maps of a scene's lights by ray casting with Embree. Holds
/// references to the BVH and the scene (they must outlive it) and keeps its maps between
/// frames (reallocated only when the resolution changes).
class rsm_ray_caster {
public:
    /// Throws parameter_error on bad settings or a scene that does not match `bvh`.
    rsm_ray_caster(const accel& bvh, const scene_view& scene, rsm_ray_cast_settings settings = {});

    /// Renders the maps of `lights` (validated as scene_view::validate_lights does), in the
    /// order of the lights, cube faces in the order +x, -x, +y, -y, +z, -z; a spot light's
    /// faces its cone does not reach are left out. Rows run in parallel (TBB); each texel is
    /// computed on its own, so the maps do not depend on the thread count.
    void render(std::span<const light> lights);
    /// Renders the maps of the scene's own lights.
    void render() { render(scene_.lights); }

    const std::vector<reflective_shadow_map>& maps() const noexcept { return maps_; }
    /// Views of maps(), for cpu::indirect_renderer::render and the GL passes.
    std::span<const rsm_view> views() const noexcept { return views_; }
    const rsm_ray_cast_settings& settings() const noexcept { return settings_; }

private:
    const accel& bvh_;
    scene_view scene_;
    rsm_ray_cast_settings settings_;
    std::vector<reflective_shadow_map> maps_;
    std::vector<rsm_view> views_;
};

}  // namespace bounce::embree
