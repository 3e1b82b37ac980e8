#pragma once
/// \file cornell_box.hpp
/// The Cornell box from the Cornell University Program of Computer Graphics, "Cornell Box
/// Data" (https://www.graphics.cornell.edu/online/box/data.html): the measured vertices in
/// millimetres, the camera, and the light opening, built into any owned scene, so that a
/// program without a scene loader (a GL-only build, tools/gpu timings) has the same box
/// `io::cornell_box()` gives. Reflectances are the usual RGB reductions of the measured
/// spectra (as in the Williams College OBJ of Cardenas and McGuire, 2011).

#include <bounce/camera.hpp>
#include <bounce/light.hpp>
#include <bounce/scene_view.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce {

namespace detail::cornell {

using quad = std::array<glm::vec3, 4>;  // millimetres, in the published order

// Every quad of the data is listed counter-clockwise as seen from the air side, so the
// triangles (0 1 2) and (0 2 3) face into the room (walls) or out of the blocks.
inline constexpr quad floor_mm{{{552.8f, 0.f, 0.f}, {0.f, 0.f, 0.f}, {0.f, 0.f, 559.2f}, {549.6f, 0.f, 559.2f}}};
inline constexpr quad ceiling_mm{{{556.f, 548.8f, 0.f}, {556.f, 548.8f, 559.2f}, {0.f, 548.8f, 559.2f}, {0.f, 548.8f, 0.f}}};
inline constexpr quad light_mm{{{343.f, 548.8f, 227.f}, {343.f, 548.8f, 332.f}, {213.f, 548.8f, 332.f}, {213.f, 548.8f, 227.f}}};
inline constexpr quad back_wall_mm{{{549.6f, 0.f, 559.2f}, {0.f, 0.f, 559.2f}, {0.f, 548.8f, 559.2f}, {556.f, 548.8f, 559.2f}}};
inline constexpr quad right_wall_mm{{{0.f, 0.f, 559.2f}, {0.f, 0.f, 0.f}, {0.f, 548.8f, 0.f}, {0.f, 548.8f, 559.2f}}};  // green
inline constexpr quad left_wall_mm{{{552.8f, 0.f, 0.f}, {549.6f, 0.f, 559.2f}, {556.f, 548.8f, 559.2f}, {556.f, 548.8f, 0.f}}};  // red
inline constexpr std::array<quad, 5> short_block_mm{{
    {{{130.f, 165.f, 65.f}, {82.f, 165.f, 225.f}, {240.f, 165.f, 272.f}, {290.f, 165.f, 114.f}}},
    {{{290.f, 0.f, 114.f}, {290.f, 165.f, 114.f}, {240.f, 165.f, 272.f}, {240.f, 0.f, 272.f}}},
    {{{130.f, 0.f, 65.f}, {130.f, 165.f, 65.f}, {290.f, 165.f, 114.f}, {290.f, 0.f, 114.f}}},
    {{{82.f, 0.f, 225.f}, {82.f, 165.f, 225.f}, {130.f, 165.f, 65.f}, {130.f, 0.f, 65.f}}},
    {{{240.f, 0.f, 272.f}, {240.f, 165.f, 272.f}, {82.f, 165.f, 225.f}, {82.f, 0.f, 225.f}}},
}};
inline constexpr std::array<quad, 5> tall_block_mm{{
    {{{423.f, 330.f, 247.f}, {265.f, 330.f, 296.f}, {314.f, 330.f, 456.f}, {472.f, 330.f, 406.f}}},
    {{{423.f, 0.f, 247.f}, {423.f, 330.f, 247.f}, {472.f, 330.f, 406.f}, {472.f, 0.f, 406.f}}},
    {{{472.f, 0.f, 406.f}, {472.f, 330.f, 406.f}, {314.f, 330.f, 456.f}, {314.f, 0.f, 456.f}}},
    {{{314.f, 0.f, 456.f}, {314.f, 330.f, 456.f}, {265.f, 330.f, 296.f}, {265.f, 0.f, 296.f}}},
    {{{265.f, 0.f, 296.f}, {265.f, 330.f, 296.f}, {423.f, 330.f, 247.f}, {423.f, 0.f, 247.f}}},
}};

inline constexpr float mm = 1e-3f;  // the data is in millimetres; bounce scenes are in metres

// Triangles get their own vertices with the exact face normal: the published quads are
// not all planar (the red wall bends by ~2 mm), so the two halves of a quad differ.
template <class Scene>
void add_triangle(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, std::uint32_t material) {
    a *= mm;
    b *= mm;
    c *= mm;
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const auto base = std::uint32_t(s.positions.size());
    for (const glm::vec3& p : {a, b, c}) {
        s.positions.push_back(p);
        s.normals.push_back(n);
    }
    s.triangles.emplace_back(base, base + 1, base + 2);
    s.material_of.push_back(material);
}

template <class Scene>
void add_quad(Scene& s, const quad& q, std::uint32_t material) {
    add_triangle(s, q[0], q[1], q[2], material);
    add_triangle(s, q[0], q[2], q[3], material);
}

}  // namespace detail::cornell

