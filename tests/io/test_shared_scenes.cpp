// The three scenes of ../shared/scenes load as their README describes them, and the scene
// descriptions shipped in docs/scenes are theirs.
#include "../skip.hpp"
#include "mesh_invariants.hpp"

#include <bounce/io/scene.hpp>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <variant>

using namespace bounce;

namespace {
// The folder of a shared scene, or nothing (the test case is skipped, saying why) when the
// shared scenes are not there: tests/CMakeLists.txt sets BOUNCE_SCENES for ctest.
std::optional<std::filesystem::path> shared_scene(const char* folder) {
    const char* env = std::getenv("BOUNCE_SCENES");
    if (!env || !*env) {
        bounce::test::skip(std::string("BOUNCE_SCENES is not set: no shared scene '") + folder + "' (run through ctest)");
        return std::nullopt;
    }
    const auto dir = std::filesystem::path(env) / folder;
    if (!std::filesystem::is_regular_file(dir / "scene.json")) {
        bounce::test::skip("no " + (dir / "scene.json").string() + ": no shared scene '" + folder + "'");
        return std::nullopt;
    }
    return dir;
}

template <class L>
std::size_t count_lights(const io::scene& s) {
    std::size_t n = 0;
    for (const auto& l : s.lights) n += std::holds_alternative<L>(l) ? 1 : 0;
    return n;
}

bool has_warning(const io::scene& s, const char* text) {
    for (const auto& w : s.warnings)
        if (w.find(text) != std::string::npos) return true;
    return false;
}
}  // namespace

TEST_CASE("the shared Cornell box loads: CRLF, relative indices, no normals, usemtl before g", "[io][scene][shared]") {
    const auto dir = shared_scene("cornell-box");
    if (!dir) return;
    const io::scene s = io::load_scene(*dir / "scene.json");
    bounce::test::check_mesh_invariants(s);
    CHECK(s.name == "cornell-box");
    // 18 quads (5 walls, 2 x 6 block faces, the light) of which two repeat an earlier face.
    CHECK(s.triangles.size() == 36);
    CHECK(has_warning(s, "4 triangles repeat"));
    CHECK(s.lights.size() == 1);
    CHECK(count_lights<bounce::spot_light>(s) == 1);
    CHECK_FALSE(s.use_emission);
    CHECK(s.emissive_triangles().empty());
    const auto& spot = std::get<bounce::spot_light>(s.lights[0]);
    CHECK(spot.falloff == bounce::spot_light::falloff_kind::cosine);
    CHECK(spot.cone_deg == 89.f);
    CHECK(spot.direction == glm::vec3(0, -1, 0));
    // Kd per face from the MTL: the left wall is red, the right one green.
    bool red = false, green = false, light = false;
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        const auto& m = s.materials[s.material_of[t]];
        const std::string& name = s.material_names.at(s.material_of[t]);
        red = red || (name == "leftWall" && m.albedo == glm::vec3(0.63f, 0.065f, 0.05f));
        green = green || (name == "rightWall" && m.albedo == glm::vec3(0.14f, 0.45f, 0.091f));
        light = light || (name == "light" && m.emission == glm::vec3(17, 12, 4));
    }
    CHECK(red);
    CHECK(green);
    CHECK(light);
    CHECK(s.camera.fov_y_deg == Approx(39.3f));
}

TEST_CASE("the shared Cornell box OBJ alone lights itself with its Ke face", "[io][scene][shared]") {
    const auto dir = shared_scene("cornell-box");
    if (!dir) return;
    const io::scene s = io::load_scene_arg((*dir / "CornellBox-Original.obj").string());
    bounce::test::check_mesh_invariants(s);
    CHECK(s.use_emission);
    CHECK(s.lights.empty());
    CHECK(s.emissive_triangles().size() == 2);
}

