// Emission agreement: each kernel, emitted to GLSL, compiled into a compute shader and run
// on the GPU (llvmpipe through EGL in CI) over 10,000 random inputs and the adversarial
// ones (poles, n = (0, 0, -1), u at 0, 1/2, 1 and their neighbours), gives what the CPU
// float instantiation gives.
//
// Tolerance, per output value v (CPU) and g (GPU): |g - v| <= 1e-5 |v| where |v| >= tiny,
// and |g - v| <= 5e-7 where |v| < tiny, with tiny = 0.05. Every kernel here works on
// quantities of order one (unit vectors, u in [0, 1], SH values below 1.3), so the rounding
// error of any output is a few float ulps of 1 (ulp = 1.2e-7) in absolute terms, whatever
// the output's own size, and GPU built-ins (sin, cos, inversesqrt, division) and fused
// multiply-adds may differ from the CPU's by an ulp or two each: allowing 4 ulp of 1
// (5e-7) absolute, a relative bound of 1e-5 is meaningful from 5e-7 / 1e-5 = 0.05 up.
// (llvmpipe measures 1 ulp of 1 at most: 6e-6 relative just above 1e-2.)
// One output is worse conditioned: cosine_hemisphere's z = sqrt(1 - x^2 - y^2) turns an
// absolute difference delta of x^2 + y^2 (up to 4 ulp, from sin and cos) into
// min(sqrt(delta), delta / (2 z)); that is below 1e-5 z only for z >= 0.2, so z has
// tiny = 0.2 and, below it, the bound sqrt(8 ulp) = 1e-3 (at the rim z is rounding noise).
#include "shared_context.hpp"

#include <bounce/gl/kernel_map.hpp>
#include <bounce/sampling.hpp>
#include <bounce/sh/basis.hpp>
#include <bounce/surface.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>
#include <tuple>
#include <vector>

