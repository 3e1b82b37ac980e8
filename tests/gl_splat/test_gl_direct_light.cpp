// Shadow-mapped direct light against geometry and closed forms: a ground plane under each
// kind of light (point: cube map; narrow spot: perspective map; wide spot: cube map;
// directional: orthographic map) with a square blocker above it. Where the segment from a
// ground point to the light clears the blocker by a margin, the radiance is the unshadowed
// closed form rho/pi * E (E = I cos/d^2, times the spot profile; E_perp cos for a distant
// light); where it passes through the blocker by the margin, it is 0. The margin is the
// reach of the filtered lookup: the PCF taps span +-1.5 texels, each bilinear over one more
// texel, and the normal offset moves the lookup 1.5 texels: 4 texels, doubled to 8 for the
// slope-scaled bias and for the stretch of a texel's footprint on a surface at incidence
// theta (divided by cos theta). Pixels in that band (the penumbra PCF makes) and within
// 1e-4 of a spot's cone border in cosine (where the profile jumps) are not judged.
//
// The lit tolerance is 1e-4 relative: the kernels run in float (a few ulps, 1e-6) against a
// double closed form at the same G-buffer point, and a fully lit PCF average is 1 up to the
// rounding of the bilinear weights' sum. In the umbra every tap fails its comparison and the
// result is 0; it is allowed 1e-6 of the unshadowed value.
#include "../gl/shared_context.hpp"

#include "../owned_scene.hpp"

#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/sampling.hpp>


#include <epoxy/gl.h>  // GL entry points from whatever context is current (EGL, GLX, WGL)
#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <array>
#include <cmath>
#include <numbers>
#include <variant>

using namespace bounce;

