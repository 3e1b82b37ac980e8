#pragma once
/// \file irradiance_cache.hpp
/// `cpu::irradiance_cache<Weight>`: irradiance caching by splatting as a library type
/// (Gautron, "Hardware Implementation", SIGGRAPH 2008 course on irradiance caching, ch. 8,
/// Algorithm 5), or the classical octree cache (Ward et al. 1988) behind the same interface.
/// It owns the records, the scan policy (batched or sequential, scan order, a per-frame
/// budget, hole filling) and neighbour clamping; a renderer calls `render` once per frame
/// with its own G-buffer view, camera and record sampler.
///
/// A frame (`render`, the CPU backend):
///   1. splat the records the cache holds into a splat buffer (octree: insert them);
///   2. scan for cache misses, measuring a record at each with the sampler and splatting it
///      at once (cpu::scan_cache_misses[_batched]);
///   3. splat every record again into a clean buffer (Gautron 2008, Algorithm 5, step 5)
///      and normalize.
/// The GL backend (gl::irradiance_splatter) does steps 1 and 3 on the GPU and asks the cache
/// for step 2 alone (`scan`) on the splat buffer it read back, so both backends share one
/// scan and one record list.
///
/// Frames over a camera path, with either backend: cpu::render_frame and cpu::walkthrough
/// (bounce/cpu/cache_walkthrough.hpp); gl::irradiance_splatter::frame follows generation().

#include <bounce/camera.hpp>
#include <bounce/cpu/batched_scan.hpp>
#include <bounce/cpu/neighbour_index.hpp>
#include <bounce/cpu/octree_cache.hpp>
#include <bounce/cpu/splatting.hpp>
#include <bounce/errors.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/output.hpp>
#include <bounce/splat_bounds.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/cache/record_filter.hpp>
#include <bounce/cache/record_sampler.hpp>
#include <bounce/cache/verification.hpp>

#include <algorithm>
#include <chrono>
#include <concepts>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <vector>

#include <tbb/parallel_for.h>

namespace bounce::cpu {

/// How a cache interpolates its records into an image.
enum class cache_interpolation {
    splat,         ///< splatting (Algorithm 5): each record adds to the pixels of its zone
    octree,        ///< classical: per pixel, the records an octree lookup finds, one at a time
    octree_lanes,  ///< classical, the records evaluated four at a time (the splat's kernel)
};

/// How the cache-miss scan measures records.
enum class scan_kind {
    batched,     ///< guesses later misses and measures them together; same records as sequential
    sequential,  ///< one record at a time, as Gautron 2008's Algorithm 5 reads
};

/// The order in which the scan visits pixels.
enum class scan_order {
    linear,          ///< row by row (Gautron 2008's order)
    coarse_to_fine,  ///< a coarse grid first, then finer ones (coarse_to_fine_order): a budget spreads over the image
};

/// Everything a cache's frames depend on besides the G-buffer, camera and sampler.
struct irradiance_cache_options {
    splat_params splat{};  ///< a (accuracy, typical 0.1-0.4), gradients, extrapolation clamp, in-front test
    /// Cache-miss threshold on a pixel's weight sum; 0: a itself (Gautron 2008, Eq. 8.8).
    float min_weight = 0.f;
    cache_interpolation interpolation = cache_interpolation::splat;
    scan_kind scan = scan_kind::batched;
    scan_batch batch{};  ///< records measured together by the batched scan (0: one per thread)
    scan_order order = scan_order::linear;
    /// New records per frame at most (progressive rendering); the default has no limit.
    std::size_t max_new_records = std::numeric_limits<std::size_t>::max();
    /// With a budget: pixels no record reaches are filled from a second splat whose zones
    /// are this many times wider (hole_filled_splat); 0 leaves them black. Typical 4.
    float fill_holes = 4.f;
    /// Clamp each new record's radius to its neighbours': R_i <= R_j + |p_i - p_j|
    /// (Krivanek et al. 2006's neighbour clamping), and at the start of each frame the
    /// records of earlier frames to the later ones (clamp_to_neighbours).
    bool neighbour_clamp = false;
    /// Each new record's irradiance shrunk toward its neighbours' prediction, weighted by
    /// both variances, unless they differ beyond filter.k standard errors
    /// (cache/record_filter.hpp); off by default (k = 0). Needs records with a variance
    /// (embree::record_sampler's); others pass unchanged.
    record_filter filter{};
    /// After the scan, the image checked against a cheap Monte Carlo probe per pixel (the
    /// cache's probe: set_probe), pooled over tiles; where a tile disagrees, a record is
    /// measured at its pixel, the older records around it shrink to it, and the scan runs
    /// again (cache/verification.hpp). Off by default (rounds = 0); splatting (render) only.
    verification_options verify{};

