#pragma once
// Views as OpenImageIO ImageBufs, for the code that hands images to OpenImageIO (the image
// files of bounce::io, the comparisons of bounce::study). Not part of io's interface: it
// needs OpenImageIO's headers, which only those two targets see.
#include <bounce/errors.hpp>
#include <bounce/image.hpp>

#include <OpenImageIO/imagebuf.h>

#include <cstddef>
#include <limits>

namespace bounce::io::detail {

/// A float ImageBuf holding a copy of a view (whatever its row stride).
template <class T>
OIIO::ImageBuf to_imagebuf(image_view<const T> v, int channels) {
    OIIO::ImageSpec spec(int(v.width()), int(v.height()), channels, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf buf(spec, OIIO::InitializePixels::No);
    buf.set_pixels(OIIO::ROI(0, int(v.width()), 0, int(v.height()), 0, 1, 0, channels), OIIO::TypeDesc::FLOAT,
                   v.data(), sizeof(T), OIIO::stride_t(v.stride() * sizeof(T)));
    return buf;
}

/// Throws parameter_error ("image") for an empty image or one OpenImageIO's int sizes cannot hold.
inline void require_writable_size(std::size_t w, std::size_t h) {
    require(w > 0 && h > 0, "image", "empty image");
    require(w <= std::size_t(std::numeric_limits<int>::max()) && h <= std::size_t(std::numeric_limits<int>::max()),
            "image", "too large for OpenImageIO");
}

}  // namespace bounce::io::detail
