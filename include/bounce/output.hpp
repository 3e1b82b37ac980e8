#pragma once
/// \file output.hpp
/// What a technique's output means, in one vocabulary for every family: the cache
/// (cpu::irradiance_cache, gl::irradiance_splatter), RSM/SII (cpu::indirect_renderer,
/// gl::indirect_renderer), radiosity (cpu and gl progressive_radiosity) and the irradiance
/// volume (cpu::light_points, gl::irradiance_volume_lookup).
///
/// The default everywhere is **indirect irradiance** E (W/m^2 per channel): the light that
/// arrives at a surface point after at least one reflection. It needs no material, and a
/// renderer multiplies it by its own BRDF at its own resolution (rho/pi for a diffuse
/// surface, with an albedo texture finer than the technique's records, probes or texels).
/// Asked for `output_quantity::radiance`, a family returns rho/pi * E with the albedo the
/// caller gave it (the G-buffer's, the scene's materials for radiosity, a span for the
/// volume), computed by the one kernel lambertian_radiance (direct_light.hpp): apply_output
/// here on the CPU, gl::output_pass on GL textures.
///
/// Only radiosity also computes direct light (the scene's point, spot and directional lights,
/// shot in its constructor); it offers `light_paths` so that a renderer with its own direct
/// lighting takes the rest alone and does not count the direct light twice. The other
/// families compute indirect light only.

#include <bounce/direct_light.hpp>
#include <bounce/errors.hpp>
#include <bounce/image.hpp>

#include <cstddef>
#include <span>

#include <glm/vec3.hpp>

namespace bounce {

/// The quantity an output holds per pixel, texel, element or point.
enum class output_quantity {
    irradiance,  ///< E, W/m^2 per channel: light arriving (the default); multiply by your BRDF
    radiance,    ///< L = rho/pi E, W/(m^2 sr): outgoing radiance of a diffuse surface of the caller's albedo
};

/// Which light an output counts (radiosity; every other family computes indirect light only).
enum class light_paths {
    /// Everything but `direct` (the default): light reflected at least once and, for
    /// radiosity, the light of emissive surfaces (shot like reflected light).
    indirect,
    /// Straight from the scene's point, spot and directional lights (scene_view::lights),
    /// what a renderer's own light pass computes; as radiance, plus the surface's emission.
    direct,
    all,  ///< both
};

/// The name of `q` as the API spells it ("irradiance", "radiance").
constexpr const char* to_string(output_quantity q) noexcept {
    return q == output_quantity::radiance ? "radiance" : "irradiance";
}
/// The name of `p` as the API spells it ("indirect", "direct", "all").
constexpr const char* to_string(light_paths p) noexcept {
    return p == light_paths::direct ? "direct" : p == light_paths::all ? "all" : "indirect";
}

/// Turns irradiance into `q` in place: nothing for irradiance, lambertian_radiance with
/// `albedo[i]` for radiance. Throws parameter_error naming "albedo" when radiance is asked
/// and the sizes differ.
inline void apply_output(output_quantity q, std::span<const glm::vec3> albedo, std::span<glm::vec3> values) {
    if (q == output_quantity::irradiance) return;
    require(albedo.size() == values.size(), "albedo", "one albedo per value is needed for radiance");
    for (std::size_t i = 0; i < values.size(); ++i)
        values[i] = lambertian_radiance<float, glm::vec3>(albedo[i], values[i]);
}

/// The same over an image (a G-buffer's albedo view beside an output image of its size).
inline void apply_output(output_quantity q, image_view<const glm::vec3> albedo, image_view<glm::vec3> values) {
    if (q == output_quantity::irradiance) return;
    require(albedo.width() == values.width() && albedo.height() == values.height(), "albedo",
            "size differs from the output's");
    for (std::size_t y = 0; y < values.height(); ++y)
        for (std::size_t x = 0; x < values.width(); ++x)
            values(x, y) = lambertian_radiance<float, glm::vec3>(albedo(x, y), values(x, y));
}

}  // namespace bounce
