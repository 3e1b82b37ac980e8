// Indirect visibility of the RSM / SII family (indirect/visibility.hpp) with Embree's
// occlusion rays: a closed form where an occluder hides part of a lit floor, a scene where
// nothing hides anything (the rays must change nothing, to the bit), the partition in a
// closed room of issue 29 (the floor behind it darker than the open floor by the
// reference's ratio), and the refusals.
#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/embree/occlusion_rays.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/embree/rsm_ray_cast.hpp>
#include <bounce/errors.hpp>

#include "../embree/hand_built_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

using namespace bounce;

namespace {

constexpr double pi = std::numbers::pi;

// Every lit texel of `maps` as a VPL (its own flux): the splat then sums the map's texels.
std::vector<vpl> every_texel(const std::vector<embree::reflective_shadow_map>& maps) {
    std::vector<vpl> out;
    for (const auto& m : maps)
        for (std::size_t y = 0; y < m.flux.height(); ++y)
            for (std::size_t x = 0; x < m.flux.width(); ++x)
                if (m.flux(x, y).x > 0.f) out.push_back({m.position(x, y), m.normal(x, y), m.flux(x, y)});
    return out;
}

// A 1 x 1 G-buffer holding one receiver.
gbuffer<float> one_receiver(glm::vec3 p, glm::vec3 n) {
    gbuffer<float> g(1, 1);
    g.view().position(0, 0) = p;
    g.view().normal(0, 0) = n;
    g.view().albedo(0, 0) = glm::vec3(1.f);
    g.view().depth(0, 0) = 1.f;
    return g;
}

// The room of docs/embedding.md (4 x 2.5 x 4, walls facing inwards) with its free-standing
// partition at x = -0.5 (1.6 wide, 1.5 high, a face on each side) and a point light on the
// partition's +x side, above the floor the partition shadows on its -x side.
hand_built::scene partition_room() {
    hand_built::scene s;
    const auto grey = hand_built::add_material(s, glm::vec3(0.7f));
    const auto red = hand_built::add_material(s, {0.7f, 0.1f, 0.1f});
    const auto green = hand_built::add_material(s, {0.1f, 0.6f, 0.1f});
    const float w = 2.f, h = 2.5f;
    hand_built::add_quad(s, {-w, 0, -w}, {-w, 0, w}, {w, 0, w}, {w, 0, -w}, {0, 1, 0}, grey);    // floor
    hand_built::add_quad(s, {-w, h, -w}, {w, h, -w}, {w, h, w}, {-w, h, w}, {0, -1, 0}, grey);   // ceiling
    hand_built::add_quad(s, {-w, 0, -w}, {w, 0, -w}, {w, h, -w}, {-w, h, -w}, {0, 0, 1}, grey);  // back
    hand_built::add_quad(s, {-w, 0, w}, {-w, h, w}, {w, h, w}, {w, 0, w}, {0, 0, -1}, grey);     // front
    hand_built::add_quad(s, {-w, 0, -w}, {-w, h, -w}, {-w, h, w}, {-w, 0, w}, {1, 0, 0}, red);   // left
    hand_built::add_quad(s, {w, 0, -w}, {w, 0, w}, {w, h, w}, {w, h, -w}, {-1, 0, 0}, green);    // right
    hand_built::add_quad(s, {-0.5f, 0, -0.8f}, {-0.5f, 0, 0.8f}, {-0.5f, 1.5f, 0.8f}, {-0.5f, 1.5f, -0.8f},
                         {-1, 0, 0}, grey);
    hand_built::add_quad(s, {-0.48f, 0, -0.8f}, {-0.48f, 1.5f, -0.8f}, {-0.48f, 1.5f, 0.8f}, {-0.48f, 0, 0.8f},
                         {1, 0, 0}, grey);
    s.lights.push_back(point_light{{0.5f, 2.2f, 0.5f}, glm::vec3(3.f)});
    return s;
}

// The camera at the partition room's ceiling looking down (both halves of the floor in
// view) and its size x size G-buffer.
struct ceiling_view {
    camera cam;
    gbuffer<float> g;
    ceiling_view(const embree::accel& bvh, const hand_built::scene& s, std::size_t size) {
        cam.position = {0.f, 2.45f, 0.f};
        cam.look_at = {0.f, 0.f, 0.f};
        cam.up = {0.f, 0.f, -1.f};
        cam.fov_y_deg = 90.f;
        g = embree::ray_cast_gbuffer(bvh, s.view(), cam, size, size);
    }
};

// The partition room seen from its ceiling at 96 x 96: the partition tests' scene and view.
struct partition_view {
    static constexpr std::size_t size = 96;
    hand_built::scene s = partition_room();
    embree::accel bvh{s.view()};
    ceiling_view view{bvh, s, size};
};

// Mean luminance-free brightness (channel sum) of `e` over the floor pixels of `g` whose
// x lies in [x0, x1] and |z| <= 0.5.
double floor_mean(gbuffer<float>& g, const image<glm::vec3>& e, float x0, float x1) {
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x) {
            const glm::vec3 p = g.view().position(x, y);
            if (!g.view().covered(x, y) || p.y > 1e-3f || p.x < x0 || p.x > x1 || std::abs(p.z) > 0.5f) continue;
            sum += double(e(x, y).x + e(x, y).y + e(x, y).z);
            ++n;
        }
    REQUIRE(n > 50);
    return sum / double(n);
}

