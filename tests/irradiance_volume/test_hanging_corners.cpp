// Hanging corners computed in the lookup (irradiance_volume_settings::hanging_corners,
// issue 31, fifth session): the volume stores no probe at a T-junction and the trilinear
// lookup interpolates it from the coarser leaf, giving the values stored conforming corners
// give, continuous across 2:1 faces, with fewer probes; what needs a probe at every corner
// refuses such a volume by name.
#include "far_triangle.hpp"

#include <bounce/volume/probe_octree.hpp>
#include <bounce/volume/probe_visibility.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <map>
#include <numbers>

using namespace bounce;

namespace {

// Noiseless probes of a radiance with a band-1 part, a step at x = 0.5 and a bend in y and
// z, so that merged cells interpolate values their hanging corners' own probes would not
// have. `scale` multiplies the light (for rebake).
struct bent_step_field {
    float scale = 1;
    static float level(glm::vec3 p) {
        return 2 + 0.3f * std::sin(2 * p.y) + 0.2f * p.z * p.z + 3 / (1 + std::exp(-(p.x - 0.5f) / 0.02f));
    }
    void operator()(std::span<const glm::vec3> p, std::span<irradiance_probe> out) const {
        for (std::size_t j = 0; j < p.size(); ++j) {
            const float l = scale * level(p[j]);
            out[j] = {};
            out[j].position = p[j];
            out[j].radiance[0] = glm::vec3(l / 0.28209479177387814f, 0.9f * l / 0.282f, 0.8f * l / 0.282f);
            out[j].radiance[1] = glm::vec3(0.3f * l);
            out[j].radiance[3] = glm::vec3(-0.2f * l);
            out[j].noise = 1e-4f * l;
            out[j].harmonic_mean_distance = 1;
        }
    }
};

irradiance_volume_settings merged(hanging_corner_storage where) {
    irradiance_volume_settings s;
    s.min_depth = 1;
    s.max_depth = 4;
    s.calibrate_noise = false;
    s.bias_tolerance = 0.01f;
    s.hanging_corners = where;
    return s;
}

// The largest jump of the trilinear lookup across the planes x = k / 8 (k = -7 .. 7), where
// leaves of depth 2, 3 and 4 meet, at 20 x 20 points of each plane.
float largest_jump(const irradiance_volume& v) {
    float worst = 0;
    const glm::vec3 n = glm::normalize(glm::vec3(0.3f, 0.5f, 0.8f));
    for (int k = -7; k <= 7; ++k)
        for (float y = -0.975f; y < 1; y += 0.1f)
            for (float z = -0.975f; z < 1; z += 0.1f) {
                const float x = float(k) / 8;
                const glm::vec3 a = v.trilinear({x - 1e-5f, y, z}, n), b = v.trilinear({x + 1e-5f, y, z}, n);
                worst = std::max(worst, glm::length(a - b));
            }
    return worst;
}

template <class F>
void check_refusal(F&& f, const char* parameter) {
    try {
        f();
        FAIL("accepted");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == parameter);
    }
}

}  // namespace

TEST_CASE("computed hanging corners: the stored corners' values, fewer probes, continuous across 2:1 faces", "[irradiance_volume]") {
    const auto scene = test::far_triangle();
    const bent_step_field field;
    irradiance_volume_build_stats st_stored, st_computed;
    const auto stored = irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), merged(hanging_corner_storage::stored), field, &st_stored);
    const auto computed =
        irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), merged(hanging_corner_storage::computed), field, &st_computed);
    // Counts: the same octree; the hanging corners leave the probes for the table.
    REQUIRE(st_stored.hanging_corners > 0);
    CHECK(st_computed.hanging_corners == st_stored.hanging_corners);
    CHECK(stored.stored_hanging_corners() == st_stored.hanging_corners);
    CHECK(computed.stored_hanging_corners() == 0);
    CHECK(stored.hanging_corners().empty());
    CHECK(computed.hanging_corners().size() == st_stored.hanging_corners);
    CHECK(computed.leaf_count() == stored.leaf_count());
    CHECK(computed.probes().size() + computed.hanging_corners().size() == stored.probes().size());
    CHECK(stored.depth() == 4);
    // Equality with stored interpolated corners, at points and normals spread over the box.
    float worst = 0, largest = 0;
    for (float x = -0.99f; x < 1; x += 0.0731f)
        for (float y = -0.97f; y < 1; y += 0.1337f)
            for (float z = -0.98f; z < 1; z += 0.1511f) {
                const glm::vec3 n = glm::normalize(glm::vec3(std::sin(7 * x), std::cos(5 * y), 0.4f + z));
                const glm::vec3 a = stored.trilinear({x, y, z}, n), b = computed.trilinear({x, y, z}, n);
                worst = std::max(worst, glm::length(a - b)), largest = std::max(largest, glm::length(a));
            }
    CHECK(worst <= 1e-5f * largest);
    // Continuity across the 2:1 faces: no jump with computed corners (as with stored ones);
    // without conforming corners the same planes jump, so the test sees the T-junctions.
    auto loose = merged(hanging_corner_storage::stored);
    loose.conforming_corners = false;
    const auto jumping = irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), loose, field);
    const float jump = largest_jump(computed), loose_jump = largest_jump(jumping);
    INFO("jump computed " << jump << ", without conforming corners " << loose_jump << ", light " << largest);
    CHECK(jump < 1e-4f * largest);
    CHECK(loose_jump > 20 * jump);
}

