#pragma once
/// \file frame_comparison.hpp
/// What a study needs to compare a technique's frames with reference images: the pixels
/// where the comparison means something. (The multi-frame runs' camera path is
/// camera_path.hpp.)

#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>

namespace bounce::study {

/// 1 where `g` sees geometry, 0 elsewhere.
image<float> coverage_mask(const gbuffer_view<float>& g);

/// The pixels where a frame's G-buffer (a raster one, say) sees the same surface as the
/// ray-cast G-buffer `reference_g` the reference was computed on (same_surface with
/// `scene_size`): elsewhere (a few silhouette pixels) the two images show different surfaces
/// and their difference is not the technique's error.
image<float> comparable_mask(const gbuffer_view<float>& g, const gbuffer_view<float>& reference_g, float scene_size);

}  // namespace bounce::study
