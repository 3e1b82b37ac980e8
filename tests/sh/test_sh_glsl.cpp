// The SH kernels emitted to GLSL (sh_evaluate, sh_irradiance, sh_irradiance_over_pi,
// sh_extrapolate), run on the GPU (llvmpipe through EGL in CI) over random coefficient sets
// and normals (poles and tiny components first), agree with their CPU float instantiation.
//
// Tolerance, per output channel: both sides compute sum_i k_i c_i Y_i(n) over the same terms
// in the same order. The basis values agree to 5e-7 absolute (4 ulp of 1: the bound of the
// sh_basis agreement test in tests/gl), which enters multiplied by sum_i |k_i c_i|; each
// product and partial sum may round differently on the two sides (GPU built-ins, fused
// multiply-adds), at most 2 ulp per operation of the running sum's magnitude, bounded by
// 2 u (2 terms + 2) sum_i |k_i c_i Y_i| with u = 2^-24. Both bounds are computed per output
// from the inputs.
#include "../gl/shared_context.hpp"

#include <bounce/gl/kernel_map.hpp>
#include <bounce/sampling.hpp>
#include <bounce/sh/gradients.hpp>
#include <bounce/sh/irradiance.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <tuple>
#include <vector>

using namespace bounce;
using glsl::f32;
using glsl::vec3;