TEST_CASE("computed hanging corners: rebake keeps the layout, and what needs a probe at every corner refuses", "[irradiance_volume]") {
    const auto scene = test::far_triangle();
    auto unfitted = merged(hanging_corner_storage::computed);
    unfitted.refit_culled = false;  // the free probes hold their baked values
    auto computed = irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), unfitted, bent_step_field{});
    const auto before = computed.trilinear({0.43f, 0.21f, -0.37f}, {0, 0, 1}), at_face = computed.trilinear({0.25f, 0.6f, 0.1f}, {1, 0, 0});
    computed.rebake(bent_step_field{2.f});  // twice the light: every lookup doubles, hanging corners included
    CHECK(glm::length(computed.trilinear({0.43f, 0.21f, -0.37f}, {0, 0, 1}) - 2.f * before) < 1e-5f * glm::length(before));
    CHECK(glm::length(computed.trilinear({0.25f, 0.6f, 0.1f}, {1, 0, 0}) - 2.f * at_face) < 1e-5f * glm::length(at_face));
    check_refusal([&] { (void)computed.weighted({0.1f, 0.1f, 0.1f}, {0, 0, 1}, weighted_lookup{}); }, "volume");
    check_refusal([&] { (void)computed.flatten(); }, "volume");  // what the GL lookup reads
    const probe_visibility vis(4, std::vector<float>(computed.probes().size() * 32, 1.f));
    check_refusal([&] {
        (void)trilinear_visible(computed, vis, {0.1f, 0.1f, 0.1f}, {0, 0, 1}, {0, 0, 1}, visibility_lookup{});
    }, "volume");
    auto stored = irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), merged(hanging_corner_storage::stored), bent_step_field{});
    check_refusal([&] { stored.rebake(bent_step_field{}); }, "volume");
    auto no_conforming = merged(hanging_corner_storage::computed);
    no_conforming.conforming_corners = false;
    check_refusal([&] { (void)irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), no_conforming, bent_step_field{}); },
                  "settings.hanging_corners");
    // A uniform grid has no hanging corners: computed storage changes nothing, and it rebakes.
    auto grid = merged(hanging_corner_storage::computed);
    grid.min_depth = grid.max_depth = 2;
    auto uniform = irradiance_volume::build(scene, glm::vec3(-1), glm::vec3(1), grid, bent_step_field{});
    CHECK(uniform.probes().size() == 125);
    CHECK(uniform.hanging_corners().empty());
    uniform.rebake(bent_step_field{});
    CHECK_NOTHROW(uniform.flatten());
}

TEST_CASE("computed hanging corners: nested T-junctions multiply out to stored probes", "[irradiance_volume]") {
    // Corner 10 hangs on a face of a leaf with corners 0..3; corner 11 hangs on an edge
    // between corner 10 and probe 4 (its leaf is finer, so it comes later); corner 12 sees
    // no usable probe.
    std::vector<detail::culled_sample> hanging(3);
    hanging[0] = {10, {0, 1, 2, 3, 5, 6, 7, 8}, {0.25f, 0.25f, 0.25f, 0.25f, 0, 0, 0, 0}};
    hanging[1] = {11, {10, 4, 1, 5, 6, 7, 8, 9}, {0.5f, 0.25f, 0.25f, 0, 0, 0, 0, 0}};
    hanging[2] = {12, {0, 1, 2, 3, 4, 5, 6, 7}, {}};
    const auto e = detail::expand_hanging(hanging);
    REQUIRE(e.size() == 3);
    const auto& t = e.at(11).terms;
    CHECK(e.at(11).valid == 1);
    CHECK(e.at(12).valid == 0);
    CHECK(e.at(12).terms.empty());
    std::map<std::uint32_t, float> w;
    for (const auto& term : t) w[term.probe] += term.weight;
    CHECK(t.size() == 5);  // probe 1 from both paths, merged
    CHECK(w[0] == Approx(0.125f));
    CHECK(w[1] == Approx(0.375f));
    CHECK(w[2] == Approx(0.125f));
    CHECK(w[3] == Approx(0.125f));
    CHECK(w[4] == Approx(0.25f));
}
