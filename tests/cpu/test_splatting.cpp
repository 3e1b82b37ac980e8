// CPU irradiance splatting on analytic G-buffers: zones of influence land where the math
// says, the scan leaves no pixel under-covered, and results do not depend on threads.
#include "plane_view.hpp"

#include <bounce/cpu/splatting.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <cstring>
#include <numbers>

using namespace bounce;
using cpu_test::plane_view;

namespace {
irradiance_record record_at(glm::vec3 p, float radius, glm::vec3 e) {
    irradiance_record r;
    r.position = p;
    r.normal = {0, 0, 1};
    r.irradiance = e;
    r.radius = radius;
    return r;
}
}  // namespace

TEST_CASE("one Ward record covers exactly the pixels within a R of it, with rho/pi E", "[splat][cpu]") {
    plane_view v(96, 64);
    pcg32 rng(4);
    for (int trial = 0; trial < 20; ++trial) {
        const glm::vec3 pk(2.f * rng.next_float() - 1.f, 2.f * rng.next_float() - 1.f, 0.f);
        const float radius = 0.2f + 2.f * rng.next_float(), a = 0.1f + 0.5f * rng.next_float();
        const auto rec = record_at(pk, radius, {1.f, 2.f, 3.f});
        image<glm::vec4> splat(96, 64, glm::vec4(0.f));
        cpu::splat_params sp;
        sp.a = a;
        cpu::splat_records<ward_weight>(v.gb.view(), v.cam, std::span(&rec, 1), sp, splat.view());
        for (std::size_t y = 0; y < 64; ++y)
            for (std::size_t x = 0; x < 96; ++x) {
                const float d = glm::length(v.gb.position(x, y) - pk);
                const glm::vec4 s = splat(x, y);
                // Same normals, so w = R/d, contributing where d <= aR. Pixels within float
                // rounding of the border may go either way.
                if (d < a * radius * (1 - 1e-5f)) {
                    REQUIRE(s.w > 0.f);
                    const float w = 1.f / std::max(float(inverse_weight_floor), d / radius);
                    CHECK(s.w == Approx(w).epsilon(1e-5));
                    CHECK(s.x / s.w == Approx(0.5f * 1.f / std::numbers::pi).epsilon(1e-5));
                    CHECK(s.z / s.w == Approx(1.f * 3.f / std::numbers::pi).epsilon(1e-5));
                } else if (d > a * radius * (1 + 1e-5f)) {
                    REQUIRE(s.w == 0.f);
                }
            }
    }
}

TEST_CASE("splatting is bitwise identical for any thread count and tile size", "[splat][cpu][determinism]") {
    plane_view v(128, 96);
    pcg32 rng(12);
    std::vector<irradiance_record> recs;
    for (int i = 0; i < 3000; ++i) {
        auto r = record_at({4.f * rng.next_float() - 2.f, 4.f * rng.next_float() - 2.f, 0.f}, 0.1f + rng.next_float(),
                           {rng.next_float(), rng.next_float(), rng.next_float()});
        r.translation[0] = {rng.next_float() - 0.5f, rng.next_float() - 0.5f, 0.f};
        recs.push_back(r);
    }
    cpu::splat_params sp;
    sp.a = 0.3f;
    auto run = [&](int threads, int tile) {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        image<glm::vec4> splat(128, 96, glm::vec4(0.f));
        cpu::splat_records<ward_smooth_weight>(v.gb.view(), v.cam, recs, sp, splat.view(), tile);
        return splat;
    };
    const auto one = run(1, 32), two = run(2, 32), odd = run(2, 7);
    image<glm::vec4> seq(128, 96, glm::vec4(0.f));
    for (const auto& r : recs) cpu::splat_record<ward_smooth_weight>(v.gb.view(), v.cam, r, sp, seq.view());
    CHECK(std::memcmp(one.data(), two.data(), 128 * 96 * sizeof(glm::vec4)) == 0);
    CHECK(std::memcmp(one.data(), odd.data(), 128 * 96 * sizeof(glm::vec4)) == 0);
    CHECK(std::memcmp(one.data(), seq.data(), 128 * 96 * sizeof(glm::vec4)) == 0);
}

