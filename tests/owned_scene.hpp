#pragma once
// A scene the tests build by hand and own, as a renderer owns its arrays (the core's
// bounce::owned_scene), with no loader and no bounce::io, so the GL and Embree tests need
// neither OpenImageIO nor tinyobjloader.
#include <bounce/owned_scene.hpp>

namespace bounce::test {

using owned_scene = bounce::owned_scene;

}  // namespace bounce::test
