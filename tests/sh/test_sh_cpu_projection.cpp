// The table-driven batch projection of cpu/sh_projection.hpp against the core's double
// reference (within a recursive-summation bound derived from the count of float terms),
// bitwise the same for any thread count and any batching, on sizes with and without a
// partial vector, an odd size (a middle row that is its own mirror), a face larger than one
// float chunk, strided faces and more than 9 coefficients of one parity (L = 5), on every
// code path.
#include "sphere_quadrature.hpp"

#include <bounce/cpu/sh_projection.hpp>
#include <bounce/sh/irradiance.hpp>
#include <bounce/sh/projection.hpp>

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <cmath>
#include <bit>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <vector>

using namespace bounce;
using namespace bounce::sh_test;

namespace {

constexpr int L = 3;

struct cube_set {
    std::size_t size;
    std::vector<std::array<image<glm::vec3>, 6>> storage;
    std::vector<cube_map_view<const glm::vec3>> views;

    // `count` maps of a smooth random RGB function plus a bright lobe (a sun), different per
    // map; with `pad` > 0 each face is a view into an image `pad` texels wider (strided rows).
    cube_set(std::size_t n, std::size_t count, std::uint64_t seed, std::size_t pad = 0) : size(n), storage(count) {
        pcg32 rng(seed);
        for (auto& faces : storage) {
            const glm::dvec3 sun = glm::normalize(glm::dvec3(rng.next_double() - 0.5, rng.next_double() - 0.5, 0.3));
            const glm::dvec3 tint(rng.next_double(), rng.next_double(), rng.next_double());
            for (int f = 0; f < 6; ++f) {
                faces[std::size_t(f)] = image<glm::vec3>(n + pad, n, glm::vec3(1e30f));  // the padding must not be read
                for (std::size_t y = 0; y < n; ++y)
                    for (std::size_t x = 0; x < n; ++x) {
                        const glm::dvec3 d = cube_texel_direction(cube_face(f), n, x, y);
                        const double lobe = std::pow(std::max(0.0, glm::dot(d, sun)), 32.0) * 20;
                        faces[std::size_t(f)](x, y) = glm::vec3(tint * (1 + d.z) + glm::dvec3(lobe));
                    }
            }
        }
        for (auto& faces : storage) {
            cube_map_view<const glm::vec3> v;
            for (int f = 0; f < 6; ++f) v.faces[std::size_t(f)] = faces[std::size_t(f)].view().subview(0, 0, n, n);
            views.push_back(v);
        }
    }
};

// The projector sums, per face, float terms w_j(t) (f(t) +- f(t')) over texel pairs t, t'
// (a row and its mirror) against the shared table, in float lanes that each add at most
// m = chunk_texels / 8 terms before going into double, then mixes the face's moments by an
// orthogonal matrix M_f (rows of norm 1). Recursive summation of m terms has error at most
// (m - 1) u sum |terms| (Higham, Accuracy and Stability, Eq. 4.4), plus one rounding each for
// the product, the pair's sum and the table entry: (m + 3) u. By Cauchy-Schwarz and the
// addition theorem, sum_j |M_f[i][j] Y_j| <= sqrt((2 l + 1) / 4 pi) over band l, so
//   |error| <= (m + 3) u sum over texels of sqrt((2 l + 1) / 4 pi) dw |f| + rounding to float.
template <int L>
double error_bound(const cube_set& set, std::size_t map, std::size_t i, int channel, double result) {
    const std::size_t n = set.size, m = cpu::cube_map_sh_projector<L>::chunk_texels / 8;
    const double band = sh_band(i), scale = std::sqrt((2 * band + 1) / (4 * std::numbers::pi));
    double magnitude = 0;
    for (int f = 0; f < 6; ++f)
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x)
                magnitude += scale * cube_texel_solid_angle(n, x, y) * std::abs(set.views[map].faces[std::size_t(f)](x, y)[channel]);
    return double(m + 3) * 0x1p-24 * magnitude + 0x1p-24 * std::abs(result);
}

