// glTF 2.0 scenes the tests write themselves (.gltf with an embedded base64 buffer, and
// .glb): node transforms, every index type, strips and fans, materials and the base-colour
// texture's mean, KHR_lights_punctual, the camera, and scene.json naming a glTF file.
#include "gltf_writer.hpp"
#include "mesh_invariants.hpp"
#include "scratch_folder.hpp"

#include <bounce/io/image_io.hpp>
#include <bounce/io/scene.hpp>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace bounce;
using bounce::test::gltf_writer;
using bounce::test::scratch_folder;
using json = nlohmann::json;

namespace {

// A unit quad in z = 0 facing +z, as two triangles over 4 vertices, indices of type T.
template <class T>
gltf_writer quad(bool normals = true) {
    gltf_writer w;
    const std::vector<glm::vec3> p = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    json prim = {{"attributes", {{"POSITION", w.vec3s(p)}}}, {"indices", w.indices<T>({0, 1, 2, 0, 2, 3})}};
    if (normals) prim["attributes"]["NORMAL"] = w.accessor(std::vector<glm::vec3>(4, {0, 0, 1}), 5126, "VEC3");
    w.push("meshes", {{"primitives", {prim}}});
    w.scene({w.push("nodes", {{"mesh", 0}})});
    return w;
}

io::scene load(const gltf_writer& w, const scratch_folder& dir, const std::string& name) {
    w.write(dir.path() / name);
    return io::load_gltf(dir.path() / name);
}

bool near(glm::vec3 a, glm::vec3 b, float tol = 1e-6f) { return glm::length(a - b) <= tol * std::max(1.f, glm::length(b)); }

}  // namespace

TEST_CASE("a glTF quad loads the same from .gltf and .glb with every index type", "[io][gltf]") {
    scratch_folder dir;
    const std::vector<gltf_writer> writers = {quad<std::uint8_t>(), quad<std::uint16_t>(), quad<std::uint32_t>()};
    for (std::size_t k = 0; k < writers.size(); ++k)
        for (const char* ext : {".gltf", ".glb"}) {
            CAPTURE(k, ext);
            const io::scene s = load(writers[k], dir, fmt::format("q{}{}", k, ext));
            test::check_mesh_invariants(s);
            REQUIRE(s.triangles.size() == 2);
            CHECK(s.positions.size() == 4);
            CHECK(s.triangles[1] == glm::uvec3(0, 2, 3));
            CHECK(s.positions[2] == glm::vec3(1, 1, 0));
            CHECK(s.normals[3] == glm::vec3(0, 0, 1));
            CHECK(s.materials.size() == 1);  // the default material, for a primitive without one
            CHECK(s.lights.size() == 1);     // the head light, as for an OBJ alone
            CHECK_FALSE(s.use_emission);
        }
}

TEST_CASE("glTF primitives without indices, strips and fans make the spec's triangles", "[io][gltf]") {
    scratch_folder dir;
    gltf_writer w;
    const int strip = w.vec3s({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 2, 0}});
    const int fan = w.vec3s({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 1, 0}});
    w.push("meshes", {{"primitives",
                       {{{"attributes", {{"POSITION", strip}}}, {"mode", 5}},
                        {{"attributes", {{"POSITION", fan}}}, {"mode", 6}},
                        {{"attributes", {{"POSITION", strip}}}, {"indices", w.indices<std::uint8_t>({0, 1, 2})}},  // a list
                        {{"attributes", {{"POSITION", strip}}}, {"mode", 1}}}}});                                  // lines
    w.scene({w.push("nodes", {{"mesh", 0}})});
    const io::scene s = load(w, dir, "modes.glb");
    test::check_mesh_invariants(s);
    // Without normals every triangle is flat (3 vertices of its own): strip 3 + fan 3 + list 1.
    REQUIRE(s.triangles.size() == 7);
    CHECK(s.positions.size() == 21);
    // Strip triangle i is (v_i, v_i+1+i%2, v_i+2-i%2): all counter-clockwise, facing +z.
    for (std::size_t t = 0; t < s.triangles.size(); ++t) CHECK(s.normals[s.triangles[t].x] == glm::vec3(0, 0, 1));
    CHECK(s.positions[3] == glm::vec3(1, 0, 0));
    CHECK(s.positions[4] == glm::vec3(1, 1, 0));
    CHECK(s.positions[5] == glm::vec3(0, 1, 0));
    // Fan triangle i is (v_i+1, v_i+2, v_0).
    CHECK(s.positions[9] == glm::vec3(1, 0, 0));
    CHECK(s.positions[10] == glm::vec3(1, 1, 0));
    CHECK(s.positions[11] == glm::vec3(0, 0, 0));
    REQUIRE_FALSE(s.warnings.empty());
    CHECK(s.warnings.back().find("point/line") != std::string::npos);
}

