#pragma once
/// \file luminance.hpp
/// Luminance of linear RGB: the one weighting of the channels that error figures and
/// profiles of radiance use. A kernel, instantiated on the CPU and emitted as GLSL.

#include <bounce/concepts.hpp>
#include <bounce/vocabulary.hpp>  // the GLM vectors meet vec3_of with the geometric functions

namespace bounce {

/// Rec. 709 (ITU-R BT.709) luminance of linear RGB: 0.2126 R + 0.7152 G + 0.0722 B.
template <real T, vec3_of<T> V>
T rec709_luminance(const V& c) {
    return T(0.2126) * c.x + T(0.7152) * c.y + T(0.0722) * c.z;
}

}  // namespace bounce
