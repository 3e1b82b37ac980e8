// Emission agreement of the radiosity kernels: each, printed as GLSL and run in a compute
// shader (llvmpipe through EGL in CI), gives what its CPU float instantiation gives, over
// random inputs and the hard cases of each kernel.
//
// Tolerance: |gpu - cpu| <= 1e-5 * scale per output, scale the size of the output's terms
// rather than of the output itself (a cosine near zero keeps the absolute error of the dot
// product it comes from): A / (pi d^2 + A) for the form factor (its value with both cosines
// 1), times rho dB for a shot, 1 for projections, directions and texture coordinates (unit
// vectors and points of the unit square), the vector's length for frame changes. A kernel of
// k rounded float operations (GLSL allows 2-3 ulp for division and inversesqrt, and fused
// multiply-adds) is off by about 2 k ulp of its terms; 1e-5 is that for k up to 40, more
// than any kernel here has. The hemicube's face numbers come from comparisons of the same
// float values on both sides and must agree exactly.
#include "../gl/agreement_inputs.hpp"
#include "../gl/shared_context.hpp"

#include <bounce/gl/kernel_map.hpp>
#include <bounce/radiosity/kernels.hpp>
#include <bounce/radiosity/subdivision.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <tuple>
#include <vector>

using namespace bounce;
using glsl::f32;
using glsl::vec2;
using glsl::vec3;

namespace {
using namespace bounce::gl_test;
constexpr double tolerance = 1e-5;
constexpr int random_count = 5000;

const auto unit_scale = [](std::size_t) { return 1.0; };
}  // namespace

TEST_CASE("disc_form_factor, element_form_factor and shot_radiosity agree on the GPU and the CPU, hard cases included",
          "[glsl][radiosity]") {
    gl_test::shared_context();
    pcg32 rng(31);
    using ff_args = std::tuple<glm::vec3, glm::vec3, glm::vec3, glm::vec3, float>;
    std::vector<ff_args> in;
    const glm::vec3 up(0, 0, 1), down(0, 0, -1);
    in.emplace_back(glm::vec3(0.5f), up, glm::vec3(0.5f), down, 0.01f);             // coincident
    in.emplace_back(glm::vec3(0), up, glm::vec3(0, 0, 1), up, 0.01f);               // shooter faces away
    in.emplace_back(glm::vec3(0), down, glm::vec3(0, 0, 1), up, 0.01f);             // both away
    in.emplace_back(glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), down, 0.01f);  // grazing receiver
    in.emplace_back(glm::vec3(0), up, glm::vec3(0, 0, 1e-3f), down, 0.01f);         // very close
    for (int k = 0; k < random_count; ++k) {
        const glm::vec3 ps = random_unit(rng) * rng.next_float();
        const glm::vec3 pr = ps + random_unit(rng) * (0.001f + 3 * rng.next_float());
        in.emplace_back(pr, random_unit(rng), ps, random_unit(rng), 1e-4f + 0.1f * rng.next_float());
    }
    std::vector<float> cpu;
    for (const auto& a : in) cpu.push_back(std::apply(disc_form_factor<float, glm::vec3>, a));
    const auto gpu = gl::map_kernel(disc_form_factor<f32, vec3>, in);
    const auto scale = [&](std::size_t e) {
        const auto& [pr, nr, ps, ns, area] = in[e];
        const double d2 = glm::dot(ps - pr, ps - pr);
        return double(area) / (std::numbers::pi * d2 + double(area));
    };
    const double worst = worst_scaled(gpu, cpu, scale);
    INFO("worst scaled difference " << worst);
    CHECK(worst <= tolerance);
    CHECK(gpu[0] == 0.f);
    CHECK(gpu[1] == 0.f);
    CHECK(gpu[2] == 0.f);

    using shot_args = std::tuple<glm::vec3, glm::vec3, glm::vec3, glm::vec3, glm::vec3, float, glm::vec3, float>;
    std::vector<shot_args> shots;
    for (std::size_t e = 0; e < in.size(); ++e) {
        const auto& [pr, nr, ps, ns, area] = in[e];
        shots.emplace_back(pr, nr, glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()), ps, ns, area,
                           glm::vec3(10 * rng.next_float(), rng.next_float(), 0.f), e % 4 == 0 ? 0.f : 1.f);
    }
    std::vector<glm::vec3> cpu_shot;
    for (const auto& a : shots) cpu_shot.push_back(std::apply(shot_radiosity<float, glm::vec3>, a));
    const auto gpu_shot = gl::map_kernel(shot_radiosity<f32, vec3>, shots);
    const double worst_shot = worst_scaled(gpu_shot, cpu_shot, [&](std::size_t e) {
        const glm::vec3 rho = std::get<2>(shots[e]), db = std::get<6>(shots[e]);
        return std::max(1e-30, scale(e) * double(glm::length(rho * db)));
    });
    INFO("worst scaled shot difference " << worst_shot);
    CHECK(worst_shot <= tolerance);

    // element_form_factor, the solvers' factor: the receiver's area beside the shooter's,
    // smaller, equal and larger (up to 100 times: a big element next to a sliver).
    using element_args = std::tuple<glm::vec3, glm::vec3, float, glm::vec3, glm::vec3, float>;
    std::vector<element_args> elements;
    for (std::size_t e = 0; e < in.size(); ++e) {
        const auto& [pr, nr, ps, ns, area] = in[e];
        const float ratio = e % 3 == 0 ? 0.f : e % 3 == 1 ? 1.f : 100.f * rng.next_float();
        elements.emplace_back(pr, nr, area * ratio, ps, ns, area);
    }
    std::vector<float> cpu_element;
    for (const auto& a : elements) cpu_element.push_back(std::apply(element_form_factor<float, glm::vec3>, a));
    const auto gpu_element = gl::map_kernel(element_form_factor<f32, vec3>, elements);
    const double worst_element = worst_scaled(gpu_element, cpu_element, scale);
    INFO("worst scaled element factor difference " << worst_element);
    CHECK(worst_element <= tolerance);
    for (std::size_t e = 0; e < elements.size(); e += 3) CHECK(cpu_element[e] == cpu[e]);  // no receiver area
}

