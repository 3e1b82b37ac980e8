#pragma once
/// \file indirect/rsm_layout.hpp
/// The layout of reflective shadow maps (Dachsbacher and Stamminger 2005, section 3.1):
/// which maps each light gets and how each map sees the scene. The one definition that
/// embree::rsm_ray_caster (casting the maps) and gl::rsm_renderer (rasterizing them) both
/// follow, so that their maps match texel for texel.
///
/// Layouts (every map square, `resolution` texels per side, row 0 at the top):
/// - point light: the six faces of a cube (90-degree perspective maps along +x, -x, +y, -y,
///   +z, -z with the up vectors of rsm_cube_faces);
/// - spot light with a cone half-angle up to `max_single_map_cone_deg`: one perspective map
///   along the axis of field of view twice the cone (a wider cone, such as the Cornell box's
///   89-degree ceiling spot, would squeeze the centre of the beam into a few texels); a
///   wider cone gets the cube faces it can reach: a face is left out when the angle between
///   the axis and the face's direction exceeds the cone by more than the face's
///   half-diagonal, acos(1/sqrt 3) = 54.7 degrees (rsm_spot_reaches_face). A backend may drop
///   further cube faces (of point or spot lights) that see no lit surface (the ray caster
///   does; the rasterizer keeps them, holding flux 0);
/// - directional light: an orthographic map across the beam covering the bounding sphere of
///   the scene's bounds (a little beyond it, so that rays start outside the scene).
/// Texel solid angles of perspective maps are exact: rectangle_solid_angle in double over the
/// texel's rectangle of the image plane at unit distance (rsm_texel_solid_angle).

#include <bounce/camera.hpp>
#include <bounce/errors.hpp>
#include <bounce/light.hpp>
#include <bounce/rectangle_solid_angle.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <span>
#include <variant>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline indirect {

/// Settings of a map layout (embree::rsm_ray_cast_settings and gl::rsm_render_options).
struct rsm_layout_settings {
    /// Texels per side of every map (and of every cube face); typical: 128-512.
    std::size_t resolution = 256;
    /// Widest spot cone (half-angle, degrees) in a single perspective map; wider ones use
    /// cube faces. In (0, 90); typical: 60.
    float max_single_map_cone_deg = 60.f;

    /// Throws parameter_error naming the field.
    void validate() const {
        require(resolution >= 1 && resolution <= 8192, "resolution", "must lie in [1, 8192]");
        require(std::isfinite(max_single_map_cone_deg) && max_single_map_cone_deg > 0.f &&
                    max_single_map_cone_deg < 90.f,
                "max_single_map_cone_deg", "must lie in (0, 90)");
    }
};

/// One face of a cube map: the direction it looks along and the up vector of its view
/// (orthogonal to the direction).
struct rsm_cube_face {
    glm::vec3 forward, up;
};
/// +x, -x, +y, -y, +z, -z.
inline constexpr std::array<rsm_cube_face, 6> rsm_cube_faces{{{{1, 0, 0}, {0, 1, 0}},
                                                              {{-1, 0, 0}, {0, 1, 0}},
                                                              {{0, 1, 0}, {0, 0, -1}},
                                                              {{0, -1, 0}, {0, 0, 1}},
                                                              {{0, 0, 1}, {0, 1, 0}},
                                                              {{0, 0, -1}, {0, 1, 0}}}};

/// One map a light needs: which light, how the map sees it.
struct rsm_map_layout {
    std::size_t light = 0;                 ///< index of the light in the span laid out
    glm::mat4 light_view_projection{1.f};  ///< world to the map's clip space (OpenGL conventions)
    glm::mat4 view{1.f};                   ///< world to the map's view space
    /// Perspective maps: the light's position; orthographic maps: the eye, 2 radius up the
    /// beam from the centre of the scene's bounds.
    glm::vec3 position{0.f};
    glm::vec3 forward{0.f, 0.f, -1.f};  ///< the map's (unit) view direction
    glm::vec3 up{0.f, 1.f, 0.f};        ///< the up vector of its view (glm::lookAt's)
    float fov_deg = 90.f;               ///< perspective maps: full field of view
    int cube_face = -1;  ///< a cube face: its index in rsm_cube_faces; a single map: -1
    /// Orthographic maps: half the map's side in world units (the bounding sphere's radius).
    float radius = 0.f;
    bool orthographic = false;
    /// World size of a texel's side where the map's rays travel one world unit (perspective
    /// maps: 2 tan(fov/2) / resolution, per unit distance from the light) or everywhere
    /// (orthographic maps: the texel's width); used to size the singularity remedies.
    float texel_size = 0.f;

    /// The pinhole camera of a perspective map (its rays through texel centres are the
    /// map's; default near and far planes, as light_view_projection's).
    camera perspective_camera() const {
        camera cam;
        cam.position = position;
        cam.look_at = position + forward;
        cam.up = up;
        cam.fov_y_deg = fov_deg;
        return cam;
    }
};

