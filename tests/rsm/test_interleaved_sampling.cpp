// Properties of the interleave index maps, the light assignment and the geometry-aware
// tent (include/bounce/indirect/interleaved_sampling.hpp, adapters/cpu/.../interleave.hpp).
#include <bounce/cpu/interleave.hpp>
#include <bounce/indirect/interleaved_sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <set>
#include <vector>

using namespace bounce;

TEST_CASE("split then gather is the identity for every size and pattern, in double and in float", "[interleave]") {
    for (int n = 1; n <= 9; ++n)
        for (int size = 1; size <= 70; ++size) {
            std::vector<int> seen(std::size_t(size), 0);
            for (int x = 0; x < size; ++x) {
                const double u = interleave_split_coordinate<double>(x, size, n);
                REQUIRE(u >= 0);
                REQUIRE(u < size);
                REQUIRE(u == std::floor(u));
                ++seen[std::size_t(u)];
                const auto g = interleave_gather_coordinate<double>(u, size, n);
                REQUIRE(g[0] == x);
                REQUIRE(g[1] == x % n);
                // The float instantiation (what GLSL computes) gives the same integers.
                const float uf = interleave_split_coordinate<float>(float(x), float(size), float(n));
                REQUIRE(uf == float(u));
                REQUIRE(interleave_gather_coordinate<float>(uf, float(size), float(n))[0] == float(x));
            }
            // Every pixel lands in exactly one place: the split map is a bijection.
            for (int c : seen) REQUIRE(c == 1);
        }
}

TEST_CASE("the float maps stay exact at large sizes that are not multiples of the pattern", "[interleave]") {
    for (int n : {3, 7, 8, 64})
        for (int size : {1023, 1280, 1921, 4097, 16383}) {
            for (int x = 0; x < size; x += 1 + size / 997) {
                const float u = interleave_split_coordinate<float>(float(x), float(size), float(n));
                INFO("n " << n << " size " << size << " x " << x);
                REQUIRE(double(u) == interleave_split_coordinate<double>(x, size, n));
                REQUIRE(interleave_gather_coordinate<float>(u, float(size), float(n))[0] == float(x));
            }
        }
}

TEST_CASE("sub-buffers tile the split buffer and hold exactly the pixels of their residue class", "[interleave]") {
    for (const interleave_pattern p : {interleave_pattern{1, 1}, interleave_pattern{2, 3}, interleave_pattern{4, 4},
                                       interleave_pattern{8, 8}, interleave_pattern{5, 2}})
        for (const auto& [w, h] : {std::pair{13, 7}, std::pair{16, 16}, std::pair{3, 2}, std::pair{37, 41}}) {
            const cpu::interleave_maps maps(p, std::size_t(w), std::size_t(h));
            std::vector<int> owner(std::size_t(w * h), -1);
            for (int j = 0; j < p.m; ++j)
                for (int i = 0; i < p.n; ++i) {
                    const auto r = maps.sub_buffer(i, j);
                    for (std::size_t v = r.y0; v < r.y0 + r.height; ++v)
                        for (std::size_t u = r.x0; u < r.x0 + r.width; ++u) {
                            REQUIRE(owner[v * std::size_t(w) + u] == -1);
                            owner[v * std::size_t(w) + u] = j * p.n + i;
                            REQUIRE(maps.cell(u, v) == j * p.n + i);
                            REQUIRE(int(maps.gather_x[u]) % p.n == i);
                            REQUIRE(int(maps.gather_y[v]) % p.m == j);
                        }
                }
            for (int o : owner) REQUIRE(o >= 0);
        }
}

TEST_CASE("split_image then gather_image returns the image, bit for bit", "[interleave]") {
    for (const auto& [w, h] : {std::pair{1, 1}, std::pair{17, 9}, std::pair{64, 48}, std::pair{5, 30}}) {
        const cpu::interleave_maps maps({8, 8}, std::size_t(w), std::size_t(h));
        const std::size_t W = std::size_t(w), H = std::size_t(h);
        image<float> a(W, H), split(W, H), back(W, H);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) a(std::size_t(x), std::size_t(y)) = float(y * w + x) + 0.25f;
        cpu::split_image<float>(a.view(), split.view(), maps);
        cpu::gather_image<float>(split.view(), back.view(), maps);
        std::set<float> values;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                REQUIRE(back(std::size_t(x), std::size_t(y)) == a(std::size_t(x), std::size_t(y)));
                values.insert(split(std::size_t(x), std::size_t(y)));
            }
        REQUIRE(values.size() == std::size_t(w * h));
    }
}