TEST_CASE("the stereographic projection, its inverse and its texture coordinates agree on the GPU and the CPU",
          "[glsl][radiosity]") {
    gl_test::shared_context();
    pcg32 rng(32);
    std::vector<std::tuple<glm::vec3>> dirs = {{glm::vec3(0, 0, 1)}, {glm::vec3(1, 0, 0)}, {glm::vec3(0, -1, 0)},
                                               {glm::vec3(1e-6f, 0, 1)}, {glm::vec3(3, 4, 1e-7f)}};
    for (int k = 0; k < random_count; ++k) dirs.emplace_back(random_upper(rng) * (0.01f + 5 * rng.next_float()));
    std::vector<glm::vec2> cpu, cpu_uv;
    for (const auto& [d] : dirs) {
        cpu.push_back(stereographic_project<float, glm::vec3, glm::vec2>(d));
        cpu_uv.push_back(stereographic_item_coords<float, glm::vec3, glm::vec2>(d));
    }
    CHECK(worst_scaled(gl::map_kernel(stereographic_project<f32, vec3, vec2>, dirs), cpu, unit_scale) <= tolerance);
    CHECK(worst_scaled(gl::map_kernel(stereographic_item_coords<f32, vec3, vec2>, dirs), cpu_uv, unit_scale) <=
          tolerance);

    std::vector<std::tuple<glm::vec2>> qs = {{glm::vec2(0)}, {glm::vec2(1, 0)}, {glm::vec2(0.6f, -0.8f)}};
    for (int k = 0; k < random_count; ++k) qs.emplace_back(glm::vec2(rng.next_float(), rng.next_float()) * 2.f - 1.f);
    std::vector<glm::vec3> cpu_dir;
    for (const auto& [q] : qs) cpu_dir.push_back(stereographic_direction<float, glm::vec3, glm::vec2>(q));
    CHECK(worst_scaled(gl::map_kernel(stereographic_direction<f32, vec3, vec2>, qs), cpu_dir, unit_scale) <= tolerance);

    std::vector<std::tuple<glm::vec3, float, float>> depth_in;
    for (int k = 0; k < random_count; ++k) depth_in.emplace_back(random_unit(rng) * (0.1f + 10 * rng.next_float()), 0.05f, 20.f);
    std::vector<float> cpu_depth;
    for (const auto& a : depth_in) cpu_depth.push_back(std::apply(hemisphere_depth<float, glm::vec3>, a));
    CHECK(worst_scaled(gl::map_kernel(hemisphere_depth<f32, vec3>, depth_in), cpu_depth, unit_scale) <= tolerance);
}

