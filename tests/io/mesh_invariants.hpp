#pragma once
// What every loaded io::scene must satisfy, whatever file it came from.
#include <bounce/io/scene.hpp>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cmath>
#include <limits>

namespace bounce::test {

/// Indices in range, one unit normal per position, one valid material per triangle,
/// finite positions, no triangle of zero area (the loader drops those).
inline void check_mesh_invariants(const io::scene& s) {
    REQUIRE(s.normals.size() == s.positions.size());
    REQUIRE(s.material_of.size() == s.triangles.size());
    REQUIRE_FALSE(s.triangles.empty());
    std::size_t bad_index = 0, bad_material = 0, bad_normal = 0, bad_position = 0, degenerate = 0;
    for (const auto& p : s.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) ++bad_position;
    // A unit vector rounded to float and normalized has length 1 within a few ulp.
    for (const auto& n : s.normals)
        if (!(std::abs(glm::length(n) - 1.f) <= 4 * std::numeric_limits<float>::epsilon())) ++bad_normal;
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        const auto tri = s.triangles[t];
        if (tri.x >= s.positions.size() || tri.y >= s.positions.size() || tri.z >= s.positions.size()) {
            ++bad_index;
            continue;
        }
        if (s.material_of[t] >= s.materials.size()) ++bad_material;
        const glm::dvec3 a(s.positions[tri.x]), b(s.positions[tri.y]), c(s.positions[tri.z]);
        if (!(glm::length(glm::cross(b - a, c - a)) > 0.0)) ++degenerate;
    }
    CHECK(bad_position == 0);
    CHECK(bad_normal == 0);
    CHECK(bad_index == 0);
    CHECK(bad_material == 0);
    CHECK(degenerate == 0);
    for (const auto& m : s.materials) {
        for (int c = 0; c < 3; ++c) {
            CHECK(m.albedo[c] >= 0.f);
            CHECK(m.albedo[c] <= 1.f);
            CHECK(m.emission[c] >= 0.f);
        }
    }
    CHECK_NOTHROW(s.camera.validate());
}

}  // namespace bounce::test