/// An up vector for a view along the unit `d`: +y unless d is within about 25 degrees of it,
/// then +x.
inline glm::vec3 rsm_up_for(const glm::vec3& d) {
    return std::abs(d.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
}

/// A perspective map of light `light` at `position` looking along `forward`.
inline rsm_map_layout rsm_perspective_map(std::size_t light, const glm::vec3& position, const glm::vec3& forward,
                                          const glm::vec3& up, float fov_deg, std::size_t resolution) {
    rsm_map_layout m;
    m.light = light;
    m.position = position;
    m.forward = forward;
    m.up = up;
    m.fov_deg = fov_deg;
    const camera cam = m.perspective_camera();
    m.view = cam.view_matrix();
    m.light_view_projection = cam.projection_matrix(resolution, resolution) * m.view;
    m.texel_size = float(2.0 * std::tan(glm::radians(double(fov_deg)) * 0.5) / double(resolution));
    return m;
}

/// An orthographic map of the directional light `light` travelling along the unit
/// `direction`, covering the sphere of `radius` around `centre`.
inline rsm_map_layout rsm_orthographic_map(std::size_t light, const glm::vec3& direction, const glm::vec3& centre,
                                           float radius, std::size_t resolution) {
    rsm_map_layout m;
    m.light = light;
    m.up = rsm_up_for(direction);
    m.position = centre - direction * (2.f * radius);
    m.forward = direction;
    m.radius = radius;
    m.view = glm::lookAt(m.position, centre, m.up);
    m.light_view_projection = glm::ortho(-radius, radius, -radius, radius, 0.f, 4.f * radius) * m.view;
    m.orthographic = true;
    m.texel_size = float(2.0 * double(radius) / double(resolution));
    return m;
}

/// Whether a spot cone of half-angle `cone_deg` around the unit `axis` can reach the cube
/// face looking along `face_forward`: every direction of a face lies within
/// acos(1/sqrt 3) = 54.7 degrees of its axis, so a cone farther than that cannot.
inline bool rsm_spot_reaches_face(const glm::vec3& axis, float cone_deg, const glm::vec3& face_forward) {
    const double angle = std::acos(std::clamp(double(glm::dot(axis, face_forward)), -1.0, 1.0));
    const double half_diagonal = std::acos(1.0 / std::sqrt(3.0));
    return !(angle - half_diagonal > glm::radians(double(cone_deg)));
}

/// Exact solid angle (sr) of texel (x, y), row y from the top, of a square perspective map
/// of `resolution` texels per side whose image plane at unit distance spans [-t, t]^2
/// (t = tan(fov/2), in double).
inline double rsm_texel_solid_angle(double t, std::size_t resolution, std::size_t x, std::size_t y) {
    const double r = double(resolution);
    const double y1 = (1.0 - 2.0 * double(y) / r) * t, y0 = (1.0 - 2.0 * double(y + 1) / r) * t;
    const double x0 = (2.0 * double(x) / r - 1.0) * t, x1 = (2.0 * double(x + 1) / r - 1.0) * t;
    return rectangle_solid_angle<double>(x0, y0, x1, y1);
}

/// The maps `lights` need, in the order of the lights (a light's cube faces in the order of
/// rsm_cube_faces), for a scene whose vertices lie within the box [lo, hi]. Validates the
/// lights as validate_lights does (naming "lights[i]"); `settings` must be valid.
inline std::vector<rsm_map_layout> rsm_layout(std::span<const light> lights, const glm::vec3& lo,
                                              const glm::vec3& hi, const rsm_layout_settings& settings) {
    validate_lights(lights, "lights");
    const std::size_t r = settings.resolution;
    const glm::vec3 centre = 0.5f * (lo + hi);
    // A little beyond the bounding sphere, so that rays start outside the scene. The floor is
    // relative to where the scene lies (a map smaller than float's rounding of its positions
    // would say nothing) and only an all-in-one-point scene meets the absolute 1e-15 (the
    // smallest radius whose squared eye distance float still holds): a scene of a tenth of a
    // millimetre gets a map of its own size, not one of 1e-3 units (the former floor).
    const float far_corner = std::max(glm::length(lo), glm::length(hi));
    const float radius = std::max(0.5f * glm::length(hi - lo) * 1.001f, std::max(1e-6f * far_corner, 1e-15f));
    std::vector<rsm_map_layout> out;
    for (std::size_t i = 0; i < lights.size(); ++i) {
        const packed_light l = pack(lights[i]);
        if (l.kind() == light_kind::directional) {
            out.push_back(rsm_orthographic_map(i, l.direction(), centre, radius, r));
            continue;
        }
        const auto* sl = std::get_if<spot_light>(&lights[i]);
        if (sl && sl->cone_deg <= settings.max_single_map_cone_deg) {
            const glm::vec3 axis = l.direction();
            out.push_back(rsm_perspective_map(i, l.position(), axis, rsm_up_for(axis), 2.f * sl->cone_deg, r));
            continue;
        }
        for (std::size_t k = 0; k < rsm_cube_faces.size(); ++k) {
            const rsm_cube_face& f = rsm_cube_faces[k];
            if (sl && !rsm_spot_reaches_face(l.direction(), sl->cone_deg, f.forward)) continue;
            out.push_back(rsm_perspective_map(i, l.position(), f.forward, f.up, 90.f, r));
            out.back().cube_face = int(k);
        }
    }
    return out;
}

}  // namespace bounce::indirect
