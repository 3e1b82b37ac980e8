#pragma once
/// \file light.hpp
/// The light sources a scene may hold (point, spot, directional), their validation, and the
/// one packed form both GPU buffers and CPU loops read. Area lights are emissive triangles of
/// the mesh (scene_view.hpp). The irradiance each delivers is in direct_light.hpp.
///
/// A renderer builds these from its own light list and hands bounce a span of them; nothing
/// here allocates or loads files.

#include <bounce/errors.hpp>

#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <variant>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce {

/// Isotropic point light; `intensity` in W/sr per channel (typical: 1-100).
struct point_light {
    glm::vec3 position{0.f}, intensity{1.f};
};

/// Spot light pointing along `direction` (need not be unit); `intensity` in W/sr on the
/// axis; dark beyond `cone_deg` (half-angle, in (0, 180], typical: 45) from the axis.
struct spot_light {
    enum class falloff_kind { none, cosine };
    glm::vec3 position{0.f}, direction{0, -1, 0}, intensity{1.f};
    float cone_deg = 45.f;
    falloff_kind falloff = falloff_kind::cosine;  ///< none: flat inside the cone; cosine: I cos(axis angle)
};

/// Distant light; `direction` is the way the light travels (need not be unit);
/// `irradiance` in W/m^2 on a surface facing it (typical: 1-10).
struct directional_light {
    glm::vec3 direction{0, -1, 0}, irradiance{1.f};
};

using light = std::variant<point_light, spot_light, directional_light>;

/// Which model a packed light holds; the numbers are what GLSL reads.
enum class light_kind : std::uint32_t { point = 0, spot = 1, directional = 2 };

/// A light as three vec4s, the std430 layout of a GL shader storage buffer and the form the
/// CPU loops read: no variant, no branch on type beyond `kind`, directions normalized and the
/// cone as a cosine, so consumers do no trigonometry per sample.
struct packed_light {
    glm::vec4 position_kind{0.f};         ///< xyz: position (point, spot); w: light_kind
    glm::vec4 direction_cos_cone{0.f};    ///< xyz: unit direction of travel or spot axis; w: cos(cone) (spot)
    glm::vec4 intensity_falloff{0.f};     ///< xyz: intensity (W/sr) or irradiance (W/m^2); w: 1 cosine falloff, 0 none

    light_kind kind() const noexcept { return light_kind(std::uint32_t(position_kind.w)); }
    glm::vec3 position() const noexcept { return glm::vec3(position_kind); }
    glm::vec3 direction() const noexcept { return glm::vec3(direction_cos_cone); }
    glm::vec3 intensity() const noexcept { return glm::vec3(intensity_falloff); }
    float cos_cone() const noexcept { return direction_cos_cone.w; }
    float cosine_falloff() const noexcept { return intensity_falloff.w; }
};
static_assert(sizeof(packed_light) == 48, "packed_light is three std430 vec4s");

/// The largest magnitude of a world coordinate (vertices, lights, cameras) that every backend
/// carries: Embree's rays need |origin| and |direction| components below 1.844e18, and with
/// coordinates up to 1e18 a squared distance (at most 12e36) still fits a float32.
inline constexpr float max_world_coordinate = 1e18f;

/// The largest light intensity (W/sr) or irradiance (W/m^2) accepted: float32 ends at 3.4e38,
/// and 1e30 leaves eight orders of magnitude for inverse-square gains and sums of many lights.
inline constexpr float max_light_value = 1e30f;

namespace detail {
inline bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline bool non_negative3(glm::vec3 v) { return finite3(v) && v.x >= 0.f && v.y >= 0.f && v.z >= 0.f; }
/// Finite, every component's magnitude at most `bound`.
inline bool bounded3(glm::vec3 v, float bound) {
    return finite3(v) && std::abs(v.x) <= bound && std::abs(v.y) <= bound && std::abs(v.z) <= bound;
}
inline bool light_value3(glm::vec3 v) { return non_negative3(v) && bounded3(v, max_light_value); }
}  // namespace detail

/// Throws parameter_error naming `<name>[i]` and the field unless every light can be rendered:
/// positions within max_world_coordinate, intensities and irradiances finite, non-negative
/// and at most max_light_value, finite non-zero directions, spot cones in (0, 180] degrees.
inline void validate_lights(std::span<const light> lights, const std::string& name = "scene.lights") {
    for (std::size_t i = 0; i < lights.size(); ++i) {
        const std::string at = name + "[" + std::to_string(i) + "]";
        const auto fail = [&](const char* what) { throw parameter_error(at, what); };
        const auto check_direction = [&](glm::vec3 d) {
            if (!detail::finite3(d) || glm::length(d) == 0.f) fail("direction must be finite and non-zero");
        };
        const auto check_position = [&](glm::vec3 p) {
            if (!detail::bounded3(p, max_world_coordinate))
                fail("position must be finite with coordinates within +-1e18 (what float32 rays carry)");
        };
        const auto check_value = [&](glm::vec3 v, const char* what) {
            if (!detail::light_value3(v)) fail(what);
        };
        if (const auto* pl = std::get_if<point_light>(&lights[i])) {
            check_position(pl->position);
            check_value(pl->intensity, "intensity must be finite, non-negative and at most 1e30 W/sr");
        } else if (const auto* sl = std::get_if<spot_light>(&lights[i])) {
            check_position(sl->position);
            check_value(sl->intensity, "intensity must be finite, non-negative and at most 1e30 W/sr");
            check_direction(sl->direction);
            if (!(std::isfinite(sl->cone_deg) && sl->cone_deg > 0.f && sl->cone_deg <= 180.f))
                fail("cone_deg must lie in (0, 180]");
        } else {
            const auto& dl = std::get<directional_light>(lights[i]);
            check_value(dl.irradiance, "irradiance must be finite, non-negative and at most 1e30 W/m^2");
            check_direction(dl.direction);
        }
    }
}

/// The packed form of one light (validate first: a zero direction packs to NaN). The cone's
/// cosine is computed in double and rounded once.
inline packed_light pack(const light& l) {
    packed_light p;
    if (const auto* pl = std::get_if<point_light>(&l)) {
        p.position_kind = glm::vec4(pl->position, float(light_kind::point));
        p.intensity_falloff = glm::vec4(pl->intensity, 0.f);
    } else if (const auto* sl = std::get_if<spot_light>(&l)) {
        p.position_kind = glm::vec4(sl->position, float(light_kind::spot));
        p.direction_cos_cone = glm::vec4(glm::normalize(sl->direction), float(std::cos(glm::radians(double(sl->cone_deg)))));
        p.intensity_falloff =
            glm::vec4(sl->intensity, sl->falloff == spot_light::falloff_kind::cosine ? 1.f : 0.f);
    } else {
        const auto& dl = std::get<directional_light>(l);
        p.position_kind = glm::vec4(glm::vec3(0.f), float(light_kind::directional));
        p.direction_cos_cone = glm::vec4(glm::normalize(dl.direction), 0.f);
        p.intensity_falloff = glm::vec4(dl.irradiance, 0.f);
    }
    return p;
}

}  // namespace bounce