    /// The weight-sum threshold the scan uses.
    float miss_threshold() const noexcept { return min_weight > 0.f ? min_weight : splat.a; }
    /// Whether a frame fills holes (a budget and fill_holes > 0).
    bool fills_holes() const noexcept {
        return max_new_records != std::numeric_limits<std::size_t>::max() && fill_holes > 0.f;
    }
    /// Throws parameter_error naming the first bad field.
    void validate() const {
        splat.validate();
        require(std::isfinite(min_weight) && min_weight >= 0.f, "min_weight", "must be a non-negative number (0: a)");
        require(std::isfinite(fill_holes) && fill_holes >= 0.f, "fill_holes", "must be a non-negative number (0: off)");
        require(max_new_records > 0, "max_new_records", "must be positive");
        filter.validate();
        verify.validate();
        require(interpolation == cache_interpolation::splat || !fills_holes(), "fill_holes",
                "applies to splatting only (set 0 for the octree)");
    }
};

/// What one frame (or one scan) did, and how long each stage took (milliseconds, wall time).
struct cache_frame_stats {
    std::size_t new_records = 0;  ///< records the scan added
    std::size_t measured = 0;     ///< records the batched scan measured (new + wasted + refused)
    std::size_t wasted = 0;       ///< guesses dropped because covered by the time the scan got there
    std::size_t reclamped = 0;    ///< older records whose radius clamp_to_neighbours shrank (render only)
    std::size_t filter_merged = 0;   ///< new records the neighbour filter shrank toward their prediction
    std::size_t filter_refused = 0;  ///< new records it left alone: beyond k standard errors of it
    double splat_existing_ms = 0; ///< step 1: the records held before the frame (octree: inserting them)
    double scan_ms = 0;           ///< step 2 without record computation
    double records_ms = 0;        ///< step 2's record computation (the sampler)
    double interpolate_ms = 0;    ///< step 3: the image from every record (octree: the lookups)
    double normalize_ms = 0;      ///< sum / weight per pixel
    double verify_ms = 0;         ///< the verification's probes and tests (its records: records_ms, its scans: scan_ms)
    std::size_t verify_tiles = 0;     ///< tiles the verification tested (over its rounds)
    std::size_t verify_disagreed = 0; ///< tiles that disagreed, one record measured at each
    std::size_t verify_shrunk = 0;    ///< older records shrunk to those records
};

/// A cheap Monte Carlo estimate of the irradiance at a pixel's point and normal
/// (cache/verification.hpp); `pixel` (y * width + x) seeds it. Called from many threads.
using irradiance_probe = std::function<probe_estimate(glm::vec3 p, glm::vec3 n, std::size_t pixel)>;

template <class Weight>
class irradiance_cache {
public:
    /// The weighting policy (cache/weighting.hpp) the cache splats and looks up with.
    using weight_type = Weight;

    /// An empty cache for a scene inside [lo, hi] (its bounds: the octree and the neighbour
    /// index are built over them; records outside still work, more slowly).
    irradiance_cache(glm::vec3 lo, glm::vec3 hi, const irradiance_cache_options& options = {})
        : lo_(lo), hi_(hi), options_(options), clamp_(lo, hi) {
        options_.validate();
    }