TEST_CASE("after the cache-miss scan every covered pixel meets the weight threshold", "[splat][cpu][scan]") {
    plane_view v(80, 60);
    const float a = GENERATE(0.4f, 0.2f, 0.1f);
    const bool shuffled = GENERATE(false, true);
    cpu::splat_params sp;
    sp.a = a;
    image<glm::vec4> splat(80, 60, glm::vec4(0.f));
    std::vector<irradiance_record> recs;
    std::vector<std::uint32_t> order;
    if (shuffled) {
        order.resize(80 * 60);
        for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
        pcg32 rng(1);
        for (std::size_t i = order.size() - 1; i > 0; --i) std::swap(order[i], order[rng.next_u32() % (i + 1)]);
    }
    auto create = [&](std::size_t x, std::size_t y) -> std::optional<irradiance_record> {
        return record_at(v.gb.position(x, y), 0.5f, {1.f, 1.f, 1.f});
    };
    const auto n = cpu::scan_cache_misses<ward_smooth_weight>(v.gb.view(), v.cam, sp, a, create, recs, splat.view(), order);
    CHECK(n == recs.size());
    CHECK(n > 0);
    for (std::size_t y = 0; y < 60; ++y)
        for (std::size_t x = 0; x < 80; ++x)
            if (v.gb.view().covered(x, y)) REQUIRE(splat(x, y).w >= a);
    // The final splat of all records equals what the scan accumulated (same order).
    image<glm::vec4> again(80, 60, glm::vec4(0.f));
    cpu::splat_records<ward_smooth_weight>(v.gb.view(), v.cam, recs, sp, again.view());
    CHECK(std::memcmp(again.data(), splat.data(), 80 * 60 * sizeof(glm::vec4)) == 0);
    // Smaller a means smaller zones, hence more records: a must cost records.
    CHECK(n >= (a < 0.3f ? 4u : 1u));
}

TEST_CASE("progressive scans stop at the record budget and resume where coverage is missing", "[splat][cpu][scan]") {
    plane_view v(64, 48);
    cpu::splat_params sp;
    sp.a = 0.15f;
    image<glm::vec4> splat(64, 48, glm::vec4(0.f));
    std::vector<irradiance_record> recs;
    auto create = [&](std::size_t x, std::size_t y) -> std::optional<irradiance_record> {
        return record_at(v.gb.position(x, y), 0.4f, {1.f, 1.f, 1.f});
    };
    std::size_t frames = 0, total = 0;
    for (;; ++frames) {
        // Each frame re-splats the whole cache, then scans with a budget of 5 new records.
        std::fill(splat.data(), splat.data() + 64 * 48, glm::vec4(0.f));
        cpu::splat_records<ward_weight>(v.gb.view(), v.cam, recs, sp, splat.view());
        const auto n = cpu::scan_cache_misses<ward_weight>(v.gb.view(), v.cam, sp, sp.a, create, recs, splat.view(), {}, 5);
        CHECK(n <= 5);
        total += n;
        if (n == 0) break;
        REQUIRE(frames < 1000);
    }
    CHECK(total == recs.size());
    CHECK(frames >= 2);
}

TEST_CASE("normalization divides by the weight and leaves uncovered pixels black", "[splat][cpu]") {
    image<glm::vec4> splat(3, 1, glm::vec4(0.f));
    splat(0, 0) = {2.f, 4.f, 6.f, 2.f};
    splat(1, 0) = {1e-30f, 0.f, 0.f, 1e-30f};
    image<glm::vec3> out(3, 1);
    cpu::normalize_splats(splat.view(), out.view());
    CHECK(out(0, 0) == glm::vec3(1.f, 2.f, 3.f));
    CHECK(out(1, 0).x == Approx(1.f));
    CHECK(out(2, 0) == glm::vec3(0.f));
}

