#pragma once
/// \file owned_scene.hpp
/// A scene held as a renderer holds its own arrays: vectors behind a bounce::scene_view, with
/// no loader (io::scene is the loaded kind). Tests and programs that build their geometry
/// by hand (cornell_box.hpp fills one) use it; a renderer keeps its own containers and hands
/// bounce a scene_view of them.
#include <bounce/camera.hpp>
#include <bounce/light.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce {

struct owned_scene {
    std::string name;
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::uvec3> triangles;
    std::vector<std::uint32_t> material_of;
    std::vector<material> materials;
    std::vector<light> lights;
    bool use_emission = false;
    bounce::camera camera;

    scene_view view() const& noexcept {
        return {positions, normals, triangles, material_of, materials, lights, use_emission};
    }
    operator scene_view() const& noexcept { return view(); }
    std::pair<glm::vec3, glm::vec3> bounds() const noexcept { return view().bounds(); }
};

}  // namespace bounce
