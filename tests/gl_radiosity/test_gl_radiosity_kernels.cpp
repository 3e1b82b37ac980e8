// The GL radiosity passes' own kernels (include/bounce/radiosity/kernels.hpp), printed as GLSL and run on
// llvmpipe, against their CPU float instantiation over random and hard inputs.
//
// Tolerance: item_plane_depth is d / (n . w), n . w off by a few ulps of 1: 1e-5 of its value
// divided by n . w (1e-5 covers the kernels' few ulps, as in tests/radiosity's agreement test). The three decisions
// (0 or 1) must agree exactly, except for inputs whose deciding quantity lies within a
// rounding (1e-4 relative, far above the few ulps two float evaluations can differ by) of its
// threshold; those are counted and left out, and must be rare.
#include "../gl/agreement_inputs.hpp"
#include "../gl/shared_context.hpp"

#include <bounce/gl/kernel_map.hpp>
#include <bounce/radiosity/kernels.hpp>
#include <bounce/radiosity/sides.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <tuple>
#include <vector>

using namespace bounce;
using glsl::f32;
using glsl::vec3;
using namespace bounce::gl_test;

namespace {
constexpr int random_count = 4000;

// Compares a 0/1 kernel on all inputs whose margin (double) is not within 1e-4 of the
// threshold; returns how many were left out.
template <class In>
std::size_t check_decisions(const std::vector<float>& gpu, const std::vector<float>& cpu, const std::vector<In>& in,
                            const std::vector<double>& margin) {
    std::size_t left_out = 0, disagree = 0;
    for (std::size_t e = 0; e < in.size(); ++e) {
        if (std::abs(margin[e]) <= 1e-4) {
            ++left_out;
            continue;
        }
        if (gpu[e] != cpu[e]) ++disagree;
    }
    CHECK(disagree == 0);
    return left_out;
}
}  // namespace

TEST_CASE("item_plane_depth agrees on the GPU and the CPU, edge-on planes included", "[glsl][gl][radiosity]") {
    gl_test::shared_context();
    pcg32 rng(71);
    using args = std::tuple<glm::vec3, float, glm::vec3, float>;
    std::vector<args> in = {{glm::vec3(0, 0, 1), 1.f, glm::vec3(0, 0, 1), 5.f},
                            {glm::vec3(0, 0, 1), 1.f, glm::vec3(1, 0, 0), 5.f},   // edge-on: the interpolated depth
                            {glm::vec3(0, 0, 1), 1.f, glm::vec3(0, 0, -1), 5.f}}; // facing away
    for (int k = 0; k < random_count; ++k) {
        const glm::vec3 n = random_unit(rng), w = random_upper(rng);
        // Keep clear of the edge-on threshold nw = 1e-6, where the two sides may choose differently.
        if (std::abs(glm::dot(n, w) - 1e-6f) < 1e-4f) continue;
        in.emplace_back(n, 0.01f + 3 * rng.next_float(), w, 0.01f + 3 * rng.next_float());
    }
    std::vector<float> cpu;
    for (const auto& a : in) cpu.push_back(std::apply(bounce::item_plane_depth<float, glm::vec3>, a));
    const auto gpu = gl::map_kernel(bounce::item_plane_depth<f32, vec3>, in);
    // d / (n . w): the dot product of unit vectors is off by a few ulps of 1, absolutely, so the
    // quotient is off by that over n . w, relatively: the scale is |depth| / |n . w|.
    CHECK(worst_scaled(gpu, cpu, [&](std::size_t e) {
              const double nw = std::abs(glm::dot(std::get<0>(in[e]), std::get<2>(in[e])));
              return std::max(1e-30, std::abs(double(cpu[e])) / std::clamp(nw, 1e-6, 1.0));
          }) <= 1e-5);
    CHECK(gpu[0] == 1.f);
    CHECK(gpu[1] == 5.f);
    CHECK(gpu[2] == 5.f);
}