TEST_CASE("Sponza loads with its default material and drops its degenerate triangle with a warning",
          "[io][scene][shared]") {
    const auto dir = shared_scene("sponza");
    if (!dir) return;
    const io::scene s = io::load_scene_arg(dir->string());  // a folder works as --scene
    bounce::test::check_mesh_invariants(s);
    CHECK(s.name == "sponza");
    // 66,454 triangles in the file, one of zero area.
    CHECK(s.triangles.size() == 66453);
    CHECK(has_warning(s, "dropped 1 degenerate"));
    CHECK(has_warning(s, "zero or not finite"));
    REQUIRE(s.materials.size() == 1);
    CHECK(s.materials[0].albedo == glm::vec3(0.627f, 0.573f, 0.561f));
    CHECK(count_lights<bounce::directional_light>(s) == 1);
    CHECK(count_lights<bounce::point_light>(s) == 1);
    // Directions are stored unit length.
    const auto& sun = std::get<bounce::directional_light>(s.lights[0]);
    CHECK(glm::length(sun.direction) == Approx(1.f).epsilon(1e-6));
}

TEST_CASE("the bunny loads with smooth normals computed from its faces", "[io][scene][shared]") {
    const auto dir = shared_scene("bunny");
    if (!dir) return;
    const io::scene s = io::load_scene(*dir / "scene.json");
    bounce::test::check_mesh_invariants(s);
    CHECK(s.triangles.size() == 69451);
    CHECK(s.lights.size() == 1);
    CHECK(count_lights<bounce::directional_light>(s) == 1);
    // No vn in the file: the positions are shared, so each appears once.
    CHECK(s.positions.size() < s.triangles.size());
    // Each normal is the area-weighted mean of its faces' normals, sum(e1 x e2) normalized
    // (|e1 x e2| is twice the area). Both sides are computed in double from the same float
    // positions and rounded to float: they agree to a few float ulp, unless the sum nearly
    // cancels, which the ratio |sum| / sum|e1 x e2| > 1e-3 excludes.
    std::vector<glm::dvec3> sum(s.positions.size(), glm::dvec3(0.0));
    std::vector<double> total(s.positions.size(), 0.0);
    for (const auto& t : s.triangles) {
        const glm::dvec3 a(s.positions[t.x]), b(s.positions[t.y]), c(s.positions[t.z]);
        const glm::dvec3 n = glm::cross(b - a, c - a);
        for (unsigned v : {t.x, t.y, t.z}) {
            sum[v] += n;
            total[v] += glm::length(n);
        }
    }
    std::size_t checked = 0, off = 0;
    for (std::size_t v = 0; v < sum.size(); ++v) {
        if (!(glm::length(sum[v]) > 1e-3 * total[v])) continue;
        ++checked;
        off += glm::dot(glm::dvec3(s.normals[v]), glm::normalize(sum[v])) > 1.0 - 1e-6 ? 0 : 1;
    }
    CHECK(checked > s.positions.size() * 99 / 100);
    CHECK(off == 0);
}

TEST_CASE("the scene descriptions shipped in docs/scenes are the shared scenes' own", "[io][scene][shared]") {
    const char* folder = GENERATE("cornell-box", "sponza", "bunny");
    const auto dir = shared_scene(folder);
    if (!dir) return;
    const auto read = [](const std::filesystem::path& file) {
        std::ifstream in(file, std::ios::binary);
        REQUIRE(in);
        return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    };
    const auto shipped = std::filesystem::path(BOUNCE_SOURCE_DIR) / "docs" / "scenes" / folder / "scene.json";
    INFO(shipped.string());
    CHECK(read(shipped) == read(*dir / "scene.json"));
}

TEST_CASE("a shipped scene description without its mesh is refused naming the mesh", "[io][scene]") {
    // The descriptions are checked before the OBJ is read, so a missing mesh (the repository
    // holds none) is the only fault left: each description is valid scene.json.
    const char* folder = GENERATE("cornell-box", "sponza", "bunny");
    const auto shipped = std::filesystem::path(BOUNCE_SOURCE_DIR) / "docs" / "scenes" / folder / "scene.json";
    INFO(shipped.string());
    try {
        (void)io::load_scene(shipped);
        SUCCEED("the mesh is there (put beside it by the reader)");
    } catch (const io::scene_error& e) {
        CHECK(e.file().extension() == ".obj");
        CHECK(e.line() == 0);
    }
}
