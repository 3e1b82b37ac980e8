// Irradiance volumes (volume/probe_octree.hpp): the octree's invariants, the exact
// triangle-box test against a brute-force clipper, trilinear and gradient-extrapolated
// lookups on linear fields (exact up to float rounding), continuity of the weighted lookup
// across a subdivision boundary, skipped inside probes and bad input.
#include "far_triangle.hpp"

#include <bounce/volume/probe_octree.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>
#include <vector>

using namespace bounce;

namespace {

irradiance_volume_settings uniform_settings(int depth) {
    irradiance_volume_settings s;
    s.min_depth = s.max_depth = depth;
    s.distance_ratio = s.neighbour_change = s.gradient_ratio = s.cull_tolerance = 0;
    s.geometry_triangles = 0;
    return s;
}

// A field whose every SH coefficient is linear in position: c_i(x) = a_i + G_i x, with
// exact gradients.
struct linear_field {
    std::array<glm::vec3, 9> a{};
    std::array<glm::mat3, 9> g{};  // column k: d c_i / d x_k (RGB)
    explicit linear_field(std::uint64_t seed) {
        pcg32 rng(seed);
        for (std::size_t i = 0; i < 9; ++i) {
            a[i] = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * (i == 0 ? 4.f : 0.5f);
            for (int k = 0; k < 3; ++k)
                g[i][k] = glm::vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f);
        }
    }
    irradiance_probe::coefficients at(glm::vec3 x) const {
        irradiance_probe::coefficients c{};
        for (std::size_t i = 0; i < 9; ++i) c[i] = a[i] + g[i] * x;
        return c;
    }
    void operator()(std::span<const glm::vec3> p, std::span<irradiance_probe> out) const {
        for (std::size_t j = 0; j < p.size(); ++j) {
            out[j] = {};
            out[j].position = p[j];
            out[j].radiance = at(p[j]);
            for (std::size_t i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) out[j].gradient[std::size_t(k)][i] = g[i][k];
            out[j].harmonic_mean_distance = 1;
        }
    }
};

glm::vec3 exact_irradiance(const linear_field& f, glm::vec3 p, glm::vec3 n) {
    const auto c = f.at(p);
    std::array<glm::dvec3, 9> cd{};
    for (std::size_t i = 0; i < 9; ++i) cd[i] = glm::dvec3(c[i]);
    return glm::vec3(sh_irradiance<3, double, glm::dvec3>(cd, glm::dvec3(n)));
}

// Bound on float rounding of a lookup: each result is a weighted sum of at most ~60 probe
// irradiances, each a 9-term sum of products of numbers of the field's magnitude M (here
// |c| <= 4 + 3 * 0.5 * 1.5, times A_l Y_l <= pi * 0.28 < 1); about 100 roundings of relative
// size 2^-24 each on terms of size M, so 100 * 6e-8 * M = 6e-6 M. M < 10: 1e-4 absolute.
constexpr float linear_tolerance = 1e-4f;

