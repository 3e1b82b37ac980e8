// The built-in Cornell box against its published data: a watertight shell open only at the
// front and under the blocks, every face looking at the air, the published reflectances
// and camera, and a spot light carrying the area light's power.
#include "mesh_invariants.hpp"

#include <bounce/io/scene.hpp>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <tuple>
#include <variant>

using namespace bounce;

namespace {

using point = std::tuple<float, float, float>;
point key(glm::vec3 p) { return {p.x, p.y, p.z}; }
glm::vec3 mm(float x, float y, float z) { return glm::vec3(x, y, z) * 1e-3f; }

// Distance along the ray o + t d to triangle (a, b, c), t > tmin (Moller-Trumbore).
std::optional<double> hit(glm::dvec3 o, glm::dvec3 d, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, double tmin) {
    const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-18) return std::nullopt;
    const glm::dvec3 s = o - a;
    const double u = glm::dot(s, p) / det;
    if (u < 0 || u > 1) return std::nullopt;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(d, q) / det;
    if (v < 0 || u + v > 1) return std::nullopt;
    const double t = glm::dot(e2, q) / det;
    return t > tmin ? std::optional<double>(t) : std::nullopt;
}

double area(const io::scene& s, std::size_t t) {
    const auto tri = s.triangles[t];
    const glm::dvec3 a(s.positions[tri.x]), b(s.positions[tri.y]), c(s.positions[tri.z]);
    return 0.5 * glm::length(glm::cross(b - a, c - a));
}

}  // namespace

TEST_CASE("the Cornell box is one shell, open only at the front and under the blocks", "[io][cornell]") {
    const io::scene s = io::cornell_box();
    bounce::test::check_mesh_invariants(s);
    // 4 walls x 2, ceiling frame 8, light 2, blocks 2 x 5 faces x 2.
    CHECK(s.triangles.size() == 38);
    // Count each directed edge by its end points.
    std::map<std::pair<point, point>, int> directed;
    for (const auto& t : s.triangles) {
        const glm::vec3 p[3] = {s.positions[t.x], s.positions[t.y], s.positions[t.z]};
        for (int k = 0; k < 3; ++k) ++directed[{key(p[k]), key(p[(k + 1) % 3])}];
    }
    // An inner edge is walked once each way (a consistently oriented, crack-free surface);
    // a border edge once. The border must be exactly the front opening and the blocks'
    // footprints on the floor (published vertices).
    std::set<std::pair<point, point>> border;
    for (const auto& [e, n] : directed) {
        CHECK(n == 1);  // never the same way twice
        if (!directed.count({e.second, e.first})) border.insert({std::min(e.first, e.second), std::max(e.first, e.second)});
    }
    const auto undirected = [](glm::vec3 a, glm::vec3 b) {
        return std::pair{std::min(key(a), key(b)), std::max(key(a), key(b))};
    };
    std::set<std::pair<point, point>> expected = {
        undirected(mm(552.8f, 0, 0), mm(0, 0, 0)),          // floor front edge
        undirected(mm(0, 0, 0), mm(0, 548.8f, 0)),          // green wall front edge
        undirected(mm(0, 548.8f, 0), mm(556, 548.8f, 0)),   // ceiling front edge
        undirected(mm(556, 548.8f, 0), mm(552.8f, 0, 0)),   // red wall front edge
    };
    const glm::vec3 short_foot[4] = {mm(130, 0, 65), mm(82, 0, 225), mm(240, 0, 272), mm(290, 0, 114)};
    const glm::vec3 tall_foot[4] = {mm(423, 0, 247), mm(265, 0, 296), mm(314, 0, 456), mm(472, 0, 406)};
    for (int k = 0; k < 4; ++k) {
        expected.insert(undirected(short_foot[k], short_foot[(k + 1) % 4]));
        expected.insert(undirected(tall_foot[k], tall_foot[(k + 1) % 4]));
    }
    CHECK(border == expected);
}