TEST_CASE("glTF node transforms: hierarchy, TRS and matrix, normals by the inverse transpose, mirrors", "[io][gltf]") {
    scratch_folder dir;
    gltf_writer w = quad<std::uint16_t>();
    // Parent: translate (10, 0, 0), rotate 90 degrees about z, scale x by 2. Child: a
    // matrix translating by (0, 0, 5). A second child mirrors x.
    const double h = std::sqrt(0.5);
    w.doc["nodes"] = json::array();
    w.push("nodes", {{"translation", {10, 0, 0}}, {"rotation", {0, 0, h, h}}, {"scale", {2, 1, 1}}, {"children", {1, 2}}});
    w.push("nodes", {{"mesh", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1}}});
    w.push("nodes", {{"mesh", 0}, {"scale", {-1, 1, 1}}});
    w.scene({0});
    const io::scene s = load(w, dir, "t.gltf");
    test::check_mesh_invariants(s);
    REQUIRE(s.triangles.size() == 4);
    // Quad corner (1, 1, 0) under the first child: scale (2, 1, 0), rotate (-1, 2, 0),
    // translate (9, 2, 0), then the child's (0, 0, 5): (9, 2, 5).
    CHECK(near(s.positions[s.triangles[0].z], {9, 2, 5}));
    CHECK(near(s.normals[0], {0, 0, 1}));
    // Every triangle stays counter-clockwise seen from its normal's side, mirrored or not.
    for (const auto& t : s.triangles) {
        const glm::vec3 face = glm::cross(s.positions[t.y] - s.positions[t.x], s.positions[t.z] - s.positions[t.x]);
        CHECK(glm::dot(face, s.normals[t.x]) > 0.f);
    }
    // A non-uniform scale: normals go by the inverse transpose, diag(1/2, 1, 1).
    gltf_writer scaled = quad<std::uint32_t>();
    scaled.doc["nodes"][0]["scale"] = {2, 1, 1};
    scaled.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] =
        scaled.accessor(std::vector<glm::vec3>(4, glm::normalize(glm::vec3(1, 0, 1))), 5126, "VEC3");
    const io::scene sc = load(scaled, dir, "scaled.glb");
    CHECK(near(sc.normals[0], glm::normalize(glm::vec3(0.5f, 0, 1))));
}