TEST_CASE("hole filling keeps covered pixels within lambda W'/W and fills the rest from the wide splat", "[splat][cpu][fill]") {
    pcg32 rng(12);
    const float lambda = 1e-3f;
    const std::size_t n = 400;
    image<glm::vec4> splat(n, 1, glm::vec4(0.f)), wide(n, 1, glm::vec4(0.f));
    for (std::size_t i = 0; i < n; ++i) {
        const float w = i % 4 == 0 ? 0.f : std::exp(8.f * rng.next_float() - 4.f);  // a quarter uncovered
        const float ww = i % 8 == 0 ? 0.f : std::exp(8.f * rng.next_float() - 2.f);  // some not even widely
        const glm::vec3 e(rng.next_float(), rng.next_float(), rng.next_float()), f(rng.next_float() + 1.f);
        splat(i, 0) = glm::vec4(e * w, w);
        wide(i, 0) = glm::vec4(f * ww, ww);
    }
    image<glm::vec3> plain(n, 1), filled(n, 1);
    cpu::normalize_splats(splat.view(), plain.view());
    cpu::normalize_splats(splat.view(), wide.view(), lambda, filled.view());
    for (std::size_t i = 0; i < n; ++i) {
        const float w = splat(i, 0).w, ww = wide(i, 0).w;
        const glm::vec3 wide_value = ww > 0.f ? glm::vec3(wide(i, 0)) / ww : glm::vec3(0.f);
        if (w == 0.f) {
            // Uncovered: the wide splat's value (black if it misses too), to float rounding.
            for (int c = 0; c < 3; ++c) REQUIRE(filled(i, 0)[c] == Approx(wide_value[c]).epsilon(1e-5).margin(1e-30));
        } else {
            // Covered: a convex blend of the two values with the wide one's share
            // lambda ww / (w + lambda ww), plus float rounding.
            const float share = lambda * ww / (w + lambda * ww);
            for (int c = 0; c < 3; ++c) {
                const float expected = (1.f - share) * plain(i, 0)[c] + share * wide_value[c];
                REQUIRE(filled(i, 0)[c] == Approx(expected).epsilon(1e-5));
            }
        }
    }
    REQUIRE_THROWS_AS(cpu::normalize_splats(splat.view(), wide.view(), 0.f, filled.view()), parameter_error);
    image<glm::vec4> small(3, 1);
    REQUIRE_THROWS_AS(cpu::normalize_splats(splat.view(), small.view(), lambda, filled.view()), parameter_error);
}

TEST_CASE("bad splatting parameters are refused with the parameter named", "[splat][cpu][bad-input]") {
    plane_view v(8, 8);
    image<glm::vec4> splat(8, 8), small(4, 4);
    const auto rec = record_at({0, 0, 0}, 1.f, {1, 1, 1});
    // Each bad value of one field, the others good: refused, naming that field.
    const auto refuses = [&](const char* name, float cpu::splat_params::*field, std::initializer_list<float> values) {
        for (float value : values) {
            cpu::splat_params sp;
            sp.*field = value;
            try {
                cpu::splat_records<ward_weight>(v.gb.view(), v.cam, std::span(&rec, 1), sp, splat.view());
                FAIL("accepted " << name << " = " << value);
            } catch (const parameter_error& e) {
                CHECK(e.parameter() == name);
            }
        }
    };
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    refuses("a", &cpu::splat_params::a, {0.f, -1.f, nan, inf});
    refuses("max_extrapolation", &cpu::splat_params::max_extrapolation, {-0.5f, nan, inf});
    refuses("front_tolerance", &cpu::splat_params::front_tolerance, {-0.1f, 1.5f, nan, inf});
    cpu::splat_params sp;
    CHECK_THROWS_AS(cpu::splat_records<ward_weight>(v.gb.view(), v.cam, std::span(&rec, 1), sp, small.view()), parameter_error);
}

#include <bounce/cpu/octree_cache.hpp>