TEST_CASE("hemicube face coordinates and directions agree on the GPU and the CPU, face edges included",
          "[glsl][radiosity]") {
    gl_test::shared_context();
    pcg32 rng(33);
    // Face edges and corners: the ties that decide between faces.
    std::vector<std::tuple<glm::vec3>> dirs = {{glm::vec3(0, 0, 1)}, {glm::vec3(1, 0, 1)},  {glm::vec3(-1, 0, 1)},
                                               {glm::vec3(0, 1, 1)}, {glm::vec3(0, -1, 1)}, {glm::vec3(1, 1, 1)},
                                               {glm::vec3(1, 1, 0.5f)}, {glm::vec3(-1, 1, 0.5f)}, {glm::vec3(1, 0, 0)},
                                               {glm::vec3(0, -1, 0)}};
    for (int k = 0; k < random_count; ++k) dirs.emplace_back(random_upper(rng) * (0.01f + 5 * rng.next_float()));
    std::vector<glm::vec3> cpu;
    for (const auto& [d] : dirs) cpu.push_back(hemicube_face_coords<float, glm::vec3>(d));
    const auto gpu = gl::map_kernel(hemicube_face_coords<f32, vec3>, dirs);
    for (std::size_t e = 0; e < cpu.size(); ++e) REQUIRE(gpu[e].x == cpu[e].x);
    CHECK(worst_scaled(gpu, cpu, unit_scale) <= tolerance);

    std::vector<std::tuple<float, float, float>> in;
    for (int face = 0; face < 5; ++face) {
        in.emplace_back(float(face), 0.f, 0.f);
        in.emplace_back(float(face), 1.f, 1.f);
        for (int k = 0; k < random_count / 5; ++k) in.emplace_back(float(face), rng.next_float(), rng.next_float());
    }
    std::vector<glm::vec3> cpu_dir;
    for (const auto& a : in) cpu_dir.push_back(std::apply(hemicube_direction<float, glm::vec3>, a));
    CHECK(worst_scaled(gl::map_kernel(hemicube_direction<f32, vec3>, in), cpu_dir, unit_scale) <= tolerance);
}

TEST_CASE("the shooter frame and the ambient display agree on the GPU and the CPU", "[glsl][radiosity]") {
    gl_test::shared_context();
    pcg32 rng(34);
    std::vector<std::tuple<glm::vec3, glm::vec3, glm::vec3, glm::vec3, glm::vec3>> in;
    for (int k = 0; k < random_count; ++k) {
        const glm::vec3 n = random_unit(rng);
        const auto tb = orthonormal_basis<float, glm::vec3>(n);
        in.emplace_back(random_unit(rng) * 3.f, random_unit(rng) * rng.next_float(), tb[0], tb[1], n);
    }
    std::vector<glm::vec3> cpu;
    for (const auto& a : in) cpu.push_back(std::apply(to_shooter_frame<float, glm::vec3>, a));
    CHECK(worst_scaled(gl::map_kernel(to_shooter_frame<f32, vec3>, in), cpu, [&](std::size_t e) {
              return std::max(1e-30, double(glm::length(std::get<0>(in[e]) - std::get<1>(in[e]))));
          }) <= tolerance);

    std::vector<std::tuple<glm::vec3, glm::vec3, glm::vec3>> amb;
    for (int k = 0; k < random_count; ++k)
        amb.emplace_back(glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 5.f,
                         glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()),
                         glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()));
    std::vector<glm::vec3> cpu_amb;
    for (const auto& a : amb) cpu_amb.push_back(std::apply(radiosity_with_ambient<float, glm::vec3>, a));
    CHECK(worst_scaled(gl::map_kernel(radiosity_with_ambient<f32, vec3>, amb), cpu_amb, [](std::size_t) { return 6.0; }) <=
          tolerance);
}

