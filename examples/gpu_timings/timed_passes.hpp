#pragma once
/// \file timed_passes.hpp
/// The fixed set of GL passes gpu_timings times, on the built-in Cornell box (optionally
/// subdivided into a denser mesh) with inputs made deterministically on the host: no ray
/// tracer, no scene files. Every pass is a library type driven through its public API.

#include "gpu_timer.hpp"

#include <bounce/camera.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/owned_scene.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::gpu_timings {

/// What the passes are run with (the command line's options).
struct settings {
    int repetitions = 7;              ///< timed runs per pass (after one warm-up)
    int subdivide = 0;                ///< each Cornell box triangle split into 4^subdivide
    std::size_t records = 4096;       ///< irradiance records in the fixed set
    std::size_t rsm_resolution = 256; ///< texels per side of each reflective shadow map
    std::size_t elements = 10000;     ///< radiosity elements (lightmap texels)
    int item_buffer = 256;            ///< radiosity item buffer side, pixels
    std::uint32_t plane_resolution = 64;  ///< hemisphere raster plane side, pixels
    std::size_t plane_batch = 64;     ///< planes per hemisphere raster batch
    int volume_depth = 4;             ///< uniform irradiance-volume octree depth
    std::size_t gather_samples = 400; ///< RSM gather disc samples per pixel and map
    std::size_t sii_vpls = 1024;      ///< SII VPLs per frame
};

/// The Cornell box, each triangle split `subdivide` times into four (midpoints; the face's
/// normal and material kept), so the denser mesh covers the same surfaces.
owned_scene timing_scene(int subdivide);

/// `count` irradiance records on the scene's surfaces, the same on every run: points drawn
/// area-weighted by pcg32 (seed fixed), the face's normal, a smooth made-up irradiance with
/// gradients, and radii between 2% and 12% of the scene's diagonal (what a cache's records
/// span in a room).
std::vector<irradiance_record> fixed_records(const owned_scene& scene, std::size_t count);

/// The passes that depend on the image size, at width x height: G-buffer, direct light, IC
/// splat and normalize, the RSM gather and SII (plain and 8x8 interleaved) on the scene's
/// RSMs, and the volume lookup at every covered pixel.
struct image_passes {
    std::size_t width = 0, height = 0;
    std::vector<pass_timing> passes;
};

/// The passes that do not: the RSM maps, the radiosity shot (with and without its item
/// buffer) and the item buffer, the hemisphere raster's planes.
struct scene_passes {
    std::vector<pass_timing> passes;
    std::size_t triangles = 0, rsm_maps = 0, radiosity_elements = 0, volume_probes = 0;
};

/// Runs everything in the current context (GL 4.5). `sizes` are (width, height) pairs.
struct timing_run {
    scene_passes scene;
    std::vector<image_passes> images;
};
timing_run run_timings(const settings& s, const std::vector<std::pair<std::size_t, std::size_t>>& sizes);

}  // namespace bounce::gpu_timings
