// The built-in Cornell box written as glTF (with a scene.json for its cosine spot, which
// glTF cannot hold) loads back as the same scene, bit for bit: positions, normals,
// triangles, materials, lights and camera. tests/embree renders both and compares.
#include "gltf_writer.hpp"
#include "scratch_folder.hpp"

#include <bounce/io/scene.hpp>

#include <catch2/catch.hpp>

#include <cstring>
#include <vector>

using namespace bounce;

TEST_CASE("the Cornell box exported as glTF loads back as the built-in box", "[io][gltf][cornell]") {
    const io::scene box = io::cornell_box();
    test::scratch_folder dir;
    const io::scene s = io::load_scene(test::write_as_gltf_scene(box, dir.path(), "cornell"));
    // Bit for bit: == would take -0 for +0, and the sign of a zero picks a tangent frame.
    const auto same_bits = [](const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
        return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
    };
    CHECK(same_bits(s.positions, box.positions));
    CHECK(same_bits(s.normals, box.normals));
    CHECK(s.triangles == box.triangles);
    CHECK(s.material_of == box.material_of);
    CHECK(s.material_names == box.material_names);
    REQUIRE(s.materials.size() == box.materials.size());
    for (std::size_t m = 0; m < s.materials.size(); ++m) {
        CHECK(s.materials[m].albedo == box.materials[m].albedo);
        CHECK(s.materials[m].emission == box.materials[m].emission);
    }
    REQUIRE(s.lights.size() == 1);
    const auto& a = std::get<spot_light>(s.lights[0]);
    const auto& b = std::get<spot_light>(box.lights[0]);
    CHECK(a.position == b.position);
    CHECK(a.direction == b.direction);
    CHECK(a.intensity == b.intensity);
    CHECK(a.cone_deg == b.cone_deg);
    CHECK(a.falloff == b.falloff);
    CHECK(s.use_emission == box.use_emission);
    // The camera: the same eye, view direction, up and field of view (look_at lies elsewhere
    // on the same ray: glTF gives a direction, not a point).
    CHECK(s.camera.position == box.camera.position);
    CHECK(glm::normalize(s.camera.look_at - s.camera.position) == glm::normalize(box.camera.look_at - box.camera.position));
    CHECK(s.camera.up == box.camera.up);
    CHECK(s.camera.fov_y_deg == box.camera.fov_y_deg);
    CHECK(s.camera.near_plane == box.camera.near_plane);
    CHECK(s.camera.far_plane == box.camera.far_plane);
    CHECK(s.warnings.empty());

    // The .glb alone: no punctual light, so the light quad's emission lights the scene.
    const io::scene alone = io::load_gltf(dir.path() / "cornell.glb");
    CHECK(alone.use_emission);
    CHECK(alone.lights.empty());
    io::scene emitting = io::cornell_box();
    emitting.use_emission = true;
    CHECK(alone.emissive_triangles() == emitting.emissive_triangles());
    CHECK(alone.emissive_triangles().size() == 2);
}