/// A scene that owns its arrays as `io::scene` does (a renderer's own struct will do):
/// vectors `positions`, `normals` (glm::vec3), `triangles` (glm::uvec3), `material_of`
/// (std::uint32_t), `materials` (bounce::material), `lights` (bounce::light), and
/// `use_emission` and `camera`.
template <class Scene>
concept owned_scene_arrays = requires(Scene& s) {
    s.positions.push_back(glm::vec3());
    s.normals.push_back(glm::vec3());
    s.triangles.emplace_back(0u, 0u, 0u);
    s.material_of.push_back(std::uint32_t(0));
    s.materials.push_back(material{});
    s.lights.emplace_back(spot_light{});
    s.use_emission = false;
    s.camera = camera{};
};

/// Replaces `s`'s geometry, materials (white, red, green, light), lights and camera with the
/// Cornell box in metres: 38 triangles (the ceiling a frame around the light opening), the
/// published camera with clip planes fitted to the box, and the light as point-like
/// techniques see it, a cosine spot carrying the light quad's power (use_emission false).
/// A `material_names` member, when `s` has one, gets the materials' names.
template <owned_scene_arrays Scene>
void build_cornell_box(Scene& s) {
    using namespace detail::cornell;
    s.positions.clear();
    s.normals.clear();
    s.triangles.clear();
    s.material_of.clear();
    s.lights.clear();
    enum : std::uint32_t { white, red, green, light };
    s.materials = {
        {{0.725f, 0.71f, 0.68f}, glm::vec3(0.f)},
        {{0.63f, 0.065f, 0.05f}, glm::vec3(0.f)},
        {{0.14f, 0.45f, 0.091f}, glm::vec3(0.f)},
        // The light's own reflectance is not published; 0.78 as in the Williams OBJ.
        {glm::vec3(0.78f), {17.f, 12.f, 4.f}},
    };
    if constexpr (requires { s.material_names = {"white", "red", "green", "light"}; })
        s.material_names = {"white", "red", "green", "light"};

    add_quad(s, floor_mm, white);
    add_quad(s, back_wall_mm, white);
    add_quad(s, right_wall_mm, green);
    add_quad(s, left_wall_mm, red);
    // The ceiling is a frame around the light opening, so that the light quad fills the
    // hole instead of lying on the ceiling (coplanar faces would fight in a depth buffer),
    // and every inner edge is shared: frame piece i joins ceiling corners i, i+1 to light
    // corners i+1, i (the two quads are listed in the same rotational order).
    for (int i = 0; i < 4; ++i) {
        const int j = (i + 1) % 4;
        add_triangle(s, ceiling_mm[i], ceiling_mm[j], light_mm[j], white);
        add_triangle(s, ceiling_mm[i], light_mm[j], light_mm[i], white);
    }
    add_quad(s, light_mm, light);
    for (const quad& q : short_block_mm) add_quad(s, q, white);
    for (const quad& q : tall_block_mm) add_quad(s, q, white);

    // Published camera: eye (278, 273, -800) mm looking along +z, up +y, focal length
    // 35 mm on a 25 x 25 mm film: fov = 2 atan(12.5 / 35) = 39.31 degrees.
    s.camera = camera{};
    s.camera.position = glm::vec3(278.f, 273.f, -800.f) * mm;
    s.camera.look_at = glm::vec3(278.f, 273.f, 0.f) * mm;
    s.camera.up = {0.f, 1.f, 0.f};
    s.camera.fov_y_deg = float(2.0 * std::atan(12.5 / 35.0) * 180.0 / std::numbers::pi);
    const scene_view v{s.positions, s.normals, s.triangles, s.material_of, s.materials, {}, false};
    fit_clip_planes(s.camera, v.bounds());

    // The light as point-like techniques see it (as the shared scene.json does): a cosine
    // spot 1 mm below the centre of the opening, pointing down. A Lambertian emitter of
    // radiance Ke and area A has intensity I(theta) = Ke A cos(theta); a cosine spot with
    // I0 = Ke A therefore emits the same power, pi Ke A sin^2(cone), i.e. all but
    // cos^2(89 deg) = 3e-4 of it.
    const float area = (343.f - 213.f) * (332.f - 227.f) * mm * mm;
    spot_light spot;
    spot.position = glm::vec3(0.5f * (343.f + 213.f), 548.8f - 1.f, 0.5f * (332.f + 227.f)) * mm;
    spot.direction = {0.f, -1.f, 0.f};
    spot.intensity = s.materials[light].emission * area;
    spot.cone_deg = 89.f;
    spot.falloff = spot_light::falloff_kind::cosine;
    s.lights.emplace_back(spot);
    s.use_emission = false;
}

}  // namespace bounce