    const irradiance_cache_options& options() const noexcept { return options_; }
    /// New options for the next frames (records stay valid: they do not depend on them,
    /// except through neighbour clamping, which applies to records added from then on).
    void set_options(const irradiance_cache_options& options) {
        options.validate();
        options_ = options;
    }

    const std::vector<irradiance_record>& records() const noexcept { return records_; }

    /// The probe the verification pass (options().verify) asks at every pixel; without one
    /// the pass is skipped.
    void set_probe(irradiance_probe probe) { probe_ = std::move(probe); }
    /// What the last render() did (the verification's counts included).
    const cache_frame_stats& last_stats() const noexcept { return last_; }
    /// Replaces the records (a saved cache, or a restart from an earlier state).
    void assign(std::vector<irradiance_record> records) {
        records_ = std::move(records);
        clamp_ = neighbour_index(lo_, hi_);
        settled_ = 0;
        ++generation_;
    }

    /// Changes whenever records are replaced (assign) or shrunk (clamp_to_neighbours
    /// returning more than 0), and only then: a copy of the records kept elsewhere (the GPU's,
    /// gl::irradiance_splatter::frame) that saw the same generation needs only the records
    /// appended since.
    std::uint64_t generation() const noexcept { return generation_; }

    /// Neighbour clamping both ways over the whole cache: every radius becomes
    /// min_j (R_j + |p_i - p_j|) over every record j (itself included), so the radius field
    /// is 1-Lipschitz (Krivanek et al. 2006) whichever record came first. One pass is exact:
    /// by the triangle inequality the clamped radii already satisfy it against each other.
    /// Why: the scan clamps a new record against older ones only (a record splatted in this
    /// frame must not shrink under the pixels it already covers), so a large record made
    /// before a small neighbour keeps claiming the neighbour's surroundings. In one frame
    /// that costs little, because each small record sits on the pixel it was made for; from
    /// another camera, the pixel centres move off the small records' sub-pixel zones and
    /// the old large records cover them with the wrong irradiance, so the miss test finds
    /// nothing to fix (a grown Sponza cache got worse with every frame of a walkthrough).
    /// Only what can change is evaluated, with the result bitwise the whole pass's: the last
    /// pass left R_i <= R_j + |p_i - p_j| (the same float sum) for every j whose radius it saw
    /// and that has not changed since, so only the `sources` (records added since, and records
    /// whose radius differs from what the last pass saw or left) can lower a record: each
    /// source is clamped against every record, and every other record against the sources
    /// whose distance is below its radius (the index's covering query).
    /// A no-op (returns 0) without neighbour_clamp or when no record was added since the
    /// last call; otherwise returns how many radii shrank. render() calls it at the start
    /// of every frame; a caller that splats elsewhere (gl::irradiance_splatter) calls it
    /// before the frame and resets the splatter's copy when it returns more than 0.
    std::size_t clamp_to_neighbours() {
        if (!options_.neighbour_clamp || settled_ == records_.size()) return 0;
        neighbour_index index(lo_, hi_);
        index.sync(records_);
        const std::size_t n = records_.size();
        std::vector<float> radius(n);
        std::vector<char> is_source(n, 1);
        std::vector<std::size_t> sources;
        for (std::size_t i = 0; i < n; ++i) {
            radius[i] = records_[i].radius;
            if (i < settled_) is_source[i] = radius[i] != seen_[i] || radius[i] != left_[i];
            if (is_source[i]) sources.push_back(i);
        }
        tbb::parallel_for(std::size_t(0), sources.size(),
                          [&](std::size_t k) { radius[sources[k]] = index.clamped_radius(records_[sources[k]]); });
        for (const std::size_t j : sources)
            index.for_each_covering(records_[j].position, 1.f, [&](std::size_t i) {
                if (is_source[i]) return;
                const float d = glm::length(records_[i].position - records_[j].position);
                radius[i] = std::min(radius[i], records_[j].radius + d);
            });
        seen_.resize(n);
        left_.resize(n);
        std::size_t shrunk = 0;
        for (std::size_t i = 0; i < n; ++i) {
            seen_[i] = records_[i].radius;
            left_[i] = radius[i];
            if (radius[i] < records_[i].radius) {
                records_[i].radius = radius[i];
                ++shrunk;
            }
        }
        if (shrunk == 0) {
            clamp_ = std::move(index);
        } else {
            clamp_ = neighbour_index(lo_, hi_);  // `index` holds the radii before the clamp
            clamp_.sync(records_);
            ++generation_;
        }
        settled_ = n;
        return shrunk;
    }