TEST_CASE("glTF materials: base colour, its texture's mean, emission with its strength", "[io][gltf]") {
    scratch_folder dir;
    // A 2 x 1 sRGB texture, full red and full blue: its linear mean is (0.5, 0, 0.5).
    image<glm::vec3> tex(2, 1);
    tex(0, 0) = {1, 0, 0};
    tex(1, 0) = {0, 0, 1};
    io::write_png(dir.path() / "tex.png", tex.view());
    gltf_writer w = quad<std::uint8_t>();
    w.push("images", {{"uri", "tex.png"}});
    w.push("textures", {{"source", 0}});
    w.push("materials", {{"name", "textured"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 1, 1, 1}}, {"baseColorTexture", {{"index", 0}}}}}});
    w.push("materials", {{"emissiveFactor", {1, 0.5, 0.25}}, {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 8}}}}}});
    w.doc["meshes"][0]["primitives"][0]["material"] = 0;
    json second = w.doc["meshes"][0]["primitives"][0];
    second["material"] = 1;
    w.doc["meshes"][0]["primitives"].push_back(second);
    const io::scene s = load(w, dir, "m.gltf");
    REQUIRE(s.materials.size() == 2);
    CHECK(near(s.materials[0].albedo, {0.25f, 0.f, 0.5f}, 1e-6f));
    CHECK(s.material_names[0] == "textured");
    CHECK(s.material_names[1] == "materials[1]");
    CHECK(s.materials[1].albedo == glm::vec3(1.f));  // the spec's default base colour
    CHECK(s.materials[1].emission == glm::vec3(8.f, 4.f, 2.f));
    CHECK(s.use_emission);  // a used material emits, so the file alone lights itself
    CHECK(s.lights.empty());
    CHECK(s.emissive_triangles().size() == 2);

    // A texture that does not decode, or whose file is missing, is a fault naming it.
    dir.write("junk.png", "not a PNG at all");
    w.doc["images"][0]["uri"] = "junk.png";
    w.write(dir.path() / "junk.gltf");
    CHECK_THROWS_WITH(io::load_gltf(dir.path() / "junk.gltf"), Catch::Matchers::Contains("images[0]: cannot decode"));
    w.doc["images"][0]["uri"] = "gone.png";
    w.write(dir.path() / "gone.gltf");
    CHECK_THROWS_WITH(io::load_gltf(dir.path() / "gone.gltf"), Catch::Matchers::Contains("gone.png: no such file"));
}