TEST_CASE("octree lookups give the splat buffer's values on the same records", "[octree][cpu]") {
    plane_view v(96, 72);
    pcg32 rng(21);
    cpu::splat_params sp;
    sp.a = GENERATE(0.15f, 0.4f);
    cpu::octree_cache<ward_weight> tree({-3, -3, -1}, {3, 3, 1}, sp);
    std::vector<irradiance_record> recs;
    for (int i = 0; i < 500; ++i) {
        auto r = record_at({4.f * rng.next_float() - 2.f, 4.f * rng.next_float() - 2.f, 0.f}, 0.05f + rng.next_float(),
                           {rng.next_float(), rng.next_float(), rng.next_float()});
        r.rotation[1] = {0.1f, -0.2f, 0.f};
        r.translation[2] = {rng.next_float() - 0.5f, 0.f, 0.f};
        recs.push_back(r);
        tree.insert(r);
    }
    image<glm::vec4> splat(96, 72, glm::vec4(0.f)), looked(96, 72);
    cpu::splat_records<ward_weight>(v.gb.view(), v.cam, recs, sp, splat.view());
    tree.render(v.gb.view(), looked.view());
    // The same contributions, summed in another order: equal to float rounding of the sums
    // (a few ulp of the largest term, relative to the total).
    for (std::size_t y = 0; y < 72; ++y)
        for (std::size_t x = 0; x < 96; ++x)
            for (int c = 0; c < 4; ++c) REQUIRE(looked(x, y)[c] == Approx(splat(x, y)[c]).epsilon(1e-5).margin(1e-30));
}

TEMPLATE_TEST_CASE("the octree's four-lane lookups equal its scalar lookups bit for bit", "[octree][cpu][lanes]",
                   ward_weight, ward_smooth_weight, ward_scaled_normal_weight, tabellion_weight) {
    plane_view v(80, 60);
    pcg32 rng(std::uint64_t(GENERATE(1, 2, 3)));
    cpu::splat_params sp;
    sp.a = GENERATE(0.15f, 0.4f);
    sp.gradients = GENERATE(true, false);
    sp.front_tolerance = GENERATE(1.f, 0.05f);
    cpu::octree_cache<TestType> tree({-3, -3, -1}, {3, 3, 1}, sp);
    // Records off the plane and tilted (so the in-front test and the normal term both act),
    // many overlapping (lookups meet more than one group of 64), and one at a pixel's point.
    for (int i = 0; i < 1500; ++i) {
        const glm::vec3 pk{4.f * rng.next_float() - 2.f, 4.f * rng.next_float() - 2.f, 0.1f * rng.next_float() - 0.05f};
        auto r = record_at(pk, 0.05f + 3.f * rng.next_float() * rng.next_float(),
                           {rng.next_float(), rng.next_float(), rng.next_float()});
        if (i % 3 == 0)
            r.normal = glm::normalize(glm::vec3(0.1f * rng.next_float() - 0.05f, 0.1f * rng.next_float() - 0.05f, 1.f));
        r.rotation[0] = {rng.next_float() - 0.5f, 0.2f, 0.f};
        r.translation[1] = {0.f, rng.next_float() - 0.5f, 0.3f};
        tree.insert(r);
    }
    tree.insert(record_at(v.gb.position(40, 30), 0.3f, {1.f, 1.f, 1.f}));
    image<glm::vec4> scalar(80, 60), lanes(80, 60);
    tree.render(v.gb.view(), scalar.view());
    tree.render(v.gb.view(), lanes.view(), cpu::octree_evaluation::lanes);
    std::size_t weighted = 0;
    for (std::size_t y = 0; y < 60; ++y)
        for (std::size_t x = 0; x < 80; ++x) {
            weighted += scalar(x, y).w > 0.f;
            for (int c = 0; c < 4; ++c) {
                INFO("pixel (" << x << ", " << y << ") component " << c);
                REQUIRE(lanes(x, y)[c] == scalar(x, y)[c]);
            }
        }
    CHECK(weighted > 80 * 60 / 2);
}