    /// One frame: the indirect light of every pixel of `gb` seen by `cam` into `indirect` as
    /// `quantity` (output.hpp): irradiance E (W/m^2, the default) or radiance rho/pi * E with
    /// the G-buffer's albedo (W/(m^2 sr)); 0 where no record reaches, or where gb sees
    /// nothing. Misses are measured with `sampler`. `record_points`, when given (same size as
    /// gb), is where the records of missed pixels are measured instead of gb's own points (a
    /// sampler's more exact hit of the same pixel). Throws parameter_error on mismatched sizes.
    template <record_sampler Sampler>
    cache_frame_stats render(const gbuffer_view<float>& gb, const camera& cam, Sampler& sampler,
                             image_view<glm::vec3> indirect, output_quantity quantity = output_quantity::irradiance,
                             const gbuffer_view<float>* record_points = nullptr) {
        require(indirect.width() == gb.width() && indirect.height() == gb.height(), "indirect",
                "size differs from the G-buffer");
        // The splat kernel weighs rho/pi * E (splat_contribution); an albedo of pi leaves E.
        image<glm::vec3> pi_albedo;
        gbuffer_view<float> g = gb;
        if (quantity == output_quantity::irradiance) {
            pi_albedo = image<glm::vec3>(gb.width(), gb.height(), glm::vec3(std::numbers::pi_v<float>));
            g.albedo = pi_albedo.view();
        }
        cache_frame_stats stats;
        timed(stats.splat_existing_ms, [&] { stats.reclamped = clamp_to_neighbours(); });
        image<glm::vec4> splat(g.width(), g.height(), glm::vec4(0.f));
        std::optional<image<glm::vec4>> wide;
        const splat_params& sp = options_.splat;
        if (options_.interpolation == cache_interpolation::splat) {
            timed(stats.splat_existing_ms, [&] { splat_records<Weight>(g, cam, records_, sp, splat.view()); });
            scan_into(g, cam, sampler, splat.view(), record_points, stats);
            const auto splat_all = [&](image_view<glm::vec4> s) {  // every record into a clean buffer
                std::fill(s.data(), s.data() + s.width() * s.height(), glm::vec4(0.f));
                splat_records<Weight>(g, cam, records_, sp, s);
            };
            if (options_.verify.enabled() && probe_)
                verify_into(g, cam, sampler, splat.view(), record_points, stats, splat_all);
            // Step 5: the image comes from splatting every record into a clean buffer.
            timed(stats.interpolate_ms, [&] {
                splat_all(splat.view());
                if (options_.fills_holes()) {
                    splat_params wide_sp = sp;
                    wide_sp.a = sp.a * options_.fill_holes;
                    wide.emplace(g.width(), g.height(), glm::vec4(0.f));
                    splat_records<Weight>(g, cam, records_, wide_sp, wide->view());
                }
            });
        } else {
            render_octree(g, cam, sampler, splat.view(), record_points, stats);
        }
        timed(stats.normalize_ms, [&] {
            if (wide) normalize_splats(splat.view(), wide->view(), 1e-3f, indirect);
            else normalize_splats(splat.view(), indirect);
        });
        last_ = stats;
        return stats;
    }

