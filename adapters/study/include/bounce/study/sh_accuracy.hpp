#pragma once
/// \file sh_accuracy.hpp
/// The SH toolkit's accuracy measured against closed forms (what `sh_study` reports):
///
/// - per order 1 .. 8, for an environment symmetric about an axis (a directional light, a
///   uniform sky, a cone light): the irradiance error over the sphere (max and mean,
///   relative to the peak) from the closed-form coefficients (sh/lights.hpp) and through a
///   rasterized cube map (sh_project_cube_map), the radiance truncation error (Parseval),
///   and for the directional light from order 2 the widest non-negative Hann window's cost;
/// - Oat's gradient extrapolation I + grad I . d against the probe re-projected at p + d.
///
/// The exact irradiance of a cone is integrated in closed form in the azimuth and by
/// Gauss-Legendre (sh/quadrature.hpp) in the polar cosine, on each side of the kink where
/// the horizon starts to cut the cap's rings.

#include <bounce/image.hpp>

#include <array>
#include <cstddef>
#include <string>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace bounce::study {

/// An environment symmetric about `axis`: radiance 1 inside the cone of half-angle
/// acos(cos_half_angle) (the sky: cos_half_angle = 0), or a directional light of unit
/// irradiance along `axis`.
struct sh_environment {
    std::string name;
    glm::dvec3 axis{0, 0, 1};  ///< unit
    double cos_half_angle = 0;  ///< cone only, in [-1, 1)
    bool directional = false;
};

/// The three environments of the study, about the axis (0.3, -0.5, 0.8): "directional",
/// "sky" and "cone-20deg".
std::array<sh_environment, 3> sh_study_environments();

/// Exact irradiance at a normal whose cosine to the axis is `c` (directional: max(0, c)).
double sh_environment_irradiance(const sh_environment& env, double c);

/// The environment rasterized into a cube map of `size`^2 faces: radiance at each texel
/// centre; the directional light goes into the texel holding it as irradiance / solid angle.
std::array<image<glm::vec3>, 6> rasterize_environment(const sh_environment& env, std::size_t size);

/// One row per order 1 .. 8: {"order", "coefficients", "irradiance_max_rel",
/// "irradiance_mean_rel", "cube_irradiance_max_rel", "cube_irradiance_mean_rel" (through a
/// `cube_size`^2 cube map), "radiance_rel_l2" (null for the directional light), and for the
/// directional light from order 2 "hann_nonnegative": {"width", "energy_kept", "peak_kept",
/// "irradiance_max_rel", "irradiance_mean_rel"}}. Errors are relative to the peak
/// irradiance, over 4001 cosines uniform in area. Throws parameter_error naming "cube_size"
/// when it is 0.
nlohmann::ordered_json sh_accuracy_table(const sh_environment& env, std::size_t cube_size);

/// Oat's extrapolation against the probe re-projected at p + d, for a sphere light of radius
/// 0.5 m whose centre is 3 m above the probe (order 2, central differences with h = 0.1 m),
/// sideways and towards the light at 0.25, 0.5 and 1 m: rows {"direction", "distance_m",
/// "step_m", "stale_max_rel", "extrapolated_max_rel"}, the largest irradiance error over
/// 4096 normals relative to the peak at p + d.
nlohmann::ordered_json sh_gradient_table();

}  // namespace bounce::study
