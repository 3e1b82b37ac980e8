// The batched cache-miss scan against the sequential one: with records that depend only on
// their pixel, both must give the same records in the same order and the same splat buffer,
// bit for bit, whatever the batch size, lookahead, order, budget and thread count.
#include "plane_view.hpp"

#include <bounce/cpu/batched_scan.hpp>
#include <bounce/cpu/neighbour_index.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <cstring>

using namespace bounce;

namespace {
// A tilted plane seen from above, with a hole (uncovered pixels) in it.
cpu_test::plane_view plane_scene(std::size_t w, std::size_t h) {
    return cpu_test::plane_view(w, h, glm::normalize(glm::vec3(0.2f, -0.1f, 1.f)), true);
}

// A pure record of the pixel: radius and irradiance from a hash of (x, y), some pixels
// refusing (nullopt), as a sampler that finds no finite estimate would.
std::optional<irradiance_record> pure_record(const gbuffer<float>& gb, std::size_t x, std::size_t y) {
    pcg32 rng(std::uint64_t(y) * 7919u + x + 1);
    if (rng.next_float() < 0.05f) return std::nullopt;
    irradiance_record r;
    r.position = gb.position(x, y);
    r.normal = gb.normal(x, y);
    r.irradiance = {rng.next_float(), rng.next_float(), rng.next_float()};
    r.translation[0] = {rng.next_float() - 0.5f, rng.next_float() - 0.5f, 0.f};
    r.radius = 0.05f + 1.5f * rng.next_float() * rng.next_float();
    return r;
}
}  // namespace

TEST_CASE("the batched scan makes the sequential scan's records and splat buffer, bitwise", "[scan][cpu][batched]") {
    const std::size_t w = 72, h = 54;
    auto s = plane_scene(w, h);
    const auto variant = GENERATE(range(0, 24));
    const std::size_t batch_size = std::array<std::size_t, 4>{1, 0, 3, 64}[variant % 4];
    const std::size_t lookahead = std::array<std::size_t, 3>{0, 1, 4000}[(variant / 4) % 3];
    const bool shuffled = variant % 2 == 1;
    const bool clamp = variant % 3 == 0;
    const std::size_t budget = variant % 5 == 0 ? 40 : std::size_t(-1);
    const int threads = 1 + variant % 2;
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));

    cpu::splat_params sp;
    sp.a = 0.1f + 0.02f * float(variant % 7);
    std::vector<std::uint32_t> order;
    if (shuffled) {
        order.resize(w * h);
        for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
        pcg32 rng{std::uint64_t(variant)};
        for (std::size_t i = order.size() - 1; i > 0; --i) std::swap(order[i], order[rng.next_u32() % (i + 1)]);
    }
    const glm::vec3 lo(-20.f), hi(20.f);

    // Sequential: create = measure, then neighbour clamping against the records so far.
    std::vector<irradiance_record> seq;
    image<glm::vec4> seq_splat(w, h, glm::vec4(0.f));
    cpu::neighbour_index seq_index(lo, hi);
    auto create = [&](std::size_t x, std::size_t y) {
        auto r = pure_record(s.gb, x, y);
        if (r && clamp) {
            seq_index.sync(seq);
            r->radius = seq_index.clamped_radius(*r);
        }
        return r;
    };
    const auto n_seq = cpu::scan_cache_misses<ward_smooth_weight>(s.gb.view(), s.cam, sp, sp.a, create, seq,
                                                                  seq_splat.view(), order, budget);

    std::vector<irradiance_record> bat;
    image<glm::vec4> bat_splat(w, h, glm::vec4(0.f));
    cpu::neighbour_index bat_index(lo, hi);
    std::atomic<std::size_t> calls{0};
    auto measure = [&](std::size_t x, std::size_t y) {
        ++calls;
        return pure_record(s.gb, x, y);
    };
    auto commit = [&](irradiance_record& r) {
        if (!clamp) return;
        bat_index.sync(bat);
        r.radius = bat_index.clamped_radius(r);
    };
    const auto stats = cpu::scan_cache_misses_batched<ward_smooth_weight>(
        s.gb.view(), s.cam, sp, sp.a, measure, commit, bat, bat_splat.view(), cpu::scan_batch{batch_size, lookahead},
        order, budget);

    REQUIRE(stats.created == n_seq);
    REQUIRE(bat.size() == seq.size());
    REQUIRE(seq.size() > 10);
    REQUIRE(std::memcmp(bat.data(), seq.data(), seq.size() * sizeof(irradiance_record)) == 0);
    REQUIRE(std::memcmp(bat_splat.data(), seq_splat.data(), w * h * sizeof(glm::vec4)) == 0);
    // Every measured record was either kept, refused by measure, or wasted.
    REQUIRE(stats.measured == calls.load());
    REQUIRE(stats.measured >= stats.created + stats.wasted);
    if (batch_size == 1 || (batch_size == 0 && threads == 1)) REQUIRE(stats.wasted == 0);  // no guesses, no waste
}