    /// Step 2 alone, for a backend that splats elsewhere (gl::irradiance_splatter): scans
    /// `splat`, which must hold every record of the cache splatted over `g`, adds a record at
    /// each miss (and splats it into `splat`), and returns what it did (records_ms and
    /// scan_ms set). Splatting only.
    template <record_sampler Sampler>
    cache_frame_stats scan(const gbuffer_view<float>& g, const camera& cam, Sampler& sampler, image_view<glm::vec4> splat,
                           const gbuffer_view<float>* record_points = nullptr) {
        require(options_.interpolation == cache_interpolation::splat, "interpolation",
                "a scan on a splat buffer needs splatting");
        cache_frame_stats stats;
        scan_into(g, cam, sampler, splat, record_points, stats);
        return stats;
    }

    /// scan() and then, with options().verify and a probe (set_probe), the verification pass
    /// on `splat`, for a backend that splats elsewhere (gl::irradiance_splatter::frame): where
    /// the CPU frame splats every record again after a round shrank some, `resplat(splat)` must
    /// leave in `splat` every record of the cache splatted over `g` (the GL frame splats them
    /// on the GPU and reads the buffer back); the round's scan follows. `g`'s albedo must be
    /// the one the splat weighs (pi for irradiance), as the residuals divide by it. Returns
    /// what it did, which last_stats() also holds. Splatting only.
    template <record_sampler Sampler, class Resplat>
        requires std::invocable<Resplat&, image_view<glm::vec4>>
    cache_frame_stats scan_and_verify(const gbuffer_view<float>& g, const camera& cam, Sampler& sampler,
                                      image_view<glm::vec4> splat, Resplat&& resplat,
                                      const gbuffer_view<float>* record_points = nullptr) {
        cache_frame_stats stats = scan(g, cam, sampler, splat, record_points);
        if (options_.verify.enabled() && probe_) verify_into(g, cam, sampler, splat, record_points, stats, resplat);
        last_ = stats;
        return stats;
    }

private:
    using clock = std::chrono::steady_clock;
    template <class F>
    static void timed(double& ms, F&& f) {
        const auto t0 = clock::now();
        f();
        ms += std::chrono::duration<double, std::milli>(clock::now() - t0).count();
    }

    std::span<const std::uint32_t> order_for(std::size_t width, std::size_t height) {
        if (options_.order == scan_order::linear) return {};
        if (order_size_ != std::pair{width, height}) {
            order_ = coarse_to_fine_order(width, height);
            order_size_ = {width, height};
        }
        return order_;
    }

    // Records for a batch of pixels: one call of the sampler on the points of `where`.
    template <class Sampler>
    auto batch_measurer(const gbuffer_view<float>& where, const camera& cam, Sampler& sampler) {
        return [&where, &cam, &sampler](std::span<const pixel_xy> px, std::span<std::optional<irradiance_record>> out) {
            std::vector<glm::vec3> p(px.size()), n(px.size());
            std::vector<double> footprint(px.size());
            for (std::size_t k = 0; k < px.size(); ++k) {
                p[k] = where.position(px[k].x, px[k].y);
                n[k] = where.normal(px[k].x, px[k].y);
                footprint[k] = cam.pixel_footprint(where.depth(px[k].x, px[k].y), where.height());
            }
            sampler(std::span<const glm::vec3>(p), std::span<const glm::vec3>(n), std::span<const double>(footprint),
                    out);
        };
    }

    // What a new record owes to the records before it, in scan order: neighbour clamping
    // and the neighbour filter (counted in `stats`).
    auto committer(cache_frame_stats& stats) {
        return [this, &stats](irradiance_record& rec) {
            if (!options_.neighbour_clamp && !options_.filter.enabled()) return;
            clamp_.sync(records_);
            if (options_.filter.enabled()) {
                const filter_outcome f = filter_record(rec);
                stats.filter_merged += f.what == filter_outcome::merged;
                stats.filter_refused += f.what == filter_outcome::refused;
            }
            if (options_.neighbour_clamp) rec.radius = clamp_.clamped_radius(rec);
        };
    }