TEST_CASE("the subdivision test's second difference agrees on the GPU and the CPU", "[glsl][radiosity]") {
    // A flag, 0 or 1: it must agree exactly except where |b0 - 2 b1 + b2| lies within the
    // rounding of the comparison (a few ulps of the terms) of the limit; inputs are drawn so
    // that none does (limits on a grid of 1/8, radiosities on a grid of 1/4: the second
    // difference is a multiple of 1/4 and never within 1/8 of a limit).
    gl_test::shared_context();
    pcg32 rng(35);
    std::vector<std::tuple<float, float, float, float>> in;
    for (int k = 0; k < random_count; ++k)
        in.emplace_back(float(int(rng.next_float() * 40)) / 4, float(int(rng.next_float() * 40)) / 4,
                        float(int(rng.next_float() * 40)) / 4, float(int(rng.next_float() * 80)) / 4 + 0.125f);
    std::vector<float> cpu;
    for (const auto& a : in) cpu.push_back(std::apply(radiosity_second_difference<float>, a));
    const auto gpu = gl::map_kernel(radiosity_second_difference<f32>, in);
    int ones = 0;
    for (std::size_t e = 0; e < cpu.size(); ++e) {
        REQUIRE(gpu[e] == cpu[e]);
        ones += cpu[e] > 0 ? 1 : 0;
    }
    CHECK(ones > 100);
    CHECK(ones < random_count - 100);
}

namespace {

// Texel numbers (whole numbers) from the GPU and the CPU agree, except where the coordinate
// they are floored from lies within rounding (1e-5 of its size, at least 1e-5 texel) of the
// texel boundary between them: GLSL's division and inversesqrt may round the other way.
bool same_texel(double gpu, double cpu, double coord) {
    if (gpu == cpu) return true;
    return std::abs(gpu - cpu) == 1 && std::abs(coord - std::max(gpu, cpu)) <= 1e-5 * std::max(1.0, std::abs(coord));
}

// A direction on the unit sphere, behind the shooter too, but not within 25 degrees of
// straight behind it (where the stereographic map runs off to infinity).
glm::vec3 random_around(pcg32& rng) {
    glm::vec3 d = random_unit(rng);
    if (d.z < -0.9f) d.z = -d.z;
    return d;
}

}  // namespace