namespace {

constexpr std::size_t W = 64, H = 48;
constexpr int resolution = 1024;
constexpr double blocker_z = 1.0, blocker_half = 0.5;
const glm::dvec2 blocker_centre(0.2, 0.1);

void add_quad(test::owned_scene& s, glm::vec3 centre, float half, std::uint32_t m) {
    const auto base = std::uint32_t(s.positions.size());
    for (const glm::vec2 c : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
        s.positions.push_back(centre + half * glm::vec3(c, 0.f));
        s.normals.emplace_back(0, 0, 1);
    }
    s.triangles.emplace_back(base, base + 1, base + 2);
    s.triangles.emplace_back(base, base + 2, base + 3);
    s.material_of.insert(s.material_of.end(), 2, m);
}

test::owned_scene ground_and_blocker(bounce::light light) {
    test::owned_scene s;
    s.materials.push_back({glm::vec3(0.5f, 0.6f, 0.7f), glm::vec3(0.f)});
    s.materials.push_back({glm::vec3(0.9f, 0.3f, 0.2f), glm::vec3(0.f)});
    add_quad(s, {0, 0, 0}, 4.f, 0);
    add_quad(s, glm::vec3(glm::dvec3(blocker_centre, blocker_z)), float(blocker_half), 1);
    s.lights.push_back(light);
    s.camera.position = {0.3f, -0.5f, 6.f};
    s.camera.look_at = {0, 0, 0};
    s.camera.fov_y_deg = 60.f;
    return s;
}

// What the geometry says about a point: the unshadowed irradiance (closed form, double),
// and whether the blocker hides the light by at least the margin (-1), leaves it visible
// by at least the margin (+1), or neither (0: penumbra band, cone border).
struct expectation {
    glm::dvec3 e{0.0};
    int visibility = 0;
};

// `ortho_texel`: the world size of the orthographic map's texel (direct_light::texel_of),
// used for directional lights only.
expectation expect(const bounce::light& light, const glm::dvec3& p, const glm::dvec3& n, double ortho_texel) {
    expectation x;
    glm::dvec3 to_light;  // unit, towards the light
    double texel = 0, scale = 1;  // shadow texel at p; ground distance per blocker-plane distance
    if (const auto* pl = std::get_if<bounce::point_light>(&light)) {
        const glm::dvec3 d = glm::dvec3(pl->position) - p;
        x.e = glm::dvec3(pl->intensity) * std::max(0.0, glm::dot(n, d)) / std::pow(glm::length(d), 3.0);
        to_light = glm::normalize(d);
        const glm::dvec3 ad = glm::abs(d);
        texel = 2.0 * std::max({ad.x, ad.y, ad.z}) / resolution;
        scale = (pl->position.z - p.z) / (pl->position.z - blocker_z);
    } else if (const auto* sl = std::get_if<bounce::spot_light>(&light)) {
        const glm::dvec3 d = glm::dvec3(sl->position) - p, axis = glm::normalize(glm::dvec3(sl->direction));
        const double dist = glm::length(d), cos_axis = -glm::dot(axis, d) / dist;
        const double cos_cone = std::cos(sl->cone_deg * std::numbers::pi / 180.0);
        const double profile =
            cos_axis >= cos_cone ? (sl->falloff == bounce::spot_light::falloff_kind::cosine ? cos_axis : 1.0) : 0.0;
        x.e = glm::dvec3(sl->intensity) * profile * std::max(0.0, glm::dot(n, d)) / std::pow(dist, 3.0);
        to_light = d / dist;
        if (sl->cone_deg <= 60.f) {
            texel = 2.0 * std::abs(glm::dot(d, axis)) * std::tan(sl->cone_deg * std::numbers::pi / 180.0) / (1.0 - 6.0 / resolution) / resolution;
        } else {
            const glm::dvec3 ad = glm::abs(d);
            texel = 2.0 * std::max({ad.x, ad.y, ad.z}) / resolution;
        }
        scale = (sl->position.z - p.z) / (sl->position.z - blocker_z);
        if (std::abs(cos_axis - cos_cone) < 1e-4) return x;  // the profile jumps here
    } else {
        const auto& dl = std::get<bounce::directional_light>(light);
        const glm::dvec3 dir = glm::normalize(glm::dvec3(dl.direction));
        x.e = glm::dvec3(dl.irradiance) * std::max(0.0, -glm::dot(n, dir));
        to_light = -dir;
        texel = ortho_texel;
        scale = 1.0;
    }
    const double cos_theta = std::max(0.2, glm::dot(n, to_light));
    const double margin = 6.0 * texel / cos_theta / scale;  // in the blocker plane
    if (p.z >= blocker_z - 1e-3) {
        x.visibility = 1;  // the blocker's top: nothing above it
        return x;
    }
    const double s = (blocker_z - p.z) / to_light.z;
    const glm::dvec3 q = p + s * to_light;
    const double sd = std::max(std::abs(q.x - blocker_centre.x), std::abs(q.y - blocker_centre.y)) - blocker_half;
    x.visibility = sd < -margin ? -1 : sd > margin ? 1 : 0;
    return x;
}

struct light_case {
    const char* name;
    bounce::light light;
    gl::direct_light::map_kind map;
};

// Lights off to one side, so that the blocker's shadow falls where the camera sees it
// (not behind the blocker itself).
std::vector<light_case> light_cases() {
    bounce::spot_light narrow;
    narrow.position = {-1.8f, 1.2f, 3.2f};
    narrow.direction = glm::vec3(0.4f, -0.3f, 0.f) - narrow.position;
    narrow.intensity = {4.f, 3.f, 2.f};
    narrow.cone_deg = 40.f;
    narrow.falloff = bounce::spot_light::falloff_kind::cosine;
    bounce::spot_light wide = narrow;
    wide.cone_deg = 75.f;
    wide.falloff = bounce::spot_light::falloff_kind::none;
    using kind = gl::direct_light::map_kind;
    return {{"point", bounce::point_light{{-2.f, 1.5f, 3.f}, {3.f, 2.f, 1.f}}, kind::cube},
            {"narrow spot", narrow, kind::perspective},
            {"wide spot", wide, kind::cube},
            {"directional", bounce::directional_light{glm::normalize(glm::vec3(0.8f, -0.5f, -1.f)), {1.5f, 1.f, 0.5f}},
             kind::orthographic},
            // 70 degrees from the ground's normal: the slope-scaled bias at work.
            {"grazing directional", bounce::directional_light{glm::normalize(glm::vec3(2.6f, 0.8f, -1.f)), {1.f, 1.f, 1.f}},
             kind::orthographic}};
}

}  // namespace