TEST_CASE("every light is dealt to exactly one sub-buffer, by every assignment and shift", "[interleave]") {
    std::vector<glm::vec3> positions;
    for (int k = 0; k < 103; ++k) positions.emplace_back(std::sin(k * 1.7f), std::cos(k * 0.3f), float(k % 7));
    for (auto how : {light_assignment::interleaved, light_assignment::blocked, light_assignment::similarity})
        for (int cells : {1, 4, 16, 64})
            for (int shift : {0, cells - 1}) {
                const auto g = assign_lights(positions.size(), cells, how, positions, shift);
                std::vector<int> count(positions.size(), 0);
                for (int s = 0; s < cells; ++s)
                    for (auto k : g.group(s)) ++count[k];
                for (int c : count) REQUIRE(c == 1);
                // Interleaved and similarity dealing fill the groups evenly.
                if (how != light_assignment::blocked)
                    for (int s = 0; s < cells; ++s) REQUIRE(g.group(s).size() >= positions.size() / std::size_t(cells));
            }
}

TEST_CASE("the tent gives every residue class of the pattern the same total weight 1/n", "[interleave]") {
    for (int n = 1; n <= 64; ++n) {
        std::vector<double> per_class(std::size_t(n), 0.0);
        for (int o = -(n - 1); o <= n - 1; ++o)
            per_class[std::size_t(((o % n) + n) % n)] += interleave_tent_weight<double>(o, n);
        for (double s : per_class) REQUIRE(s == Approx(1.0 / n).epsilon(1e-12));
        REQUIRE(interleave_tent_weight<double>(n, n) == 0.0);
    }
}

TEST_CASE("the geometry-aware tent keeps a constant, averages a pattern, and stops at an edge", "[interleave]") {
    constexpr int R = 3;
    std::array<glm::vec3, 2 * R + 1> v;
    std::array<float, 2 * R> no_edges{};
    for (auto& x : v) x = glm::vec3(2.5f);
    CHECK(geometry_aware_tent<R, float, glm::vec3>(v, no_edges, 4.f).x == Approx(2.5f).epsilon(1e-6));
    // A period-4 pattern (only one of four taps lit, at 4x the value): the tent returns its mean.
    for (int k = 0; k < 2 * R + 1; ++k) v[std::size_t(k)] = glm::vec3((k % 4 == 1) ? 4.f : 0.f);
    CHECK(geometry_aware_tent<R, float, glm::vec3>(v, no_edges, 4.f).x == Approx(1.f).epsilon(1e-6));
    // An edge between the centre and the right taps: only the centre and the left side count.
    std::array<float, 2 * R> edge{};
    edge[R] = 1.f;
    for (int k = 0; k < 2 * R + 1; ++k) v[std::size_t(k)] = glm::vec3(k <= R ? 1.f : 100.f);
    CHECK(geometry_aware_tent<R, float, glm::vec3>(v, edge, 4.f).x == Approx(1.f).epsilon(1e-6));
}

TEST_CASE("where an edge cuts the tent short, every sub-buffer it still reaches gets the same weight",
          "[interleave]") {
    constexpr int R = 7;
    for (int n = 1; n <= R + 1; ++n)
        for (int cut_left = 0; cut_left <= R; ++cut_left)
            for (int cut_right = 0; cut_right <= R; ++cut_right) {
                // Edges just beyond the cut_left-th tap on the left and cut_right-th on the right.
                std::array<double, 2 * R> edges{};
                if (cut_left < R) edges[std::size_t(R - cut_left - 1)] = 1;
                if (cut_right < R) edges[std::size_t(R + cut_right)] = 1;
                const int reached_left = std::min(cut_left, n - 1), reached_right = std::min(cut_right, n - 1);
                const int classes = 1 + std::min(n - 1, reached_left + reached_right);
                double total = 0;
                for (int c = 0; c < n; ++c) {
                    std::array<glm::dvec3, 2 * R + 1> v;
                    bool reached = false;
                    for (int o = -R; o <= R; ++o) {
                        const bool in_class = ((o % n) + n) % n == c;
                        v[std::size_t(o + R)] = glm::dvec3(in_class ? 1.0 : 0.0);
                        reached = reached || (in_class && o >= -reached_left && o <= reached_right);
                    }
                    const double w = geometry_aware_tent<R, double, glm::dvec3>(v, edges, double(n)).x;
                    INFO("n " << n << " cuts " << cut_left << ", " << cut_right << " class " << c);
                    REQUIRE(w == Approx(reached ? 1.0 / classes : 0.0).margin(1e-12));
                    total += w;
                }
                REQUIRE(total == Approx(1.0).epsilon(1e-12));
            }
}

TEST_CASE("bad patterns and sizes raise parameter_error naming the parameter", "[interleave]") {
    CHECK_THROWS_AS(cpu::interleave_maps({0, 4}, 8, 8), parameter_error);
    CHECK_THROWS_AS(cpu::interleave_maps({4, 65}, 8, 8), parameter_error);
    CHECK_THROWS_AS(cpu::interleave_maps({4, 4}, 0, 8), parameter_error);
    CHECK_THROWS_AS(assign_lights(3, 0, light_assignment::interleaved), parameter_error);
    CHECK_THROWS_AS(assign_lights(3, 4, light_assignment::similarity), parameter_error);
    try {
        cpu::interleave_maps({4, 0}, 8, 8);
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "pattern.m");
    }
}