TEST_CASE("KHR_lights_punctual: point, spot and directional placed by their nodes", "[io][gltf]") {
    scratch_folder dir;
    gltf_writer w = quad<std::uint8_t>();
    const double inner = 0.3, outer = 0.6;
    w.use_lights({{{"type", "point"}, {"color", {1, 0.5, 0}}, {"intensity", 40}, {"range", 9}},
                  {{"type", "spot"}, {"intensity", 10}, {"spot", {{"innerConeAngle", inner}, {"outerConeAngle", outer}}}},
                  {{"type", "directional"}, {"intensity", 3}}});
    const double h = std::sqrt(0.5);
    w.push("nodes", {{"translation", {1, 2, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    // Rotated -90 degrees about x: -z turns to -y (pointing down).
    w.push("nodes", {{"translation", {0, 4, 0}}, {"rotation", {-h, 0, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
    w.push("nodes", {{"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
    w.scene({0, 1, 2, 3});
    const io::scene s = load(w, dir, "l.glb");
    REQUIRE(s.lights.size() == 3);
    const auto& p = std::get<point_light>(s.lights[0]);
    CHECK(p.position == glm::vec3(1, 2, 3));
    CHECK(p.intensity == glm::vec3(40, 20, 0));  // candela taken as W/sr
    const auto& spot = std::get<spot_light>(s.lights[1]);
    CHECK(near(spot.position, {0, 4, 0}));
    CHECK(near(spot.direction, {0, -1, 0}));
    CHECK(spot.intensity == glm::vec3(10.f));
    CHECK(spot.falloff == spot_light::falloff_kind::none);
    // Same power as the spec's quadratic fade: cos c = (2 cos inner + cos outer) / 3.
    CHECK(std::abs(std::cos(glm::radians(double(spot.cone_deg))) - (2 * std::cos(inner) + std::cos(outer)) / 3) < 1e-6);
    const auto& d = std::get<directional_light>(s.lights[2]);
    CHECK(d.direction == glm::vec3(0, 0, -1));
    CHECK(d.irradiance == glm::vec3(3.f));  // lux taken as W/m^2
    CHECK(std::find_if(s.warnings.begin(), s.warnings.end(), [](const std::string& x) { return x.find("range") != std::string::npos; }) !=
          s.warnings.end());
    CHECK_NOTHROW(validate_lights(s.lights));
}

TEST_CASE("the first perspective glTF camera, placed by its node; without one the OBJ framing", "[io][gltf]") {
    scratch_folder dir;
    gltf_writer w = quad<std::uint8_t>();
    w.push("cameras", {{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 10}}}});
    w.push("cameras", {{"type", "perspective"}, {"perspective", {{"yfov", std::numbers::pi / 3}, {"znear", 0.1}, {"aspectRatio", 2}}}});
    w.push("nodes", {{"camera", 0}});
    w.push("nodes", {{"camera", 1}, {"translation", {0.5, 0.5, 4}}});
    w.push("nodes", {{"camera", 1}, {"translation", {9, 9, 9}}});  // not the first
    w.scene({0, 1, 2, 3});
    const io::scene s = load(w, dir, "c.gltf");
    CHECK(s.camera.position == glm::vec3(0.5f, 0.5f, 4.f));
    CHECK(near(glm::normalize(s.camera.look_at - s.camera.position), {0, 0, -1}));
    CHECK(s.camera.up == glm::vec3(0, 1, 0));
    CHECK(std::abs(s.camera.fov_y_deg - 60.f) < 1e-4f);
    CHECK(s.warnings.front().find("orthographic") != std::string::npos);
    // No camera: framed from +z, 45 degrees, as load_obj does.
    const io::scene framed = load(quad<std::uint8_t>(), dir, "f.gltf");
    CHECK(framed.camera.fov_y_deg == 45.f);
    CHECK(framed.camera.position.z > 1.f);
}

TEST_CASE("scene.json names a glTF file and adds or overrides its lights and camera", "[io][gltf][scene]") {
    scratch_folder dir;
    gltf_writer w = quad<std::uint8_t>();
    w.use_lights({{{"type", "point"}, {"intensity", 5}}});
    w.push("nodes", {{"translation", {0, 0, 2}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    w.push("materials", {{"emissiveFactor", {1, 1, 1}}});
    w.doc["meshes"][0]["primitives"][0]["material"] = 0;
    w.scene({0, 1});
    w.write(dir.path() / "m.glb");
    const json spot = {{"type", "spot"}, {"position", {0, 0, 3}}, {"direction", {0, 0, -1}}, {"intensity", {1, 1, 1}},
                       {"cone_deg", 60}, {"falloff", "cosine"}};
    const json cam = {{"position", {0, 0, 5}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_y_deg", 30}};
    const auto scene_with = [&](const json& j) { return io::load_scene(dir.write("scene.json", j.dump())); };

    const io::scene plain = scene_with({{"gltf", "m.glb"}});
    CHECK(plain.lights.size() == 1);
    CHECK(plain.use_emission);
    const io::scene added = scene_with({{"gltf", "m.glb"}, {"lights", {spot}}, {"camera", cam}, {"use_emission", false}});
    REQUIRE(added.lights.size() == 2);
    CHECK(std::holds_alternative<point_light>(added.lights[0]));
    CHECK(std::holds_alternative<spot_light>(added.lights[1]));
    CHECK(added.camera.fov_y_deg == 30.f);
    CHECK_FALSE(added.use_emission);
    const io::scene replaced = scene_with({{"gltf", "m.glb"}, {"lights", {spot}}, {"gltf_lights", false}});
    REQUIRE(replaced.lights.size() == 1);
    CHECK(std::holds_alternative<spot_light>(replaced.lights[0]));

    CHECK_THROWS_WITH(scene_with({{"gltf", "m.glb"}, {"obj", "m.obj"}}), Catch::Matchers::Contains("name one mesh file"));
    CHECK_THROWS_WITH(scene_with({{"obj", "m.obj"}, {"gltf_lights", true}, {"camera", cam}, {"lights", {spot}}}),
                      Catch::Matchers::Contains("gltf_lights: only with gltf"));
    CHECK_THROWS_WITH(scene_with({{"gltf", "m.glb"}, {"gltf_lights", false}, {"use_emission", false}}),
                      Catch::Matchers::Contains("the scene has no light"));
    // --scene takes the glTF file itself.
    CHECK(io::load_scene_arg((dir.path() / "m.glb").string()).triangles.size() == 2);
}