TEST_CASE("the classical fill leaves every pixel covered once both passes ran", "[octree][cpu][scan]") {
    plane_view v(64, 48);
    cpu::splat_params sp;
    sp.a = 0.2f;
    cpu::octree_cache<ward_weight> tree({-4, -4, -1}, {4, 4, 1}, sp);
    auto create = [&](std::size_t x, std::size_t y) -> std::optional<irradiance_record> {
        return record_at(v.gb.position(x, y), 0.5f, {1.f, 1.f, 1.f});
    };
    const auto n = tree.fill(v.gb.view(), sp.a, create);
    CHECK(n == tree.records().size());
    image<glm::vec4> out(64, 48);
    tree.render(v.gb.view(), out.view());
    for (std::size_t y = 0; y < 48; ++y)
        for (std::size_t x = 0; x < 64; ++x)
            if (v.gb.view().covered(x, y)) REQUIRE(out(x, y).w >= sp.a);
}

TEST_CASE("the coarse-to-fine order is a permutation that visits the coarse grid first", "[scan][cpu][order]") {
    const std::size_t w = GENERATE(1, 7, 33, 64, 100), h = GENERATE(1, 5, 32, 61);
    const std::size_t coarsest = GENERATE(1, 4, 32);
    const auto order = cpu::coarse_to_fine_order(w, h, coarsest);
    REQUIRE(order.size() == w * h);
    std::vector<bool> seen(w * h, false);
    for (auto i : order) {
        REQUIRE(i < w * h);
        REQUIRE_FALSE(seen[i]);
        seen[i] = true;
    }
    // The first ceil(w/c) * ceil(h/c) entries are the coarsest grid, row by row; each later
    // level's pixels lie on its own grid and no coarser one.
    const std::size_t cw = (w + coarsest - 1) / coarsest, ch = (h + coarsest - 1) / coarsest;
    for (std::size_t k = 0; k < cw * ch; ++k) REQUIRE(order[k] == (k / cw) * coarsest * w + (k % cw) * coarsest);
    std::size_t level = coarsest;
    for (std::size_t k = cw * ch; k < order.size(); ++k) {
        const std::size_t x = order[k] % w, y = order[k] / w;
        while (x % level != 0 || y % level != 0) level /= 2;  // levels only get finer
        REQUIRE(level >= 1);
    }
}

TEST_CASE("a coarse-to-fine progressive scan spreads its first records over the image", "[scan][cpu][order]") {
    plane_view v(96, 64);
    cpu::splat_params sp;
    sp.a = 0.15f;
    image<glm::vec4> splat(96, 64, glm::vec4(0.f));
    std::vector<irradiance_record> recs;
    std::size_t max_y = 0;
    auto create = [&](std::size_t x, std::size_t y) -> std::optional<irradiance_record> {
        max_y = std::max(max_y, y);
        return record_at(v.gb.position(x, y), 0.4f, {1.f, 1.f, 1.f});
    };
    cpu::scan_cache_misses<ward_weight>(v.gb.view(), v.cam, sp, sp.a, create, recs, splat.view(), {}, 20);
    REQUIRE(recs.size() == 20);
    CHECK(max_y < 8);  // row by row: zones of ~1.3 pixels, so 20 records stay in the top rows
    recs.clear();
    max_y = 0;
    std::fill(splat.data(), splat.data() + 96 * 64, glm::vec4(0.f));
    const auto order = cpu::coarse_to_fine_order(96, 64, 16);
    cpu::scan_cache_misses<ward_weight>(v.gb.view(), v.cam, sp, sp.a, create, recs, splat.view(), order, 20);
    REQUIRE(recs.size() == 20);
    CHECK(max_y >= 32);  // the 6 x 4 grid of 16-pixel steps: 20 records reach the bottom half
    REQUIRE_THROWS_AS(cpu::coarse_to_fine_order(8, 8, 3), parameter_error);
    REQUIRE_THROWS_AS(cpu::coarse_to_fine_order(8, 8, 0), parameter_error);
}
