#pragma once
// The raster sampler's options as the hemisphere tests spell them: N x N planes of
// `aperture` degrees, `batch` per atlas, the eye `offset` along the normal, and the turn.
#include <bounce/gl/hemisphere_raster.hpp>

#include <cstddef>
#include <cstdint>

namespace bounce {

inline gl::hemisphere_raster_options raster_options(std::uint32_t N, double aperture, std::size_t batch, float offset,
                                              double turn = 0, bool hashed_turn = false) {
    gl::hemisphere_raster_options o;
    o.camera = {N, aperture, turn, hashed_turn};
    o.batch = batch;
    o.offset = offset;
    return o;
}

}  // namespace bounce