TEST_CASE("where an element is looked up agrees on the GPU and the CPU: face and texel edges, grazing, behind",
          "[glsl][radiosity]") {
    // The texel of an element in the stereographic buffer, on the hemicube, and in a
    // directional light's buffer, and a hemicube face's first row. Points behind the shooter
    // (which the solvers never ask about) must still land on the buffer's border.
    gl_test::shared_context();
    pcg32 rng(36);
    const float res = 128.f;
    std::vector<std::tuple<glm::vec3, float>> in;
    for (const glm::vec3 d : {glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::vec3(0, -1, 0), glm::vec3(3, 4, 1e-7f),
                              glm::vec3(1, 0, 1), glm::vec3(-1, 0, 1), glm::vec3(0, 1, 1), glm::vec3(0, -1, 1),
                              glm::vec3(1, 1, 1), glm::vec3(1, 1, 0.5f), glm::vec3(-1, 1, 0.5f), glm::vec3(1, -1, 0.5f),
                              glm::vec3(1, 0.3f, 1 - 1e-6f), glm::vec3(1, 0.3f, 1 + 1e-6f),
                              glm::vec3(0.5f, 0.5f + 1e-7f, 0.2f), glm::vec3(1, 0.2f, 1e-7f), glm::vec3(0.3f, -1, 0),
                              glm::vec3(0.3f, 0.2f, -0.5f), glm::vec3(-1, 0.2f, -0.5f), glm::vec3(0.1f, 0.2f, -1)})
        in.emplace_back(d, res);
    for (int k = 0; k < random_count; ++k) in.emplace_back(random_around(rng) * (0.01f + 5 * rng.next_float()), res);
    int flips = 0, wrong = 0;
    const auto compare = [&](double gpu, double cpu, double coord) {
        flips += gpu != cpu ? 1 : 0;
        wrong += same_texel(gpu, cpu, coord) ? 0 : 1;
    };

    const auto gpu_st = gl::map_kernel(stereographic_item_texel<f32, vec3, vec2>, in);
    for (std::size_t e = 0; e < in.size(); ++e) {
        const glm::vec3 l = std::get<0>(in[e]);
        const glm::vec2 cpu = stereographic_item_texel<float, glm::vec3, glm::vec2>(l, res);
        const glm::vec2 coord = stereographic_item_coords<float, glm::vec3, glm::vec2>(l) * res;
        compare(gpu_st[e].x, cpu.x, coord.x);
        compare(gpu_st[e].y, cpu.y, coord.y);
    }
    const auto gpu_cube = gl::map_kernel(hemicube_item_texel<f32, vec3>, in);
    for (std::size_t e = 0; e < in.size(); ++e) {
        const glm::vec3 l = std::get<0>(in[e]);
        const glm::vec3 cpu = hemicube_item_texel<float, glm::vec3>(l, res);
        const glm::vec3 f = hemicube_face_coords<float, glm::vec3>(l);
        REQUIRE(gpu_cube[e].x == cpu.x);
        compare(gpu_cube[e].y, cpu.y, f.y * res);
        compare(gpu_cube[e].z, cpu.z, f.z * hemicube_face_rows(f.x, res));
    }
    std::vector<std::tuple<float, float>> faces;
    for (int face = 0; face < 5; ++face) faces.emplace_back(float(face), res);
    const auto rows = gl::map_kernel(hemicube_face_first_row<f32>, faces);
    for (int face = 0; face < 5; ++face) CHECK(rows[std::size_t(face)] == hemicube_face_first_row(float(face), res));

    // A directional light's buffer over a box of side 7 about the origin; points inside it,
    // outside it, and on its corner.
    const glm::vec3 light = glm::normalize(glm::vec3(0.3f, -1, 0.2f));
    const auto tb = orthonormal_basis<float, glm::vec3>(light);
    const glm::vec2 lo(-3.5f);
    const float scale = res / 7.f;
    std::vector<std::tuple<glm::vec3, glm::vec3, glm::vec3, glm::vec2, float, float>> par;
    par.emplace_back(tb[0] * -3.5f + tb[1] * -3.5f, tb[0], tb[1], lo, scale, res);
    par.emplace_back(tb[0] * 3.5f + tb[1] * 3.5f + light * 2.f, tb[0], tb[1], lo, scale, res);
    for (int k = 0; k < random_count; ++k)
        par.emplace_back(random_point(rng, k % 5 == 0 ? 12.f : 3.5f), tb[0], tb[1], lo, scale, res);
    const auto gpu_par = gl::map_kernel(parallel_item_texel<f32, vec3, vec2>, par);
    std::vector<std::tuple<glm::vec3, glm::vec3, glm::vec3, glm::vec2, float>> par_coords;
    std::vector<glm::vec2> cpu_coords;
    for (std::size_t e = 0; e < par.size(); ++e) {
        const auto& [p, t, b, corner, s, r] = par[e];
        const glm::vec2 cpu = parallel_item_texel<float, glm::vec3, glm::vec2>(p, t, b, corner, s, r);
        const glm::vec2 coord = parallel_item_coords<float, glm::vec3, glm::vec2>(p, t, b, corner, s);
        compare(gpu_par[e].x, cpu.x, coord.x);
        compare(gpu_par[e].y, cpu.y, coord.y);
        par_coords.emplace_back(p, t, b, corner, s);
        cpu_coords.push_back(coord);
    }
    CHECK(worst_scaled(gl::map_kernel(parallel_item_coords<f32, vec3, vec2>, par_coords), cpu_coords,
                       [&](std::size_t e) { return (double(glm::length(std::get<0>(par[e]))) + 3.5) * scale; }) <=
          tolerance);
    INFO(flips << " texels differ, all within rounding of a texel edge but " << wrong);
    CHECK(wrong == 0);
    CHECK(flips < 10);
}

