#include <bounce/io/scene.hpp>

#include <cmath>
#include <string>

#include <glm/geometric.hpp>

namespace bounce::io {

namespace {
bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool non_negative3(glm::vec3 v) { return finite3(v) && v.x >= 0.f && v.y >= 0.f && v.z >= 0.f; }
}  // namespace

void validate_lights(const scene& s) {
    for (std::size_t i = 0; i < s.lights.size(); ++i) {
        const std::string name = "scene.lights[" + std::to_string(i) + "]";
        auto fail = [&](const char* what) { throw parameter_error(name, what); };
        auto check_direction = [&](glm::vec3 d) {
            if (!finite3(d) || glm::length(d) == 0.f) fail("direction must be finite and non-zero");
        };
        if (const auto* pl = std::get_if<point_light>(&s.lights[i])) {
            if (!finite3(pl->position)) fail("position is not finite");
            if (!non_negative3(pl->intensity)) fail("intensity must be finite and non-negative");
        } else if (const auto* sl = std::get_if<spot_light>(&s.lights[i])) {
            if (!finite3(sl->position)) fail("position is not finite");
            if (!non_negative3(sl->intensity)) fail("intensity must be finite and non-negative");
            check_direction(sl->direction);
            if (!(std::isfinite(sl->cone_deg) && sl->cone_deg > 0.f && sl->cone_deg <= 180.f))
                fail("cone_deg must lie in (0, 180]");
        } else {
            const auto& dl = std::get<directional_light>(s.lights[i]);
            if (!non_negative3(dl.irradiance)) fail("irradiance must be finite and non-negative");
            check_direction(dl.direction);
        }
    }
}

}  // namespace bounce::io
