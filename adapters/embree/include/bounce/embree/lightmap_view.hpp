#pragma once
/// \file lightmap_view.hpp
/// A camera's view of a radiosity solution stored as a lightmap (radiosity/lightmap_atlas.hpp): one
/// primary ray per pixel centre, the hit's chart and its atlas coordinates, a bilinear
/// lookup of the radiosity B there (the chapter's reconstruction: Coombe and Harris 2005,
/// section 39.3.3, draws the atlas with bilinear filtering; the atlas's padding keeps the
/// four texels of a lookup in the hit's chart), and the radiance of a Lambertian surface,
/// L = B / pi. The same pixels as multi_bounce_reference::render, so the two compare pixel
/// for pixel.

#include <bounce/camera.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/image.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/scene_view.hpp>

#include <glm/vec3.hpp>

namespace bounce::embree {

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

}  // namespace bounce::embree