template <int L>
void check_against_reference(const cube_set& set) {
    for (const auto path : {cpu::sh_projection_path::automatic, cpu::sh_projection_path::avx2, cpu::sh_projection_path::portable}) {
        const cpu::cube_map_sh_projector<L> projector(set.size, path);
        std::vector<sh_coefficients<L, glm::vec3>> out(set.views.size());
        projector.project(set.views, out);
        for (std::size_t k = 0; k < set.views.size(); ++k) {
            const auto reference = sh_project_cube_map<L>(set.views[k]);
            for (std::size_t i = 0; i < sh_count(L); ++i)
                for (int c = 0; c < 3; ++c) {
                    INFO("size " << set.size << ", L " << L << ", path " << projector.path_name() << ", map " << k << ", coefficient " << i);
                    CHECK(std::abs(double(out[k][i][c]) - reference[i][c]) <= error_bound<L>(set, k, i, c, reference[i][c]));
                }
        }
    }
}

}  // namespace

TEST_CASE("batch cube-map projection matches the double reference within the float summation bound", "[sh][cpu]") {
    for (const std::size_t n : {64u, 13u, 100u}) check_against_reference<L>(cube_set(n, 5, 40 + n));
    SECTION("strided faces") { check_against_reference<L>(cube_set(21, 3, 5, 7)); }
    SECTION("more coefficients of one parity than one pass holds") { check_against_reference<5>(cube_set(24, 3, 9)); }
}

TEST_CASE("batch cube-map projection is bitwise the same for any thread count and batching", "[sh][cpu]") {
    const cube_set set(32, 40, 7);
    const auto path = GENERATE(cpu::sh_projection_path::automatic, cpu::sh_projection_path::avx2, cpu::sh_projection_path::portable);
    const cpu::cube_map_sh_projector<L> projector(32, path);
    INFO("path " << projector.path_name());
    std::vector<sh_coefficients<L, glm::vec3>> one_thread(set.views.size()), two_threads(set.views.size());
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        projector.project(set.views, one_thread);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        projector.project(set.views, two_threads);
    }
    CHECK(std::memcmp(one_thread.data(), two_threads.data(), one_thread.size() * sizeof(one_thread[0])) == 0);
    for (std::size_t k = 0; k < set.views.size(); k += 7) {
        const auto single = projector.project(set.views[k]);
        CHECK(std::memcmp(&single, &one_thread[k], sizeof(single)) == 0);
    }
}

TEST_CASE("a constant cube map projected in float gives E = pi L to float accuracy", "[sh][cpu]") {
    image<glm::vec3> face(64, 64, glm::vec3(0.5f, 1.f, 2.f));
    cube_map_view<const glm::vec3> cube;
    for (auto& f : cube.faces) f = face.view();
    const auto c = cpu::cube_map_sh_projector<L>(64).project(cube);
    std::array<glm::dvec3, 9> rgb{};
    for (std::size_t i = 0; i < 9; ++i) rgb[i] = glm::dvec3(c[i]);
    // 512-term float sums per lane: relative error below 512 x 2^-24 = 3e-5 in the worst case.
    for (const auto& n : test_directions(5, 50)) {
        const glm::dvec3 e = sh_irradiance<L, double, glm::dvec3>(rgb, n);
        CHECK(std::abs(e.x / (std::numbers::pi * 0.5) - 1) < 3e-5);
        CHECK(std::abs(e.z / (std::numbers::pi * 2.0) - 1) < 3e-5);
    }
}

TEST_CASE("the batch projector rejects sizes and maps that do not fit", "[sh][cpu][errors]") {
    CHECK_THROWS_AS(cpu::cube_map_sh_projector<L>(0), parameter_error);
    const cube_set set(8, 2, 3);
    const cpu::cube_map_sh_projector<L> projector(16);
    std::vector<sh_coefficients<L, glm::vec3>> out(2), short_out(1);
    CHECK_THROWS_AS(projector.project(set.views, out), parameter_error);
    const cpu::cube_map_sh_projector<L> right(8);
    CHECK_THROWS_AS(right.project(set.views, short_out), parameter_error);
    CHECK_NOTHROW(right.project(set.views, out));
}

