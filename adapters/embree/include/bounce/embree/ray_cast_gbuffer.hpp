#pragma once
/// \file ray_cast_gbuffer.hpp
/// The G-buffer by ray casting: one camera ray through each pixel centre, so that a CPU
/// G-buffer can be compared pixel by pixel with the raster one of the GL adapter.

#include <bounce/camera.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/scene_view.hpp>

namespace bounce::embree {

/// Fills `out` (all four views the same, non-zero size) with the first surface seen
/// through each pixel centre of `cam`, as include/bounce/camera.hpp defines it: the ray
/// from cam.position along cam.direction(x + 0.5, y + 0.5, W, H), restricted to depths in
/// [near_plane, far_plane] as a rasterizer clips. Per pixel: world position, the
/// interpolated vertex normal (barycentric) normalized and flipped to face the camera, the
/// triangle's Kd as albedo, and depth = distance along cam.forward(); background pixels get
/// depth = +infinity, position and normal 0, albedo 0. Rows run in parallel (TBB); each
/// pixel is computed on its own, so the result does not depend on the thread count.
/// Throws parameter_error on mismatched or empty views, an invalid camera, or a scene that
/// does not match `bvh`.
void ray_cast_gbuffer(const accel& bvh, const scene_view& scene, const bounce::camera& cam, gbuffer_view<float> out);

/// Convenience: a new `width` x `height` G-buffer from ray_cast_gbuffer.
gbuffer<float> ray_cast_gbuffer(const accel& bvh, const scene_view& scene, const bounce::camera& cam,
                                std::size_t width, std::size_t height);

/// Replaces each pixel's position, normal and depth of `g` (a raster G-buffer, say) by the
/// ray cast's through the same pixel centre where both see the same surface (same_surface
/// with the scene's size). Record samplers that start rays at a pixel's point need this: a
/// rasterized point is only within ~1e-6 of its triangle, and at a contact line (a ledge
/// meeting a wall) that puts the origin inside the touching solid, whose record then sees a
/// closed hemisphere. Silhouette pixels, where the two see different surfaces, keep g's.
void snap_to_ray_hits(const accel& bvh, const scene_view& scene, const bounce::camera& cam, gbuffer_view<float> g);

}  // namespace bounce::embree
