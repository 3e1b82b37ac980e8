#pragma once
/// \file lightmap_view.hpp
/// A camera's view of a radiosity solution stored as a lightmap (radiosity/lightmap_atlas.hpp): one
/// primary ray per pixel centre, the hit's chart and its atlas coordinates, a bilinear
/// lookup of the radiosity B there (the chapter's reconstruction: Coombe and Harris 2005,
/// section 39.3.3, draws the atlas with bilinear filtering; the atlas's padding keeps the
/// four texels of a lookup in the hit's chart), and the radiance of a Lambertian surface,
/// L = B / pi. The same pixels as multi_bounce_reference::render, so the two compare pixel
/// for pixel.
///
/// The lightmap renderer's other answer (lightmap_direct_view): the lights' direct light
/// computed per pixel with shadow rays (reference_integrator::direct_irradiance, the
/// references' own direct light), and only the rest of B (the bounced light: B less the
/// lights' direct deposit rho E_d) looked up in the lightmap, so that sun shadows and thin
/// lit strips are not limited by the texel size.

#include <bounce/camera.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/image.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace bounce::embree {

/// What the primary ray through a pixel centre meets: its triangle (no_triangle on a miss),
/// the triangle's chart (lightmap_atlas::none where it has none), the side seen (the hit
/// triangle's own winding: a chart that follows a curved surface tilts its triangles up to
/// its cone from the chart's normal), the point, the unit geometric normal facing the
/// camera, and the atlas coordinates in base texels.
struct lightmap_hit {
    std::uint32_t triangle = no_triangle;
    std::uint32_t chart = lightmap_atlas::none;
    bool back = false;
    glm::vec3 position{0.f};
    glm::vec3 normal{0.f};
    glm::vec2 uv{0.f};
};

/// The hits of `cam`'s `width` x `height` view (row-major, `width * height`). Throws
/// parameter_error when the atlas or the BVH do not match the scene.
std::vector<lightmap_hit> lightmap_hits(const accel& bvh, const scene_view& scene, const lightmap_atlas& atlas,
                                        const bounce::camera& cam, std::size_t width, std::size_t height);

/// Radiance (W/(m^2 sr)) per pixel of `cam`'s `width` x `height` view of `scene`, from the
/// radiosity `lightmap` (W/m^2) laid out as `atlas` at 2^level times its resolution
/// (lightmap_atlas::to_fine_texels); 0 where no geometry is seen or the hit triangle has no
/// chart. Throws parameter_error when the atlas, the lightmap's size or the BVH do not
/// match the scene.
image<glm::vec3> lightmap_view(const accel& bvh, const scene_view& scene, const lightmap_atlas& atlas,
                               image_view<const glm::vec3> lightmap, int level, const bounce::camera& cam,
                               std::size_t width, std::size_t height);

/// The same for two-sided elements (radiosity_options::two_sided): `front` where the ray meets
/// a chart's front side (counter-clockwise), `back` where it meets its back, both laid out as
/// `atlas` (cpu::progressive_radiosity::radiosity_lightmap(level, 0) and (level, 1)).
image<glm::vec3> lightmap_view(const accel& bvh, const scene_view& scene, const lightmap_atlas& atlas,
                               image_view<const glm::vec3> front, image_view<const glm::vec3> back, int level,
                               const bounce::camera& cam, std::size_t width, std::size_t height);

/// The lookup of lightmap_view over given hits (`width` x `height` of them).
image<glm::vec3> lightmap_view(const std::vector<lightmap_hit>& hits, std::size_t width, std::size_t height,
                               const lightmap_atlas& atlas, image_view<const glm::vec3> front,
                               image_view<const glm::vec3> back, int level);

/// Per pixel of `hits`, the direct light of the scene's point, spot and directional lights
/// with shadow rays, rho / pi E_d (reference_integrator::direct_irradiance at the hit, its
/// normal facing the camera), the emitters' light included when scene.use_emission (by
/// `area_samples` samples seeded from `seed` and the pixel), their own emission L_e not.
/// W/(m^2 sr); 0 where nothing is seen.
image<glm::vec3> direct_light_view(const accel& bvh, const scene_view& scene, const std::vector<lightmap_hit>& hits,
                                   std::size_t width, std::size_t height, std::uint32_t area_samples = 16,
                                   std::uint64_t seed = 1);

/// The view with the lights' direct light per pixel: direct_light_view of the point, spot
/// and directional lights (emitters left out) plus the lookup of `front_rest` and
/// `back_rest`, the radiosity less the lights' direct deposit (B - rho E_d, emission and what
/// emissive surfaces shot included): the same light as lightmap_view, with the direct part
/// not limited by the texels. Throws as lightmap_view.
image<glm::vec3> lightmap_direct_view(const accel& bvh, const scene_view& scene, const lightmap_atlas& atlas,
                                      image_view<const glm::vec3> front_rest, image_view<const glm::vec3> back_rest,
                                      int level, const bounce::camera& cam, std::size_t width, std::size_t height);

}  // namespace bounce::embree
