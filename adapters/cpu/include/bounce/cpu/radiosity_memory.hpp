#pragma once
/// \file radiosity_memory.hpp
/// What a CPU radiosity solve will hold at its peak, estimated before anything is allocated
/// (cpu::progressive_radiosity, radiosity.hpp; the program's --elements check).

#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/scene_view.hpp>

#include <algorithm>
#include <cmath>

namespace bounce::cpu {

/// Bytes that building an atlas (build_lightmap_atlas(scene, options)) and then a
/// progressive_radiosity<V, float> over it hold at their peak, with the solver's lightmap()
/// and the unshot radiosity laid out as texels at the end: an estimate from the element budget
/// and the triangle count made before anything is allocated, so a caller can refuse a budget
/// that cannot fit (`--elements 50000000`) instead of dying in std::bad_alloc or the OOM
/// killer. Per element: the atlas's arrays (64 bytes), twice while the solver copies it, and
/// the solver's radiosity, unshot, direct, gathered and received arrays (60, twice for
/// `two_sided` elements, radiosity_options::two_sided); per texel of the atlas (elements
/// plus each chart's padding ring and the packing's waste, at most one chart per triangle):
/// element_at, the build's overlap sums and the lightmaps laid out (56, and 12 more for the
/// back's lightmap when two-sided); per triangle the
/// build's adjacency (about 200). Visibility is not included (an item buffer: about 112
/// bytes per triangle and 12 per pixel of its buffers). Measured peaks are lower by 10-25%
/// (docs/radiosity.md, section 7).
inline double radiosity_memory_estimate(const scene_view& scene, const atlas_options& options, bool two_sided = true) {
    // Each chart takes at least one element whatever the budget: at most one chart per triangle.
    const double n = double(scene.triangles.size()), e = std::max(double(options.elements), n);
    const double p = double(options.padding);
    const double texels = 1.25 * (1.3 * e + 4 * p * std::sqrt(e * n) + 4 * p * p * n);
    const double shooters = e / double(options.block_texels * options.block_texels) + n;
    const double sides = two_sided ? 2 : 1;
    return e * (2 * 64 + 60 * sides) + texels * (44 + 12 * sides) + shooters * 60 + n * 200 +
           double(scene.positions.size()) * 48;
}

}  // namespace bounce::cpu