    // The neighbour filter: the prediction of the records whose zones at reach * a cover
    // rec's point, as the splat would weigh and extrapolate them there.
    filter_outcome filter_record(irradiance_record& rec) const {
        const splat_params& sp = options_.splat;
        const float a = options_.filter.reach * sp.a;
        neighbour_prediction p;
        clamp_.for_each_covering(rec.position, Weight::template influence_radius<float>(1.f, a), [&](std::size_t j) {
            add_neighbour<Weight>(p, rec, records_[j], a, sp.gradients, sp.max_extrapolation);
        });
        return shrink_to_prediction(rec, p, options_.filter.k, options_.filter.soft);
    }

    template <class Sampler>
    void scan_into(const gbuffer_view<float>& g, const camera& cam, Sampler& sampler, image_view<glm::vec4> splat,
                   const gbuffer_view<float>* record_points, cache_frame_stats& stats) {
        const gbuffer_view<float>& where = record_points ? *record_points : g;
        require(where.width() == g.width() && where.height() == g.height(), "record_points",
                "size differs from the G-buffer");
        const auto t0 = clock::now();
        const auto order = order_for(g.width(), g.height());
        const float min_weight = options_.miss_threshold();
        auto measure = batch_measurer(where, cam, sampler);
        if (options_.scan == scan_kind::batched) {
            const scan_stats s = scan_cache_misses_batched<Weight>(g, cam, options_.splat, min_weight, measure,
                                                                   committer(stats), records_, splat, options_.batch, order,
                                                                   options_.max_new_records);
            stats.new_records += s.created;
            stats.measured += s.measured;
            stats.wasted += s.wasted;
            stats.records_ms += s.measure_ms;
            stats.scan_ms += ms_since(t0) - s.measure_ms;
        } else {
            double record_ms = 0;
            auto commit = committer(stats);
            const auto create = [&](std::size_t x, std::size_t y) {
                std::optional<irradiance_record> rec;
                const pixel_xy px{x, y};
                timed(record_ms, [&] { measure(std::span(&px, 1), std::span(&rec, 1)); });
                if (rec) commit(*rec);
                return rec;
            };
            stats.new_records += scan_cache_misses<Weight>(g, cam, options_.splat, min_weight, create, records_, splat,
                                                           order, options_.max_new_records);
            stats.records_ms += record_ms;
            stats.scan_ms += ms_since(t0) - record_ms;
        }
    }

