#pragma once
/// \file direct_light.hpp
/// Direct lighting of a scene_view's point, spot and directional lights on OpenGL, with
/// shadow maps and 16-tap percentage-closer filtering.
///
/// Each light gets one depth map rendered from it:
/// - spot light with a cone up to `max_spot_map_cone_deg`: a perspective 2D map whose field
///   of view is the cone (plus the PCF footprint);
/// - directional light: an orthographic 2D map spanning the rectangle the scene's box
///   projects to across the light;
/// - point light, and spot light with a wider cone: a cube map (six 90-degree faces) of
///   radial distance to the light, which compares and filters alike across face seams.
/// The unshadowed irradiance is the emitted kernel of direct_light.hpp (the same the reference
/// integrator uses); the lookup coordinates, the normal offset and the PCF average are the
/// emitted kernels of shadow_mapping.hpp; hardware depth comparison (sampler2DShadow,
/// samplerCubeShadow, bilinear) does each tap's test.
///
/// Biases, both needed: a slope-scaled depth bias when the maps are rendered (the stored
/// depth is pushed away from the light by slope_bias times its slope per texel plus
/// constant_bias depth steps, which covers the depth change across the PCF footprint on
/// surfaces seen at a grazing angle: glPolygonOffset(slope_bias, constant_bias) for 2D
/// maps, the same computed by the radial-depth shader for cube maps), and a normal offset
/// of the lookup point (normal_offset_texels texels along the surface normal, a texel
/// measured at the point), which keeps a lit surface from comparing against its own depth where the slope
/// term is not enough. Their cost: shadows start about that many texels late at contact
/// points (light leaks of the order of a shadow texel, "peter panning").
///
/// Geometry closer to a spot or point light than 1/1000 of its farthest distance to the
/// scene bounds is clipped from its map (casts no shadow).
///
/// The shadow maps are drawn by a callback (shadow_drawer), as hemisphere_raster's planes
/// are: a renderer with its own vertex buffers passes one that draws them; the scene_mesh
/// constructors pass one that draws the mesh. The radiance pass reads G-buffer textures,
/// which may be the renderer's own (gbuffer_textures).

#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/image.hpp>
#include <bounce/scene_view.hpp>

#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace bounce::gl {

/// Settings of the shadow maps.
struct direct_light_options {
    int shadow_resolution = 1024;        ///< texels per side of each map (cube: per face); typical 512-2048
    float slope_bias = 2.f;              ///< depth bias in depth slopes per texel (glPolygonOffset factor); typical 1-4
    float constant_bias = 4.f;           ///< depth bias in smallest depth steps (glPolygonOffset units); typical 1-8
    float normal_offset_texels = 1.5f;   ///< lookup point moved this many shadow texels along n; typical 1-2
    float max_spot_map_cone_deg = 60.f;  ///< wider spot cones use a cube map; in (0, 80]

    /// Throws parameter_error naming the field.
    void validate() const;
};

/// What a shadow_drawer is given for one shadow map (each face of a cube map is one).
struct shadow_draw {
    std::size_t light = 0;           ///< the light's index in the scene's lights
    int face = -1;                   ///< the cube face (0-5: +x, -x, +y, -y, +z, -z), -1 for a 2D map
    glm::mat4 view_projection{1.f};  ///< world to the map's clip space, as the bound program applies it
};

/// The caller's geometry drawer: draws every shadow caster into the bound shadow map with
/// the pass's program.
///
/// Contract. Before each call the pass sets, and the callback may rely on: the map's
/// depth-only framebuffer bound as GL_DRAW_FRAMEBUFFER and cleared, its viewport, depth test
/// GL_LESS with writes on, the slope-scaled polygon offset, no culling (both sides cast
/// shadows), and the program bound with its uniforms set. The callback binds its own vertex
/// array, whose attribute 0 is the world position (vec3, float), and draws triangles (any
/// number of draws). It must not change the program, its uniforms, the framebuffer, the
/// viewport, the depth or polygon-offset state. The pass restores the vertex array it saved,
/// as the rest of its state.
using shadow_drawer = std::function<void(const shadow_draw&)>;