// The partition tests' frame: 1024 lights at 4 x 4 and blur, the scene's 1/d^2 clamp.
indirect_options partition_options(indirect_technique technique, const scene_view& v) {
    indirect_options o;
    o.technique = technique;
    o.count = 1024;
    o.pattern = {4, 4};
    const float clamp = scene_clamp_distance(v);
    o.light.min_distance2 = clamp * clamp;
    return o;
}

}  // namespace

TEST_CASE("with occlusion rays the texels an occluder hides from a receiver stop lighting it",
          "[rsm][embree][visibility]") {
    // hand_built::lit_floor_under_occluder, the receiver at height 1 facing down. Every
    // texel splatted as a VPL sums the RSM: without visibility that approaches
    // M (F(1) - F(0.3) + F(0.6)), the floor seen through the occluder; with it the occluder
    // hides the floor's |x|, |y| <= 0.6 and replaces it by its own top: M F(1).
    const float rho = 0.8f, e0 = 2.f;
    const hand_built::scene s = hand_built::lit_floor_under_occluder(rho, e0);
    const embree::accel bvh(s.view());
    embree::rsm_ray_caster caster(bvh, s.view(), {1024, 60.f});
    caster.render();
    const std::vector<vpl> vpls = every_texel(caster.maps());
    gbuffer<float> g = one_receiver({0.f, 0.f, 1.f}, {0.f, 0.f, -1.f});
    camera cam;  // the splat covers the whole (one-pixel) screen with cutoff 0
    cam.position = {0.f, 0.f, 3.f};
    const embree::occlusion_rays rays(bvh);
    image<glm::vec3> none(1, 1), visible(1, 1);
    cpu::splat_vpls(g.view(), cam, vpls, {}, none.view());
    cpu::splat_vpls(g.view(), cam, vpls, {}, visible.view(), &rays);

    const double m = rho * e0;
    const double unoccluded = m * (hand_built::square_factor(1.0) - hand_built::square_factor(0.3) + hand_built::square_factor(0.6));
    const double occluded = m * hand_built::square_factor(1.0);
    // The texel sum's bound of test_rsm_embree.cpp (midpoint rule, and each texel an outline
    // crosses off by at most M t^2 / (pi h^2), h >= 0.5), the outlines now 17.6 long: the
    // floor's 8, the occluder's and its shadow's 2.4 each, and the 4.8 of the floor's part
    // the occluder hides from the receiver.
    const double t = caster.maps()[0].texel_size;
    const double bound = (4.0 + 0.36 / 0.0625) * t * t * m / (3 * pi) + (17.6 / t) * m * t * t / (pi * 0.25);
    REQUIRE(unoccluded - occluded > 3 * bound);  // the test can tell them apart
    CHECK(std::abs(double(none(0, 0).x) - unoccluded) <= bound);
    CHECK(std::abs(double(visible(0, 0).x) - occluded) <= bound);
}