glm::vec3 random_unit(pcg32& rng) {
    const float z = 2 * rng.next_float() - 1, phi = 6.2831853f * rng.next_float(), r = std::sqrt(std::max(0.f, 1 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
}

// An adaptive octree over [-1, 1]^3 (dyadic: every box coordinate is exact in float):
// cells with x > 0 split to depth 4 through the geometry heuristic (a triangle sheet in
// that half), the rest stay at depth 1-2.
struct adaptive_fixture {
    test::owned_scene scene;
    irradiance_volume_settings settings;
    adaptive_fixture() {
        scene.materials = {material{glm::vec3(0.5f), glm::vec3(0.f)}};
        // Triangles near the plane x = 0.55 (inside the upper-x half only).
        scene.positions = {{0.55f, -0.9f, -0.9f}, {0.55f, 0.9f, -0.9f}, {0.55f, -0.9f, 0.9f}, {0.55f, 0.9f, 0.9f}};
        scene.triangles = {{0, 1, 2}, {1, 3, 2}};
        scene.material_of = {0, 0};
        settings.min_depth = 1;
        settings.max_depth = 4;
        settings.distance_ratio = settings.neighbour_change = settings.gradient_ratio = settings.cull_tolerance = 0;
        settings.prediction_tolerance = 0;  // Oat's heuristics shape this octree
        settings.geometry_triangles = 1;
    }
};

// Brute-force triangle-box overlap: Sutherland-Hodgman clipping of the triangle by the
// box's six closed half-spaces grown by `grow`; overlap iff something remains.
bool clipped_overlap(glm::dvec3 c, glm::dvec3 h, std::array<glm::dvec3, 3> tri, double grow) {
    std::vector<glm::dvec3> poly(tri.begin(), tri.end());
    for (int axis = 0; axis < 3 && !poly.empty(); ++axis)
        for (double sign : {1.0, -1.0}) {
            // keep sign * (x[axis] - c[axis]) <= h[axis] + grow
            const auto inside = [&](const glm::dvec3& p) { return sign * (p[axis] - c[axis]) - h[axis] - grow; };
            std::vector<glm::dvec3> out;
            for (std::size_t i = 0; i < poly.size(); ++i) {
                const glm::dvec3 a = poly[i], b = poly[(i + 1) % poly.size()];
                const double da = inside(a), db = inside(b);
                if (da <= 0) out.push_back(a);
                if ((da < 0 && db > 0) || (da > 0 && db < 0)) out.push_back(a + (b - a) * (da / (da - db)));
            }
            poly = std::move(out);
            if (poly.empty()) break;
        }
    return !poly.empty();
}

}  // namespace

TEST_CASE("triangle-box overlap agrees with clipping on random, touching and degenerate cases", "[irradiance_volume]") {
    pcg32 rng(2001);
    const auto coord = [&](int range) { return double(int(rng.next_u32() % std::uint32_t(2 * range + 1)) - range) / 4; };
    int decided = 0, overlapping = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const glm::dvec3 c(coord(4), coord(4), coord(4));
        const glm::dvec3 h(std::abs(coord(4)) + 0.25, std::abs(coord(4)) + 0.25, std::abs(coord(4)) + 0.25);
        std::array<glm::dvec3, 3> t{glm::dvec3(coord(12), coord(12), coord(12)), glm::dvec3(coord(12), coord(12), coord(12)),
                                    glm::dvec3(coord(12), coord(12), coord(12))};
        if (trial % 5 == 1) t[2] = t[0] + (t[1] - t[0]) * 0.5;  // collinear: a segment
        if (trial % 5 == 2) t[1] = t[2] = t[0];                 // a point
        // Clipping decides only where growing or shrinking the box by far less than the
        // 1/4 grid cannot change its answer; those ambiguous cases (touching) are the
        // explicit ones below.
        const bool grown = clipped_overlap(c, h, t, 1e-7), shrunk = clipped_overlap(c, h, t, -1e-7);
        if (grown != shrunk) continue;
        ++decided;
        overlapping += grown ? 1 : 0;
        INFO("trial " << trial);
        REQUIRE(triangle_box_overlap(c, h, t[0], t[1], t[2]) == grown);
    }
    CHECK(decided > 15000);
    CHECK(overlapping > 1000);  // both answers well represented
    CHECK(decided - overlapping > 1000);

    // Touching exactly (closed sets): a vertex on a face, an edge along a box edge, a
    // triangle in a face's plane, a vertex at a box corner; moved out by 2^-10, apart.
    const glm::dvec3 c(0.0), h(1.0);
    const double gap = 1.0 / 1024;
    const std::vector<std::array<glm::dvec3, 3>> touching = {
        {glm::dvec3(1, 0, 0), glm::dvec3(2, 1, 0), glm::dvec3(2, -1, 0.5)},    // vertex on the +x face
        {glm::dvec3(1, 1, -3), glm::dvec3(1, 1, 3), glm::dvec3(3, 3, 0)},      // edge along the (+x, +y) edge
        {glm::dvec3(-0.5, -0.5, 1), glm::dvec3(0.5, -0.5, 1), glm::dvec3(0, 0.5, 1)},  // in the +z face
        {glm::dvec3(1, 1, 1), glm::dvec3(2, 1, 1), glm::dvec3(1, 2, 1)},        // at the corner
        {glm::dvec3(3, 0, 0), glm::dvec3(0, 3, 0), glm::dvec3(0, 0, 3)},        // plane x + y + z = 3 through a corner
    };
    const std::vector<glm::dvec3> outward = {{1, 0, 0}, {1, 1, 0}, {0, 0, 1}, {1, 1, 1}, {1, 1, 1}};
    for (std::size_t i = 0; i < touching.size(); ++i) {
        INFO("touching case " << i);
        const auto& t = touching[i];
        CHECK(triangle_box_overlap(c, h, t[0], t[1], t[2]));
        const glm::dvec3 d = outward[i] * gap;
        CHECK_FALSE(triangle_box_overlap(c, h, t[0] + d, t[1] + d, t[2] + d));
    }
    // A large triangle whose plane cuts the box although no vertex or edge is near it.
    CHECK(triangle_box_overlap(c, h, {-10, -10, 0}, {10, -10, 0}, {0, 10, 0}));
    // Separated only by an edge-cross-axis: the bounding boxes overlap, the plane cuts the box.
}

