// Bad scene files of every kind raise io::scene_error naming the right file and line (OBJ,
// MTL, JSON syntax) or field (JSON content); random damage to good files never gets
// anything else out of the loader.
#include "mesh_invariants.hpp"
#include "random_damage.hpp"
#include "scratch_folder.hpp"

#include <bounce/io/scene.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <string>
#include <vector>

using namespace bounce;
using bounce::test::scratch_folder;
using Catch::Matchers::Contains;
using json = nlohmann::json;
using namespace std::string_literals;

namespace {

const std::string good_obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";  // a face on line 4

json good_scene() {
    return json::parse(R"({
      "obj": "m.obj",
      "default_material": { "kd": [0.5, 0.5, 0.5] },
      "camera": { "position": [0, 0, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 45 },
      "lights": [ { "type": "spot", "position": [0, 0, 2], "direction": [0, 0, -1],
                    "intensity": [1, 1, 1], "cone_deg": 60, "falloff": "cosine" } ],
      "use_emission": false
    })");
}

struct bad_case {
    std::string name;
    std::vector<std::pair<std::string, std::string>> files;  // name, content
    std::string load;    // what to load, relative to the folder
    std::string blamed;  // the file the error must name
    std::size_t line;    // the line it must name (0: none)
    std::string text;    // what its message must contain (the field, for JSON content)
};

// A scene.json made from the good one by `edit`, with a good OBJ beside it.
template <class Edit>
bad_case json_case(std::string name, Edit edit, std::string text) {
    json j = good_scene();
    edit(j);
    return {std::move(name), {{"scene.json", j.dump(2)}, {"m.obj", good_obj}}, "scene.json", "scene.json", 0, std::move(text)};
}

// The good scene.json with `obj` as its OBJ.
bad_case obj_case(std::string name, std::string obj, std::size_t line, std::string text) {
    return {std::move(name), {{"scene.json", good_scene().dump(2)}, {"m.obj", std::move(obj)}}, "scene.json", "m.obj", line,
            std::move(text)};
}

// An OBJ using m.mtl, loaded alone.
bad_case mtl_case(std::string name, std::string mtl, std::size_t line, std::string text) {
    return {std::move(name),
            {{"m.obj", "mtllib m.mtl\n" + good_obj + "usemtl a\nf 1 2 3\n"}, {"m.mtl", std::move(mtl)}},
            "m.obj",
            "m.mtl",
            line,
            std::move(text)};
}

std::vector<bad_case> bad_cases() {
    std::vector<bad_case> c;
    // --- OBJ files ---
    c.push_back({"missing OBJ", {{"scene.json", [] {
                                      json j = good_scene();
                                      j["obj"] = "nothere.obj";
                                      return j.dump(2);
                                  }()}},
                 "scene.json", "nothere.obj", 0, "no such file"});
    c.push_back({"OBJ is a folder", {{"scene.json", [] {
                                          json j = good_scene();
                                          j["obj"] = ".";
                                          return j.dump(2);
                                      }()}},
                 "scene.json", ".", 0, "not a regular file"});
    c.push_back(obj_case("empty OBJ", "", 0, "empty file"));
    c.push_back(obj_case("OBJ without faces", "# nothing\n\nv 0 0 0\n", 0, "no faces"));
    c.push_back(obj_case("truncated vertex", "v 0 0 0\nv 1 0", 2, "v: expected 3"));
    c.push_back(obj_case("keyword alone", "v 0 0 0\nv\n", 2, "v: expected 3"));
    c.push_back(obj_case("non-numeric coordinate", "v 0 0 0\nv 1 abc 0\nv 0 1 0\nf 1 2 3\n", 2, "v: expected 3 finite numbers"));
    c.push_back(obj_case("coordinate with a tail", "v 0 0 0\nv 1 0 0\nv 0 1x 0\nf 1 2 3\n", 3, "v: expected 3"));
    c.push_back(obj_case("NaN coordinate", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 1, "finite"));
    c.push_back(obj_case("coordinate beyond float", "v 1e39 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 1, "finite"));
    // A vertex at 1e30 was dropped as "degenerate" before: it is out of range, and said so.
    c.push_back(obj_case("coordinate beyond what rays carry", "v 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n", 2,
                         "v: coordinate 1e30 beyond +-1e18"));
    c.push_back(obj_case("face index past the end", good_obj + "f 1 2 4\n", 5, "refers to vertex 4 but the file has 3"));
    c.push_back(obj_case("face index zero", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", 4, "index 0"));
    c.push_back(obj_case("relative index before the first vertex", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", 4,
                         "reaches before the first"));
    c.push_back(obj_case("two-vertex face", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", 4, "at least 3 vertices"));
    c.push_back(obj_case("four-part face vertex", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", 4, "expected v, v/vt"));
    c.push_back(obj_case("word as index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 two 3\n", 4, "not an integer"));
    c.push_back(obj_case("empty normal index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1// 2//1 3//1\n", 5,
                         "not an integer"));
    c.push_back(obj_case("normal index past the end", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n", 5,
                         "refers to normal 2 but the file has 1"));
    c.push_back(obj_case("texcoord index past the end", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/7 3/1\n", 5,
                         "refers to texcoord 7"));
    c.push_back(obj_case("word as normal", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 up 1\nf 1//1 2//1 3//1\n", 4, "vn: expected 3"));
    c.push_back(obj_case("NUL byte", "v 0 0 0\nv 1 0\0 0\nv 0 1 0\nf 1 2 3\n"s, 2, "NUL byte"));
    c.push_back(obj_case("binary garbage", "\x89PNG\r\n\x1a\n\0\0\0\rIHDR"s, 3, "NUL byte"));
    c.push_back(obj_case("CRLF file cut inside a face", "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2", 4, "at least 3"));
    c.push_back(obj_case("only degenerate faces", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", 0, "every face is degenerate"));
    {
        std::string big = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
        for (int i = 0; i < 300; ++i) big.append(" ").append(std::to_string(1 + i % 3));
        c.push_back(obj_case("face with 300 vertices", big + "\n", 4, "at most 256"));
    }
    // Refused at its first vertex (before, only when framing it overflowed float).
    c.push_back({"OBJ alone too large for float32 rays",
                 {{"m.obj", "v -3e38 0 0\nv 3e38 0 0\nv 0 3e38 0\nf 1 2 3\n"}},
                 "m.obj",
                 "m.obj",
                 1,
                 "v: coordinate -3e38 beyond +-1e18"});
    // --- MTL files ---
    c.push_back({"missing MTL",
                 {{"m.obj", "# header\nmtllib missing.mtl\n" + good_obj}},
                 "m.obj",
                 "missing.mtl",
                 0,
                 "no such file (named by mtllib on line 2 of m.obj)"});
    c.push_back({"usemtl naming no material",
                 {{"m.obj", "mtllib m.mtl\n" + good_obj + "usemtl stone\nf 1 2 3\n"}, {"m.mtl", "newmtl a\nKd 1 1 1\n"}},
                 "m.obj",
                 "m.obj",
                 6,
                 "usemtl 'stone'"});
    c.push_back(mtl_case("Kd with two numbers", "newmtl a\nKd 0.5 0.5\n", 2, "Kd: expected 3 numbers"));
    c.push_back(mtl_case("Kd above one", "newmtl a\nKd 0.5 1.5 0.5\n", 2, "Kd: expected 3 numbers in [0, 1]"));
    c.push_back(mtl_case("Kd spectral", "newmtl a\nKd spectral file.rfl\n", 2, "Kd: expected 3 numbers"));
    c.push_back(mtl_case("negative Ke", "newmtl a\nKd 1 1 1\nKe 1 -1 1\n", 3, "Ke: expected 3 finite numbers >= 0"));
    c.push_back(mtl_case("empty MTL", "", 0, "empty file"));
    c.push_back(mtl_case("MTL without newmtl", "Kd 1 1 1\n", 0, "no material (newmtl)"));
    c.push_back(mtl_case("newmtl without a name", "newmtl\nKd 1 1 1\n", 1, "newmtl: expected a material name"));
    // --- scene.json: files and syntax ---
    c.push_back({"missing scene.json", {}, "nothere.json", "nothere.json", 0, "no such file"});
    c.push_back({"empty scene.json", {{"scene.json", ""}}, "scene.json", "scene.json", 0, "empty file"});
    {
        const std::string text = good_scene().dump(2);
        // Cut in the middle of line 9: the parser meets the end there.
        std::size_t pos = 0;
        for (int k = 0; k < 8; ++k) pos = text.find('\n', pos) + 1;
        const std::string cut = text.substr(0, pos + 6);
        c.push_back({"truncated scene.json", {{"scene.json", cut}, {"m.obj", good_obj}}, "scene.json", "scene.json", 9, "JSON"});
        std::string broken = text;
        const std::size_t line3 = broken.find('\n', broken.find('\n') + 1) + 1;
        broken[broken.find(':', line3)] = '=';
        c.push_back({"syntax error on line 3", {{"scene.json", broken}, {"m.obj", good_obj}}, "scene.json", "scene.json", 3,
                     "syntax error"});
    }
    c.push_back({"top level is an array", {{"scene.json", "[1, 2]"}}, "scene.json", "scene.json", 0, "expected a JSON object"});
    {
        std::string deep = "{\"obj\": ";
        for (int i = 0; i < 200; ++i) deep += "[";
        c.push_back({"deep nesting", {{"scene.json", deep}}, "scene.json", "scene.json", 0, "nested deeper"});
    }
    // --- scene.json: fields ---
    c.push_back(json_case("unknown top field", [](json& j) { j["lightz"] = json::array(); }, "lightz: unknown field"));
    c.push_back(json_case("missing obj", [](json& j) { j.erase("obj"); }, "obj: missing"));
    c.push_back(json_case("obj not a string", [](json& j) { j["obj"] = 3; }, "obj: expected a string"));
    c.push_back(json_case("missing camera", [](json& j) { j.erase("camera"); }, "camera: missing"));
    c.push_back(json_case("missing camera.up", [](json& j) { j["camera"].erase("up"); }, "camera.up: missing"));
    for (double fov : {0.0, -5.0, 180.0, 400.0})
        c.push_back(json_case("fov " + std::to_string(fov), [fov](json& j) { j["camera"]["fov_y_deg"] = fov; },
                              "camera.fov_y_deg: must lie in (0, 180)"));
    c.push_back(json_case("fov as a string", [](json& j) { j["camera"]["fov_y_deg"] = "45"; },
                          "camera.fov_y_deg: expected a number"));
    c.push_back(json_case("position of length 2", [](json& j) { j["camera"]["position"] = {1, 2}; },
                          "camera.position: expected 3 numbers"));
    c.push_back(json_case("position beyond float", [](json& j) { j["camera"]["position"] = {1e39, 2, 3}; },
                          "camera.position: expected 3 numbers within +-1e18"));
    // Finite in float, but beyond what Embree's rays carry (an assertion inside Embree before).
    c.push_back(json_case("camera at 1e19", [](json& j) { j["camera"]["position"] = {1e19, 0, 3}; },
                          "camera.position: expected 3 numbers within +-1e18"));
    c.push_back(json_case("look_at at -1e19", [](json& j) { j["camera"]["look_at"] = {0, -1e19, 0}; },
                          "camera.look_at: expected 3 numbers within +-1e18"));
    c.push_back(json_case("light at 1e19", [](json& j) { j["lights"][0]["position"] = {0, 0, 1e19}; },
                          "lights[0].position: expected 3 numbers within +-1e18"));
    c.push_back(json_case("intensity of 1e38", [](json& j) { j["lights"][0]["intensity"] = {1e38, 1, 1}; },
                          "lights[0].intensity: expected 3 numbers in [0, 1e30]"));
    c.push_back(json_case("up along the view", [](json& j) { j["camera"]["up"] = {0, 0, 1}; }, "camera.up:"));
    c.push_back(json_case("look_at on the eye", [](json& j) { j["camera"]["look_at"] = {0, 0, 3}; }, "camera.look_at:"));
    c.push_back(json_case("lights not an array", [](json& j) { j["lights"] = json::object(); },
                          "lights: expected an array"));
    c.push_back(json_case("no light at all", [](json& j) { j["lights"] = json::array(); }, "lights: empty"));
    c.push_back(json_case("light not an object", [](json& j) { j["lights"][0] = 5; }, "lights[0]: expected an object"));
    c.push_back(json_case("unknown light type", [](json& j) { j["lights"][0]["type"] = "area"; },
                          "lights[0].type: unknown light type 'area'"));
    c.push_back(json_case("light type missing", [](json& j) { j["lights"][0].erase("type"); }, "lights[0].type: missing"));
    c.push_back(json_case("light type a number", [](json& j) { j["lights"][0]["type"] = 1; },
                          "lights[0].type: expected a string"));
    c.push_back(json_case("intensity missing", [](json& j) { j["lights"][0].erase("intensity"); },
                          "lights[0].intensity: missing"));
    c.push_back(json_case("intensity with a word", [](json& j) { j["lights"][0]["intensity"] = {"a", 1, 1}; },
                          "lights[0].intensity: expected 3 numbers"));
    c.push_back(json_case("intensity of length 4", [](json& j) { j["lights"][0]["intensity"] = {1, 1, 1, 1}; },
                          "lights[0].intensity: expected 3 numbers"));
    c.push_back(json_case("negative intensity", [](json& j) { j["lights"][0]["intensity"] = {1, -1, 1}; },
                          "lights[0].intensity: expected 3 numbers in [0, 1e30]"));
    c.push_back(json_case("cone of zero", [](json& j) { j["lights"][0]["cone_deg"] = 0; },
                          "lights[0].cone_deg: must lie in (0, 180]"));
    c.push_back(json_case("unknown falloff", [](json& j) { j["lights"][0]["falloff"] = "linear"; },
                          "lights[0].falloff: unknown falloff 'linear'"));
    c.push_back(json_case("falloff missing", [](json& j) { j["lights"][0].erase("falloff"); }, "lights[0].falloff: missing"));
    c.push_back(json_case("zero direction", [](json& j) { j["lights"][0]["direction"] = {0, 0, 0}; },
                          "lights[0].direction: expected a non-zero direction"));
    c.push_back(json_case("unknown light field", [](json& j) {
        j["lights"].push_back({{"type", "directional"}, {"direction", {0, -1, 0}}, {"irradiance", {1, 1, 1}}, {"colour", 1}});
    }, "lights[1].colour: unknown field"));
    c.push_back(json_case("point light with a spot field", [](json& j) {
        j["lights"][0] = {{"type", "point"}, {"position", {0, 0, 1}}, {"intensity", {1, 1, 1}}, {"cone_deg", 30}};
    }, "lights[0].cone_deg: unknown field"));
    c.push_back(json_case("irradiance missing", [](json& j) {
        j["lights"][0] = {{"type", "directional"}, {"direction", {0, -1, 0}}};
    }, "lights[0].irradiance: missing"));
    c.push_back(json_case("kd above one", [](json& j) { j["default_material"]["kd"] = {1.5, 0, 0}; },
                          "default_material.kd: expected 3 numbers in [0, 1]"));
    c.push_back(json_case("use_emission a word", [](json& j) { j["use_emission"] = "yes"; },
                          "use_emission: expected true or false"));
    return c;
}

}  // namespace

TEST_CASE("bad scene files raise scene_error naming the file and the line or field", "[io][scene][bad-input]") {
    static const std::vector<bad_case> cases = bad_cases();
    const auto i = GENERATE(range<std::size_t>(0, bad_cases().size()));
    const bad_case& c = cases[i];
    INFO("case: " << c.name);
    scratch_folder dir;
    for (const auto& [name, content] : c.files) dir.write(name, content);
    try {
        const io::scene s = io::load_scene_arg((dir.path() / c.load).string());
        FAIL("loaded without an error: " << s.triangles.size() << " triangles");
    } catch (const io::scene_error& e) {
        INFO("message: " << e.what());
        CHECK(e.file() == dir.path() / c.blamed);
        CHECK(e.line() == c.line);
        CHECK_THAT(e.what(), Contains(c.text));
        // The message names the file, and the line when there is one.
        CHECK_THAT(e.what(), Contains((dir.path() / c.blamed).string()));
        if (c.line) CHECK_THAT(e.what(), Contains(std::string(":").append(std::to_string(c.line)).append(":")));
    }
}

TEST_CASE("an empty --scene argument is a scene_error", "[io][scene][bad-input]") {
    CHECK_THROWS_AS(io::load_scene_arg(""), io::scene_error);
}

namespace {
// Damages `text` at random: flips, deletions, duplications, and insertions of the tokens
// that trouble OBJ and JSON readers.
std::string damage(std::string text, pcg32& rng) {
    static const std::vector<std::string> tokens = {"-",   "0",  "/",    "//",   "\r",   std::string(1, '\0'),
                                                    "1e39", "nan", "f ",   "v ",   "vn ",  "usemtl x\n",
                                                    "\n",  "-99", "999999999999", "mtllib m.mtl\n", "{", "]", "\"", ","};
    return bounce::test::damage(std::move(text), rng, tokens);
}

const char* cornell_like_obj =
    "mtllib m.mtl\r\nv -1 0 1\r\nv 1 0 1\r\nv 1 0 -1\r\nv -1 0 -1\r\nusemtl white\r\ng floor\r\nf -4 -3 -2 -1\r\n"
    "v -1 2 1\r\nv -1 2 -1\r\nv 1 2 -1\r\nv 1 2 1\r\nvn 0 -1 0\r\nvn 0 0 0\r\nusemtl lamp\r\n"
    "f -4//1 -3//2 -2//1 -1//1\r\nf 1 2 3\r\n";
const char* cornell_like_mtl = "newmtl white\nKd 0.7 0.7 0.7\nKe 0 0 0\nnewmtl lamp\nKd 0.8 0.8 0.8\nKe 17 12 4\n";
}  // namespace

TEST_CASE("randomly damaged OBJ, MTL and JSON files load or raise scene_error, nothing else", "[io][scene][bad-input]") {
    const std::uint64_t seed = GENERATE(range<std::uint64_t>(0, 300));
    pcg32 rng(seed);
    scratch_folder dir;
    const int target = int(seed % 3);  // which file to damage
    const std::string scene_text = good_scene().dump(2);
    dir.write("scene.json", target == 0 ? damage(scene_text, rng) : scene_text);
    dir.write("m.obj", target == 1 ? damage(cornell_like_obj, rng) : cornell_like_obj);
    dir.write("m.mtl", target == 2 ? damage(cornell_like_mtl, rng) : cornell_like_mtl);
    try {
        const io::scene s = io::load_scene(dir.path() / "scene.json");
        bounce::test::check_mesh_invariants(s);
    } catch (const io::scene_error& e) {
        // Every fault names a file: one of the three, or one a damaged name points to.
        CHECK_FALSE(e.file().empty());
    }
}
