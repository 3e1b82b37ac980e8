#pragma once
/// \file cache_study.hpp
/// The measurements of irradiance-cache frames (bounce::cache_frame, of the CPU or the GL
/// backend) against the reference integrator, as ic_splatting and the benchmark take them:
///   - cache_frame_study: one scene's references in halves (cached on disk), the pixels a
///     frame is compared on, its error, and brute-force Monte Carlo at its error;
///   - walkthrough_report / progressive_report: the per-frame bookkeeping of a camera path
///     rendered by cpu::walkthrough (error, the fresh frame's error, Monte Carlo at equal
///     per-frame error on every k-th frame) and its JSON;
///   - a_sweep: one camera at several accuracies a from one growing cache, each repeated
///     from the same records, its entries and the last one's error;
///   - monte_carlo_report, ray_rates, write_beside_reference: what a run adds after its frame.
/// Progress goes to the settings' `log` (stdout by default; nullptr: silent).

#include <bounce/cache/frame.hpp>
#include <bounce/camera.hpp>
#include <bounce/cpu/cache_walkthrough.hpp>
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/image.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/equal_error.hpp>
#include <bounce/study/noisy_error_report.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/study/stage_timer.hpp>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace bounce::study {

/// What a cache study measures its frames against.
struct cache_study_settings {
    std::size_t width = 512, height = 512;  ///< the frames' size
    /// Samples per pixel of every reference, as two independent halves of half as many
    /// (even, at least 2; reference_halves).
    std::uint32_t reference_spp = 1024;
    std::uint64_t reference_seed = 1;
    /// The error Monte Carlo at equal error matches: the debiased one (it may go past the
    /// reference's samples) or the raw one (beyond half the reference's samples it would
    /// meet that reference's noise).
    error_measure measure = error_measure::debiased;
    std::uint32_t mc_max_spp = 4096;  ///< Monte Carlo at equal error stops doubling here
    /// The frames' G-buffers are rasterized (the GL frame): errors are measured only where
    /// they see the surface the ray-cast reference saw (comparable_mask).
    bool rasterized_gbuffer = false;
    std::filesystem::path cache_dir = default_cache_dir();  ///< where references are kept
    std::FILE* log = stdout;  ///< progress lines (the references' on stderr); nullptr: none
    /// Throws parameter_error naming the first bad field.
    void validate() const;
};

/// One scene's references, masks, errors and Monte Carlo baselines for cache frames.
class cache_frame_study {
public:
    /// Borrows `bvh` and `scene` (they must outlive the study). Validates the settings.
    cache_frame_study(const embree::accel& bvh, const io::scene& scene, const cache_study_settings& settings);
    const cache_study_settings& settings() const noexcept { return settings_; }
    const embree::accel& bvh() const noexcept { return bvh_; }
    const io::scene& scene() const noexcept { return scene_; }

    /// The reference of `cam` in halves: from the cache folder, or computed and stored (a line
    /// on stderr says which).
    reference_halves reference(const camera& cam) const;
    /// The pixels where `frame` (seen by `cam`) is compared: where its G-buffer sees geometry,
    /// and with rasterized_gbuffer only where it sees the ray cast's surfaces.
    image<float> mask(const cache_frame& frame, const camera& cam) const;
    /// The frame's indirect image against `ref` over `mask`.
    noisy_error error(const cache_frame& frame, const reference_halves& ref, const image<float>& mask) const;
    /// Brute-force Monte Carlo over the frame's G-buffer at doubling spp until it reaches
    /// `target` in settings().measure (monte_carlo_at_equal_error against the halves).
    monte_carlo_equal_error monte_carlo(const cache_frame& frame, const reference_halves& ref,
                                        const image<float>& mask, double target,
                                        const std::function<void(const monte_carlo_step&)>& progress = {}) const;
    /// Writes the study's progress `text` to settings().log.
    void log(const std::string& text) const;

private:
    const embree::accel& bvh_;
    const io::scene& scene_;
    cache_study_settings settings_;
    float scene_size_;
};

/// A frame with what it was measured against: the last frame of a path or a sweep, for the
/// pictures a run writes (write_beside_reference).
struct measured_frame {
    cache_frame frame;
    reference_halves reference;
    image<float> mask;
    noisy_error error;
};

/// A frame's counts into `report` (records; the batched scan's measured and wasted guesses
/// when it measured any; the neighbour filter's merged and refused with `filter`) and, with
/// `verify`, the verification pass's tiles, shrunk records and time (`extra["verify_ms"]`),
/// printed as one line.
void add_frame_counts(run_report& report, nlohmann::ordered_json& extra, std::size_t records, const cache_frame& frame,
                      const cpu::cache_frame_stats& stats, bool filter, bool verify);

/// The bookkeeping of a walkthrough (cpu::walkthrough): each step's error against its own
/// reference, the fresh frame's, and Monte Carlo at the frame's error on every
/// `mc_stride`-th frame (0: none; their mean time stands for every frame).
class walkthrough_report {
public:
    walkthrough_report(const cache_frame_study& study, std::size_t frames, std::size_t mc_stride);
    /// Measures `step`, logs its line, adds its stages and its "total" to `timer`. Its entry in
    /// frames[]: frame, records, new_records, ms, the errors, reclamped (records the frame's
    /// start clamped), verify (tiles, disagreed, shrunk; where the pass ran), stages_ms, and
    /// fresh and mc_equal_error where they ran.
    void add(const cpu::walkthrough_step& step, stage_timer& timer);
    /// The run report's "walkthrough" object: frames_count, path, total_ms, mean_rel_rms,
    /// mean_rel_rms_debiased, frames_debiased_unresolved, mean_reference_noise_rel_rms,
    /// frames[] and, when Monte Carlo ran, mc_equal_error (its mean time per frame times the
    /// frames, against the cache's total). Logs the summary line when Monte Carlo ran.
    nlohmann::ordered_json json() const;
    /// The references' own rel_rms, mean over the frames so far.
    double mean_reference_noise() const noexcept;
    /// The last frame added (nothing before the first).
    const std::optional<measured_frame>& last() const noexcept { return last_; }

private:
    const cache_frame_study& study_;
    std::size_t frames_, mc_stride_, added_ = 0;
    nlohmann::ordered_json entries_ = nlohmann::ordered_json::array();
    double cache_ms_ = 0, error_sum_ = 0, debiased_sum_ = 0, noise_sum_ = 0, mc_ms_sum_ = 0, mc_error_sum_ = 0;
    std::size_t mc_frames_ = 0, mc_unreached_ = 0, mc_skipped_ = 0, unresolved_ = 0;
    std::optional<measured_frame> last_;
};

