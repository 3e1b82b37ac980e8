// OBJ+MTL loading on small files whose mesh is known in closed form: smooth normals are
// area-weighted, vertices are shared by (position, normal), given normals are normalized
// or replaced, materials come from Kd/Ke, and line endings and relative indices do not
// change the mesh.
#include "mesh_invariants.hpp"
#include "scratch_folder.hpp"
#include "../scoped_environment.hpp"

#include <bounce/io/scene.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <sstream>
#include <string>

using namespace bounce;
using bounce::test::scratch_folder;

namespace {
std::string fmt3(double x, double y, double z) {
    std::ostringstream s;
    s.precision(17);
    s << x << ' ' << y << ' ' << z;
    return s.str();
}

// The normal of the vertex nearest to `p` (tinyobjloader's number parsing is not
// correctly rounded, so positions may differ from `p` in the last bit), or nullptr when
// no vertex is within 1e-5.
const glm::vec3* normal_at(const io::scene& s, glm::vec3 p) {
    const glm::vec3* best = nullptr;
    float best_d = 1e-5f;
    for (std::size_t v = 0; v < s.positions.size(); ++v)
        if (const float d = glm::length(s.positions[v] - p); d <= best_d) {
            best_d = d;
            best = &s.normals[v];
        }
    return best;
}

double total_area(const io::scene& s) {
    double a = 0;
    for (const auto& t : s.triangles) {
        const glm::dvec3 p0(s.positions[t.x]), p1(s.positions[t.y]), p2(s.positions[t.z]);
        a += 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
    }
    return a;
}

bool has_warning(const io::scene& s, const char* text) {
    for (const auto& w : s.warnings)
        if (w.find(text) != std::string::npos) return true;
    return false;
}
}  // namespace

TEST_CASE("the apex of a square pyramid gets the axis as its smooth normal", "[io][obj][normals]") {
    // Four congruent faces around the apex: their area-weighted mean normal is the axis by
    // symmetry, whatever the height. Tolerance: a few float roundings of O(1) values.
    pcg32 rng(3);
    const int i = GENERATE(range(0, 50));
    const double h = i == 0 ? 1e-3 : i == 1 ? 1e3 : 0.01 + 10.0 * rng.next_double() * (i + 1) / 50.0;
    scratch_folder dir;
    const auto obj = dir.write("pyramid.obj", "v 1 1 0\nv -1 1 0\nv -1 -1 0\nv 1 -1 0\nv 0 0 " + std::to_string(h) +
                                                  "\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n");
    const io::scene s = io::load_obj(obj);
    bounce::test::check_mesh_invariants(s);
    REQUIRE(s.triangles.size() == 4);
    REQUIRE(s.positions.size() == 5);  // no vn: one vertex per position
    const auto top = std::max_element(s.positions.begin(), s.positions.end(),
                                      [](const glm::vec3& p, const glm::vec3& q) { return p.z < q.z; });
    const glm::vec3* apex = &s.normals[std::size_t(top - s.positions.begin())];
    CHECK(std::abs(apex->x) < 1e-6f);
    CHECK(std::abs(apex->y) < 1e-6f);
    CHECK(apex->z == Approx(1.f).epsilon(1e-6));
}

