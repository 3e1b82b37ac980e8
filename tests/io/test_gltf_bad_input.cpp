// Bad glTF files raise io::scene_error naming the file and the glTF object at fault (node,
// mesh, accessor, view, buffer, material, light, camera) and what is wrong; randomly
// damaged .gltf and .glb files get nothing else out of the loader.
#include "gltf_writer.hpp"
#include "mesh_invariants.hpp"
#include "random_damage.hpp"
#include "scratch_folder.hpp"

#include <bounce/io/scene.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <functional>
#include <limits>
#include <string>
#include <vector>

using namespace bounce;
using bounce::test::gltf_writer;
using bounce::test::scratch_folder;
using json = nlohmann::json;

namespace {

// One triangle over 3 vertices with u16 indices and normals, in a node, with a material.
gltf_writer good() {
    gltf_writer w;
    const int pos = w.vec3s({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    const int nrm = w.accessor(std::vector<glm::vec3>(3, {0, 0, 1}), 5126, "VEC3");
    const int idx = w.indices<std::uint16_t>({0, 1, 2});
    w.push("materials", {{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}}}});
    w.push("meshes", {{"primitives", {{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}}, {"indices", idx}, {"material", 0}}}}});
    w.scene({w.push("nodes", {{"mesh", 0}})});
    return w;
}

struct bad_case {
    std::string name;
    std::function<void(gltf_writer&)> damage;
    std::string expected;  // a part of what()
};

void set_float(gltf_writer& w, std::size_t byte, float value) { std::memcpy(&w.bin[byte], &value, 4); }