TEST_CASE("every point finds exactly one leaf and corner probes are shared", "[irradiance_volume]") {
    adaptive_fixture f;
    const linear_field field(3);
    const auto v = irradiance_volume::build(f.scene, glm::vec3(-1), glm::vec3(1), f.settings, field);
    REQUIRE(v.depth() == 4);
    REQUIRE(v.leaf_count() > 64);
    // Leaves at several depths (the point of an adaptive octree).
    std::map<int, int> depths;
    for (const auto& n : v.nodes())
        if (n.leaf()) ++depths[n.depth];
    CHECK(depths.size() >= 2);

    pcg32 rng(7);
    for (int trial = 0; trial < 3000; ++trial) {
        glm::vec3 p(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
        if (trial % 10 == 0) p.x = 0.f;       // on a splitting plane
        if (trial % 10 == 1) p.x = 0.5f;      // on a deeper splitting plane
        if (trial % 10 == 2) p = glm::vec3(1.f);  // the volume's far corner
        std::vector<std::uint32_t> holding;
        for (std::uint32_t i = 0; i < v.nodes().size(); ++i) {
            const auto& n = v.nodes()[i];
            if (!n.leaf()) continue;
            bool in = true;
            for (int k = 0; k < 3; ++k) {
                const float hi = n.lo[k] + n.size[k];
                in = in && p[k] >= n.lo[k] && (p[k] < hi || (hi == 1.f && p[k] == 1.f));
            }
            if (in) holding.push_back(i);
        }
        INFO("p = " << p.x << " " << p.y << " " << p.z);
        REQUIRE(holding.size() == 1);
        REQUIRE(v.find_leaf(p) == holding[0]);
    }
    // Each leaf corner's probe sits at that corner, and one position has one probe.
    std::map<std::tuple<float, float, float>, std::uint32_t> at;
    for (const auto& n : v.nodes()) {
        if (!n.leaf()) continue;
        for (int k = 0; k < 8; ++k) {
            const glm::vec3 corner = n.lo + n.size * glm::vec3(float(k & 1), float((k >> 1) & 1), float((k >> 2) & 1));
            const std::uint32_t idx = n.corner[std::size_t(k)];
            REQUIRE(v.probes()[idx].position == corner);
            const auto key = std::make_tuple(corner.x, corner.y, corner.z);
            const auto [it, fresh] = at.emplace(key, idx);
            REQUIRE(it->second == idx);
            (void)fresh;
        }
    }
    CHECK(at.size() == v.probes().size());  // no probe that no leaf uses
}

TEST_CASE("trilinear lookup reproduces a linear field exactly on a uniform grid", "[irradiance_volume]") {
    const auto scene = test::far_triangle();
    const linear_field field(11);
    const auto v = irradiance_volume::build(scene, glm::vec3(-1, -2, 0), glm::vec3(1, 2, 3), uniform_settings(2), field);
    CHECK(v.probes().size() == 125);
    pcg32 rng(12);
    for (int trial = 0; trial < 2000; ++trial) {
        const glm::vec3 p(-1 + 2 * rng.next_float(), -2 + 4 * rng.next_float(), 3 * rng.next_float());
        const glm::vec3 n = random_unit(rng);
        const glm::vec3 got = v.trilinear(p, n), want = exact_irradiance(field, p, n);
        for (int k = 0; k < 3; ++k) REQUIRE(got[k] == Approx(want[k]).margin(linear_tolerance));
    }
}

TEST_CASE("gradient extrapolation makes the weighted lookup exact for a linear field", "[irradiance_volume]") {
    adaptive_fixture f;
    const linear_field field(21);
    const auto v = irradiance_volume::build(f.scene, glm::vec3(-1), glm::vec3(1), f.settings, field);
    pcg32 rng(22);
    double worst_without = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        const glm::vec3 p(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
        const glm::vec3 n = random_unit(rng);
        const glm::vec3 want = exact_irradiance(field, p, n);
        const glm::vec3 got = v.weighted(p, n, weighted_lookup{2.f, true, 1.5f});
        for (int k = 0; k < 3; ++k) REQUIRE(got[k] == Approx(want[k]).margin(linear_tolerance));
        // Any exponent and support is exact too: extrapolation makes every probe agree.
        const glm::vec3 plain = v.weighted(p, n, weighted_lookup{4.f, true, 3.f});
        for (int k = 0; k < 3; ++k) REQUIRE(plain[k] == Approx(want[k]).margin(linear_tolerance));
        const glm::vec3 without = v.weighted(p, n, weighted_lookup{2.f, false, 1.5f});
        worst_without = std::max(worst_without, double(glm::length(without - want)));
    }
    CHECK(worst_without > 100 * linear_tolerance);  // without gradients it is not exact (the test can fail)
}

TEST_CASE("the weighted lookup does not pop across a subdivision boundary", "[irradiance_volume]") {
    // A quadratic field: trilinear interpolation is not exact, and the T-junction probes of
    // the finer side differ from what the coarse side's corners interpolate, so trilinear
    // lookups jump at the boundary between depths.
    adaptive_fixture f;
    const auto source = [](std::span<const glm::vec3> p, std::span<irradiance_probe> out) {
        for (std::size_t j = 0; j < p.size(); ++j) {
            out[j] = {};
            out[j].position = p[j];
            const float v = 1 + 2 * p[j].y * p[j].y + p[j].z * p[j].z;
            out[j].radiance[0] = glm::vec3(v);
            out[j].harmonic_mean_distance = 1;
        }
    };
    f.settings.conforming_corners = false;  // the T-junction probes keep their baked values
    const auto v = irradiance_volume::build(f.scene, glm::vec3(-1), glm::vec3(1), f.settings, source);
    f.settings.conforming_corners = true;   // they take the coarse side's interpolation
    const auto conforming = irradiance_volume::build(f.scene, glm::vec3(-1), glm::vec3(1), f.settings, source);
    // The boundary between the depth-2 cells of x < 0 and the depth-4 cells of x > 0.
    REQUIRE(v.nodes()[v.find_leaf({-0.01f, 0.3f, 0.3f})].depth < v.nodes()[v.find_leaf({0.01f, 0.3f, 0.3f})].depth);
    const glm::vec3 n(0, 1, 0);
    // Value range of the probes' irradiance: the scale a jump is measured against.
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (const auto& pr : v.probes()) {
        const float e = sh_irradiance<3, float, glm::vec3>(pr.radiance, n).x;
        lo = std::min(lo, e), hi = std::max(hi, e);
    }
    const float range = hi - lo;
    pcg32 rng(31);
    float worst_weighted = 0, worst_trilinear = 0, worst_conforming = 0;
    const float eps = 1e-4f;
    for (int trial = 0; trial < 400; ++trial) {
        const float y = 1.8f * rng.next_float() - 0.9f, z = 1.8f * rng.next_float() - 0.9f;
        const glm::vec3 left(-eps, y, z), right(eps, y, z);
        worst_weighted = std::max(worst_weighted, std::abs(v.weighted(left, n, {}).x - v.weighted(right, n, {}).x));
        worst_trilinear = std::max(worst_trilinear, std::abs(v.trilinear(left, n).x - v.trilinear(right, n).x));
        worst_conforming = std::max(worst_conforming, std::abs(conforming.trilinear(left, n).x - conforming.trilinear(right, n).x));
    }
    // Budget: the weighted lookup is continuous (every probe enters and leaves the average
    // with weight 0), so over 2 eps it changes by at most its slope times 2 eps. The field's
    // slope is below 4 (4 y + 2 z, times pi Y00 < 1); Shepard's averages steepen it between
    // probes by a factor of order b + 1 = 3 (Franke and Nielson 1980), so 2e-4 * 4 * 3 =
    // 0.0024 < 0.01 of the range (2.66). Trilinear lookups jump at the T-junctions by an
    // amount that does not shrink with eps (the quadratic's deviation from the coarse
    // corners' interpolation, ~ 2 * 0.5^2 / 4 * pi Y00), far above it.
    CHECK(worst_weighted < 0.01f * range);
    CHECK(worst_trilinear > 0.01f * range);  // the budget is tight enough to see trilinear pop
    // With conforming corners trilinear is continuous too: over 2 eps it changes by at most
    // its slope (below 4, times 3 / 2 for the coarse cell's bilinear face) times 2 eps.
    CHECK(worst_conforming < 0.01f * range);
}

TEST_CASE("probes inside geometry are skipped by every lookup", "[irradiance_volume]") {
    const auto scene = test::far_triangle();
    // Probes with x > 0.3 are "inside" and carry absurd values that would show at once.
    const auto source = [](std::span<const glm::vec3> p, std::span<irradiance_probe> out) {
        for (std::size_t j = 0; j < p.size(); ++j) {
            out[j] = {};
            out[j].position = p[j];
            out[j].inside = p[j].x > 0.3f;
            out[j].radiance[0] = glm::vec3(out[j].inside ? 1e6f : 1.f + 0.1f * p[j].y);
            out[j].harmonic_mean_distance = out[j].inside ? 0.f : 1.f;
        }
    };
    const auto v = irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), uniform_settings(2), source);
    std::size_t inside = 0;
    for (const auto& p : v.probes()) inside += p.inside ? 1 : 0;
    REQUIRE(inside == 50);  // the layers x = 0.5 and x = 1, 5 x 5 each
    const auto flat = v.flatten();
    for (std::size_t i = 0; i < flat.probes.size(); ++i) CHECK(flat.probes[i].position[3] == (v.probes()[i].inside ? 0.f : v.probes()[i].reach));
    pcg32 rng(41);
    // Irradiance of a valid probe: pi * c00 * Y00 * (1 + 0.1 y) in (0.9, 1.1) times pi Y00^2 *...
    const float y00 = 0.28209479f, scale = std::numbers::pi_v<float> * y00;
    for (int trial = 0; trial < 1000; ++trial) {
        const glm::vec3 p(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
        const glm::vec3 n = random_unit(rng);
        for (const glm::vec3 e : {v.trilinear(p, n), v.weighted(p, n, {}), v.weighted(p, n, {4.f, false, 3.f})}) {
            // Where every corner is inside (none here: x = 0 and -0.5 layers always exist
            // within reach of the weighted lookup; trilinear cells with x > 0.5 have none) 0.
            REQUIRE(e.x <= 1.1f * scale + 1e-5f);
            REQUIRE(e.x >= 0.f);
        }
    }
}