TEST_CASE("shadow-mapped direct light: the closed form where lit, zero in the blocker's umbra", "[gl][direct]") {
    gl_test::shared_context();
    const auto cases = light_cases();
    const auto& lc = cases[std::size_t(GENERATE(0, 1, 2, 3, 4))];
    INFO(lc.name);
    const test::owned_scene scene = ground_and_blocker(lc.light);
    const gl::scene_mesh mesh(scene);
    gl::gbuffer_pass gpass;
    gpass.render(mesh, scene.camera, W, H);
    const auto gb = gpass.read();

    gl::direct_light dl(scene, mesh, resolution);
    REQUIRE(dl.map_of(0) == lc.map);
    dl.render(gl::textures_of(gpass));
    image<glm::vec3> radiance(W, H);
    dl.read(radiance.view());

    std::size_t lit = 0, umbra = 0, uncovered = 0;
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            if (!(gb.depth(x, y) < std::numeric_limits<float>::infinity())) {
                REQUIRE(radiance(x, y) == glm::vec3(0.f));
                ++uncovered;
                continue;
            }
            const auto ex = expect(lc.light, gb.position(x, y), gb.normal(x, y), dl.texel_of(0));
            const glm::dvec3 l = glm::dvec3(gb.albedo(x, y)) * ex.e / std::numbers::pi;
            INFO("pixel (" << x << ", " << y << ") p = (" << gb.position(x, y).x << ", " << gb.position(x, y).y << ", "
                           << gb.position(x, y).z << ")");
            for (int c = 0; c < 3; ++c) {
                if (ex.visibility > 0) REQUIRE(std::abs(radiance(x, y)[c] - l[c]) <= 1e-4 * l[c] + 1e-9);
                if (ex.visibility < 0) REQUIRE(radiance(x, y)[c] <= 1e-6 * l[c]);
            }
            lit += ex.visibility > 0 && l.x > 0;
            umbra += ex.visibility < 0 && l.x > 0;
        }
    CHECK(lit > W * H / 3);
    CHECK(umbra >= 20);
    // The ground quad ends inside the view: the background was exercised.
    CHECK(uncovered > 0);
}

