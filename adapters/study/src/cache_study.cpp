// Irradiance-cache frames measured against the reference: paths, sweeps, Monte Carlo.
#include <bounce/study/cache_study.hpp>
#include <bounce/study/frame_comparison.hpp>

#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/image_io.hpp>

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace bounce::study {

namespace {

embree::reference_settings reference_settings_of(const cache_study_settings& s) {
    embree::reference_settings r;
    r.hemisphere_samples = s.reference_spp;
    r.seed = s.reference_seed;
    return r;
}

// gbuffer<T> has no const view; the functions below only read through this one.
gbuffer_view<float> read_view(const gbuffer<float>& g) { return const_cast<gbuffer<float>&>(g).view(); }

const char* measure_name(error_measure m) { return m == error_measure::raw ? "raw" : "debiased"; }

}  // namespace

void cache_study_settings::validate() const {
    require(width > 0 && height > 0, "width/height", "must be positive");
    require(reference_spp >= 2 && reference_spp % 2 == 0, "reference_spp",
            "must be even and at least 2: the reference is two independent halves of N/2 samples");
    require(mc_max_spp > 0, "mc_max_spp", "must be positive");
}

cache_frame_study::cache_frame_study(const embree::accel& bvh, const io::scene& scene,
                                     const cache_study_settings& settings)
    : bvh_(bvh), scene_(scene), settings_(settings) {
    settings_.validate();
    const auto [lo, hi] = scene.bounds();
    scene_size_ = glm::length(hi - lo);
}

reference_halves cache_frame_study::reference(const camera& cam) const {
    bool hit = false;
    auto ref = cached_reference_halves(bvh_, scene_, cam, settings_.width, settings_.height,
                                       reference_settings_of(settings_), settings_.cache_dir, &hit);
    if (settings_.log)
        fmt::print(stderr, "reference {}x{} at {} spp (two halves of {}): {}\n", settings_.width, settings_.height,
                   settings_.reference_spp, ref.half_samples, hit ? "from cache" : "computed");
    return ref;
}

image<float> cache_frame_study::mask(const cache_frame& frame, const camera& cam) const {
    if (!settings_.rasterized_gbuffer) return coverage_mask(read_view(frame.g));
    const gbuffer<float> ray = embree::ray_cast_gbuffer(bvh_, scene_, cam, frame.g.width(), frame.g.height());
    return comparable_mask(read_view(frame.g), read_view(ray), scene_size_);
}

noisy_error cache_frame_study::error(const cache_frame& frame, const reference_halves& ref,
                                     const image<float>& mask) const {
    return measure_error(frame.indirect.view(), ref, mask.view());
}

monte_carlo_equal_error cache_frame_study::monte_carlo(const cache_frame& frame, const reference_halves& ref,
                                                       const image<float>& mask, double target,
                                                       const std::function<void(const monte_carlo_step&)>& progress) const {
    return monte_carlo_at_equal_error(bvh_, scene_, read_view(frame.g), ref.indirect_a.view(), ref.indirect_b.view(),
                                      mask.view(), target, settings_.measure, settings_.mc_max_spp, progress);
}

void cache_frame_study::log(const std::string& text) const {
    if (settings_.log) fmt::print(settings_.log, "{}", text);
}

// ---- walkthrough ----------------------------------------------------------------------------

walkthrough_report::walkthrough_report(const cache_frame_study& study, std::size_t frames, std::size_t mc_stride)
    : study_(study), frames_(frames), mc_stride_(mc_stride) {
    require(frames > 0, "frames", "must be positive");
}

void walkthrough_report::add(const cpu::walkthrough_step& step, stage_timer& timer) {
    measured_frame m{step.frame, study_.reference(step.cam), {}, {}};
    m.mask = study_.mask(m.frame, step.cam);
    m.error = study_.error(m.frame, m.reference, m.mask);
    const noisy_error& err = m.error;
    cache_ms_ += step.ms;
    error_sum_ += err.raw.rel_rms;
    debiased_sum_ += err.debiased.rel_rms_debiased;
    noise_sum_ += err.debiased.reference_noise_rel_rms;
    if (!err.debiased.resolved()) ++unresolved_;
    nlohmann::ordered_json entry = {{"frame", step.index},
                                    {"records", step.records},
                                    {"new_records", step.frame.new_records},
                                    {"ms", step.ms},
                                    {"rel_rms", err.raw.rel_rms}};
    add_debiased(entry, err.debiased);
    // Where the frame's time went, and what the clamp and the verification did to the records.
    entry["reclamped"] = step.frame.reclamped;
    if (step.frame.verify_tiles > 0)
        entry["verify"] = {{"tiles", step.frame.verify_tiles},
                           {"disagreed", step.frame.verify_disagreed},
                           {"shrunk", step.frame.verify_shrunk}};
    entry["stages_ms"] = nlohmann::ordered_json::object();
    for (const auto& [stage, ms] : step.frame.stages_ms) entry["stages_ms"][stage] = ms;
    std::string line = fmt::format("frame {:2}: {:6} records (+{:5}), {:8.1f} ms, indirect rel_rms {}", step.index,
                                   step.records, step.frame.new_records, step.ms, error_text(err));
    if (step.frame.verify_tiles > 0)
        line += fmt::format("; verify: {} tiles disagreed, {:.0f} ms", step.frame.verify_disagreed,
                            step.frame.ms("verify"));
    if (step.fresh) {
        const noisy_error fresh = study_.error(*step.fresh, m.reference, study_.mask(*step.fresh, step.cam));
        entry["fresh"] = {{"records", step.fresh_records}, {"ms", step.fresh_ms}, {"rel_rms", fresh.raw.rel_rms}};
        add_debiased(entry["fresh"], fresh.debiased);
        line += fmt::format("; fresh: {:6} records, {:8.1f} ms, rel_rms {}", step.fresh_records, step.fresh_ms,
                            error_text(fresh));
    }
    if (mc_stride_ > 0 && step.index % mc_stride_ == 0) {
        const double target = err.target(study_.settings().measure);
        if (target > 0.0) {
            const auto mc = study_.monte_carlo(m.frame, m.reference, m.mask, target);
            entry["mc_equal_error"] = mc.equal_error_json(step.ms);
            mc_ms_sum_ += mc.ms;
            mc_error_sum_ += target;
            ++mc_frames_;
            if (!mc.reached) ++mc_unreached_;
            line += fmt::format("; monte carlo {}{:.0f} spp, {:.1f} ms", mc.reached ? "~" : ">", mc.spp, mc.ms);
        } else {
            // The debiased error came out at or below 0: no error to match.
            entry["mc_equal_error"] = {{"skipped", "the frame's debiased error is not above 0"}};
            ++mc_skipped_;
            line += "; monte carlo skipped (debiased error <= 0)";
        }
    }
    study_.log(line + "\n");
    entries_.push_back(std::move(entry));
    for (const auto& [stage, ms] : step.frame.stages_ms) timer.add_sample(stage, ms);
    timer.add_sample("total", step.ms);
    ++added_;
    last_ = std::move(m);
}

double walkthrough_report::mean_reference_noise() const noexcept {
    return added_ > 0 ? noise_sum_ / double(added_) : 0.0;
}

nlohmann::ordered_json walkthrough_report::json() const {
    const double n = double(std::max<std::size_t>(1, added_));
    nlohmann::ordered_json walk = {{"frames_count", frames_},
                                   {"path", "study::camera_path: forward a tenth of the way to the target "
                                            "(at most half way to the first surface), panning -10 to +10 degrees"},
                                   {"total_ms", cache_ms_},
                                   {"mean_rel_rms", error_sum_ / n},
                                   {"mean_rel_rms_debiased", debiased_sum_ / n},
                                   {"frames_debiased_unresolved", unresolved_},
                                   {"mean_reference_noise_rel_rms", mean_reference_noise()},
                                   {"frames", entries_}};
    if (mc_frames_ > 0) {
        const double mc_total = mc_ms_sum_ / double(mc_frames_) * double(frames_);
        const char* measure = measure_name(study_.settings().measure);
        walk["mc_equal_error"] = {{"measure", measure},
                                  {"frames_measured", mc_frames_},
                                  {"stride", mc_stride_},
                                  {"frames_not_reached", mc_unreached_},
                                  {"frames_skipped", mc_skipped_},
                                  // Monte Carlo stopped short of a frame's error: its time, and the
                                  // speedup, are lower bounds.
                                  {"lower_bound", mc_unreached_ > 0},
                                  {"mean_rel_rms_measured", mc_error_sum_ / double(mc_frames_)},
                                  {"total_ms", mc_total},
                                  {"speedup", mc_total / cache_ms_}};
        study_.log(fmt::format("walkthrough: cache {:.1f} ms over {} frames, mean rel_rms {:.4f} (debiased {:.4f}, {} "
                               "of {} frames unresolved; references' own {:.4f}); Monte Carlo at equal per-frame {} "
                               "error {}{:.1f} ms: {:.1f}x\n",
                               cache_ms_, frames_, error_sum_ / n, debiased_sum_ / n, unresolved_, frames_,
                               mean_reference_noise(), measure, mc_unreached_ ? ">" : "~", mc_total,
                               mc_total / cache_ms_));
    }
    return walk;
}

// ---- progressive path -----------------------------------------------------------------------

void progressive_report::add(const cpu::walkthrough_step& step, stage_timer& timer) {
    const reference_halves ref = study_.reference(step.cam);
    const noisy_error err = study_.error(step.frame, ref, study_.mask(step.frame, step.cam));
    reference_noise_ = err.debiased.reference_noise_rel_rms;
    study_.log(fmt::format("frame {:2}: {:5} records (+{:3}), {:8.1f} ms ({:5.2f} fps), indirect rel_rms {}\n",
                           step.index, step.records, step.frame.new_records, step.ms, 1000.0 / step.ms,
                           error_text(err)));
    nlohmann::ordered_json entry = {{"frame", step.index},
                                    {"records", step.records},
                                    {"new_records", step.frame.new_records},
                                    {"ms", step.ms},
                                    {"fps", 1000.0 / step.ms},
                                    {"rel_rms", err.raw.rel_rms}};
    add_debiased(entry, err.debiased);
    entries_.push_back(std::move(entry));
    for (const auto& [stage, ms] : step.frame.stages_ms) timer.add_sample(stage, ms);
    timer.add_sample("total", step.ms);
}

// ---- a sweep ---------------------------------------------------------------------------------

void detail::add_a_sweep_entry(const cache_frame_study& study, float a, std::size_t records, cache_frame frame,
                               const reference_halves& ref, const camera& cam, stage_timer timer,
                               a_sweep_result& result) {
    measured_frame m{std::move(frame), ref, {}, {}};
    m.mask = study.mask(m.frame, cam);
    m.error = study.error(m.frame, ref, m.mask);
    study.log(fmt::format("a = {:.3f}: {:6} records (+{:5}), total {:9.1f} ms (interpolate {:8.2f}, records {:9.1f}), "
                          "indirect rel_rms {}\n",
                          a, records, m.frame.new_records, timer.median_ms("total"), timer.median_ms("interpolate"),
                          timer.median_ms("compute_records"), error_text(m.error)));
    nlohmann::ordered_json entry = {{"a", a},
                                    {"records", records},
                                    {"new_records", m.frame.new_records},
                                    {"timings_ms", nlohmann::ordered_json::object()},
                                    {"error", error_json(m.error)}};
    for (const auto& s : timer.stages()) entry["timings_ms"][s] = timer.median_ms(s);
    result.entries.push_back(std::move(entry));
    result.timer = std::move(timer);
    result.last = std::move(m);
}

// ---- after the frame ------------------------------------------------------------------------

nlohmann::ordered_json monte_carlo_report(const cache_frame_study& study, const measured_frame& m, double technique_ms) {
    const error_measure measure = study.settings().measure;
    const double target = m.error.target(measure);
    if (!(target > 0.0)) {
        // The debiased error came out at or below 0 (lost in the reference's noise): no error
        // to match; the run's figures are still reported.
        study.log("monte carlo at equal error skipped: the debiased error is not above 0 (raise --ref-spp)\n");
        return {{"mc_equal_error", {{"skipped", "the debiased error is not above 0: raise --ref-spp"}}}};
    }
    if (measure == error_measure::debiased && !m.error.debiased.resolved())
        study.log("warning: the debiased error is within two standard errors of 0; the ratio below means little\n");
    const auto mc = study.monte_carlo(m.frame, m.reference, m.mask, target, [&](const monte_carlo_step& s) {
        study.log(fmt::format("monte carlo {:4} spp: {:9.1f} ms, indirect rel_rms {:.4f} (debiased {:.4f} +- {:.4f})\n",
                              s.spp, s.ms, s.rel_rms, s.rel_rms_debiased, s.rel_rms_debiased_se));
    });
    study.log(fmt::format("at equal {} error Monte Carlo needs {}{:.0f} spp, {:.1f} ms: {}{:.1f}x the cache's {:.1f} ms\n",
                          measure_name(measure), mc.reached ? "~" : "more than ", mc.spp, mc.ms,
                          mc.reached ? "" : "at least ", mc.ms / technique_ms, technique_ms));
    return {{"mc_equal_error", mc.equal_error_json(technique_ms)}, {"mc_sweep", mc.sweep_json()}};
}

nlohmann::ordered_json ray_rates(const embree::record_sampler& sampler, std::span<const irradiance_record> records,
                                 std::size_t most, std::FILE* log) {
    require(!records.empty() && most > 0, "records", "ray rates need at least one record");
    const std::size_t count = std::min(most, records.size());
    std::vector<glm::vec3> p(count), n(count);
    std::vector<double> footprint(count, 0.0);
    std::vector<std::optional<irradiance_record>> out(count);
    for (std::size_t k = 0; k < count; ++k) {
        p[k] = records[k].position;
        n[k] = records[k].normal;
    }
    const double rays = double(count) * double(sampler.grid().count());
    auto t0 = std::chrono::steady_clock::now();
    sampler(std::span<const glm::vec3>(p), std::span<const glm::vec3>(n), std::span<const double>(footprint),
            std::span(out));
    const double record_s = ms_since(t0) / 1000;
    t0 = std::chrono::steady_clock::now();
    sampler.trace_only(p, n);
    const double trace_s = ms_since(t0) / 1000;
    if (log)
        fmt::print(log, "ray rates over {} records: records {:.3g} rays/s, Embree alone {:.3g} rays/s ({:.2f} of it)\n",
                   count, rays / record_s, rays / trace_s, trace_s / record_s);
    return {{"records", count},
            {"rays", rays},
            {"record_rays_per_s", rays / record_s},
            {"embree_rays_per_s", rays / trace_s},
            {"record_fraction_of_embree", trace_s / record_s}};
}

double view_mean_irradiance(const embree::record_sampler& probe, const embree::accel& bvh, const io::scene& scene,
                            const camera& cam) {
    const gbuffer<float> frame = embree::ray_cast_gbuffer(bvh, scene, cam, 64, 64);
    const gbuffer_view<float> g = read_view(frame);
    std::vector<glm::vec3> p, n;
    for (std::size_t y = 0; y < g.height(); y += 4)
        for (std::size_t x = 0; x < g.width(); x += 4)
            if (g.covered(x, y)) {
                p.push_back(g.position(x, y));
                n.push_back(g.normal(x, y));
            }
    return probe.mean_irradiance(p, n);
}

void write_beside_reference(const std::filesystem::path& png, image_view<const glm::vec3> indirect,
                            image_view<const glm::vec3> reference_indirect, image_view<const float> mask) {
    require(indirect.width() == reference_indirect.width() && indirect.height() == reference_indirect.height(),
            "reference_indirect", "size differs from the image's");
    const std::size_t w = indirect.width(), h = indirect.height();
    image<glm::vec3> pair(2 * w, h);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            pair(x, y) = indirect(x, y);
            pair(w + x, y) = reference_indirect(x, y);
        }
    io::write_png(png, pair.view(), io::auto_exposure(reference_indirect, mask));
}

void add_frame_counts(run_report& report, nlohmann::ordered_json& extra, std::size_t records, const cache_frame& frame,
                      const cpu::cache_frame_stats& stats, bool filter, bool verify) {
    report.set_count("records", records);
    if (frame.measured > 0) {
        // The batched scan's guesses: measured, and dropped because covered by then.
        report.set_count("records_measured", frame.measured);
        report.set_count("records_wasted", frame.wasted);
    }
    if (filter) {
        report.set_count("records_filter_merged", frame.filter_merged);
        report.set_count("records_filter_refused", frame.filter_refused);
    }
    if (!verify) return;
    report.set_count("verify_tiles", stats.verify_tiles);
    report.set_count("verify_disagreed", stats.verify_disagreed);
    report.set_count("verify_shrunk", stats.verify_shrunk);
    extra["verify_ms"] = stats.verify_ms;
    fmt::print("verification: {} of {} tiles disagreed, {} older records shrunk, {:.0f} ms of probes and tests\n",
               stats.verify_disagreed, stats.verify_tiles, stats.verify_shrunk, stats.verify_ms);
}

}  // namespace bounce::study