/// The bookkeeping of a progressive camera path (a per-frame record budget, no fresh frames,
/// no Monte Carlo): each frame's records, time, frame rate and error.
class progressive_report {
public:
    explicit progressive_report(const cache_frame_study& study) : study_(study) {}
    /// Measures `step`, logs its line, adds its stages and its "total" to `timer`.
    void add(const cpu::walkthrough_step& step, stage_timer& timer);
    /// frames[]: frame, records, new_records, ms, fps, rel_rms and the debiased figures.
    const nlohmann::ordered_json& frames() const noexcept { return entries_; }
    /// The last frame's reference's own rel_rms.
    double reference_noise() const noexcept { return reference_noise_; }

private:
    const cache_frame_study& study_;
    nlohmann::ordered_json entries_ = nlohmann::ordered_json::array();
    double reference_noise_ = 0;
};

/// What a_sweep measured.
struct a_sweep_result {
    measured_frame last;  ///< the last a's last repeat
    stage_timer timer;    ///< the last a's stages and "total" over its repeats
    /// One per a: a, records, new_records, timings_ms (medians over the repeats), error.
    nlohmann::ordered_json entries = nlohmann::ordered_json::array();
};

namespace detail {
// One a of a sweep measured, logged and added to `result`.
void add_a_sweep_entry(const cache_frame_study& study, float a, std::size_t records, cache_frame frame,
                       const reference_halves& ref, const camera& cam, stage_timer timer, a_sweep_result& result);
}  // namespace detail

/// `cam` at each accuracy of `as` in order, from one cache that keeps what earlier entries
/// built (records are valid for every a): for each a the cache's options take it, and
/// `frame(cam)` (render_frame, or the GL frame) runs `repeat` times, each from the records
/// the cache held before that a (timings are medians over the repeats). Each entry is
/// measured against one reference of `cam`. Throws parameter_error for an empty sweep or
/// repeat < 1.
template <class Weight, class Frame>
    requires std::invocable<Frame&, const camera&>
a_sweep_result a_sweep(cpu::irradiance_cache<Weight>& cache, std::span<const float> as, int repeat, const camera& cam,
                       Frame&& frame, const cache_frame_study& study) {
    require(!as.empty(), "as", "needs at least one accuracy");
    require(repeat >= 1, "repeat", "must be at least 1");
    const reference_halves ref = study.reference(cam);
    a_sweep_result result;
    for (const float a : as) {
        cpu::irradiance_cache_options o = cache.options();
        o.splat.a = a;
        cache.set_options(o);
        stage_timer timer;
        const std::vector<irradiance_record> start = cache.records();
        cache_frame last;
        for (int r = 0; r < repeat; ++r) {
            cache.assign(start);
            const auto t0 = std::chrono::steady_clock::now();
            last = frame(cam);
            const double ms = ms_since(t0);
            for (const auto& [stage, stage_ms] : last.stages_ms) timer.add_sample(stage, stage_ms);
            timer.add_sample("total", ms);
        }
        detail::add_a_sweep_entry(study, a, cache.records().size(), std::move(last), ref, cam, std::move(timer), result);
    }
    return result;
}

/// Monte Carlo at the error of `m` (in study.settings().measure; a run taking
/// `technique_ms`): {"mc_equal_error": ..., "mc_sweep": ...}, each run logged; or, when that
/// error is not above 0 (lost in the reference's noise), {"mc_equal_error": {"skipped": ...}}.
nlohmann::ordered_json monte_carlo_report(const cache_frame_study& study, const measured_frame& m, double technique_ms);

/// Up to `most` of `records` measured again by `sampler` and their hemisphere rays traced
/// alone (embree::record_sampler::trace_only), logged: records, rays, record_rays_per_s,
/// embree_rays_per_s, record_fraction_of_embree. Throws parameter_error without records.
nlohmann::ordered_json ray_rates(const embree::record_sampler& sampler, std::span<const irradiance_record> records,
                                 std::size_t most = 2048, std::FILE* log = stdout);

/// The mean luminance of the irradiance `probe` measures (its first round alone:
/// embree::record_sampler::mean_irradiance) at 256 points of `cam`'s view (every fourth pixel
/// of a 64 x 64 ray-cast G-buffer that sees geometry): the scene's irradiance scale, e.g. for
/// adaptive_rays::irradiance_floor. 0 when the view sees nothing.
double view_mean_irradiance(const embree::record_sampler& probe, const embree::accel& bvh, const io::scene& scene,
                            const camera& cam);

/// `indirect` beside `reference_indirect` in one PNG (twice as wide), one exposure from the
/// reference over `mask`. Throws io::output_error or parameter_error (sizes differ).
void write_beside_reference(const std::filesystem::path& png, image_view<const glm::vec3> indirect,
                            image_view<const glm::vec3> reference_indirect, image_view<const float> mask);

}  // namespace bounce::study