    // The verification pass (cache/verification.hpp): probes at every pixel (once), then per
    // round the tiles whose pooled residual disagrees, a record at each (measured as the scan
    // measures, committed in tile order), the older records within their zone of it shrunk to
    // R_new + distance (neighbour clamping towards the new record alone), and the splat and
    // scan redone on what that uncovered. Odd rounds shift the tiles by half a tile, so a
    // feature on a tile border is pooled whole once. Probes sit on a checkerboard (half the
    // pixels: a strip one pixel wide still has every other pixel probed) at half the cost.
    // Probes start where records are measured (record_points when given). `resplat(splat)`
    // splats every record again into the cleared buffer (the backend's splat).
    template <class Sampler, class Resplat>
    void verify_into(const gbuffer_view<float>& g, const camera& cam, Sampler& sampler, image_view<glm::vec4> splat,
                     const gbuffer_view<float>* record_points, cache_frame_stats& stats, Resplat&& resplat) {
        const verification_options& vo = options_.verify;
        const std::size_t w = g.width(), h = g.height();
        const gbuffer_view<float>& where = record_points ? *record_points : g;
        std::vector<probe_estimate> probes(w * h);
        timed(stats.verify_ms, [&] {
            tbb::parallel_for(std::size_t(0), h, [&](std::size_t y) {
                for (std::size_t x = 0; x < w; ++x)
                    probes[y * w + x] = g.covered(x, y) && (x + y) % 2 == 0
                                            ? probe_(where.position(x, y), where.normal(x, y), y * w + x)
                                            : probe_estimate{glm::vec3(0.f), -1.f};
            });
        });
        auto measure = batch_measurer(where, cam, sampler);
        auto commit = committer(stats);
        for (std::uint32_t round = 0; round < vo.rounds; ++round) {
            std::vector<pixel_xy> seeds;
            timed(stats.verify_ms, [&] {
                // The frame's scale: the cache's mean luminance over the pixels with weight.
                double sum = 0;
                std::size_t count = 0;
                for (std::size_t y = 0; y < h; ++y)
                    for (std::size_t x = 0; x < w; ++x)
                        if (const glm::vec4 s = splat(x, y); g.covered(x, y) && s.w > 0.f) {
                            sum += verification_luminance(glm::vec3(s) / s.w);
                            ++count;
                        }
                const double scale = count > 0 ? sum / double(count) : 0.0;
                const std::size_t t = vo.tile, shift = (round % 2) ? t / 2 : 0;
                const std::size_t tw = (w + shift + t - 1) / t, th = (h + shift + t - 1) / t;
                std::vector<std::optional<pixel_xy>> found(tw * th);
                tbb::parallel_for(std::size_t(0), th, [&](std::size_t ty) {
                    for (std::size_t tx = 0; tx < tw; ++tx) {
                        tile_residuals tile;
                        const std::size_t x0 = tx * t > shift ? tx * t - shift : 0, y0 = ty * t > shift ? ty * t - shift : 0;
                        const std::size_t x1 = std::min(w, (tx + 1) * t - shift), y1 = std::min(h, (ty + 1) * t - shift);
                        for (std::size_t y = y0; y < y1; ++y)
                            for (std::size_t x = x0; x < x1; ++x)
                                tile.add(residual_at(splat(x, y), g.albedo(x, y), probes[y * w + x]));
                        if (!tile.disagrees(vo, scale)) continue;
                        // The pixel whose residual points furthest the tile's way.
                        const double sign = tile.residual < 0 ? -1.0 : 1.0;
                        double best = -std::numeric_limits<double>::infinity();
                        for (std::size_t y = y0; y < y1; ++y)
                            for (std::size_t x = x0; x < x1; ++x) {
                                const pixel_residual r = residual_at(splat(x, y), g.albedo(x, y), probes[y * w + x]);
                                if (r.valid && sign * r.residual > best) {
                                    best = sign * r.residual;
                                    found[ty * tw + tx] = pixel_xy{x, y};
                                }
                            }
                    }
                });
                stats.verify_tiles += tw * th;
                for (const auto& f : found)
                    if (f) seeds.push_back(*f);
            });
            stats.verify_disagreed += seeds.size();
            if (seeds.empty()) continue;  // the next round pools the pixels on shifted tiles
            std::vector<std::optional<irradiance_record>> measured(seeds.size());
            timed(stats.records_ms, [&] {
                measure(std::span<const pixel_xy>(seeds), std::span<std::optional<irradiance_record>>(measured));
            });
            const auto t0 = clock::now();
            const std::size_t first = records_.size();
            for (auto& rec : measured) {
                if (!rec) continue;
                commit(*rec);
                records_.push_back(*rec);
                stats.new_records += 1;
            }
            stats.verify_shrunk += shrink_to(first);
            resplat(splat);
            stats.scan_ms += ms_since(t0);
            scan_into(g, cam, sampler, splat, record_points, stats);
        }
    }