const std::vector<bad_case>& bad_cases() {
    static const std::vector<bad_case> cases = {
        {"index past the vertices", [](gltf_writer& w) { w.bin[72] = 3; }, "accessors[2]): element 0 is 3, past the last of 3 vertices"},
        {"accessor beyond its view", [](gltf_writer& w) { w.doc["accessors"][0]["count"] = 4; }, "accessors[0]): 4 elements from byte 0 do not fit bufferViews[0]"},
        {"view beyond its buffer", [](gltf_writer& w) { w.doc["bufferViews"][2]["byteLength"] = 100; }, "bufferViews[2]: bytes [72, +100) lie beyond buffers[0]"},
        {"positions of shorts", [](gltf_writer& w) { w.doc["accessors"][0]["componentType"] = 5123; }, "POSITION (accessors[0]): type 3, component type 5123; expected VEC3 of FLOAT"},
        {"signed indices", [](gltf_writer& w) { w.doc["accessors"][2]["componentType"] = 5122; }, "indices (accessors[2]): type 65, component type 5122"},
        {"float indices", [](gltf_writer& w) { w.doc["accessors"][2]["componentType"] = 5126; }, "expected SCALAR of UNSIGNED_BYTE"},
        {"NaN position", [](gltf_writer& w) { set_float(w, 16, std::numeric_limits<float>::quiet_NaN()); }, "(accessors[0]): element 1 is not finite"},
        {"infinite position", [](gltf_writer& w) { set_float(w, 0, std::numeric_limits<float>::infinity()); }, "element 0 is not finite"},
        {"position beyond 1e18", [](gltf_writer& w) { w.doc["nodes"][0]["scale"] = {1e19, 1, 1}; }, "nodes[0]: vertex 1 of meshes[0].primitives[0] lies beyond +-1e18"},
        {"missing accessor", [](gltf_writer& w) { w.doc["meshes"][0]["primitives"][0]["indices"] = 7; }, "tinygltf: primitive indices accessor out of bounds"},
        {"missing position accessor", [](gltf_writer& w) { w.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 7; }, "accessor"},
        {"missing buffer file", [](gltf_writer& w) { w.doc["buffers"] = {{{"byteLength", 84}, {"uri", "gone.bin"}}}; }, "gone.bin: no such file"},
        {"missing bufferView", [](gltf_writer& w) { w.doc["accessors"][1]["bufferView"] = 9; }, "bufferView 9 does not exist"},
        {"sparse accessor", [](gltf_writer& w) { w.doc["accessors"][0]["sparse"] = {{"count", 1}, {"indices", {{"bufferView", 2}, {"componentType", 5123}}}, {"values", {{"bufferView", 0}}}}; }, "sparse accessors are not supported"},
        {"bad stride", [](gltf_writer& w) { w.doc["bufferViews"][0]["byteStride"] = 8; }, "bufferViews[0]: byteStride 8 does not fit 12-byte elements"},
        {"unknown mode", [](gltf_writer& w) { w.doc["meshes"][0]["primitives"][0]["mode"] = 7; }, "meshes[0].primitives[0].mode: 7"},
        {"list not of triples", [](gltf_writer& w) { w.doc["accessors"][2]["count"] = 2; }, "2 indices, not a multiple of 3"},
        {"no POSITION", [](gltf_writer& w) { w.doc["meshes"][0]["primitives"][0]["attributes"].erase("POSITION"); }, "attributes: no POSITION"},
        {"normals short", [](gltf_writer& w) { w.doc["accessors"][1]["count"] = 2; }, "NORMAL: 2 normals for 3 positions"},
        {"node cycle", [](gltf_writer& w) { w.doc["nodes"][0]["children"] = {0}; }, "nodes[0]: reached twice"},
        {"missing child", [](gltf_writer& w) { w.doc["nodes"][0]["children"] = {5}; }, "node 5 does not exist"},
        {"missing mesh", [](gltf_writer& w) { w.doc["nodes"][0]["mesh"] = 3; }, "nodes[0].mesh: mesh 3 does not exist"},
        {"missing material", [](gltf_writer& w) { w.doc["meshes"][0]["primitives"][0]["material"] = 2; }, "material 2 does not exist"},
        {"base colour above 1", [](gltf_writer& w) { w.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {2, 0, 0, 1}; }, "materials[0].pbrMetallicRoughness.baseColorFactor: expected 4 numbers in [0, 1]"},
        {"negative emission", [](gltf_writer& w) { w.doc["materials"][0]["emissiveFactor"] = {-1, 0, 0}; }, "materials[0].emissiveFactor"},
        {"zero quaternion", [](gltf_writer& w) { w.doc["nodes"][0]["rotation"] = {0, 0, 0, 0}; }, "nodes[0].rotation: a zero quaternion"},
        {"short matrix", [](gltf_writer& w) { w.doc["nodes"][0]["matrix"] = {1, 0, 0}; }, "nodes[0].matrix: expected 16 finite numbers"},
        {"missing camera", [](gltf_writer& w) { w.doc["nodes"][0]["camera"] = 0; }, "nodes[0].camera: camera 0 does not exist"},
        {"zero fov", [](gltf_writer& w) { w.push("cameras", {{"type", "perspective"}, {"perspective", {{"yfov", 0}, {"znear", 1}}}}); w.doc["nodes"][0]["camera"] = 0; }, "cameras[0].perspective.yfov"},
        {"missing light", [](gltf_writer& w) { w.doc["nodes"][0]["extensions"]["KHR_lights_punctual"]["light"] = 0; }, "light 0 does not exist"},
        {"inverted spot cones", [](gltf_writer& w) { w.use_lights({{{"type", "spot"}, {"spot", {{"innerConeAngle", 0.5}, {"outerConeAngle", 0.4}}}}}); w.doc["nodes"][0]["extensions"]["KHR_lights_punctual"]["light"] = 0; }, "lights[0].spot: expected 0 <= innerConeAngle < outerConeAngle"},
        {"missing scene", [](gltf_writer& w) { w.doc["scene"] = 3; }, "scene: 3 does not exist"},
        {"required extension", [](gltf_writer& w) { w.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"}; }, "extensionsRequired: 'KHR_draco_mesh_compression' is not supported"},
        {"version 1", [](gltf_writer& w) { w.doc["asset"]["version"] = "1.0"; }, "asset.version '1.0'"},
        {"no triangles", [](gltf_writer& w) { w.doc["meshes"][0]["primitives"][0]["mode"] = 0; }, "no triangles"},
        {"missing texture", [](gltf_writer& w) { w.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 4}}; }, "baseColorTexture: texture 4 does not exist"},
    };
    return cases;
}

}  // namespace

