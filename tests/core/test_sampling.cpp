// Properties of the sampling helpers: bases stay orthonormal for every normal, the
// hemisphere maps have the densities they claim, point sets are stratified and seeded.
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cmath>
#include <numbers>
#include <string_view>

using namespace bounce;

namespace {
// Random unit vectors (fixed seed) followed by the normals that break naive bases.
std::vector<glm::dvec3> test_normals() {
    std::vector<glm::dvec3> ns = {{0, 0, 1},  {0, 0, -1}, {1, 0, 0},  {0, 1, 0}, {-1, 0, 0}, {0, -1, 0},
                                  {1e-9, 0, -1}, {0, 1e-7, -1}, {1e-4, 1e-4, -1}, {-1e-12, 1e-12, -1},
                                  {1e-4, -1e-4, 1}};
    pcg32 rng(7);
    for (int i = 0; i < 500; ++i) {
        const glm::dvec2 u(rng.next_double(), rng.next_double());
        const double z = 2 * u.x - 1, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * std::numbers::pi * u.y;
        ns.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    for (auto& n : ns) n = glm::normalize(n);
    return ns;
}
}  // namespace

TEST_CASE("the orthonormal basis is orthonormal and right-handed for every unit normal", "[sampling][basis]") {
    static const auto normals = test_normals();
    const auto i = GENERATE(range<std::size_t>(0, 511));
    const glm::dvec3 nd = normals[i];

    SECTION("double") {
        const auto [t, b] = orthonormal_basis<double, glm::dvec3>(nd);
        // Each entry is a handful of roundings of O(1) quantities: a few ulp of 1.
        const double tol = 16 * std::numeric_limits<double>::epsilon();
        CHECK(std::abs(glm::length(t) - 1) < tol);
        CHECK(std::abs(glm::length(b) - 1) < tol);
        CHECK(std::abs(glm::dot(t, b)) < tol);
        CHECK(std::abs(glm::dot(t, nd)) < tol);
        CHECK(std::abs(glm::dot(b, nd)) < tol);
        CHECK(glm::length(glm::cross(t, b) - nd) < tol);
    }
    SECTION("float") {
        const glm::vec3 n(nd);
        const auto [t, b] = orthonormal_basis<float, glm::vec3>(n);
        const double tol = 16 * double(std::numeric_limits<float>::epsilon());
        CHECK(std::abs(glm::length(t) - 1) < tol);
        CHECK(std::abs(glm::length(b) - 1) < tol);
        CHECK(std::abs(glm::dot(t, b)) < tol);
        CHECK(std::abs(glm::dot(t, n)) < tol);
        CHECK(std::abs(glm::dot(b, n)) < tol);
    }
}

TEST_CASE("the concentric map sends the square into the disc and its border onto the circle", "[sampling]") {
    pcg32 rng(11);
    for (int i = 0; i < 2000; ++i) {
        const glm::dvec2 u(rng.next_double(), rng.next_double());
        const auto d = concentric_disc<double, glm::dvec2>(u);
        REQUIRE(std::isfinite(d.x));
        REQUIRE(glm::length(d) <= 1 + 1e-15);
        // The radius is the Chebyshev distance of u from the centre, by construction.
        CHECK(glm::length(d) == Approx(std::max(std::abs(2 * u.x - 1), std::abs(2 * u.y - 1))).margin(1e-14));
    }
    const auto centre = concentric_disc<double, glm::dvec2>({0.5, 0.5});
    CHECK(centre.x == 0.0);
    CHECK(centre.y == 0.0);
    for (double s : {0.0, 0.1, 0.37, 0.5, 0.99, 1.0}) {
        CHECK(glm::length(concentric_disc<double, glm::dvec2>({s, 0.0})) == Approx(1.0));
        CHECK(glm::length(concentric_disc<double, glm::dvec2>({1.0, s})) == Approx(1.0));
    }
}

TEST_CASE("cosine-weighted directions follow the cosine density", "[sampling]") {
    // Under pdf cos/pi, P(cos theta <= c) = c^2, E[cos] = 2/3, E[cos^2] = 1/2.
    const std::uint32_t n = 128;
    const auto pts = stratified2(n, n, 3);
    double sum_cos = 0, below = 0;
    for (const auto& u : pts) {
        const auto d = cosine_hemisphere<double, glm::dvec3, glm::dvec2>(glm::dvec2(u));
        REQUIRE(d.z >= 0);
        REQUIRE(glm::length(d) == Approx(1.0).epsilon(1e-12));
        sum_cos += d.z;
        below += d.z <= 0.5 ? 1 : 0;
    }
    const double N = double(pts.size());
    // Tolerances: 4 standard deviations of an estimator over N independent samples
    // (stratified samples only do better): var(cos) = 1/2 - 4/9 = 1/18; var(indicator) = p(1-p).
    CHECK(std::abs(sum_cos / N - 2.0 / 3.0) < 4 * std::sqrt(1.0 / 18.0 / N));
    CHECK(std::abs(below / N - 0.25) < 4 * std::sqrt(0.25 * 0.75 / N));
}

TEST_CASE("uniform hemisphere directions follow the uniform density", "[sampling]") {
    // Under pdf 1/(2 pi), cos theta is uniform on [0, 1]: E = 1/2, var = 1/12.
    pcg32 rng(5);
    const int n = 20000;
    double s = 0;
    for (int i = 0; i < n; ++i) {
        const auto d = uniform_hemisphere<double, glm::dvec3, glm::dvec2>({rng.next_double(), rng.next_double()});
        REQUIRE(glm::length(d) == Approx(1.0).epsilon(1e-12));
        s += d.z;
    }
    CHECK(std::abs(s / n - 0.5) < 4 * std::sqrt(1.0 / 12.0 / n));
}

TEST_CASE("to_world keeps unit length and maps +z to the normal", "[sampling][basis]") {
    static const auto normals = test_normals();
    const auto i = GENERATE(range<std::size_t>(0, 511, 7));
    const auto n = normals[i];
    CHECK(glm::length(to_world<double, glm::dvec3>({0, 0, 1}, n) - n) < 1e-14);
    const glm::dvec3 d = glm::normalize(glm::dvec3(0.3, -0.4, 0.5));
    const auto w = to_world<double, glm::dvec3>(d, n);
    CHECK(glm::length(w) == Approx(1.0).epsilon(1e-14));
    CHECK(glm::dot(w, n) == Approx(d.z).epsilon(1e-13));
}

TEST_CASE("pcg32 reproduces the reference stream of the PCG paper", "[sampling][rng]") {
    pcg32 rng(42, 54);
    CHECK(rng.next_u32() == 0xa15c02b7u);
    CHECK(rng.next_u32() == 0x7b47f409u);
    CHECK(rng.next_u32() == 0xba1d3330u);
    pcg32 a(9), b(9), c(10);
    for (int i = 0; i < 100; ++i) {
        const float fa = a.next_float();
        CHECK(fa == b.next_float());
        CHECK(fa < 1.f);
    }
    CHECK(a.next_u32() != c.next_u32());
}

TEST_CASE("the Halton sequence puts one point in every elementary interval", "[sampling][qmc]") {
    CHECK(radical_inverse(1, 2) == 0.5);
    CHECK(radical_inverse(2, 2) == 0.25);
    CHECK(radical_inverse(3, 2) == 0.75);
    CHECK(radical_inverse(1, 3) == Approx(1.0 / 3.0));
    CHECK(radical_inverse(3, 3) == Approx(1.0 / 9.0));
    // The first 2^k * 3^l points of (base 2, base 3) fill a 2^k x 3^l grid, one point a cell.
    const int nx = 8, ny = 9;
    std::vector<int> count(nx * ny, 0);
    for (int i = 0; i < nx * ny; ++i) {
        const auto p = halton2(std::uint64_t(i));
        ++count[int(p.y * ny) * nx + int(p.x * nx)];
    }
    for (int c : count) CHECK(c == 1);
}

TEST_CASE("stratified points lie one per cell, fixed by their seed", "[sampling][qmc]") {
    const auto nx = GENERATE(1u, 3u, 16u);
    const auto ny = GENERATE(1u, 5u, 16u);
    const auto a = stratified2(nx, ny, 1), b = stratified2(nx, ny, 1), c = stratified2(nx, ny, 2);
    REQUIRE(a.size() == std::size_t(nx) * ny);
    for (std::uint32_t j = 0; j < ny; ++j)
        for (std::uint32_t i = 0; i < nx; ++i) {
            const auto p = a[j * nx + i];
            CHECK(int(p.x * float(nx)) == int(i));
            CHECK(int(p.y * float(ny)) == int(j));
            CHECK(p == b[j * nx + i]);
        }
    CHECK(a[0] != c[0]);
    CHECK_THROWS_AS(stratified2(0, 4, 1), parameter_error);
}