TEST_CASE("where nothing stands between receivers and senders the rays change no bit of the frame",
          "[rsm][embree][visibility]") {
    // A floor and a back wall meeting at a corner, lit by a spot and a directional light:
    // every receiver sees every sender in front of it, the segments near the corner graze
    // both planes, and the end offsets must keep them from finding the surfaces they join.
    hand_built::scene sc;
    const auto grey = hand_built::add_material(sc, glm::vec3(0.6f));
    const auto red = hand_built::add_material(sc, glm::vec3(0.8f, 0.2f, 0.2f));
    hand_built::add_quad(sc, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {0, 1, 0}, grey);
    hand_built::add_quad(sc, {-1, 0, -1}, {1, 0, -1}, {1, 2, -1}, {-1, 2, -1}, {0, 0, 1}, red);
    sc.lights.push_back(spot_light{{0.3f, 1.5f, 0.2f}, {-0.2f, -1.f, -0.4f}, glm::vec3(1.f), 50.f});
    sc.lights.push_back(directional_light{{0.4f, -1.f, -0.5f}, glm::vec3(1.f)});
    camera cam;
    cam.position = {0.f, 1.2f, 3.f};
    cam.look_at = {0.f, 0.6f, 0.f};
    const embree::accel bvh(sc.view());
    gbuffer<float> g = embree::ray_cast_gbuffer(bvh, sc.view(), cam, 40, 30);
    embree::rsm_ray_caster caster(bvh, sc.view(), {64, 60.f});
    caster.render();
    const embree::occlusion_rays rays(bvh);
    for (const auto technique : {indirect_technique::rsm_gather, indirect_technique::sii}) {
        indirect_options o;
        o.technique = technique;
        o.count = 256;
        o.pattern = {2, 2};
        o.view_selection.candidates = 1;  // the senders drawn as without rays, so the frames compare bit for bit
        image<glm::vec3> none(40, 30), visible(40, 30);
        cpu::indirect_renderer(o).render(g.view(), cam, caster.views(), none.view());
        o.visibility = indirect_visibility::rays;
        cpu::indirect_renderer(o, &rays).render(g.view(), cam, caster.views(), visible.view());
        double lit = 0;
        for (std::size_t y = 0; y < 30; ++y)
            for (std::size_t x = 0; x < 40; ++x) {
                INFO("technique " << int(technique) << ", pixel " << x << ", " << y);
                REQUIRE(visible(x, y) == none(x, y));
                lit += double(none(x, y).x);
            }
        CHECK(lit > 0);
    }
}

TEST_CASE("behind a partition the floor is darker than the open floor by the reference's ratio",
          "[rsm][embree][visibility]") {
    // Issue 29's partition test: SII with 1024 VPLs, 4 x 4 interleaving and blur, and the
    // RSM gather, against the one-bounce reference with visibility, on the floor seen from
    // the ceiling. The ratio of the mean indirect irradiance behind the partition (x in
    // [-1.6, -0.7]) to the open floor's (x in [0.7, 1.6]) must be the reference's within
    // 10%; without visibility the light leaking through the partition makes it brighter.
    partition_view room;
    auto& [s, bvh, view] = room;
    const std::size_t size = partition_view::size;
    const camera& cam = view.cam;
    gbuffer<float>& g = view.g;

    // The reference at the same pixels: 256 stratified samples each, ~400 pixels a region,
    // so its mean's noise is far below the 10% asked.
    const embree::reference_integrator ref(bvh, s.view());
    image<glm::vec3> reference(size, size);
    for (std::size_t y = 0; y < size; ++y)
        for (std::size_t x = 0; x < size; ++x)
            if (g.view().covered(x, y))
                reference(x, y) = ref.indirect_irradiance(g.view().position(x, y), g.view().normal(x, y), 256,
                                                          y * size + x);
    const double ref_ratio = floor_mean(g, reference, -1.6f, -0.7f) / floor_mean(g, reference, 0.7f, 1.6f);

    embree::rsm_ray_caster caster(bvh, s.view(), {128, 60.f});
    caster.render();
    const embree::occlusion_rays rays(bvh);
    for (const auto technique : {indirect_technique::sii, indirect_technique::rsm_gather}) {
        indirect_options o = partition_options(technique, s.view());
        image<glm::vec3> none(size, size), visible(size, size);
        cpu::indirect_renderer(o).render(g.view(), cam, caster.views(), none.view());
        o.visibility = indirect_visibility::rays;
        cpu::indirect_renderer(o, &rays).render(g.view(), cam, caster.views(), visible.view());
        const double none_ratio = floor_mean(g, none, -1.6f, -0.7f) / floor_mean(g, none, 0.7f, 1.6f);
        const double ratio = floor_mean(g, visible, -1.6f, -0.7f) / floor_mean(g, visible, 0.7f, 1.6f);
        INFO("technique " << int(technique) << ": reference ratio " << ref_ratio << ", with rays " << ratio
                          << ", without visibility " << none_ratio);
        CHECK(std::abs(none_ratio / ref_ratio - 1) > 0.2);  // the leak the rays remove
        CHECK(std::abs(ratio / ref_ratio - 1) <= 0.1);
    }
}