TEST_CASE("bad glTF files name the file, the glTF object and the fault", "[io][gltf][bad-input]") {
    scratch_folder dir;
    for (const bool binary : {false, true}) {
        REQUIRE_NOTHROW(good().write(dir.path() / (binary ? "good.glb" : "good.gltf")));
        REQUIRE_NOTHROW(io::load_gltf(dir.path() / (binary ? "good.glb" : "good.gltf")));
        for (const bad_case& c : bad_cases()) {
            const std::filesystem::path file = dir.path() / (c.name + (binary ? ".glb" : ".gltf"));
            gltf_writer w = good();
            c.damage(w);
            // A buffer named by the test keeps its uri: write the JSON as it is.
            if (w.doc.contains("buffers")) {
                const std::string text = w.doc.dump();
                dir.write(file.filename().string(), text);
                if (binary) continue;  // the same file as .gltf; a GLB needs its chunk layout
            } else {
                w.write(file);
            }
            CAPTURE(c.name, binary);
            try {
                io::load_gltf(file);
                FAIL("no scene_error");
            } catch (const io::scene_error& e) {
                CHECK_THAT(e.what(), Catch::Matchers::Contains(c.expected));
                CHECK_FALSE(e.file().empty());
            }
        }
    }
}

TEST_CASE("bad glTF containers and JSON: GLB header and chunks, syntax with its line, nesting", "[io][gltf][bad-input]") {
    scratch_folder dir;
    const std::string glb = good().glb_bytes();
    const auto fails_with = [&](const std::string& name, const std::string& bytes, const std::string& expected, std::size_t line = 0) {
        CAPTURE(name);
        const auto file = dir.write(name, bytes);
        try {
            io::load_gltf(file);
            FAIL("no scene_error");
        } catch (const io::scene_error& e) {
            CHECK_THAT(e.what(), Catch::Matchers::Contains(expected));
            CHECK(e.file() == file);
            CHECK(e.line() == line);
        }
    };
    fails_with("truncated.glb", glb.substr(0, glb.size() - 5), "the header gives");
    fails_with("magic.glb", "GLTF" + glb.substr(4), "does not start with the magic");
    std::string long_json = glb;
    long_json[12] = char(0xff);
    fails_with("chunk.glb", long_json, "the JSON chunk's length");
    fails_with("short.glb", "glTF\x02", "shorter than a header");
    fails_with("syntax.gltf", "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [,]\n}", "JSON", 3);
    fails_with("deep.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"extras\": " + std::string(100, '[') + std::string(100, ']') + "}",
               "nested deeper than 64 levels");
    fails_with("empty.gltf", "", "empty file");
    fails_with("not_json.gltf", "solid cube\nfacet normal 0 0 1\n", "JSON", 1);
    CHECK_THROWS_AS(io::load_gltf(dir.path()), io::scene_error);  // a folder is not a regular file
}

namespace {
const std::vector<std::string> damage_tokens = {"-1", "0", "1e39", "99999", "\"", "{", "]", ",", std::string(1, '\0'), "nan", "5126", "\"mode\":5,"};
}  // namespace

TEST_CASE("randomly damaged .gltf and .glb files load or raise scene_error, nothing else", "[io][gltf][bad-input]") {
    const std::uint64_t seed = GENERATE(range<std::uint64_t>(0, 200));
    pcg32 rng(seed);
    scratch_folder dir;
    const bool binary = seed % 2 == 1;
    const gltf_writer w = good();
    const auto file = dir.write(binary ? "d.glb" : "d.gltf", test::damage(binary ? w.glb_bytes() : w.gltf_text(), rng, damage_tokens));
    try {
        const io::scene s = io::load_gltf(file);
        bounce::test::check_mesh_invariants(s);
    } catch (const io::scene_error& e) {
        CHECK_FALSE(e.file().empty());
    }
}