namespace {

constexpr int L = 3;
constexpr std::size_t n_coeff = sh_count(L);
using rgb_coefficients = std::array<glm::vec3, n_coeff>;

std::vector<glm::vec3> normals(std::uint64_t seed, int count) {
    std::vector<glm::vec3> v = {{0, 0, 1},      {0, 0, -1},   {1, 0, 0},     {-1, 0, 0},          {0, 1, 0},
                                {0, -1, 0},     {1e-9f, 0, -1}, {0, 1e-7f, 1}, {-1e-12f, 1e-12f, -1}, {1e-4f, -1e-4f, 1},
                                {1, 1e-20f, 0}, {1, 1, 1}};
    pcg32 rng(seed);
    for (int i = 0; i < count; ++i) {
        const float z = 2 * rng.next_float() - 1, phi = 6.2831853f * rng.next_float();
        const float r = std::sqrt(std::max(0.f, 1 - z * z));
        v.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    for (auto& n : v) n = glm::normalize(n);
    return v;
}

rgb_coefficients random_coefficients(pcg32& rng) {
    rgb_coefficients c{};
    for (auto& ci : c) ci = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 2.f - 1.f;
    c[0] += glm::vec3(3.f);  // a positive mean, as radiance has
    return c;
}

// The bound of the file comment for sum_i k_i c_i Y_i(n), channel `ch`.
double bound(const rgb_coefficients& c, const glm::vec3& n, const std::array<double, n_coeff>& k, int ch) {
    const auto y = sh_basis<L, double, glm::dvec3>(glm::dvec3(n));
    double weights = 0, terms = 0;
    for (std::size_t i = 0; i < n_coeff; ++i) {
        weights += std::abs(k[i] * c[i][ch]);
        terms += std::abs(k[i] * c[i][ch] * y[i]);
    }
    return 5e-7 * weights + 2 * 0x1p-24 * (2 * double(n_coeff) + 2) * terms;
}

template <class Gpu, class Cpu>
void check_agreement(const std::vector<glm::vec3>& gpu, const std::vector<glm::vec3>& cpu, Gpu&& bound_of, Cpu&& describe) {
    REQUIRE(gpu.size() == cpu.size());
    double worst = 0;
    for (std::size_t e = 0; e < gpu.size(); ++e)
        for (int ch = 0; ch < 3; ++ch) {
            const double b = bound_of(e, ch), d = std::abs(double(gpu[e][ch]) - double(cpu[e][ch]));
            worst = std::max(worst, d / b);
            if (!(d <= b)) {
                INFO(describe(e) << " channel " << ch << ": gpu " << gpu[e][ch] << ", cpu " << cpu[e][ch] << ", bound " << b);
                CHECK(d <= b);
            }
        }
    INFO("worst difference / bound: " << worst);
    CHECK(worst <= 1.0);
}

}  // namespace

TEST_CASE("sh_irradiance, sh_irradiance_over_pi and sh_evaluate (order 2) agree on the GPU and the CPU", "[glsl][agreement][sh]") {
    gl_test::shared_context();
    pcg32 rng(81);
    const auto ns = normals(82, 5000);
    std::vector<std::tuple<rgb_coefficients, glm::vec3>> in;
    std::vector<glm::vec3> e_cpu, e_pi_cpu, f_cpu;
    for (const auto& n : ns) {
        in.emplace_back(random_coefficients(rng), n);
        const auto& c = std::get<0>(in.back());
        e_cpu.push_back(sh_irradiance<L, float, glm::vec3>(c, n));
        e_pi_cpu.push_back(sh_irradiance_over_pi<L, float, glm::vec3>(c, n));
        f_cpu.push_back(sh_evaluate<L, float, glm::vec3, glm::vec3>(c, n));
    }
    const auto e_gpu = gl::map_kernel(sh_irradiance<L, f32, vec3>, in);
    const auto e_pi_gpu = gl::map_kernel(sh_irradiance_over_pi<L, f32, vec3>, in);
    const auto f_gpu = gl::map_kernel(sh_evaluate<L, f32, vec3, vec3>, in);

    std::array<double, n_coeff> a{}, a_pi{}, one{};
    for (std::size_t i = 0; i < n_coeff; ++i) {
        a[i] = clamped_cosine_band_factor(sh_band(i));
        a_pi[i] = a[i] / std::numbers::pi;
        one[i] = 1;
    }
    auto describe = [&](std::size_t e) {
        const auto& n = std::get<1>(in[e]);
        return "normal (" + std::to_string(n.x) + ", " + std::to_string(n.y) + ", " + std::to_string(n.z) + ")";
    };
    check_agreement(e_gpu, e_cpu, [&](std::size_t e, int ch) { return bound(std::get<0>(in[e]), std::get<1>(in[e]), a, ch); }, describe);
    check_agreement(e_pi_gpu, e_pi_cpu, [&](std::size_t e, int ch) { return bound(std::get<0>(in[e]), std::get<1>(in[e]), a_pi, ch); },
                    describe);
    check_agreement(f_gpu, f_cpu, [&](std::size_t e, int ch) { return bound(std::get<0>(in[e]), std::get<1>(in[e]), one, ch); },
                    describe);
}

TEST_CASE("sh_extrapolate (Oat's I + grad I . d) agrees on the GPU and the CPU", "[glsl][agreement][sh]") {
    gl_test::shared_context();
    pcg32 rng(91);
    std::vector<std::tuple<rgb_coefficients, rgb_coefficients, rgb_coefficients, rgb_coefficients, glm::vec3>> in;
    std::vector<rgb_coefficients> cpu;
    for (int k = 0; k < 2000; ++k) {
        const glm::vec3 d(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f);
        in.emplace_back(random_coefficients(rng), random_coefficients(rng), random_coefficients(rng), random_coefficients(rng),
                        d * 4.f);
        const auto& [c, gx, gy, gz, dd] = in.back();
        cpu.push_back(sh_extrapolate<L, float, glm::vec3, glm::vec3>(c, gx, gy, gz, dd));
    }
    const auto gpu = gl::map_kernel(sh_extrapolate<L, f32, vec3, vec3>, in);
    REQUIRE(gpu.size() == cpu.size());
    // c + gx dx + gy dy + gz dz: three products and three sums, each rounded (or fused) on
    // either side: at most 2 u (6 + 2) (|c| + |gx dx| + |gy dy| + |gz dz|).
    for (std::size_t e = 0; e < gpu.size(); ++e) {
        const auto& [c, gx, gy, gz, d] = in[e];
        for (std::size_t i = 0; i < n_coeff; ++i)
            for (int ch = 0; ch < 3; ++ch) {
                const double magnitude = std::abs(c[i][ch]) + std::abs(gx[i][ch] * d.x) + std::abs(gy[i][ch] * d.y) +
                                         std::abs(gz[i][ch] * d.z);
                CHECK(std::abs(double(gpu[e][i][ch]) - double(cpu[e][i][ch])) <= 2 * 0x1p-24 * 8 * magnitude);
            }
    }
}

TEST_CASE("the irradiance kernel prints as one GLSL function of nine radiance vectors and a normal", "[glsl][sh]") {
    const std::string src = glsl::emit("sh_irradiance", sh_irradiance<L, f32, vec3>, "radiance", "n");
    CHECK(src.rfind("vec3 sh_irradiance(vec3 radiance[9], vec3 n) {\n", 0) == 0);
    // Bands with A_l = 0 print nothing; no trigonometry reaches the shader.
    CHECK(src.find("sin(") == std::string::npos);
    CHECK(src.find("cos(") == std::string::npos);
}