TEST_CASE("visibility by rays without an occlusion query is refused by its option's name",
          "[rsm][embree][visibility]") {
    indirect_options o;
    o.visibility = indirect_visibility::rays;
    CHECK_THROWS_AS(cpu::indirect_renderer(o), parameter_error);
    cpu::indirect_renderer r;
    CHECK_THROWS_WITH(r.set_options(o), Catch::Contains("visibility"));
    CHECK(r.options().visibility == indirect_visibility::none);  // the old options stay
    hand_built::scene sc;
    hand_built::add_square_z(sc, 0.f, 1.f, true, hand_built::add_material(sc, glm::vec3(0.5f)));
    const embree::accel bvh(sc.view());
    const embree::occlusion_rays rays(bvh);
    r.set_occlusion_query(&rays);
    r.set_options(o);
    CHECK_THROWS_WITH(r.set_occlusion_query(nullptr), Catch::Contains("visibility"));
    CHECK_THROWS_WITH(embree::occlusion_rays(bvh, -1.f), Catch::Contains("offset"));
    CHECK_THROWS_WITH(embree::occlusion_rays(bvh, std::nanf("")), Catch::Contains("offset"));
}

TEST_CASE("imperfect shadow maps darken the floor behind the partition as the rays do",
          "[rsm][embree][visibility][ism]") {
    // The partition room above, SII with 1024 VPLs, 4 x 4 and blur: with imperfect shadow
    // maps (indirect/imperfect_shadow_maps.hpp) the floor behind the partition must be
    // darker than the open floor, and its ratio near the one the exact rays give.
    partition_view room;
    auto& [s, bvh, view] = room;
    const std::size_t size = partition_view::size;
    const camera& cam = view.cam;
    gbuffer<float>& g = view.g;
    embree::rsm_ray_caster caster(bvh, s.view(), {128, 60.f});
    caster.render();
    const embree::occlusion_rays rays(bvh);
    const ism_point_sampler points(s.view());
    indirect_options o = partition_options(indirect_technique::sii, s.view());
    image<glm::vec3> none(size, size), exact(size, size), ism(size, size);
    cpu::indirect_renderer(o).render(g.view(), cam, caster.views(), none.view());
    o.visibility = indirect_visibility::rays;
    cpu::indirect_renderer(o, &rays).render(g.view(), cam, caster.views(), exact.view());
    o.visibility = indirect_visibility::ism;
    cpu::indirect_renderer(o, nullptr, &points).render(g.view(), cam, caster.views(), ism.view());
    const auto ratio = [&](const image<glm::vec3>& e) {
        return floor_mean(g, e, -1.6f, -0.7f) / floor_mean(g, e, 0.7f, 1.6f);
    };
    const double r_none = ratio(none), r_rays = ratio(exact), r_ism = ratio(ism);
    INFO("behind / open floor: none " << r_none << ", rays " << r_rays << ", ism " << r_ism);
    CHECK(r_ism < 0.6 * r_none);
    CHECK(std::abs(r_ism / r_rays - 1) <= 0.15);
    // The open floor sees most VPLs: ISM's false shadows there stay small.
    CHECK(floor_mean(g, ism, 0.7f, 1.6f) >= 0.85 * floor_mean(g, exact, 0.7f, 1.6f));
}