TEST_CASE("a directional light's map spans the rectangle the scene's box projects to across the light",
          "[gl][direct]") {
    gl_test::shared_context();
    // A long, flat box (30 x 2 x 6), seen from 200 directions including the axes and the
    // diagonals. The map's longer side must hold every corner's projection (so it is at
    // least the projected set's diameter over sqrt 2) and be no longer than that diameter.
    test::owned_scene s;
    s.materials.push_back({glm::vec3(0.5f), glm::vec3(0.f)});
    const glm::dvec3 lo(-15, -1, -3), hi(15, 1, 3);
    add_quad(s, glm::vec3(0, 0, -3), 1.f, 0);  // only the box matters: a quad and a triangle spanning it
    s.positions.push_back(glm::vec3(lo));
    s.positions.push_back(glm::vec3(hi));
    s.positions.push_back(glm::vec3(float(hi.x), float(lo.y), float(hi.z)));
    s.normals.resize(s.positions.size(), glm::vec3(0, 0, 1));
    s.triangles.push_back({std::uint32_t(s.positions.size() - 3), std::uint32_t(s.positions.size() - 2),
                           std::uint32_t(s.positions.size() - 1)});
    s.material_of.push_back(0);
    const int res = 512;
    pcg32 rng(77);
    std::vector<glm::dvec3> dirs = {{1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {1, -1, 1}, {-1, -1, 0}, {0.2, -1, 0.35}};
    while (dirs.size() < 200) {  // uniform on the sphere: z uniform in [-1, 1], phi uniform
        const double z = 2 * rng.next_double() - 1, phi = 2 * std::numbers::pi * rng.next_double();
        dirs.push_back({std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi), z});
    }
    std::array<glm::dvec3, 8> corners;
    for (int c = 0; c < 8; ++c) corners[c] = {(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z};
    for (const glm::dvec3& d : dirs) {
        CAPTURE(d);
        s.lights = {bounce::directional_light{glm::vec3(glm::normalize(d)), {1.f, 1.f, 1.f}}};
        const gl::scene_mesh mesh(s);
        const gl::direct_light dl(s, mesh, res);
        const glm::dvec3 u = glm::normalize(glm::abs(d.x) < 0.9 ? glm::cross(d, glm::dvec3(1, 0, 0))
                                                                : glm::cross(d, glm::dvec3(0, 1, 0)));
        const glm::dvec3 v = glm::cross(glm::normalize(d), u);
        double diameter = 0;  // of the corners' projections across the light
        for (const glm::dvec3& ca : corners)
            for (const glm::dvec3& cb : corners)
                diameter = std::max(diameter, glm::length(glm::dvec2(glm::dot(ca - cb, u), glm::dot(ca - cb, v))));
        const double side = double(dl.texel_of(0)) * res;
        CHECK(side >= diameter / std::sqrt(2.0) * (1 - 1e-5));
        // and no wider than the set along any direction (plus its 1% and PCF margin):
        // the bounding sphere's map (diameter 30.7) would fail this for most directions.
        CHECK(side <= diameter * 1.01 / (1.0 - 6.0 / res) * (1 + 1e-5));
    }
}

TEST_CASE("direct_irradiance pasted into another shader gives the closed form and the shadow", "[gl][direct][glsl]") {
    gl_test::shared_context();
    const auto cases = light_cases();
    const auto& lc = cases[std::size_t(GENERATE(0, 1, 3))];
    INFO(lc.name);
    test::owned_scene scene = ground_and_blocker(lc.light);
    // Two lights at once: the sum of both, each with its own map.
    scene.lights.push_back(bounce::point_light{{-1.f, -1.f, 2.5f}, {1.f, 1.f, 1.f}});
    const gl::scene_mesh mesh(scene);
    const gl::direct_light dl(scene, mesh, resolution);
    REQUIRE(dl.texture_units() == 2);

    const std::string source = std::string("#version 450 core\nlayout(local_size_x = 64) in;\n"
                                           "layout(std430, binding = 0) readonly buffer points { vec4 pn[]; };\n"
                                           "layout(std430, binding = 1) writeonly buffer results { vec4 e[]; };\n"
                                           "layout(location = 0) uniform uint count;\n") +
                               dl.glsl_source() +
                               "void main() {\n    uint i = gl_GlobalInvocationID.x;\n    if (i >= count) return;\n"
                               "    e[i] = vec4(direct_irradiance(pn[2u * i].xyz, pn[2u * i + 1u].xyz), 0.0);\n}\n";
    const gl::program prog = gl::program::compute(source);
    dl.bind(prog, 5);

    pcg32 rng(9);
    std::vector<glm::vec4> pn;
    std::vector<glm::dvec3> points;
    for (int i = 0; i < 4000; ++i) {
        const glm::dvec3 p(6.0 * rng.next_float() - 3.0, 6.0 * rng.next_float() - 3.0, 0.0);
        // Mostly facing up; every 10th faces down (one-sided: no light).
        const glm::dvec3 n(0.0, 0.0, i % 10 == 9 ? -1.0 : 1.0);
        points.push_back(p);
        pn.emplace_back(glm::vec3(p), 1.f);
        pn.emplace_back(glm::vec3(n), 0.f);
    }
    const gl::buffer in{std::span<const glm::vec4>(pn)};
    gl::buffer out(points.size() * sizeof(glm::vec4));
    glUseProgram(prog.id());
    prog.set(0, unsigned(points.size()));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
    glDispatchCompute(GLuint((points.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    const auto e = out.read_all<glm::vec4>();
    glUseProgram(0);
    for (GLuint u = 5; u < 7; ++u) glBindTextureUnit(u, 0);

    std::size_t judged_lit = 0, judged_umbra = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const glm::dvec3 n = glm::dvec3(pn[2 * i + 1]);
        const auto a = expect(scene.lights[0], points[i], n, dl.texel_of(0));
        const auto b = expect(scene.lights[1], points[i], n, dl.texel_of(1));
        if (a.visibility == 0 || b.visibility == 0) continue;
        const glm::dvec3 want = (a.visibility > 0 ? a.e : glm::dvec3(0.0)) + (b.visibility > 0 ? b.e : glm::dvec3(0.0));
        INFO("point " << i << " (" << points[i].x << ", " << points[i].y << ")");
        for (int c = 0; c < 3; ++c)
            REQUIRE(std::abs(e[i][c] - want[c]) <= 1e-4 * (a.e[c] + b.e[c]) + 1e-9);
        judged_lit += a.visibility > 0 && a.e.x > 0;
        judged_umbra += a.visibility < 0 && a.e.x > 0;
    }
    CHECK(judged_lit > 500);
    CHECK(judged_umbra > 20);
}

TEST_CASE("direct_light refuses bad lights and settings, naming them", "[gl][direct][bad-input]") {
    gl_test::shared_context();
    bounce::spot_light bad_spot;
    bad_spot.direction = {0, 0, 0};
    test::owned_scene scene = ground_and_blocker(bad_spot);
    const gl::scene_mesh mesh(scene);
    try {
        gl::direct_light dl(scene, mesh, 64);
        FAIL("accepted a spot light without a direction");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "scene.lights[0]");
    }
    scene.lights[0] = bounce::point_light{{0, 0, 2}, {-1.f, 1.f, 1.f}};
    CHECK_THROWS_AS(gl::direct_light(scene, mesh, 64), parameter_error);
    scene.lights[0] = bounce::point_light{{0, 0, 2}, {1.f, 1.f, 1.f}};
    try {
        gl::direct_light dl(scene, mesh, 8);
        FAIL("accepted an 8-texel shadow map");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "shadow_resolution");
    }
    // No lights: no direct light at all, and a valid shader.
    scene.lights.clear();
    gl::direct_light none(scene, mesh, 64);
    gl::gbuffer_pass gpass;
    gpass.render(mesh, scene.camera, 16, 12);
    none.render(gl::textures_of(gpass));
    image<glm::vec3> out(16, 12);
    none.read(out.view());
    for (std::size_t y = 0; y < 12; ++y)
        for (std::size_t x = 0; x < 16; ++x) CHECK(out(x, y) == glm::vec3(0.f));
}
