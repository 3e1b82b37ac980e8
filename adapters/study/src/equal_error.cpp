// Monte Carlo at equal error: doubling sample counts, then log-log interpolation.
#include <bounce/study/equal_error.hpp>
#include <bounce/study/image_comparison.hpp>

#include <bounce/embree/reference.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace bounce::study {

namespace {

// The doubling search shared by both overloads; `measure_step` fills a step's errors from
// Monte Carlo's indirect image.
template <class Measure>
monte_carlo_equal_error search(const embree::accel& bvh, const scene_view& scene, const gbuffer_view<float>& g,
                               monte_carlo_equal_error r, std::uint32_t max_spp, Measure measure_step,
                               const std::function<void(const monte_carlo_step&)>& progress) {
    require(std::isfinite(r.target) && r.target > 0.0, "target", "must be a positive error");
    require(max_spp > 0, "max_spp", "must be positive");
    for (std::uint32_t spp = 1; spp <= max_spp; spp *= 2) {
        embree::reference_settings settings;
        settings.hemisphere_samples = spp;
        settings.seed = 99;  // independent of the references' seeds (1, and the halves' hashed seeds)
        const embree::reference_integrator mc(bvh, scene, settings);
        const auto t0 = std::chrono::steady_clock::now();
        const image<glm::vec3> indirect = mc.indirect_image(g);
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        monte_carlo_step step{spp, ms, 0.0};
        measure_step(indirect, step);
        r.sweep.push_back(step);
        if (progress) progress(step);
        const double err = r.error_of(step);
        if (err <= r.target) {
            r.reached = true;
            r.spp = spp;
            r.ms = ms;
            if (r.sweep.size() >= 2) {
                const monte_carlo_step& prev = r.sweep[r.sweep.size() - 2];
                const double prev_err = r.error_of(prev);  // > target > 0, or the search had stopped there
                if (err > 0.0) {
                    const double t = (std::log(r.target) - std::log(prev_err)) / (std::log(err) - std::log(prev_err));
                    r.spp = std::exp(std::log(double(prev.spp)) + t * (std::log(double(spp)) - std::log(double(prev.spp))));
                } else {
                    // A debiased error at or below 0 has no logarithm: follow error ~ spp^-1/2
                    // from the run before, never past this run.
                    r.spp = std::min(double(spp), double(prev.spp) * (prev_err / r.target) * (prev_err / r.target));
                }
                r.ms = ms * r.spp / spp;
            }
            return r;
        }
        if (spp > max_spp / 2) break;  // the next doubling would pass max_spp (and overflow near 2^32)
    }
    if (!r.sweep.empty()) {
        r.spp = r.sweep.back().spp;
        r.ms = r.sweep.back().ms;
    }
    return r;
}

}  // namespace

monte_carlo_equal_error monte_carlo_at_equal_error(const embree::accel& bvh, const scene_view& scene,
                                                   const gbuffer_view<float>& g, image_view<const glm::vec3> reference,
                                                   image_view<const float> mask, double target, std::uint32_t max_spp,
                                                   const std::function<void(const monte_carlo_step&)>& progress) {
    monte_carlo_equal_error r;
    r.target = target;
    return search(
        bvh, scene, g, std::move(r), max_spp,
        [&](const image<glm::vec3>& indirect, monte_carlo_step& step) {
            step.rel_rms = compare_luminance(indirect.view(), reference, mask).rel_rms;
        },
        progress);
}

monte_carlo_equal_error monte_carlo_at_equal_error(const embree::accel& bvh, const scene_view& scene,
                                                   const gbuffer_view<float>& g, image_view<const glm::vec3> half_a,
                                                   image_view<const glm::vec3> half_b, image_view<const float> mask,
                                                   double target, error_measure measure, std::uint32_t max_spp,
                                                   const std::function<void(const monte_carlo_step&)>& progress) {
    require(half_a.width() == g.width() && half_a.height() == g.height() && half_b.width() == g.width() &&
                half_b.height() == g.height(),
            "half_a/half_b", "size differs from the G-buffer");
    monte_carlo_equal_error r;
    r.target = target;
    r.measure = measure;
    r.against_halves = true;
    return search(
        bvh, scene, g, std::move(r), max_spp,
        [&](const image<glm::vec3>& indirect, monte_carlo_step& step) {
            const noisy_reference_error e = compare_luminance_debiased(indirect.view(), half_a, half_b, mask);
            step.rel_rms = e.rel_rms;
            step.rel_rms_debiased = e.rel_rms_debiased;
            step.rel_rms_debiased_se = e.rel_rms_debiased_se;
        },
        progress);
}

nlohmann::ordered_json monte_carlo_equal_error::equal_error_json(double technique_ms) const {
    if (sweep.empty()) return nlohmann::ordered_json::object();
    const monte_carlo_step& last = sweep.back();
    nlohmann::ordered_json j;
    if (against_halves) j["measure"] = measure == error_measure::debiased ? "debiased" : "raw";
    if (reached) {
        j["spp"] = spp;
        j["ms"] = ms;
        j["rel_rms"] = target;
    } else {
        j["rel_rms"] = target;
        j["lower_bound"] = true;
    }
    j["measured_spp"] = last.spp;
    j["measured_ms"] = last.ms;
    j["measured_rel_rms"] = error_of(last);
    j["speedup"] = ms / technique_ms;
    return j;
}

nlohmann::ordered_json monte_carlo_equal_error::sweep_json() const {
    nlohmann::ordered_json j = nlohmann::ordered_json::array();
    for (const auto& s : sweep) {
        nlohmann::ordered_json e = {{"spp", s.spp}, {"ms", s.ms}, {"rel_rms", s.rel_rms}};
        if (against_halves) {
            e["rel_rms_debiased"] = s.rel_rms_debiased;
            e["rel_rms_debiased_se"] = s.rel_rms_debiased_se;
        }
        j.push_back(e);
    }
    return j;
}

}  // namespace bounce::study