TEST_CASE("bad input throws parameter_error naming the parameter", "[irradiance_volume]") {
    const auto scene = test::far_triangle();
    const linear_field field(5);
    const auto name_of = [&](auto&& f) -> std::string {
        try {
            f();
        } catch (const parameter_error& e) {
            return e.parameter();
        }
        return "(nothing thrown)";
    };
    auto s = uniform_settings(2);
    s.max_depth = 11;
    CHECK(name_of([&] { irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), s, field); }) == "settings.max_depth");
    s.max_depth = -1;
    CHECK(name_of([&] { irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), s, field); }) == "settings.max_depth");
    s = uniform_settings(2);
    s.min_depth = 3;
    CHECK(name_of([&] { irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), s, field); }) == "settings.min_depth");
    s = uniform_settings(2);
    s.cull_tolerance = std::nanf("");
    CHECK(name_of([&] { irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), s, field); }) ==
          "settings.cull_tolerance");
    s = uniform_settings(2);
    CHECK(name_of([&] { irradiance_volume::build(scene, glm::vec3(1), glm::vec3(1), s, field); }) == "hi");
    CHECK(name_of([&] { irradiance_volume::build(scene, glm::vec3(std::nanf("")), glm::vec3(1), s, field); }) == "lo");
    test::owned_scene empty;
    CHECK(name_of([&] { irradiance_volume::build(empty, glm::vec3(-1), glm::vec3(1), s, field); }) == "scene");
    const auto nan_source = [](std::span<const glm::vec3> p, std::span<irradiance_probe> out) {
        for (std::size_t j = 0; j < p.size(); ++j) {
            out[j] = {};
            out[j].position = p[j];
            out[j].radiance[4] = glm::vec3(j == p.size() / 2 ? std::nanf("") : 0.f);
        }
    };
    CHECK(name_of([&] { irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), s, nan_source); }) == "probes");
    const auto v = irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), s, field);
    CHECK(name_of([&] { v.weighted({0, 0, 0}, {0, 0, 1}, {0.f, true, 1.5f}); }) == "b");
    CHECK(name_of([&] { v.weighted({0, 0, 0}, {0, 0, 1}, {2.f, true, 1.f}); }) == "support");
    CHECK(name_of([&] { v.weighted({0, 0, 0}, {0, 0, 1}, {5.f, true, 1.5f}); }) == "b");
}