TEST_CASE("a vertex shared by two faces of different areas leans towards the larger", "[io][obj][normals]") {
    // Face 1 in z = 0 with legs a: normal +z, |e1 x e2| = a^2. Face 2 in x = 0 with legs b:
    // normal +x, |e1 x e2| = b^2. At the shared origin, n = normalize(b^2, 0, a^2).
    pcg32 rng(17);
    const int i = GENERATE(range(0, 100));
    (void)i;
    const double a = 0.01 + 5 * rng.next_double(), b = 0.01 + 5 * rng.next_double();
    scratch_folder dir;
    const auto obj = dir.write("corner.obj", "v 0 0 0\nv " + fmt3(a, 0, 0) + "\nv " + fmt3(0, a, 0) + "\nv " +
                                                 fmt3(0, b, 0) + "\nv " + fmt3(0, 0, b) + "\nf 1 2 3\nf 1 4 5\n");
    const io::scene s = io::load_obj(obj);
    bounce::test::check_mesh_invariants(s);
    const glm::vec3* n = normal_at(s, {0.f, 0.f, 0.f});
    REQUIRE(n);
    // a and b are rounded to float in the mesh; relative 1e-6 covers that and the sums.
    const glm::dvec3 expected = glm::normalize(glm::dvec3(float(b) * double(float(b)), 0.0, float(a) * double(float(a))));
    CHECK(glm::length(glm::dvec3(*n) - expected) < 1e-6);
    // The other vertices belong to one face each: their normal is that face's.
    CHECK(*normal_at(s, {float(a), 0.f, 0.f}) == glm::vec3(0, 0, 1));
    CHECK(*normal_at(s, {0.f, 0.f, float(b)}) == glm::vec3(1, 0, 0));
}

TEST_CASE("vertices are shared by (position, normal) pairs", "[io][obj]") {
    scratch_folder dir;
    const std::string v = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 3\n";
    SECTION("one normal: the quad's four corners") {
        const io::scene s = io::load_obj(dir.write("a.obj", v + "f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n"));
        CHECK(s.triangles.size() == 2);
        CHECK(s.positions.size() == 4);
    }
    SECTION("two normals on the shared edge: six vertices") {
        const io::scene s = io::load_obj(dir.write("b.obj", v + "f 1//1 2//1 3//1\nf 1//2 3//2 4//2\n"));
        CHECK(s.triangles.size() == 2);
        CHECK(s.positions.size() == 6);
        // Given normals are normalized: (0, 0, 3) -> (0, 0, 1).
        for (const auto& n : s.normals) CHECK(n == glm::vec3(0, 0, 1));
    }
    SECTION("a quad face is split into two triangles sharing the diagonal") {
        const io::scene s = io::load_obj(dir.write("c.obj", v + "f 1//1 2//1 3//1 4//1\n"));
        CHECK(s.triangles.size() == 2);
        CHECK(s.positions.size() == 4);
        CHECK(total_area(s) == Approx(1.0));
    }
}

TEST_CASE("zero and overflowing vn fall back to the face normal", "[io][obj][normals]") {
    scratch_folder dir;
    // Triangle in the plane x + y + z = 1, counter-clockwise seen from +(1,1,1).
    const std::string tri = "v 1 0 0\nv 0 1 0\nv 0 0 1\n";
    const glm::vec3 face = glm::normalize(glm::vec3(1, 1, 1));
    const std::string bad_normal = GENERATE(as<std::string>{}, "0 0 0", "1e39 0 0", "1e39 1 1", "-0 0 -0", "nan 0 0");
    const io::scene s = io::load_obj(dir.write("t.obj", tri + "vn 0 0 1\nvn " + bad_normal + "\nf 1//1 2//2 3//1\n"));
    bounce::test::check_mesh_invariants(s);
    CHECK(has_warning(s, "1 vertex normal zero or not finite"));
    const glm::vec3* repaired = normal_at(s, {0.f, 1.f, 0.f});
    REQUIRE(repaired);
    CHECK(glm::length(*repaired - face) < 1e-6f);
    CHECK(*normal_at(s, {1.f, 0.f, 0.f}) == glm::vec3(0, 0, 1));  // a good vn is kept
}

TEST_CASE("a convex polygon is triangulated without losing area", "[io][obj]") {
    // Regular n-gon of circumradius 1: area n/2 sin(2 pi / n).
    const int n = GENERATE(3, 4, 5, 7, 16, 64, 256);
    std::string text;
    for (int k = 0; k < n; ++k) {
        const double phi = 2 * std::numbers::pi * k / n;
        text += "v " + fmt3(std::cos(phi), std::sin(phi), 0.0) + "\n";
    }
    text += "f";
    for (int k = 1; k <= n; ++k) text.append(" ").append(std::to_string(k));
    text += "\n";
    scratch_folder dir;
    const io::scene s = io::load_obj(dir.write("ngon.obj", text));
    bounce::test::check_mesh_invariants(s);
    CHECK(s.triangles.size() == std::size_t(n - 2));
    // Float positions: relative error of the area ~ a few float epsilons per triangle.
    CHECK(total_area(s) == Approx(0.5 * n * std::sin(2 * std::numbers::pi / n)).epsilon(1e-5));
    for (const auto& nrm : s.normals) CHECK(nrm == glm::vec3(0, 0, 1));
}