TEST_CASE("a hemicube face's clip position and coordinates and a stereographic texel's direction agree on the GPU "
          "and the CPU",
          "[glsl][radiosity]") {
    gl_test::shared_context();
    pcg32 rng(37);
    // Points in a face's frame: inside its frustum, on its edges and corners, grazing.
    std::vector<std::tuple<glm::vec3, float, float, float>> in;
    for (int face = 0; face < 5; ++face) {
        for (const glm::vec3 q : {glm::vec3(0, 0, 1), glm::vec3(1, 1, 1), glm::vec3(-1, 0, 1), glm::vec3(0.5f, 0, 0.5f),
                                  glm::vec3(1, 1e-7f, 1e-6f), glm::vec3(-2, 0.5f, 1e-3f)})
            in.emplace_back(q, float(face), 0.01f, 10.f);
        for (int k = 0; k < random_count / 5; ++k) {
            const float z = 0.01f + 5 * rng.next_float();
            in.emplace_back(glm::vec3(rng.next_float() * 2 - 1, rng.next_float() * 2 - 1, 0) * z + glm::vec3(0, 0, z),
                            float(face), 0.01f, 10.f);
        }
    }
    std::vector<glm::vec4> cpu;
    for (const auto& a : in) cpu.push_back(std::apply(hemicube_face_clip<float, glm::vec3, glm::vec4>, a));
    CHECK(worst_scaled(gl::map_kernel(hemicube_face_clip<f32, vec3, glsl::vec4>, in), cpu, [&](std::size_t e) {
              return 2 * (double(glm::length(std::get<0>(in[e]))) + 1);
          }) <= tolerance);
    std::vector<std::tuple<glm::vec3, float>> on_face;
    std::vector<glm::vec3> cpu_on_face;
    for (const auto& [q, face, near_z, far_z] : in) {
        on_face.emplace_back(q, face);
        cpu_on_face.push_back(hemicube_coords_on_face<float, glm::vec3>(q, face));
    }
    const auto gpu_on_face = gl::map_kernel(hemicube_coords_on_face<f32, vec3>, on_face);
    // u, v of a point on the face are within [0, 1] (scale 1); off the face, s and t grow as
    // the point's sideways distance over its forward one.
    CHECK(worst_scaled(gpu_on_face, cpu_on_face, [&](std::size_t e) {
              const glm::vec3 q = std::get<0>(on_face[e]);
              return std::max(1.0, double(std::max(std::abs(q.x), std::abs(q.y)) / q.z));
          }) <= tolerance);

    std::vector<std::tuple<glm::vec2, float>> centres = {{glm::vec2(0.5f), 128.f}, {glm::vec2(127.5f), 128.f},
                                                         {glm::vec2(64.f), 128.f}, {glm::vec2(0.5f, 127.5f), 128.f}};
    for (int k = 0; k < random_count; ++k)
        centres.emplace_back(glm::vec2(float(int(rng.next_float() * 256)), float(int(rng.next_float() * 256))) + 0.5f,
                             256.f);
    std::vector<glm::vec3> cpu_dir;
    for (const auto& a : centres) cpu_dir.push_back(std::apply(stereographic_texel_direction<float, glm::vec3, glm::vec2>, a));
    CHECK(worst_scaled(gl::map_kernel(stereographic_texel_direction<f32, vec3, vec2>, centres), cpu_dir, unit_scale) <=
          tolerance);
}

TEST_CASE("the side of a light's hemisphere a receiver is on agrees on the GPU and the CPU, the plane included",
          "[glsl][radiosity]") {
    gl_test::shared_context();
    pcg32 rng(38);
    const glm::vec3 light(1, 2, 3), up(0, 0, 1);
    std::vector<std::tuple<glm::vec3, glm::vec3, glm::vec3, float>> in = {
        {glm::vec3(4, -2, 3), light, up, 0.f},  {glm::vec3(4, -2, 3), light, up, 1.f},
        {glm::vec3(4, -2, 3), light, -up, 0.f}, {glm::vec3(4, -2, 3), light, -up, 1.f},
        {glm::vec3(1, 2, 4), light, up, 1.f},   {glm::vec3(1, 2, 2), light, -up, 1.f}};
    for (int k = 0; k < random_count; ++k) {
        const glm::vec3 p = random_point(rng, 3.f), o = random_point(rng, 3.f), axis = random_unit(rng);
        // Away from the plane by more than the rounding of the dot product.
        if (std::abs(glm::dot(p - o, axis)) < 1e-4f) continue;
        in.emplace_back(p, o, axis, float(k % 2));
    }
    std::vector<float> cpu;
    for (const auto& a : in) cpu.push_back(std::apply(light_hemisphere_side<float, glm::vec3>, a));
    const auto gpu = gl::map_kernel(light_hemisphere_side<f32, vec3>, in);
    for (std::size_t e = 0; e < in.size(); ++e) REQUIRE(gpu[e] == cpu[e]);
    CHECK(cpu[0] == 1.f);
    CHECK(cpu[1] == 0.f);
    CHECK(cpu[2] == 1.f);
    CHECK(cpu[3] == 0.f);
}
