// Translational SH gradients by central differences (Oat, ShaderX5 6.1) and the
// extrapolation I'_i = I_i + grad I_i . d: exact for fields up to quadratic, the known
// h^2 / 6 error on a cubic, the probe callback's calls, bad steps.
#include <bounce/errors.hpp>
#include <bounce/sh/gradients.hpp>
#include <bounce/sh/lights.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace bounce;

namespace {
constexpr int L = 3;
using coeffs = sh_coefficients<L, glm::dvec3>;

// A probe field whose coefficient i is a quadratic in position.
coeffs quadratic_field(const glm::dvec3& p) {
    coeffs c{};
    for (std::size_t i = 0; i < sh_count(L); ++i) {
        const double a = 0.1 * double(i + 1);
        c[i] = glm::dvec3(1 + a * p.x - 2 * p.y * p.z + a * p.z * p.z, 0.5 * p.y, -a * p.x * p.y);
    }
    return c;
}
}  // namespace

TEST_CASE("central differences are exact on a quadratic probe field, whatever the step", "[sh][gradients]") {
    const glm::dvec3 p(0.3, -1.2, 2.0);
    for (const double h : {1e-3, 0.1, 1.0}) {
        const auto g = sh_translational_gradient<L, glm::dvec3>(quadratic_field, p, h);
        for (std::size_t i = 0; i < sh_count(L); ++i) {
            const double a = 0.1 * double(i + 1);
            const glm::dvec3 dx(a, 0, -a * p.y), dy(-2 * p.z, 0.5, -a * p.x), dz(-2 * p.y + 2 * a * p.z, 0, 0);
            // (f(p + h) - f(p - h)) / 2h on values of size ~10: cancellation leaves ~10 eps / h.
            const double tolerance = 10 * 2.2e-16 * 8 / h;
            for (int k = 0; k < 3; ++k) {
                CHECK(std::abs(g.x[i][k] - dx[k]) < tolerance);
                CHECK(std::abs(g.y[i][k] - dy[k]) < tolerance);
                CHECK(std::abs(g.z[i][k] - dz[k]) < tolerance);
            }
        }
    }
}

TEST_CASE("extrapolation with the gradient reproduces a linear field exactly", "[sh][gradients]") {
    auto linear = [](const glm::dvec3& p) {
        coeffs c{};
        for (std::size_t i = 0; i < sh_count(L); ++i) c[i] = glm::dvec3(1.0 + double(i) * p.x - p.z, 2 * p.y, 3.0);
        return c;
    };
    const glm::dvec3 p(1, 2, 3), d(0.4, -0.7, 1.5);
    const auto g = sh_translational_gradient<L, glm::dvec3>(linear, p, 0.25);
    const auto extrapolated = sh_extrapolate<L, glm::dvec3>(linear(p), g, d);
    const auto direct = linear(p + d);
    for (std::size_t i = 0; i < sh_count(L); ++i)
        for (int k = 0; k < 3; ++k) CHECK(std::abs(extrapolated[i][k] - direct[i][k]) < 1e-14 * 16);
}

TEST_CASE("on a cubic field the gradient is off by h^2 / 6 times the third derivative", "[sh][gradients]") {
    // c_0(x) = x^3: (( x + h)^3 - (x - h)^3) / 2h = 3 x^2 + h^2.
    auto cubic = [](const glm::dvec3& p) {
        sh_coefficients<1, double> c{};
        c[0] = p.x * p.x * p.x;
        return c;
    };
    for (const double h : {0.5, 0.1, 0.01}) {
        const auto g = sh_translational_gradient<1, double>(cubic, glm::dvec3(2, 0, 0), h);
        CHECK(std::abs(g.x[0] - (12 + h * h)) < 1e-13 / h);
        CHECK(g.y[0] == 0);
    }
}

TEST_CASE("a moving light's probes: the callback is called six times, in +x -x +y -y +z -z order", "[sh][gradients]") {
    // The probe at p sees a point-like light at q as a directional light of irradiance
    // I / |q - p|^2 from (q - p) / |q - p|.
    const glm::dvec3 q(0, 0, 5);
    std::vector<glm::dvec3> calls;
    auto probe_at = [&](const glm::dvec3& p) {
        calls.push_back(p);
        const glm::dvec3 d = q - p;
        return sh_project_directional_light<L, double>(d, 10.0 / glm::dot(d, d));
    };
    const auto g = sh_translational_gradient<L, double>(probe_at, glm::dvec3(0), 0.05);
    REQUIRE(calls.size() == 6);
    CHECK(calls[0] == glm::dvec3(0.05, 0, 0));
    CHECK(calls[1] == glm::dvec3(-0.05, 0, 0));
    CHECK(calls[4] == glm::dvec3(0, 0, 0.05));
    // Band 0: c_00(z) = Y_00 I / (5 - z)^2, so c_00' = 2 Y_00 I / 125 and the central
    // difference adds h^2 / 6 times c_00''' = 24 Y_00 I / 5^5 (2e-4 relative); the next
    // term, h^4 / 120 times c_00^(5) = 720 Y_00 I / 5^7, is 3e-8 relative.
    const double y00 = 0.5 / std::sqrt(std::numbers::pi), h = 0.05;
    const double expected = y00 * 10 * 2 / 125 + h * h / 6 * 24 * y00 * 10 / 3125;
    CHECK(std::abs(g.z[0] - expected) < 5e-8 * expected);
    CHECK(std::abs(g.x[0]) < 1e-15);
    CHECK_THROWS_AS((sh_translational_gradient<L, double>(probe_at, glm::dvec3(0), 0.0)), parameter_error);
    CHECK_THROWS_AS((sh_translational_gradient<L, double>(probe_at, glm::dvec3(0), -1.0)), parameter_error);
}