TEST_CASE("a per-batch measure (a GPU atlas) gives the per-pixel scan's records", "[scan][cpu][batched]") {
    const std::size_t w = 64, h = 48;
    auto s = plane_scene(w, h);
    cpu::splat_params sp;
    sp.a = 0.12f;
    const std::size_t batch_size = GENERATE(1, 5, 32);
    std::vector<irradiance_record> seq, bat;
    image<glm::vec4> seq_splat(w, h, glm::vec4(0.f)), bat_splat(w, h, glm::vec4(0.f));
    auto create = [&](std::size_t x, std::size_t y) { return pure_record(s.gb, x, y); };
    cpu::scan_cache_misses<ward_weight>(s.gb.view(), s.cam, sp, sp.a, create, seq, seq_splat.view());
    std::size_t calls = 0, largest = 0;
    auto measure_batch = [&](std::span<const cpu::pixel_xy> px, std::span<std::optional<irradiance_record>> out) {
        ++calls;
        largest = std::max(largest, px.size());
        REQUIRE(px.size() == out.size());
        for (std::size_t k = 0; k < px.size(); ++k) out[k] = pure_record(s.gb, px[k].x, px[k].y);
    };
    const auto stats = cpu::scan_cache_misses_batched<ward_weight>(
        s.gb.view(), s.cam, sp, sp.a, measure_batch, [](irradiance_record&) {}, bat, bat_splat.view(),
        cpu::scan_batch{batch_size, 0});
    REQUIRE(bat.size() == seq.size());
    REQUIRE(std::memcmp(bat.data(), seq.data(), seq.size() * sizeof(irradiance_record)) == 0);
    REQUIRE(std::memcmp(bat_splat.data(), seq_splat.data(), w * h * sizeof(glm::vec4)) == 0);
    REQUIRE(largest <= batch_size);
    REQUIRE(calls <= stats.measured);
    if (batch_size > 1) REQUIRE(calls < stats.created);  // batches did hold several records
}

TEST_CASE("the batched scan refuses bad orders by name", "[scan][cpu][batched][bad-input]") {
    auto s = plane_scene(8, 6);
    cpu::splat_params sp;
    std::vector<irradiance_record> recs;
    image<glm::vec4> splat(8, 6, glm::vec4(0.f));
    auto measure = [&](std::size_t x, std::size_t y) { return pure_record(s.gb, x, y); };
    auto commit = [](irradiance_record&) {};
    auto run = [&](cpu::scan_batch b, std::vector<std::uint32_t> order) {
        cpu::scan_cache_misses_batched<ward_weight>(s.gb.view(), s.cam, sp, sp.a, measure, commit, recs, splat.view(), b, order);
    };
    REQUIRE_THROWS_AS(run({4, 10}, {1, 2, 3}), parameter_error);
    std::vector<std::uint32_t> bad(48, 0);
    bad[5] = 1000;
    REQUIRE_THROWS_AS(run({4, 10}, bad), parameter_error);
}