namespace bounce::agreement_test {

// A kernel with a tuple result and a boolean in it, to cover out parameters of each kind.
template <real T, vec3_of<T> V>
auto length_direction_upper(const V& v) {
    return std::tuple{length(v), normalize(v), v.z > T(0)};
}

constexpr double relative_tolerance = 1e-5;
constexpr int random_count = 10000;

// What "tiny" means for one output value, and the absolute bound that applies below it.
struct tiny_rule {
    double tiny = 0.05, bound = 5e-7;
};

void flatten(float v, std::vector<float>& out) { out.push_back(v); }
void flatten(bool v, std::vector<float>& out) { out.push_back(v ? 1.f : 0.f); }
template <int N>
void flatten(const glm::vec<N, float>& v, std::vector<float>& out) {
    for (int i = 0; i < N; ++i) out.push_back(v[i]);
}
template <class E, std::size_t N>
void flatten(const std::array<E, N>& v, std::vector<float>& out) {
    for (const auto& e : v) flatten(e, out);
}
template <class... E>
void flatten(const std::tuple<E...>& v, std::vector<float>& out) {
    std::apply([&](const auto&... e) { (flatten(e, out), ...); }, v);
}

struct agreement {
    double worst = 0;         // largest |g - v| / |v| over values not tiny
    double worst_tiny = 0;    // largest |g - v| / bound over tiny values (must be <= 1)
    std::size_t element = 0;  // where the worst relative difference is
    float gpu = 0, cpu = 0;
    std::size_t values = 0, tiny = 0, non_finite = 0;
};

// Compares element by element; `rule(k)` gives the tiny rule of the k-th float of a result.
template <class R, class Rule>
agreement compare(const std::vector<R>& gpu, const std::vector<R>& cpu, Rule rule) {
    agreement a;
    REQUIRE(gpu.size() == cpu.size());
    std::vector<float> g, c;
    for (std::size_t e = 0; e < cpu.size(); ++e) {
        g.clear();
        c.clear();
        flatten(gpu[e], g);
        flatten(cpu[e], c);
        for (std::size_t k = 0; k < c.size(); ++k) {
            ++a.values;
            if (!std::isfinite(c[k]) || !std::isfinite(g[k])) {
                ++a.non_finite;
                continue;
            }
            const tiny_rule r = rule(k);
            const double diff = std::abs(double(g[k]) - double(c[k])), v = std::abs(double(c[k]));
            if (v < r.tiny) {
                ++a.tiny;
                a.worst_tiny = std::max(a.worst_tiny, diff / r.bound);
            } else if (diff / v > a.worst) {
                a.worst = diff / v;
                a.element = e;
                a.gpu = g[k];
                a.cpu = c[k];
            }
        }
    }
    return a;
}

template <class R>
agreement compare(const std::vector<R>& gpu, const std::vector<R>& cpu) {
    return compare(gpu, cpu, [](std::size_t) { return tiny_rule{}; });
}

std::string describe(const agreement& a) {
    std::ostringstream s;
    s.precision(9);
    s << "worst relative difference " << a.worst << " at element " << a.element << ": gpu " << a.gpu << ", cpu "
      << a.cpu << "; tiny values within " << a.worst_tiny << " of their bound (" << a.values << " values, " << a.tiny
      << " tiny)";
    return s.str();
}

// Unit vectors: the ones that break naive formulas, then random ones (fixed seed).
std::vector<glm::vec3> unit_vectors(std::uint64_t seed) {
    std::vector<glm::vec3> v = {{0, 0, 1},     {0, 0, -1},      {1, 0, 0},       {-1, 0, 0},    {0, 1, 0},
                                {0, -1, 0},    {0.6f, 0.8f, 0}, {0.6f, 0.8f, -0.f}, {-0.f, -0.f, -1}, {1e-9f, 0, -1},
                                {0, 1e-7f, -1}, {1e-4f, 1e-4f, -1}, {-1e-12f, 1e-12f, -1}, {1e-4f, -1e-4f, 1},
                                {1, 1, 1},     {-1, -1, -1}};
    pcg32 rng(seed);
    for (int i = 0; i < random_count; ++i) {
        const float z = 2 * rng.next_float() - 1, phi = 6.2831853f * rng.next_float();
        const float r = std::sqrt(std::max(0.f, 1 - z * z));
        v.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    for (auto& n : v) n = glm::normalize(n);
    return v;
}

// Points of the unit square: a grid of the values where the concentric map changes wedge
// or divides by a vanishing offset, then random ones.
std::vector<glm::vec2> square_points(std::uint64_t seed) {
    const float edges[] = {0.f, 1e-7f, 0.25f, std::nextafter(0.5f, 0.f), 0.5f, std::nextafter(0.5f, 1.f),
                           0.75f, std::nextafter(1.f, 0.f), 1.f};
    std::vector<glm::vec2> u;
    for (float a : edges)
        for (float b : edges) u.emplace_back(a, b);
    pcg32 rng(seed);
    for (int i = 0; i < random_count; ++i) u.emplace_back(rng.next_float(), rng.next_float());
    return u;
}

}  // namespace bounce::agreement_test

using namespace bounce;
using namespace bounce::agreement_test;
using glsl::f32;
using glsl::vec2;
using glsl::vec3;

TEST_CASE("orthonormal_basis agrees on the GPU and the CPU, n = (0, 0, -1) included", "[glsl][agreement]") {
    gl_test::shared_context();
    const auto ns = unit_vectors(1);
    std::vector<std::tuple<glm::vec3>> in;
    std::vector<std::array<glm::vec3, 2>> cpu;
    for (const auto& n : ns) {
        in.emplace_back(n);
        cpu.push_back(orthonormal_basis<float, glm::vec3>(n));
    }
    const auto gpu = gl::map_kernel(orthonormal_basis<f32, vec3>, in);
    const auto a = compare(gpu, cpu);
    INFO(describe(a));
    CHECK(a.non_finite == 0);
    CHECK(a.worst < relative_tolerance);
    CHECK(a.worst_tiny <= 1.0);
}

TEST_CASE("to_world agrees on the GPU and the CPU", "[glsl][agreement]") {
    gl_test::shared_context();
    const auto ns = unit_vectors(2), ds = unit_vectors(3);
    std::vector<std::tuple<glm::vec3, glm::vec3>> in;
    std::vector<glm::vec3> cpu;
    for (std::size_t i = 0; i < ns.size(); ++i) {
        // Every adversarial normal meets every adversarial direction once.
        const auto& d = ds[(i * 7) % ds.size()];
        in.emplace_back(d, ns[i]);
        cpu.push_back(to_world<float, glm::vec3>(d, ns[i]));
    }
    const auto gpu = gl::map_kernel(to_world<f32, vec3>, in);
    const auto a = compare(gpu, cpu);
    INFO(describe(a));
    CHECK(a.non_finite == 0);
    CHECK(a.worst < relative_tolerance);
    CHECK(a.worst_tiny <= 1.0);
}

TEST_CASE("concentric_disc and cosine_hemisphere (select, sin, cos) agree on the GPU and the CPU",
          "[glsl][agreement]") {
    gl_test::shared_context();
    const auto us = square_points(4);
    std::vector<std::tuple<glm::vec2>> in;
    std::vector<glm::vec2> cpu_disc;
    std::vector<glm::vec3> cpu_hemi;
    for (const auto& u : us) {
        in.emplace_back(u);
        cpu_disc.push_back(concentric_disc<float, glm::vec2>(u));
        cpu_hemi.push_back(cosine_hemisphere<float, glm::vec3, glm::vec2>(u));
    }
    const auto disc = compare(gl::map_kernel(concentric_disc<f32, vec2>, in), cpu_disc);
    const auto hemi = compare(gl::map_kernel(cosine_hemisphere<f32, vec3, vec2>, in), cpu_hemi, [](std::size_t k) {
        return k == 2 ? tiny_rule{0.2, 1e-3} : tiny_rule{};  // z: see the file comment
    });
    INFO("concentric_disc: " << describe(disc));
    INFO("cosine_hemisphere: " << describe(hemi));
    CHECK(disc.non_finite == 0);
    CHECK(hemi.non_finite == 0);
    CHECK(disc.worst < relative_tolerance);
    CHECK(disc.worst_tiny <= 1.0);
    CHECK(hemi.worst < relative_tolerance);
    CHECK(hemi.worst_tiny <= 1.0);
}

TEST_CASE("sh_basis<4> (compile-time loops) agrees on the GPU and the CPU, poles included", "[glsl][agreement][sh]") {
    gl_test::shared_context();
    const auto ds = unit_vectors(5);
    std::vector<std::tuple<glm::vec3>> in;
    std::vector<std::array<float, 16>> cpu;
    for (const auto& d : ds) {
        in.emplace_back(d);
        cpu.push_back(sh_basis<4, float, glm::vec3>(d));
    }
    const auto gpu = gl::map_kernel(sh_basis<4, f32, vec3>, in);
    const auto a = compare(gpu, cpu);
    INFO(describe(a));
    CHECK(a.non_finite == 0);
    CHECK(a.worst < relative_tolerance);
    CHECK(a.worst_tiny <= 1.0);
}

TEST_CASE("the G-buffer kernels facing_normal and view_depth agree on the GPU and the CPU", "[glsl][agreement]") {
    gl_test::shared_context();
    const auto ns = unit_vectors(6), ps = unit_vectors(7);
    std::vector<std::tuple<glm::vec3, glm::vec3, glm::vec3>> in;
    std::vector<glm::vec3> cpu_n;
    std::vector<float> cpu_d;
    const glm::vec3 eye(0.3f, -2.f, 4.f), forward = glm::normalize(glm::vec3(-0.1f, 0.4f, -1.f));
    for (std::size_t i = 0; i < ns.size(); ++i) {
        // Unnormalized normals (as interpolation leaves them) at points around the origin.
        const glm::vec3 n = ns[i] * (0.5f + float(i % 5) * 0.25f), p = ps[i] * 2.f;
        in.emplace_back(n, p, eye);
        cpu_n.push_back(facing_normal<float, glm::vec3>(n, p, eye));
        cpu_d.push_back(view_depth<float, glm::vec3>(p, eye, forward));
    }
    const auto normal = compare(gl::map_kernel(facing_normal<f32, vec3>, in), cpu_n);
    std::vector<std::tuple<glm::vec3, glm::vec3, glm::vec3>> depth_in;
    for (std::size_t i = 0; i < ps.size(); ++i) depth_in.emplace_back(ps[i] * 2.f, eye, forward);
    const auto depth = compare(gl::map_kernel(view_depth<f32, vec3>, depth_in), cpu_d);
    INFO("facing_normal: " << describe(normal));
    INFO("view_depth: " << describe(depth));
    CHECK(normal.worst < relative_tolerance);
    CHECK(normal.worst_tiny <= 1.0);
    CHECK(depth.worst < relative_tolerance);
    CHECK(depth.worst_tiny <= 1.0);
}

TEST_CASE("tuple results with a boolean travel back through out parameters", "[glsl][agreement]") {
    gl_test::shared_context();
    const auto vs = unit_vectors(8);
    std::vector<std::tuple<glm::vec3>> in;
    std::vector<std::tuple<float, glm::vec3, bool>> cpu;
    for (std::size_t i = 0; i < vs.size(); ++i) {
        const glm::vec3 v = vs[i] * (1.f + float(i % 7));
        in.emplace_back(v);
        cpu.push_back(length_direction_upper<float, glm::vec3>(v));
    }
    const auto gpu = gl::map_kernel(length_direction_upper<f32, vec3>, in);
    const auto a = compare(gpu, cpu);
    INFO(describe(a));
    CHECK(a.worst < relative_tolerance);
    CHECK(a.worst_tiny <= 1.0);
    for (std::size_t i = 0; i < cpu.size(); ++i) REQUIRE(std::get<2>(gpu[i]) == std::get<2>(cpu[i]));
}