TEST_CASE("every Cornell box face looks at the air", "[io][cornell]") {
    // From a point of a triangle along its normal, the first surface met must face back at
    // the ray, or the ray must leave through the open front (z = 0 inside the opening):
    // then the point sees the air. A face turned the wrong way sees no air from any point
    // (it looks into a wall, a block, or out of the box). The floor runs on under the
    // blocks (as in the published data), so a point of it may be hidden: we require that
    // most of 21 points spread over each triangle see the air. The hidden part of a floor
    // triangle is a block footprint, under 40% of its area.
    const io::scene s = io::cornell_box();
    const auto t = GENERATE(range<std::size_t>(0, 38));
    const auto tri = s.triangles[t];
    const glm::dvec3 a(s.positions[tri.x]), b(s.positions[tri.y]), c(s.positions[tri.z]);
    const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    // The stored vertex normals are the face normal (flat faces), unit length.
    for (unsigned v : {tri.x, tri.y, tri.z}) CHECK(glm::length(glm::dvec3(s.normals[v]) - n) < 1e-6);
    const auto sees_air = [&](glm::dvec3 o) {
        double nearest = 1e30;
        std::size_t first = s.triangles.size();
        for (std::size_t u = 0; u < s.triangles.size(); ++u) {
            if (u == t) continue;
            const auto q = s.triangles[u];
            // tmin 1e-9 m skips coplanar neighbours touching the origin.
            const auto d = hit(o, n, glm::dvec3(s.positions[q.x]), glm::dvec3(s.positions[q.y]),
                               glm::dvec3(s.positions[q.z]), 1e-9);
            if (d && *d < nearest) {
                nearest = *d;
                first = u;
            }
        }
        if (first < s.triangles.size()) {
            const auto q = s.triangles[first];
            const glm::dvec3 m = glm::cross(glm::dvec3(s.positions[q.y] - s.positions[q.x]),
                                            glm::dvec3(s.positions[q.z] - s.positions[q.x]));
            return glm::dot(m, n) < 0.0;
        }
        if (!(n.z < 0.0)) return false;  // escaping anywhere but towards the camera
        const glm::dvec3 exit = o + n * (-o.z / n.z);
        return exit.x > 0.0 && exit.x < 0.556 && exit.y > 0.0 && exit.y < 0.5488;
    };
    const int N = 6;
    int seen = 0, points = 0;
    for (int i = 0; i < N; ++i)
        for (int j = 0; i + j < N; ++j) {
            const double u = (i + 1.0 / 3.0) / N, v = (j + 1.0 / 3.0) / N;
            seen += sees_air(a + u * (b - a) + v * (c - a)) ? 1 : 0;
            ++points;
        }
    REQUIRE(points == 21);
    CHECK(2 * seen > points);
}