TEST_CASE("line endings and relative indices do not change the mesh", "[io][obj]") {
    const std::string lf = "# cube corner\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n";
    std::string crlf, cr, relative = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf -4 -2 -3\nf -4 -3 -1\nf -4 -1 -2\n";
    for (char c : lf) {
        crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
        cr += c == '\n' ? '\r' : c;
    }
    scratch_folder dir;
    const io::scene ref = io::load_obj(dir.write("lf.obj", lf));
    bounce::test::check_mesh_invariants(ref);
    CHECK(ref.triangles.size() == 3);
    for (const auto& [name, text] : {std::pair{"crlf.obj", crlf}, {"cr.obj", cr}, {"rel.obj", relative},
                                     {"noeol.obj", lf.substr(0, lf.size() - 1)}}) {
        INFO(name);
        const io::scene s = io::load_obj(dir.write(name, text));
        CHECK(s.positions == ref.positions);
        CHECK(s.normals == ref.normals);
        CHECK(s.triangles == ref.triangles);
    }
}

TEST_CASE("materials: Kd is the reflectance, Ke the emission, faces without usemtl get the default",
          "[io][obj][mtl]") {
    scratch_folder dir;
    dir.write("m.mtl",
              "# two materials\r\nnewmtl wall\r\n  Kd 0.5 0.25 0.125 # a comment\r\n  Ke 0 0 0\r\n"
              "newmtl lamp\r\nKd 0.78 0.78 0.78\r\nKe 17 12 4\r\n");
    const auto obj = dir.write("m.obj",
                               "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                               "f 1 2 3\nusemtl wall\nf 2 4 3\nusemtl lamp\nf 1 3 4\n");
    bounce::material fallback;
    fallback.albedo = glm::vec3(0.1f, 0.2f, 0.3f);
    io::scene s = io::load_obj(obj, fallback);
    bounce::test::check_mesh_invariants(s);
    REQUIRE(s.triangles.size() == 3);
    CHECK(s.materials[s.material_of[0]].albedo == fallback.albedo);
    CHECK(s.material_names.at(s.material_of[1]) == "wall");
    CHECK(s.materials[s.material_of[1]].albedo == glm::vec3(0.5f, 0.25f, 0.125f));
    CHECK(s.materials[s.material_of[2]].emission == glm::vec3(17, 12, 4));
    // load_obj turns emission on when a face emits, and adds no other light.
    CHECK(s.use_emission);
    CHECK(s.lights.empty());
    CHECK(s.emissive_triangles() == std::vector<std::uint32_t>{2});
    s.use_emission = false;
    CHECK(s.emissive_triangles().empty());
}

TEST_CASE("usemtl without any mtllib falls back to the default material with a warning", "[io][obj][mtl]") {
    scratch_folder dir;
    const io::scene s = io::load_obj(dir.write("u.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl stone\nf 1 2 3\n"));
    CHECK(s.materials.size() == 1);
    CHECK(has_warning(s, "without mtllib"));
    // No emission: a head light at the camera, E = I / d^2 = 1 at the centre of the bounds.
    REQUIRE(s.lights.size() == 1);
    const auto& l = std::get<bounce::point_light>(s.lights[0]);
    const auto [lo, hi] = s.bounds();
    const float d = glm::length(l.position - 0.5f * (lo + hi));
    CHECK(l.intensity.r / (d * d) == Approx(1.f).epsilon(1e-5));
}

TEST_CASE("zero-area triangles are dropped and counted, not fatal", "[io][obj]") {
    scratch_folder dir;
    // Repeated vertex, collinear vertices, and one good triangle.
    const io::scene s = io::load_obj(
        dir.write("d.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 4\nf 1 2 4\n"));
    CHECK(s.triangles.size() == 1);
    CHECK(has_warning(s, "dropped 2 degenerate"));
}

TEST_CASE("a minimal scene.json loads with its lights, and load_scene_arg finds it", "[io][scene]") {
    scratch_folder dir;
    dir.write("box.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    dir.write("scene.json", R"({
      "obj": "box.obj",
      "default_material": { "kd": [0.2, 0.4, 0.6] },
      "camera": { "position": [0, 0, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 50 },
      "lights": [
        { "type": "point", "position": [0, 0, 1], "intensity": [1, 2, 3] },
        { "type": "spot", "position": [0, 1, 1], "direction": [0, -2, 0], "intensity": [4, 4, 4],
          "cone_deg": 30, "falloff": "none" },
        { "type": "directional", "direction": [0, 0, -5], "irradiance": [1, 1, 1] }
      ],
      "use_emission": false
    })");
    for (const std::string& arg : {(dir.path() / "scene.json").string(), dir.path().string()}) {
        const io::scene s = io::load_scene_arg(arg);
        bounce::test::check_mesh_invariants(s);
        CHECK(s.source == dir.path() / "scene.json");
        CHECK(s.materials.at(0).albedo == glm::vec3(0.2f, 0.4f, 0.6f));
        CHECK(s.camera.fov_y_deg == 50.f);
        REQUIRE(s.lights.size() == 3);
        CHECK(std::get<bounce::point_light>(s.lights[0]).intensity == glm::vec3(1, 2, 3));
        const auto& spot = std::get<bounce::spot_light>(s.lights[1]);
        CHECK(spot.direction == glm::vec3(0, -1, 0));
        CHECK(spot.falloff == bounce::spot_light::falloff_kind::none);
        CHECK(spot.cone_deg == 30.f);
        CHECK(std::get<bounce::directional_light>(s.lights[2]).direction == glm::vec3(0, 0, -1));
        // The clip planes enclose the scene: far reaches past its farthest corner.
        CHECK(s.camera.far_plane > glm::length(s.camera.position - glm::vec3(1, 0, 0)));
    }
}

TEST_CASE("load_scene_arg finds a bare name under scenes_dir, and only where nothing here has it", "[io][scene]") {
    scratch_folder dir;
    dir.write("tri/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    dir.write("tri/scene.json", R"({"obj": "tri.obj",
      "camera": { "position": [0, 0, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 40 },
      "lights": [{ "type": "point", "position": [0, 0, 1], "intensity": [1, 1, 1] }]})");
    const bounce::test::scoped_environment scenes("BOUNCE_SCENES");
    scenes.set(dir.path().string());
    const io::scene s = io::load_scene_arg("tri");
    CHECK(s.source == dir.path() / "tri" / "scene.json");
    CHECK(s.triangles.size() == 1);
    CHECK(io::load_scene_arg("cornell").name == io::cornell_box().name);  // the built-in box still wins
    // A name with no folder there stays a missing file, named as given.
    CHECK_THROWS_AS(io::load_scene_arg("no-such-scene"), io::scene_error);
    CHECK_THROWS_WITH(io::load_scene_arg("no-such-scene"), Catch::Contains("no-such-scene"));
    // A path (not a bare name) is never looked up there.
    CHECK_THROWS_AS(io::load_scene_arg("./tri"), io::scene_error);
}

TEST_CASE("scenes_dir follows BOUNCE_SCENES", "[io][scene]") {
    const bounce::test::scoped_environment scenes("BOUNCE_SCENES");
    scenes.set("/some/where");
    CHECK(io::scenes_dir() == std::filesystem::path("/some/where"));
    scenes.unset();
    CHECK(io::scenes_dir() == std::filesystem::path("../shared/scenes"));
}
