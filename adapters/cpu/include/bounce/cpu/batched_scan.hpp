#pragma once
/// \file batched_scan.hpp
/// The cache-miss scan with records measured ahead, in parallel, and the same result as the
/// sequential scan (Gautron 2008, Algorithm 5, step 4).
///
/// The sequential scan cannot run two records at once: each record is splatted before the
/// next pixel is tested, so whether a later pixel is a miss depends on every record before
/// it. But a record itself depends only on its pixel (position, normal, footprint) when the
/// sampler is seeded by the pixel, not by a call counter. So the scan can guess: at a miss
/// it also picks the next misses that lie at least one zone of influence apart (the last
/// record's projected radius), measures all of them at once, and then walks on in order as
/// before. A guessed record is kept only if its pixel is still a miss when the walk reaches
/// it; otherwise it is dropped (counted in `scan_stats::wasted`). Work that depends on the
/// records before (neighbour clamping) runs in order in `commit`.
///
/// Result: records, their order and the splat buffer are bitwise those of the sequential
/// scan with create = measure then commit, for any batch size and thread count.

#include <bounce/cpu/splatting.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace bounce::cpu {

/// How far the batched scan guesses ahead.
struct scan_batch {
    /// Records measured together; 0: one per worker thread. More than the threads only adds
    /// guesses that are later wasted (each record's rays are parallel already).
    std::size_t max_records = 0;
    /// Pixels, in scan order, searched for guesses; 0: one image row. Guesses further on
    /// than the zones of the records before them are mostly covered by those records and
    /// wasted, so a row (the zones reach down, not back) is about right.
    std::size_t lookahead = 0;
};

/// A pixel of a batch of guesses.
struct pixel_xy {
    std::size_t x = 0, y = 0;
};

/// What a scan did.
struct scan_stats {
    std::size_t created = 0;   ///< records appended
    std::size_t measured = 0;  ///< calls of measure (created + wasted + those measure refused)
    std::size_t wasted = 0;    ///< guessed records whose pixel was covered when the walk got there
    double measure_ms = 0;     ///< wall time spent measuring (the parallel batches)
};

