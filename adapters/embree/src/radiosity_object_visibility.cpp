// The visibility of one moved object alone (radiosity_object_visibility.hpp).
#include <bounce/embree/radiosity_object_visibility.hpp>

#include <bounce/errors.hpp>

#include <string>
#include <vector>

namespace bounce::embree {

namespace {

// The triangles `moved` of `scene` alone, their vertices bitwise the scene's.
radiosity_visibility object_alone(const scene_view& scene, const radiosity_visibility& whole, std::span<const std::uint32_t> moved,
                                  std::span<const std::uint32_t> chart_of_triangle) {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;
    std::vector<std::uint32_t> material_of, charts;
    for (const std::uint32_t t : moved) {
        const auto base = std::uint32_t(positions.size());
        for (int k = 0; k < 3; ++k) positions.push_back(scene.positions[scene.triangles[t][k]]);
        triangles.emplace_back(base, base + 1, base + 2);
        material_of.push_back(scene.material_of[t]);
        charts.push_back(chart_of_triangle[t]);
    }
    scene_view object;
    object.positions = positions, object.triangles = triangles, object.material_of = material_of, object.materials = scene.materials;
    radiosity_visibility::options o = whole.settings();
    o.ray_epsilon = whole.ray_epsilon();
    return radiosity_visibility(whole.bvh().owner(), object, charts, o);
}

}  // namespace

radiosity_object_visibility object_visibility(const scene_view& before_scene, const radiosity_visibility& whole_before,
                                              const scene_view& after_scene, const radiosity_visibility& whole_after,
                                              std::span<const std::uint32_t> moved,
                                              std::span<const std::uint32_t> chart_of_triangle) {
    require(!moved.empty(), "moved_triangles", "must name at least one triangle");
    require(after_scene.triangles.size() == before_scene.triangles.size(), "after_scene",
            "must hold the same triangles as the scene before the move");
    require(chart_of_triangle.size() == before_scene.triangles.size(), "chart_of_triangle", "needs one chart per triangle of the scene");
    for (const std::uint32_t t : moved)
        if (t >= before_scene.triangles.size())
            throw parameter_error("moved_triangles", "triangle " + std::to_string(t) + " is not in the scene");
    return {object_alone(before_scene, whole_before, moved, chart_of_triangle),
            object_alone(after_scene, whole_after, moved, chart_of_triangle)};
}

}  // namespace bounce::embree
