// Reflective shadow maps cast with Embree, and the one-bounce reference without
// receiver-sender visibility, against closed forms: flux budgets of the three light types,
// the maps' projection, and a lit floor under a lit occluder seen from above.
#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/embree/rsm_ray_cast.hpp>
#include <bounce/embree/rsm_unoccluded_reference.hpp>
#include <bounce/errors.hpp>
#include <bounce/indirect/rsm.hpp>

#include "../embree/hand_built_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace bounce;

namespace {

constexpr double pi = std::numbers::pi;

glm::dvec3 total_flux(const embree::rsm_ray_caster& caster) {
    glm::dvec3 sum(0.0);
    for (const auto& m : caster.maps())
        for (std::size_t y = 0; y < m.flux.height(); ++y)
            for (std::size_t x = 0; x < m.flux.width(); ++x) sum += glm::dvec3(m.flux(x, y));
    return sum;
}

// A closed cube of half-size 1 around the origin, albedo rho.
hand_built::scene closed_box(float rho) {
    hand_built::scene s;
    const auto mat = hand_built::add_material(s, glm::vec3(rho));
    hand_built::add_square_z(s, -1.f, 1.f, true, mat);
    hand_built::add_square_z(s, 1.f, 1.f, false, mat);
    const glm::vec3 p[8] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                            {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
    hand_built::add_quad(s, p[0], p[1], p[5], p[4], {0, 1, 0}, mat);
    hand_built::add_quad(s, p[1], p[2], p[6], p[5], {-1, 0, 0}, mat);
    hand_built::add_quad(s, p[2], p[3], p[7], p[6], {0, -1, 0}, mat);
    hand_built::add_quad(s, p[3], p[0], p[4], p[7], {1, 0, 0}, mat);
    return s;
}

}  // namespace

TEST_CASE("the six cube faces of a point light in a closed box reflect rho I 4 pi", "[rsm][embree]") {
    const float rho = 0.6f;
    auto s = closed_box(rho);
    s.lights.push_back(point_light{{0.2f, -0.1f, 0.3f}, {2.f, 1.f, 0.5f}});
    const embree::accel bvh(s.view());
    embree::rsm_ray_caster caster(bvh, s.view(), {64, 60.f});
    caster.render();
    REQUIRE(caster.maps().size() == 6);
    // Every texel sees a wall, so the texel solid angles (exact, rectangle_solid_angle in
    // double) sum to 4 pi; each flux is rounded to float once (relative 2^-24), with the
    // albedo and intensity products another two roundings: 1e-6 covers it.
    const glm::dvec3 flux = total_flux(caster);
    const glm::dvec3 expected = double(rho) * glm::dvec3(2.0, 1.0, 0.5) * (4 * pi);
    for (int c = 0; c < 3; ++c) CHECK(std::abs(flux[c] - expected[c]) <= 1e-6 * expected[c]);
    CHECK(caster.views().size() == 6);
}

TEST_CASE("a texel's point projects back into that texel through light_view_projection", "[rsm][embree]") {
    auto s = closed_box(0.5f);
    s.lights.push_back(point_light{{0.1f, 0.2f, -0.3f}, glm::vec3(1.f)});
    s.lights.push_back(spot_light{{0.f, 0.f, 0.5f}, {0.3f, -0.2f, -1.f}, glm::vec3(1.f), 40.f});
    s.lights.push_back(directional_light{{0.3f, 0.4f, -1.f}, glm::vec3(1.f)});
    const embree::accel bvh(s.view());
    embree::rsm_ray_caster caster(bvh, s.view(), {32, 60.f});
    caster.render();
    REQUIRE(caster.maps().size() == 8);  // six faces, one spot map, one orthographic map
    int checked = 0;
    for (const auto& m : caster.maps()) {
        const float r = float(m.flux.width());
        for (std::size_t y = 0; y < m.flux.height(); ++y)
            for (std::size_t x = 0; x < m.flux.width(); ++x) {
                const glm::vec3 f = m.flux(x, y);
                if (!(f.x > 0.f)) continue;  // a ray that missed, or outside the spot's cone
                const glm::vec4 clip = m.light_view_projection * glm::vec4(m.position(x, y), 1.f);
                const float u = (clip.x / clip.w * 0.5f + 0.5f) * r, v = (0.5f - clip.y / clip.w * 0.5f) * r;
                // The ray passed through the texel centre: the projection lands there to float
                // rounding of the hit point and the matrix products (1e-3 texel is far above it).
                CHECK(std::abs(u - (float(x) + 0.5f)) < 1e-3f);
                CHECK(std::abs(v - (float(y) + 0.5f)) < 1e-3f);
                ++checked;
            }
    }
    // Six faces and the orthographic map are lit almost everywhere; the spot's cone covers pi/4
    // of its map.
    CHECK(checked > 6 * 32 * 32);
}

TEST_CASE("a spot light's single map reflects rho times the intensity integrated over its cone", "[rsm][embree]") {
    const float rho = 0.7f;
    hand_built::scene s;
    hand_built::add_square_z(s, 0.f, 50.f, true, hand_built::add_material(s, glm::vec3(rho)));
    const float cone = 50.f;
    s.lights.push_back(spot_light{{0.f, 0.f, 1.f}, {0, 0, -1}, glm::vec3(1.f), cone, spot_light::falloff_kind::none});
    const embree::accel bvh(s.view());
    const std::size_t res = 256;
    embree::rsm_ray_caster caster(bvh, s.view(), {res, 60.f});
    caster.render();
    REQUIRE(caster.maps().size() == 1);
    // Flat profile: Phi = rho I 2 pi (1 - cos cone). The map is the cone's circumscribed
    // square, so only texels the cone's edge crosses are wrong, each by at most its solid
    // angle: about pi R of them (the circle of radius tan(cone) crosses ~ pi R / 2 ... pi R
    // texel rows and columns), each at most dw_edge = (2t/R)^2 / (1 + t^2)^(3/2).
    const double t = std::tan(cone * pi / 180.0);
    const double dw_edge = std::pow(2 * t / double(res), 2) / std::pow(1 + t * t, 1.5);
    const double expected = rho * 2 * pi * (1 - std::cos(cone * pi / 180.0));
    const double bound = rho * pi * double(res) * dw_edge;
    CHECK(std::abs(total_flux(caster).x - expected) <= bound);
    CHECK(bound < 0.01 * expected);

    // Wider than max_single_map_cone_deg: cube faces, those the cone misses left out.
    s.lights[0] = spot_light{{0.f, 0.f, 1.f}, {0, 0, -1}, glm::vec3(1.f), 80.f, spot_light::falloff_kind::cosine};
    caster.render();
    CHECK(caster.maps().size() == 5);  // the face looking up sees nothing lit
    // Cosine profile over the cone: rho I 2 pi (1 - cos^2 cone) / 2; the floor is 50 wide,
    // so the beam reaches tan(80 deg) = 5.7 < 50: nothing escapes.
    const double wide = rho * pi * (1 - std::pow(std::cos(80 * pi / 180.0), 2));
    CHECK(std::abs(total_flux(caster).x - wide) < 0.01 * wide);
}

TEST_CASE("a directional light's map reflects rho E times the area across the beam", "[rsm][embree]") {
    const float rho = 0.5f;
    hand_built::scene s;
    hand_built::add_square_z(s, 0.f, 1.f, true, hand_built::add_material(s, glm::vec3(rho)));
    const glm::vec3 dir = glm::normalize(glm::vec3(0.3f, 0.f, -1.f));
    s.lights.push_back(directional_light{dir, glm::vec3(3.f)});
    const embree::accel bvh(s.view());
    const std::size_t res = 512;
    embree::rsm_ray_caster caster(bvh, s.view(), {res, 60.f});
    caster.render();
    REQUIRE(caster.maps().size() == 1);
    const auto& m = caster.maps()[0];
    // The floor's cross-section across the beam is 4 cos(theta); texels its outline crosses
    // (perimeter / side of them at most, 8 cos-shortened or not) are off by at most one area.
    const double side = m.texel_size;
    const double expected = rho * 3.0 * 4.0 * double(-dir.z);
    const double bound = rho * 3.0 * (8.0 / side + 4) * side * side;
    CHECK(std::abs(total_flux(caster).x - expected) <= bound);
    CHECK(bound < 0.02 * expected);
}

TEST_CASE("the unoccluded reference counts senders hidden from the receiver, the full one does not",
          "[rsm][embree][reference]") {
    // A lit floor (half-side 1, z = 0) under a lit occluder (half-side 0.3, z = 0.5, which
    // shadows the floor's centre), light straight down; receiver at height 1 above the centre
    // facing down. Exitance M = rho E0 on every lit surface. Without visibility the receiver
    // sees the floor less its shadow plus the occluder:
    //   E_u = M (F(1) - F(0.3) + F(0.3 / 0.5));
    // with visibility the occluder hides exactly the floor's |x|, |y| <= 0.6, which it
    // replaces with the same radiance: E = M F(1).
    const float rho = 0.8f, e0 = 2.f;
    hand_built::scene s;
    const auto mat = hand_built::add_material(s, glm::vec3(rho));
    hand_built::add_square_z(s, 0.f, 1.f, true, mat);
    hand_built::add_square_z(s, 0.5f, 0.3f, true, mat);
    s.lights.push_back(directional_light{{0, 0, -1}, glm::vec3(e0)});
    const embree::accel bvh(s.view());
    const glm::vec3 p(0.f, 0.f, 1.f), n(0.f, 0.f, -1.f);
    const double m = rho * e0;
    const double unoccluded = m * (hand_built::square_factor(1.0) - hand_built::square_factor(0.3) + hand_built::square_factor(0.6));
    const double occluded = m * hand_built::square_factor(1.0);
    REQUIRE(unoccluded - occluded > 0.3 * occluded);  // the test can tell them apart

    // Monte Carlo bound: each ray brings pi L k with L <= M / pi and k <= 2 surfaces, so a
    // sample lies in [0, 2 M] and its standard deviation is at most M; stratification only
    // lowers it. Five standard deviations of the mean of N samples: 5 M / sqrt(N).
    const std::uint32_t samples = 65536;
    const double tolerance = 5 * m / std::sqrt(double(samples));
    const embree::unoccluded_reference ref(bvh, s.view(), {samples, 256, 0.f, 1});
    const double eu = ref.indirect_irradiance(p, n, samples, 7).x;
    CHECK(std::abs(eu - unoccluded) <= tolerance);
    const embree::reference_integrator full(bvh, s.view());
    const double ef = full.indirect_irradiance(p, n, samples, 7).x;
    CHECK(std::abs(ef - occluded) <= tolerance);

    // The RSM's texel sum approaches the same unoccluded value (Riemann sum over the lit
    // surfaces seen from the light; DS05 Eq. 1 with bounce's 1/pi): the midpoint rule's error
    // on the parallel squares is below A t^2 M / (3 pi h^4) per square (|f_xx| + |f_yy| <=
    // 8 M / (pi h^4)), and each texel an outline crosses is off by at most M t^2 / (pi h^2):
    // outlines 8 + 2.4 + 2.4 long, h >= 0.5.
    embree::rsm_ray_caster caster(bvh, s.view(), {1024, 60.f});
    caster.render();
    REQUIRE(caster.maps().size() == 1);
    const auto& map = caster.maps()[0];
    double sum = 0;
    for (std::size_t y = 0; y < map.flux.height(); ++y)
        for (std::size_t x = 0; x < map.flux.width(); ++x)
            sum += double(pixel_light_irradiance<float, glm::vec3>(p, n, map.position(x, y), map.normal(x, y),
                                                                  map.flux(x, y), 0.f, 0.f)
                              .x);
    const double t = map.texel_size;
    const double midpoint = (4.0 / 1.0 + 0.36 / 0.0625) * t * t * m / (3 * pi);
    const double outline = (12.8 / t) * m * t * t / (pi * 0.25);
    CHECK(std::abs(sum - unoccluded) <= midpoint + outline + tolerance);
    CHECK(midpoint + outline < 0.1 * unoccluded);
}

TEST_CASE("the unoccluded reference image reports its measured noise, and bad settings are refused by name",
          "[rsm][embree][reference]") {
    hand_built::scene s;
    const auto mat = hand_built::add_material(s, glm::vec3(0.5f));
    hand_built::add_square_z(s, 0.f, 1.f, true, mat);
    hand_built::add_square_z(s, 0.5f, 0.3f, true, mat);
    s.lights.push_back(directional_light{{0.2f, 0.1f, -1}, glm::vec3(1.f)});
    const embree::accel bvh(s.view());
    gbuffer<float> g(8, 6);
    for (std::size_t y = 0; y < 6; ++y)
        for (std::size_t x = 0; x < 8; ++x) {
            g.position(x, y) = {-0.9f + 0.2f * float(x), -0.5f + 0.2f * float(y), 1.f};
            g.normal(x, y) = {0, 0, -1};
            g.albedo(x, y) = glm::vec3(1.f);
            g.depth(x, y) = x == 0 && y == 0 ? std::numeric_limits<float>::infinity() : 1.f;
        }
    const auto few = embree::render_unoccluded_reference(bvh, s.view(), g.view(), {64, 256, 0.f, 3});
    const auto many = embree::render_unoccluded_reference(bvh, s.view(), g.view(), {4096, 256, 0.f, 3});
    CHECK(few.samples == 64);
    CHECK(few.noise_rel_rms > 0);
    // Noise falls at least as N^(-1/2): 64x the samples, at most 1/8 the noise (with a factor
    // 2 for the noise of the noise estimate itself over 47 pixels).
    CHECK(many.noise_rel_rms < few.noise_rel_rms / 4);
    CHECK(many.indirect(0, 0) == glm::vec3(0.f));
    CHECK_THROWS_AS(embree::unoccluded_reference(bvh, s.view(), {1, 256, 0.f, 1}), parameter_error);
    // Two halves of equal size, at least 2 rays each: an odd count or 2 is refused up front.
    for (const std::uint32_t bad : {2u, 3u, 65u})
        CHECK_THROWS_AS(embree::render_unoccluded_reference(bvh, s.view(), g.view(), {bad, 256, 0.f, 3}),
                        parameter_error);
    CHECK(embree::render_unoccluded_reference(bvh, s.view(), g.view(), {4, 256, 0.f, 3}).samples == 4);
    CHECK_THROWS_AS(embree::rsm_ray_caster(bvh, s.view(), {0, 60.f}), parameter_error);
    CHECK_THROWS_AS(embree::rsm_ray_caster(bvh, s.view(), {64, 90.f}), parameter_error);
    embree::rsm_ray_caster caster(bvh, s.view(), {16, 60.f});
    const light bad[] = {spot_light{{0, 0, 2}, {0, 0, 0}, glm::vec3(1.f), 30.f}};
    CHECK_THROWS_AS(caster.render(bad), parameter_error);
}

TEST_CASE("the ray caster's maps are bounce::rsm_layout's, less the cube faces that see nothing lit",
          "[rsm][embree][layout]") {
    auto s = closed_box(0.5f);
    s.lights.push_back(point_light{{0.1f, 0.2f, -0.3f}, glm::vec3(1.f)});
    s.lights.push_back(spot_light{{0.f, 0.f, 0.5f}, {0.3f, -0.2f, -1.f}, glm::vec3(1.f), 40.f});
    s.lights.push_back(spot_light{{0.f, 0.9f, 0.f}, {0.f, -1.f, 0.f}, glm::vec3(1.f), 89.f});
    s.lights.push_back(directional_light{{0.3f, 0.4f, -1.f}, glm::vec3(1.f)});
    const embree::accel bvh(s.view());
    const embree::rsm_ray_cast_settings settings{16, 60.f};
    embree::rsm_ray_caster caster(bvh, s.view(), settings);
    caster.render();
    const auto [lo, hi] = s.view().bounds();
    const auto layout = rsm_layout(s.lights, lo, hi, settings);
    // Inside a closed box every face the layout keeps sees a lit wall.
    REQUIRE(layout.size() == 6 + 1 + 5 + 1);
    REQUIRE(caster.maps().size() == layout.size());
    for (std::size_t k = 0; k < layout.size(); ++k) {
        const auto& m = caster.maps()[k];
        CHECK(m.light == layout[k].light);
        CHECK(m.light_view_projection == layout[k].light_view_projection);
        CHECK(m.texel_size == layout[k].texel_size);
        CHECK(m.orthographic == layout[k].orthographic);
    }
}

TEST_CASE("RSM and SII frames do not depend on the scene's unit: the defaults scale with the scene", "[rsm][embree]") {
    // A floor and a back wall lit by a spot and a directional light, built at scale s with
    // intensities s^2 (so every irradiance is the same), rendered with the library's
    // scene-derived default clamp (scene_clamp_distance): the frames at 1e-4 and 1e4 must be
    // the one at 1. A fixed constant anywhere (the directional map's old 1e-3 floor, an
    // absolute clamp) would change the tenth-of-a-millimetre or the ten-kilometre frame.
    const auto frame = [](float s, indirect_technique technique) {
        hand_built::scene sc;
        const auto grey = hand_built::add_material(sc, glm::vec3(0.6f));
        const auto red = hand_built::add_material(sc, glm::vec3(0.8f, 0.2f, 0.2f));
        hand_built::add_quad(sc, s * glm::vec3(-1, 0, -1), s * glm::vec3(-1, 0, 1), s * glm::vec3(1, 0, 1),
                             s * glm::vec3(1, 0, -1), {0, 1, 0}, grey);
        hand_built::add_quad(sc, s * glm::vec3(-1, 0, -1), s * glm::vec3(1, 0, -1), s * glm::vec3(1, 2, -1),
                             s * glm::vec3(-1, 2, -1), {0, 0, 1}, red);
        sc.lights.push_back(spot_light{s * glm::vec3(0.3f, 1.5f, 0.2f), {-0.2f, -1.f, -0.4f}, glm::vec3(s * s), 50.f});
        sc.lights.push_back(directional_light{{0.4f, -1.f, -0.5f}, glm::vec3(1.f)});
        camera cam;
        cam.position = s * glm::vec3(0.f, 1.2f, 3.f);
        cam.look_at = s * glm::vec3(0.f, 0.6f, 0.f);
        cam.near_plane = 1e-3f * s;
        cam.far_plane = 10.f * s;
        const embree::accel bvh(sc.view());
        gbuffer<float> g = embree::ray_cast_gbuffer(bvh, sc.view(), cam, 40, 30);
        embree::rsm_ray_caster caster(bvh, sc.view(), {64, 60.f});
        caster.render();
        indirect_options o;
        o.technique = technique;
        o.count = 256;
        o.pattern = {2, 2};
        const float clamp = scene_clamp_distance(sc.view());
        o.light.min_distance2 = clamp * clamp;
        image<glm::vec3> e(40, 30);
        cpu::indirect_renderer(o).render(g.view(), cam, caster.views(), e.view());
        return e;
    };
    for (const auto technique : {indirect_technique::rsm_gather, indirect_technique::sii}) {
        const image<glm::vec3> unit = frame(1.f, technique);
        double ref2 = 0;
        for (std::size_t y = 0; y < 30; ++y)
            for (std::size_t x = 0; x < 40; ++x) ref2 += double(glm::dot(unit(x, y), unit(x, y)));
        REQUIRE(ref2 > 0);
        for (const float s : {1e-4f, 1e4f}) {
            const image<glm::vec3> scaled = frame(s, technique);
            double d2 = 0;
            for (std::size_t y = 0; y < 30; ++y)
                for (std::size_t x = 0; x < 40; ++x) {
                    const glm::vec3 d = scaled(x, y) - unit(x, y);
                    d2 += double(glm::dot(d, d));
                }
            INFO("technique " << int(technique) << ", scale " << s << ", relative RMS difference "
                              << std::sqrt(d2 / ref2));
            CHECK(std::sqrt(d2 / ref2) < 1e-3);
        }
    }
}