TEST_CASE("the item-buffer lookups and the near-field test decide alike on the GPU and the CPU", "[glsl][gl][radiosity]") {
    gl_test::shared_context();
    pcg32 rng(72);
    const float diagonal = 3.f;
    {
        // item_buffer_sees: the element at distance dist along its ray, the plane n . x = d
        // met at d / (n . w); seen when that is beyond dist - slack.
        using args = std::tuple<glm::vec3, float, float, glm::vec3, float, float, float>;
        std::vector<args> in = {
            {glm::vec3(0, 0, 1), 2.f, 2.f, glm::vec3(0, 0, 1), 0.5f, 0.5f, diagonal},   // own chart
            {glm::vec3(0, 0, 1), 2.f, -1.f, glm::vec3(0, 0, 1), 0.5f, 0.5f, diagonal},  // nothing drawn
            {glm::vec3(0, 0, 1), 2.f, 3.f, glm::vec3(0, 0, 1), 0.5f, 0.5f, diagonal},   // occluder in front
            {glm::vec3(0, 0, 1), 2.f, 3.f, glm::vec3(0, 0, 1), 2.f, 2.f, diagonal},     // coplanar: seen (slack)
            {glm::vec3(0, 0, 1), 2.f, 3.f, glm::vec3(1, 0, 0), 0.5f, 0.5f, diagonal},   // edge-on, depth in front
            {glm::vec3(0, 0, 1), 2.f, 3.f, glm::vec3(1, 0, 0), 0.5f, 1.5f, diagonal}};  // edge-on, depth behind
        std::vector<double> margin(in.size(), 1.0);
        for (int k = 0; k < random_count; ++k) {
            const glm::vec3 p = random_upper(rng) * (0.05f + 2 * rng.next_float());
            glm::vec3 n = random_unit(rng);
            const float d = 0.05f + 2 * rng.next_float();
            const float shown = float(rng.next_u32() % 3) - 1.f;
            in.emplace_back(p, 1.f, shown, n, d, 0.05f + 2 * rng.next_float(), diagonal);
            const double dist = glm::length(glm::dvec3(p)), nw = glm::dot(glm::dvec3(n), glm::dvec3(p)) / dist;
            const double slack = 1e-4 * dist + 1e-6 * diagonal;
            const double m = std::abs(nw - 1e-6) < 1e-4 ? 0.0
                             : nw <= 1e-6            ? (double(std::get<5>(in.back())) - (dist - slack)) / dist
                                                     : (double(d) / nw - (dist - slack)) / dist;
            margin.push_back(shown == 1.f || shown < 0 ? 1.0 : m);
        }
        std::vector<float> cpu;
        for (const auto& a : in) cpu.push_back(std::apply(bounce::item_buffer_sees<float, glm::vec3>, a));
        const auto gpu = gl::map_kernel(bounce::item_buffer_sees<f32, vec3>, in);
        CHECK(check_decisions(gpu, cpu, in, margin) <= in.size() / 100);
        CHECK(std::vector<float>(gpu.begin(), gpu.begin() + 6) == std::vector<float>{1, 1, 0, 1, 0, 1});
    }
    {
        using args = std::tuple<glm::vec3, float, float, glm::vec3, float, float, glm::vec3, float>;
        const glm::vec3 down(0, -1, 0);
        std::vector<args> in = {
            {glm::vec3(0, 0, 0), 2.f, 3.f, glm::vec3(0, 1, 0), 1.f, 0.f, down, diagonal},    // plane above: upstream, hidden
            {glm::vec3(0, 0, 0), 2.f, 3.f, glm::vec3(0, 1, 0), -1.f, 0.f, down, diagonal},   // plane below: seen
            {glm::vec3(0, 0, 0), 2.f, 3.f, glm::vec3(1, 0, 0), 0.f, -1.f, down, diagonal}};  // parallel, depth upstream
        std::vector<double> margin(in.size(), 1.0);
        for (int k = 0; k < random_count; ++k) {
            const glm::vec3 p = random_point(rng, 1.f), n = random_unit(rng), dir = random_unit(rng);
            const float w = 2 * rng.next_float() - 1;
            in.emplace_back(p, 1.f, 2.f, n, w, 2 * rng.next_float() - 1, dir, diagonal);
            const double nd = glm::dot(glm::dvec3(n), glm::dvec3(dir));
            const double s = (double(w) - glm::dot(glm::dvec3(n), glm::dvec3(p))) / nd;
            margin.push_back(std::abs(std::abs(nd) - 1e-6) < 1e-4 ? 0.0
                             : std::abs(nd) <= 1e-6             ? 1.0
                                                                : s + 1e-6 * diagonal);
        }
        std::vector<float> cpu;
        for (const auto& a : in) cpu.push_back(std::apply(bounce::parallel_item_sees<float, glm::vec3>, a));
        const auto gpu = gl::map_kernel(bounce::parallel_item_sees<f32, vec3>, in);
        CHECK(check_decisions(gpu, cpu, in, margin) <= in.size() / 100);
        CHECK(std::vector<float>(gpu.begin(), gpu.begin() + 3) == std::vector<float>{0, 1, 0});
    }
    {
        using args = std::tuple<glm::vec3, glm::vec3, float, float>;
        std::vector<args> in;
        std::vector<double> margin;
        for (int k = 0; k < random_count; ++k) {
            const glm::vec3 r = random_point(rng, 1.f), q = random_point(rng, 1.f);
            const float area = 0.001f + 0.05f * rng.next_float(), near2 = 16.f;
            in.emplace_back(r, q, area, near2);
            const double d2 = glm::dot(glm::dvec3(q - r), glm::dvec3(q - r));
            margin.push_back((d2 - double(near2) * area) / (double(near2) * area));
        }
        std::vector<float> cpu;
        for (const auto& a : in) cpu.push_back(std::apply(bounce::near_field_opens<float, glm::vec3>, a));
        const auto gpu = gl::map_kernel(bounce::near_field_opens<f32, vec3>, in);
        CHECK(check_decisions(gpu, cpu, in, margin) <= in.size() / 100);
        CHECK(std::count(cpu.begin(), cpu.end(), 1.f) > 10);  // both outcomes occur
        CHECK(std::count(cpu.begin(), cpu.end(), 0.f) > 10);
    }
    {
        // The side a source lights (radiosity/sides.hpp): two-sided and one-sided.
        using args = std::tuple<glm::vec3, glm::vec3, glm::vec3, float>;
        std::vector<args> in;
        std::vector<double> margin;
        for (int k = 0; k < random_count; ++k) {
            const glm::vec3 r = random_point(rng, 1.f), q = random_point(rng, 1.f);
            const glm::vec3 n = glm::normalize(random_point(rng, 1.f) + glm::vec3(1e-3f));
            const float two_sided = k % 4 == 0 ? 0.f : 1.f;
            in.emplace_back(r, n, q, two_sided);
            margin.push_back(glm::dot(glm::dvec3(n), glm::dvec3(q - r)) / std::max(1e-30, glm::length(glm::dvec3(q - r))));
        }
        std::vector<float> cpu;
        for (const auto& a : in) cpu.push_back(std::apply(bounce::receiving_side<float, glm::vec3>, a));
        const auto gpu = gl::map_kernel(bounce::receiving_side<f32, vec3>, in);
        CHECK(check_decisions(gpu, cpu, in, margin) <= in.size() / 100);
        CHECK(std::count(cpu.begin(), cpu.end(), 1.f) > 10);  // both outcomes occur
        CHECK(std::count(cpu.begin(), cpu.end(), 0.f) > 10);
        for (std::size_t e = 0; e < in.size(); e += 4) CHECK(cpu[e] == 0.f);  // one-sided: the front always
    }
}