    // Records before `first` whose zone holds a record from `first` on shrink to
    // R_new + |p - p_new| (neighbour clamping towards the new ones); the neighbour index is
    // rebuilt when any did. Returns how many shrank.
    std::size_t shrink_to(std::size_t first) {
        const float a = options_.splat.a;
        std::vector<float> radius(first);
        tbb::parallel_for(std::size_t(0), first, [&](std::size_t i) {
            float r = records_[i].radius;
            const float zone = Weight::template influence_radius<float>(r, a);
            for (std::size_t j = first; j < records_.size(); ++j) {
                const float d = glm::length(records_[i].position - records_[j].position);
                if (d < zone) r = std::min(r, records_[j].radius + d);
            }
            radius[i] = r;
        });
        std::size_t shrunk = 0;
        for (std::size_t i = 0; i < first; ++i)
            if (radius[i] < records_[i].radius) {
                records_[i].radius = radius[i];
                ++shrunk;
            }
        if (shrunk > 0) {
            clamp_ = neighbour_index(lo_, hi_);
            clamp_.sync(records_);
            ++generation_;
        }
        return shrunk;
    }

    // The classical two passes: insert the records in an octree (built for this frame's a),
    // fill it by the same scan driver (lookups as the miss test), then one lookup per pixel.
    template <class Sampler>
    void render_octree(const gbuffer_view<float>& g, const camera& cam, Sampler& sampler, image_view<glm::vec4> out,
                       const gbuffer_view<float>* record_points, cache_frame_stats& stats) {
        const gbuffer_view<float>& where = record_points ? *record_points : g;
        const splat_params& sp = options_.splat;
        octree_cache<Weight> tree(lo_, hi_, sp);
        timed(stats.splat_existing_ms, [&] {
            for (const auto& r : records_) tree.insert(r);
        });
        const auto t0 = clock::now();
        // A sequential scan is the batched driver with batches of one (it guesses nothing).
        scan_batch batch = options_.batch;
        if (options_.scan == scan_kind::sequential) batch.max_records = 1;
        const float min_weight = options_.miss_threshold();
        const glm::mat4 view = cam.view_matrix();
        const scan_stats s = batched_scan(
            g.width(), g.height(), order_for(g.width(), g.height()), options_.max_new_records, batch,
            [&](std::size_t x, std::size_t y) {
                return g.covered(x, y) && tree.lookup(g.position(x, y), g.normal(x, y), g.albedo(x, y)).w < min_weight;
            },
            batch_measurer(where, cam, sampler), committer(stats), [&](const irradiance_record& rec) {
                records_.push_back(rec);
                tree.insert(rec);
                const float zone = Weight::template influence_radius<float>(rec.radius, sp.a);
                return guess_spacing(sphere_pixel_rect(cam, view, rec.position, zone, g.width(), g.height()));
            });
        stats.new_records += s.created;
        stats.measured += s.measured;
        stats.wasted += s.wasted;
        stats.records_ms += s.measure_ms;
        stats.scan_ms += ms_since(t0) - s.measure_ms;
        timed(stats.interpolate_ms, [&] {
            tree.render(g, out, options_.interpolation == cache_interpolation::octree_lanes ? octree_evaluation::lanes
                                                                                           : octree_evaluation::scalar);
        });
    }

    static double ms_since(clock::time_point t0) {
        return std::chrono::duration<double, std::milli>(clock::now() - t0).count();
    }

    glm::vec3 lo_, hi_;
    irradiance_cache_options options_;
    std::vector<irradiance_record> records_;
    neighbour_index clamp_;
    irradiance_probe probe_;
    cache_frame_stats last_;
    std::size_t settled_ = 0;  // records_.size() at the last clamp_to_neighbours
    std::vector<float> seen_, left_;  // the radii that clamp saw and left (clamp_to_neighbours)
    std::uint64_t generation_ = 0;
    std::vector<std::uint32_t> order_;
    std::pair<std::size_t, std::size_t> order_size_{0, 0};
};

}  // namespace bounce::cpu
