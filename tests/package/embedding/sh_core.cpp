// docs/embedding.md, spherical harmonics: the header-only core alone. Components: core.
#include "room.hpp"

#include <bounce/sh/irradiance.hpp>
#include <bounce/sh/projection.hpp>

int main() {
    // [recipe]
    using namespace bounce;
    image<glm::vec3> sky(64, 32, glm::vec3(0.1f));       // your environment, latitude-longitude, W/(m^2 sr)
    for (std::size_t y = 0; y < sky.height() / 2; ++y)   // its upper half (row 0 at +z: latlong_direction)
        for (std::size_t x = 0; x < sky.width(); ++x) sky(x, y) = glm::vec3(1.f, 1.f, 1.2f);
    const auto radiance = sh_project_latlong<3>(sky.view());  // 9 glm::dvec3 coefficients
    const glm::dvec3 e = sh_irradiance(radiance, glm::dvec3(0, 0, 1));  // irradiance, W/m^2, normal +z
    // [/recipe]
    return report("sh: irradiance facing +z", e.x);
}