/// The generic driver, for any cache that answers "is (x, y) a miss?": visits pixels in
/// `order` (row by row when empty), and at each pixel where `is_miss(x, y)` measures a
/// record unless a guess already did. `measure` is either per pixel,
/// std::optional<irradiance_record>(x, y), called from several threads at once, or per
/// batch, void(std::span<const pixel_xy>, std::span<std::optional<irradiance_record>> out),
/// called once per batch (a GPU sampler that renders a batch in one atlas); either way a
/// pure function of the pixel. The driver passes each record it keeps to
/// `commit(record&)` and then to `accept(const record&) -> float`, which adds it to the
/// cache and returns its zone of influence's radius in pixels (the spacing of the next
/// guesses). Stops after `max_new` records.
template <class IsMiss, class Measure, class Commit, class Accept>
scan_stats batched_scan(std::size_t width, std::size_t height, std::span<const std::uint32_t> order,
                        std::size_t max_new, const scan_batch& batch, IsMiss&& is_miss, Measure&& measure,
                        Commit&& commit, Accept&& accept) {
    const std::size_t n = width * height;
    const std::size_t lookahead = batch.lookahead > 0 ? batch.lookahead : width;
    const std::size_t max_records =
        batch.max_records > 0 ? batch.max_records : std::size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
    require(order.empty() || order.size() == n, "order", "must list every pixel once");
    auto pixel = [&](std::size_t i) {
        const std::size_t idx = order.empty() ? i : order[i];
        require(idx < n, "order", "pixel index out of range");
        return std::pair{idx % width, idx / width};
    };
    scan_stats stats;
    std::map<std::size_t, std::optional<irradiance_record>> ahead;  // scan position -> guessed record
    float spacing = 1.f;                                              // pixels between guesses
    for (std::size_t i = 0; i < n && stats.created < max_new; ++i) {
        // Guesses behind the walk were covered before it got there.
        while (!ahead.empty() && ahead.begin()->first < i) {
            ahead.erase(ahead.begin());
            ++stats.wasted;
        }
        const auto [x, y] = pixel(i);
        if (!is_miss(x, y)) continue;
        auto it = ahead.find(i);
        if (it == ahead.end()) {
            // Guess: this miss and later ones at least `spacing` apart (Chebyshev, pixels)
            // from each other and from the guesses already made.
            std::vector<std::size_t> guess{i};
            auto far_enough = [&](std::size_t qx, std::size_t qy, std::size_t pos) {
                const auto [px, py] = pixel(pos);
                const auto dx = std::abs(std::ptrdiff_t(qx) - std::ptrdiff_t(px));
                const auto dy = std::abs(std::ptrdiff_t(qy) - std::ptrdiff_t(py));
                return float(std::max(dx, dy)) >= spacing;
            };
            for (std::size_t j = i + 1; j < std::min(n, i + lookahead) && guess.size() < max_records; ++j) {
                if (ahead.count(j)) continue;
                // Named members, not a structured binding: the lambdas below capture them,
                // which C++20 allows but Clang before 16 refuses.
                const auto q = pixel(j);
                const std::size_t qx = q.first, qy = q.second;
                if (!is_miss(qx, qy)) continue;
                const bool ok = std::all_of(guess.begin(), guess.end(), [&](std::size_t g) { return far_enough(qx, qy, g); }) &&
                                std::all_of(ahead.begin(), ahead.end(), [&](const auto& a) { return far_enough(qx, qy, a.first); });
                if (ok) guess.push_back(j);
            }
            std::vector<std::optional<irradiance_record>> measured(guess.size());
            std::vector<pixel_xy> where(guess.size());
            for (std::size_t k = 0; k < guess.size(); ++k) {
                const auto [gx, gy] = pixel(guess[k]);
                where[k] = {gx, gy};
            }
            const auto t0 = std::chrono::steady_clock::now();
            if constexpr (std::is_invocable_v<Measure&, std::span<const pixel_xy>, std::span<std::optional<irradiance_record>>>)
                measure(std::span<const pixel_xy>(where), std::span<std::optional<irradiance_record>>(measured));
            else
                tbb::parallel_for(std::size_t(0), guess.size(), [&](std::size_t k) { measured[k] = measure(where[k].x, where[k].y); });
            stats.measure_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            stats.measured += guess.size();
            for (std::size_t k = 0; k < guess.size(); ++k) ahead.emplace(guess[k], std::move(measured[k]));
            it = ahead.find(i);
        }
        std::optional<irradiance_record> rec = std::move(it->second);
        ahead.erase(it);
        if (!rec) continue;
        commit(*rec);
        spacing = std::max(1.f, accept(*rec));
        ++stats.created;
    }
    stats.wasted += ahead.size();
    return stats;
}

/// The spacing of guesses after a record whose splat touched `r`: its zone's radius in
/// pixels (at least 1).
inline float guess_spacing(const pixel_rect& r) noexcept {
    return r.empty() ? 1.f : std::max(1.f, 0.5f * float(std::max(r.x1 - r.x0, r.y1 - r.y0)));
}

/// scan_cache_misses with records measured ahead in parallel (see the file comment):
/// `measure` (per pixel and thread-safe, or per batch; see batched_scan) must be a pure
/// function of the pixel; `commit(record&)`
/// runs in scan order before the record is appended and splatted. Bitwise the same
/// records and splat buffer as scan_cache_misses<Weight> with create = measure + commit.
template <class Weight, class Measure, class Commit>
scan_stats scan_cache_misses_batched(const gbuffer_view<float>& gb, const camera& cam, const splat_params& sp,
                                     float min_weight, Measure&& measure, Commit&& commit,
                                     std::vector<irradiance_record>& records, image_view<glm::vec4> splat,
                                     const scan_batch& batch = {}, std::span<const std::uint32_t> order = {},
                                     std::size_t max_new = std::size_t(-1)) {
    sp.validate();
    require(std::isfinite(min_weight) && min_weight > 0.f, "min_weight", "must be a positive number");
    require(splat.width() == gb.width() && splat.height() == gb.height(), "splat", "splat buffer and G-buffer sizes differ");
    return batched_scan(
        gb.width(), gb.height(), order, max_new, batch,
        [&](std::size_t x, std::size_t y) { return gb.covered(x, y) && splat(x, y).w < min_weight; }, measure, commit,
        [&](const irradiance_record& rec) {
            records.push_back(rec);
            return guess_spacing(splat_record<Weight>(gb, cam, records.back(), sp, splat));
        });
}

}  // namespace bounce::cpu
