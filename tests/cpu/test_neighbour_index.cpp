// The octree neighbour clamp against the linear loop it replaces: both take the min of the
// same float expressions, so they must agree bitwise, whatever the bounds, on clustered,
// spread, coincident, isolated and out-of-bounds records.
#include <bounce/cpu/neighbour_index.hpp>
#include <bounce/errors.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <limits>
#include <vector>

using namespace bounce;

namespace {
irradiance_record rec_at(glm::vec3 p, float radius) {
    irradiance_record r;
    r.position = p;
    r.radius = radius;
    return r;
}

// A cache shaped like a scan's: clusters of small records, a few huge ones, duplicates.
std::vector<irradiance_record> random_cache(pcg32& rng, std::size_t n, float extent) {
    std::vector<irradiance_record> out;
    for (std::size_t i = 0; i < n; ++i) {
        const float u = rng.next_float();
        glm::vec3 p(rng.next_float(), rng.next_float(), rng.next_float());
        p = (p - 0.5f) * extent;
        if (u < 0.3f && !out.empty()) p = out[(rng.next_u32() % std::uint32_t(out.size()))].position + 0.01f * (p / extent);
        if (u > 0.97f && !out.empty()) p = out.back().position;  // coincident records
        float radius = extent * 0.001f * std::exp(6.f * rng.next_float());  // 1e-3 .. 0.4 extent
        if (u > 0.99f) radius = extent * 10.f;                               // a huge one
        if (u > 0.995f) p *= 3.f;                                            // far out
        out.push_back(rec_at(p, radius));
    }
    return out;
}
}  // namespace

TEST_CASE("the octree's neighbour clamp equals the linear loop bitwise", "[neighbour][cpu]") {
    const std::uint64_t seed = GENERATE(range(1, 41));
    pcg32 rng(seed);
    const float extent = 0.1f + 50.f * rng.next_float();
    const auto cache = random_cache(rng, 100 + rng.next_u32() % 1500, extent);
    // Bounds from the whole box down to a corner of it, so some records fall outside.
    const float shrink = seed % 4 == 0 ? 0.2f : 0.5f;
    cpu::neighbour_index index(glm::vec3(-shrink * extent), glm::vec3(shrink * extent));
    std::vector<irradiance_record> inserted;
    for (const auto& r : cache) {
        // Query before inserting, as the scan does: the new record against the cache so far.
        const float expected = neighbour_clamped_radius(r, inserted);
        const float got = index.clamped_radius(r);
        REQUIRE(got == expected);
        REQUIRE(got <= r.radius);
        index.insert(r);
        inserted.push_back(r);
    }
    REQUIRE(index.size() == cache.size());
}

TEST_CASE("neighbour clamping is 1-Lipschitz: after clamping, R_i <= R_j + |p_i - p_j| for j before i", "[neighbour][cpu]") {
    pcg32 rng(77);
    auto cache = random_cache(rng, 600, 8.f);
    cpu::neighbour_index index(glm::vec3(-4.f), glm::vec3(4.f));
    for (auto& r : cache) {
        r.radius = index.clamped_radius(r);
        index.insert(r);
    }
    for (std::size_t i = 0; i < cache.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            // The clamp adds in float: allow the one rounding of that sum.
            REQUIRE(cache[i].radius <= (cache[j].radius + glm::length(cache[i].position - cache[j].position)) * (1.f + 1e-6f));
}

TEST_CASE("sync mirrors a growing cache, and bad input is refused by name", "[neighbour][cpu]") {
    std::vector<irradiance_record> cache{rec_at({0, 0, 0}, 1.f), rec_at({1, 0, 0}, 0.01f)};
    cpu::neighbour_index index(glm::vec3(-1.f), glm::vec3(1.f));
    index.sync(cache);
    REQUIRE(index.size() == 2);
    cache.push_back(rec_at({1.5f, 0, 0}, 5.f));
    index.sync(cache);
    REQUIRE(index.size() == 3);
    // 0.01 + |(1.2,0,0) - (1,0,0)| = 0.21, below the others.
    REQUIRE(index.clamped_radius(rec_at({1.2f, 0, 0}, 9.f)) == Approx(0.21f).epsilon(1e-6));
    // An empty index leaves the radius alone.
    REQUIRE(cpu::neighbour_index(glm::vec3(0.f), glm::vec3(1.f)).clamped_radius(rec_at({0, 0, 0}, 3.f)) == 3.f);

    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    REQUIRE_THROWS_AS(cpu::neighbour_index(glm::vec3(1.f), glm::vec3(0.f)), parameter_error);
    REQUIRE_THROWS_AS(cpu::neighbour_index(glm::vec3(nan), glm::vec3(1.f)), parameter_error);
    REQUIRE_THROWS_AS(cpu::neighbour_index(glm::vec3(0.f), glm::vec3(inf)), parameter_error);
    REQUIRE_THROWS_AS(index.insert(rec_at({inf, 0, 0}, 1.f)), parameter_error);
    REQUIRE_THROWS_AS(index.insert(rec_at({0, nan, 0}, 1.f)), parameter_error);
    REQUIRE_THROWS_AS(index.insert(rec_at({0, 0, 0}, -1.f)), parameter_error);
    REQUIRE_THROWS_AS(index.insert(rec_at({0, 0, 0}, nan)), parameter_error);
    REQUIRE(index.size() == 3);  // a refused record leaves the index as it was
    REQUIRE(index.clamped_radius(rec_at({1.2f, 0, 0}, 9.f)) == Approx(0.21f).epsilon(1e-6));
}