TEST_CASE("the Cornell box has the published reflectances, light and camera", "[io][cornell]") {
    const io::scene s = io::cornell_box();
    CHECK(s.name == "cornell");
    CHECK(s.source.empty());
    std::map<std::string, bounce::material> by_name;
    REQUIRE(s.material_names.size() == s.materials.size());
    for (std::size_t m = 0; m < s.materials.size(); ++m) by_name[s.material_names[m]] = s.materials[m];
    CHECK(by_name.at("white").albedo == glm::vec3(0.725f, 0.71f, 0.68f));
    CHECK(by_name.at("red").albedo == glm::vec3(0.63f, 0.065f, 0.05f));
    CHECK(by_name.at("green").albedo == glm::vec3(0.14f, 0.45f, 0.091f));
    CHECK(by_name.at("light").emission == glm::vec3(17.f, 12.f, 4.f));
    // The red wall is the one at x ~ 556 mm (left as the camera sees it), green at x = 0.
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        const std::string& name = s.material_names[s.material_of[t]];
        const auto tri = s.triangles[t];
        const float x = (s.positions[tri.x].x + s.positions[tri.y].x + s.positions[tri.z].x) / 3.f;
        if (name == "red") CHECK(x > 0.549f);
        if (name == "green") CHECK(x == 0.f);
    }
    // The light quad: 130 x 105 mm at y = 548.8 mm.
    double light_area = 0;
    for (std::size_t t = 0; t < s.triangles.size(); ++t)
        if (s.material_names[s.material_of[t]] == "light") {
            light_area += area(s, t);
            for (unsigned v : {s.triangles[t].x, s.triangles[t].y, s.triangles[t].z}) {
                CHECK(s.positions[v].y == Approx(0.5488f));
                CHECK(s.normals[v] == glm::vec3(0, -1, 0));
            }
        }
    CHECK(light_area == Approx(0.130 * 0.105).epsilon(1e-6));

    // Camera: (278, 273, -800) mm looking along +z; 35 mm lens, 25 mm film.
    CHECK(glm::length(s.camera.position - glm::vec3(0.278f, 0.273f, -0.8f)) < 1e-7f);
    CHECK(glm::length(s.camera.forward() - glm::vec3(0, 0, 1)) < 1e-7f);
    CHECK(s.camera.fov_y_deg == Approx(2 * std::atan(12.5 / 35.0) * 180 / std::numbers::pi).epsilon(1e-6));
    CHECK(s.camera.fov_y_deg == Approx(39.3077).epsilon(1e-5));
    CHECK_NOTHROW(s.camera.validate());
    // It sees the whole opening: each front corner projects inside a square image.
    for (const glm::vec3 corner : {mm(552.8f, 0, 0), mm(0, 0, 0), mm(0, 548.8f, 0), mm(556, 548.8f, 0)}) {
        const glm::vec3 d = corner - s.camera.position;
        const float z = glm::dot(d, s.camera.forward());
        CHECK(std::abs(glm::dot(d, s.camera.right())) / z < s.camera.tan_half_fov());
        CHECK(std::abs(glm::dot(d, s.camera.true_up())) / z < s.camera.tan_half_fov());
    }
    CHECK(s.camera.near_plane < 0.8f);
    CHECK(s.camera.far_plane > 0.8f + 0.5592f);
}

TEST_CASE("the Cornell spot light carries the area light's power", "[io][cornell]") {
    const io::scene s = io::cornell_box();
    CHECK_FALSE(s.use_emission);
    CHECK(s.emissive_triangles().empty());
    REQUIRE(s.lights.size() == 1);
    const auto& spot = std::get<bounce::spot_light>(s.lights[0]);
    CHECK(spot.falloff == bounce::spot_light::falloff_kind::cosine);
    CHECK(spot.cone_deg == 89.f);
    CHECK(spot.direction == glm::vec3(0, -1, 0));
    // Just below the centre of the opening, inside the box.
    CHECK(spot.position.x == Approx(0.278f));
    CHECK(spot.position.z == Approx(0.2795f));
    CHECK(spot.position.y < 0.5488f);
    CHECK(spot.position.y > 0.5488f - 0.002f);

    // Area light: a Lambertian emitter of radiance Ke and area A emits pi Ke A.
    io::scene lit = s;
    lit.use_emission = true;
    const auto emissive = lit.emissive_triangles();
    CHECK(emissive.size() == 2);
    double a = 0;
    for (auto t : emissive) a += area(s, t);
    const glm::dvec3 ke(s.materials[s.material_of[emissive[0]]].emission);
    const glm::dvec3 area_power = std::numbers::pi * ke * a;
    // Cosine spot: int_0^c I0 cos(theta) 2 pi sin(theta) d theta = pi I0 sin^2(c).
    const double c = glm::radians(double(spot.cone_deg));
    const glm::dvec3 spot_power = std::numbers::pi * glm::dvec3(spot.intensity) * std::sin(c) * std::sin(c);
    // They differ by the sliver beyond 89 degrees, cos^2(89 deg) = 3.0e-4 of the power,
    // plus float rounding of I0 (1e-6).
    const double tol = std::cos(c) * std::cos(c) + 1e-6;
    for (int k = 0; k < 3; ++k) CHECK(std::abs(spot_power[k] / area_power[k] - 1.0) <= tol);
}

TEST_CASE("the scene argument cornell is the built-in box", "[io][cornell]") {
    const io::scene a = io::load_scene_arg("cornell"), b = io::cornell_box();
    CHECK(a.positions == b.positions);
    CHECK(a.triangles == b.triangles);
    CHECK(a.lights.size() == b.lights.size());
}