/// Shadowed direct lighting of a scene's lights, as a GLSL function other passes paste into
/// their shaders and as a full-screen pass over a G-buffer.
class direct_light {
public:
    /// Validates the lights (parameter_error naming "scene.lights[i]"), creates and
    /// renders the shadow maps of `mesh` (which must be `scene`'s geometry and must outlive
    /// this object). A context must be current.
    direct_light(const scene_view& scene, const scene_mesh& mesh, int shadow_resolution = 1024);
    direct_light(const scene_view& scene, const scene_mesh& mesh, const direct_light_options& options);
    /// The caller's geometry: `draw` draws the shadow casters into each map (the contract is
    /// shadow_drawer's; kept, and called again by render_shadow_maps). `scene` gives the
    /// lights and the bounds the maps span (a view of positions and lights alone will do)
    /// and need not outlive the constructor. Throws parameter_error naming "draw" when it is
    /// empty, and as the constructors above.
    direct_light(const scene_view& scene, shadow_drawer draw, const direct_light_options& options = {});

    /// Renders every shadow map again (after the geometry changed). Restores the GL state it
    /// changes.
    void render_shadow_maps();

    /// GLSL (no #version) declaring the uniforms and samplers of the lights and
    /// `vec3 direct_irradiance(vec3 p, vec3 n)`: the shadowed irradiance (W/m^2) at the
    /// world-space point p with unit normal n (one-sided: light from behind n is 0).
    /// Every other name it declares starts with `bounce_dl_`. Paste it before the main of
    /// a fragment (or compute) shader and call `bind` on the linked program.
    std::string glsl_source() const;
    /// Sets the uniforms of glsl_source in `p` and binds the shadow maps to texture units
    /// first_texture_unit .. first_texture_unit + texture_units() - 1 (with sampler object
    /// 0). Changes those units' bindings and nothing else. Throws gl_error when the units
    /// exceed GL_MAX_COMBINED_TEXTURE_IMAGE_UNITS.
    void bind(const program& p, unsigned first_texture_unit) const;
    /// Texture units bind() uses: one per light.
    unsigned texture_units() const noexcept { return unsigned(lights_.size()); }
    /// Number of lights (those of the scene, in its order).
    std::size_t light_count() const noexcept { return lights_.size(); }

    /// Direct radiance L = albedo / pi * direct_irradiance(p, n) per pixel of `g` (0 where
    /// no geometry), into the RGBA32F texture radiance() (rgb; alpha 1). Restores the GL
    /// state it changes.
    void render(const gbuffer_textures& g);
    /// The last render (throws parameter_error before any).
    const texture& radiance() const;
    /// Copies the last render's rgb into `out` (row 0 at the top; sizes must match).
    void read(image_view<glm::vec3> out) const;

    /// The light's shadow-map kind, for tests and tools.
    enum class map_kind { perspective, orthographic, cube };
    map_kind map_of(std::size_t light) const { return lights_.at(light).map; }
    /// World size of a texel of the light's orthographic map (the longer side of the
    /// rectangle it spans; normal offsets are measured in it); 0 for other maps.
    float texel_of(std::size_t light) const { return lights_.at(light).texel_world; }

private:
    struct light_entry {
        packed_light light;
        map_kind map = map_kind::cube;
        glm::mat4 view_projection{1.f};  // 2D maps
        std::array<glm::mat4, 6> face_view_projection{};  // cube maps
        float tan_half_fov = 1.f;   // perspective maps
        float texel_world = 0.f;    // orthographic maps
        float near_depth = 0.f, far_depth = 1.f;
        detail::object depth;       // GL_TEXTURE_2D or GL_TEXTURE_CUBE_MAP, depth32f
    };

    static std::vector<light_entry> prepare(const scene_view& scene, const direct_light_options& options);
    std::string radiance_fragment_source() const;

    shadow_drawer draw_;
    direct_light_options options_;
    std::vector<light_entry> lights_;
    program window_depth_program_, radial_depth_program_, radiance_program_;
    framebuffer shadow_fbo_, radiance_fbo_;
    std::optional<texture> radiance_;
    vertex_array empty_vao_;
};

}  // namespace bounce::gl