TEST_CASE("binary16 texels decode exactly, including subnormals, infinities and signs", "[sh][cpu]") {
    CHECK(cpu::half_to_float(0x3c00) == 1.f);
    CHECK(cpu::half_to_float(0xc000) == -2.f);
    CHECK(cpu::half_to_float(0x7bff) == 65504.f);
    CHECK(cpu::half_to_float(0x0001) == 0x1p-24f);
    CHECK(cpu::half_to_float(0x03ff) == 1023 * 0x1p-24f);
    CHECK(cpu::half_to_float(0x3555) == 0x1.554p-2f);
    CHECK(cpu::half_to_float(0x7c00) == INFINITY);
    CHECK(std::signbit(cpu::half_to_float(0x8000)));
    CHECK(std::isnan(cpu::half_to_float(0x7e00)));
}

TEST_CASE("float_to_half rounds to nearest even and inverts half_to_float on every half", "[sh][cpu]") {
    for (std::uint32_t h = 0; h < 0x10000u; ++h) {
        const float f = cpu::half_to_float(std::uint16_t(h));
        if (std::isnan(f)) continue;
        INFO("half " << h);
        CHECK(cpu::float_to_half(f) == h);
    }
    CHECK(cpu::float_to_half(65520.f) == 0x7c00);              // halfway to 2^16: ties to even = infinity
    CHECK(cpu::float_to_half(65519.f) == 0x7bff);
    CHECK(cpu::float_to_half(1.f + 0x1p-11f) == 0x3c00);      // halfway, even neighbour 1.0
    CHECK(cpu::float_to_half(1.f + 3 * 0x1p-11f) == 0x3c02);  // halfway, even neighbour above
    CHECK(cpu::float_to_half(0x1p-25f) == 0x0000);             // halfway to the smallest subnormal
    CHECK(cpu::float_to_half(0x1.8p-25f) == 0x0001);
    CHECK(cpu::float_to_half(-0x1p-30f) == 0x8000);
    CHECK(cpu::float_to_half(NAN) == 0x7e00);
}

TEST_CASE("half-float maps project as their decoded float values do, on every path", "[sh][cpu]") {
    for (const std::size_t n : {64u, 13u}) {
        const cube_set set(n, 4, 70 + n);
        std::vector<std::array<image<cpu::half_rgb>, 6>> halves(set.views.size());
        std::vector<std::array<image<glm::vec3>, 6>> decoded(set.views.size());
        std::vector<cube_map_view<const cpu::half_rgb>> half_views(set.views.size());
        std::vector<cube_map_view<const glm::vec3>> decoded_views(set.views.size());
        for (std::size_t k = 0; k < set.views.size(); ++k)
            for (int f = 0; f < 6; ++f) {
                auto& h = halves[k][std::size_t(f)];
                auto& d = decoded[k][std::size_t(f)];
                h = image<cpu::half_rgb>(n, n);
                d = image<glm::vec3>(n, n);
                for (std::size_t y = 0; y < n; ++y)
                    for (std::size_t x = 0; x < n; ++x)
                        for (int c = 0; c < 3; ++c) {
                            h(x, y).bits[c] = cpu::float_to_half(set.views[k].faces[std::size_t(f)](x, y)[c]);
                            d(x, y)[c] = cpu::half_to_float(h(x, y).bits[c]);
                        }
                half_views[k].faces[std::size_t(f)] = h.view();
                decoded_views[k].faces[std::size_t(f)] = d.view();
            }
        for (const auto path : {cpu::sh_projection_path::automatic, cpu::sh_projection_path::avx2, cpu::sh_projection_path::portable}) {
            const cpu::cube_map_sh_projector<L> projector(n, path);
            std::vector<sh_coefficients<L, glm::vec3>> from_half(half_views.size()), from_float(half_views.size());
            projector.project(half_views, from_half);
            projector.project(decoded_views, from_float);
            // The same floats through the same products in the same order: bitwise equal.
            CHECK(std::memcmp(from_half.data(), from_float.data(), from_half.size() * sizeof(from_half[0])) == 0);
        }
    }
}
