// The benchmark's error figures, Monte Carlo sweeps, and the equal-error points read off them.
#include <bounce/luminance.hpp>
#include <bounce/study/benchmark_parts.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/ssim.hpp>
#include <bounce/study/stage_timer.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bounce::study::bench {

ojson number_or_null(double v) { return std::isfinite(v) ? ojson(v) : ojson(nullptr); }

ojson halves_reference::to_json() const {
    return {{"spp", spp}, {"ms", number_or_null(ms)}, {"cached", cached}, {"noise_rel_rms", number_or_null(noise_rel_rms)}};
}

ojson measured_error::to_json() const {
    return {{"rel_rms", number_or_null(rel_rms)},
            {"rel_rms_debiased", number_or_null(rel_rms_debiased)},
            {"rel_rms_debiased_se", number_or_null(rel_rms_debiased_se)},
            {"ssim", number_or_null(ssim)},
            {"debiased_resolved", resolved}};
}

ojson visibility_error_split(image_view<const glm::vec3> rays, image_view<const glm::vec3> none,
                             const halves_reference& occ, const halves_reference& unocc, image_view<const float> mask) {
    const auto lum = [](const glm::vec3& c) { return rec709_luminance<double, glm::dvec3>(glm::dvec3(c)); };
    double none_sq = 0, diff_sq = 0, occ_sq = 0, unocc_sq = 0, occ_noise = 0, unocc_noise = 0;
    for (std::size_t y = 0; y < rays.height(); ++y)
        for (std::size_t x = 0; x < rays.width(); ++x) {
            if (!mask.empty() && mask(x, y) == 0.f) continue;
            const double oa = lum(occ.a(x, y)), ob = lum(occ.b(x, y)), ua = lum(unocc.a(x, y)), ub = lum(unocc.b(x, y));
            const double ro = 0.5 * (oa + ob), ru = 0.5 * (ua + ub);
            const double no = 0.25 * (oa - ob) * (oa - ob), nu = 0.25 * (ua - ub) * (ua - ub);
            const double bn = lum(none(x, y)) - ru, br = lum(rays(x, y)) - ro;
            none_sq += bn * bn - nu;
            diff_sq += (br - bn) * (br - bn) - no - nu;
            occ_sq += ro * ro - no;
            unocc_sq += ru * ru - nu;
            occ_noise += no;
            unocc_noise += nu;
        }
    const auto root = [](double a, double b) { return b > 0 ? std::sqrt(std::max(a, 0.0) / b) : 0.0; };
    return {{"none_error_in_occluded_units", root(none_sq, occ_sq)},
            {"visibility_change", root(diff_sq, occ_sq)},
            {"references_rms_ratio", root(unocc_sq, occ_sq)}};
}

measured_error measure_error(image_view<const glm::vec3> x, const halves_reference& ref, image_view<const float> mask) {
    const noisy_reference_error d = compare_luminance_debiased(x, ref.a.view(), ref.b.view(), mask);
    measured_error e;
    e.rel_rms = d.rel_rms;
    e.rel_rms_debiased = d.rel_rms_debiased;
    e.rel_rms_debiased_se = d.rel_rms_debiased_se;
    e.resolved = d.resolved();
    e.ssim = tonemapped_ssim(x, ref.mean.view(), mask);
    return e;
}

mc_sweep monte_carlo_sweep(const std::function<image<glm::vec3>(std::uint32_t spp)>& render,
                           const halves_reference& ref, image_view<const float> mask, std::uint32_t max_spp,
                           const std::function<void(std::uint32_t spp)>& before, std::uint32_t first_spp) {
    require(first_spp > 0, "first_spp", "must be positive");
    require(max_spp >= first_spp, "max_spp", "must be at least first_spp");
    mc_sweep sweep;
    for (std::uint32_t spp = first_spp; spp <= max_spp; spp *= 2) {
        if (before) before(spp);
        const auto t0 = std::chrono::steady_clock::now();
        const image<glm::vec3> img = render(spp);
        const double ms = ms_since(t0);
        sweep.push_back({spp, ms, measure_error(img.view(), ref, mask)});
        if (spp > max_spp / 2) break;  // the next doubling passes max_spp (and would overflow near 2^32)
    }
    return sweep;
}

ojson sweep_to_json(const mc_sweep& sweep) {
    ojson j = ojson::array();
    for (const auto& s : sweep)
        j.push_back({{"spp", s.spp},
                     {"ms", number_or_null(s.ms)},
                     {"rel_rms", number_or_null(s.error.rel_rms)},
                     {"rel_rms_debiased", number_or_null(s.error.rel_rms_debiased)},
                     {"rel_rms_debiased_se", number_or_null(s.error.rel_rms_debiased_se)},
                     {"ssim", number_or_null(s.error.ssim)}});
    return j;
}

namespace {

// The first run of `sweep` at which `met(step)` holds, interpolated with the run before it by
// `spp_between(prev, step)`; not reached: the last run, flagged.
template <class Met, class Between>
equal_error_point read_off(const mc_sweep& sweep, Met met, Between spp_between) {
    require(!sweep.empty(), "sweep", "is empty");
    equal_error_point p;
    for (std::size_t k = 0; k < sweep.size(); ++k) {
        const sweep_step& step = sweep[k];
        if (!met(step)) continue;
        p.reached = true;
        p.at_first_step = k == 0;
        p.spp = k == 0 ? double(step.spp) : std::clamp(spp_between(sweep[k - 1], step), double(sweep[k - 1].spp), double(step.spp));
        p.ms = step.ms * p.spp / double(step.spp);
        return p;
    }
    p.spp = sweep.back().spp;
    p.ms = sweep.back().ms;
    return p;
}

double log_interpolated_spp(const sweep_step& prev, const sweep_step& step, double f_prev, double f_step, double f_target) {
    // f is linear in log spp between the two runs.
    const double t = (f_target - f_prev) / (f_step - f_prev);
    return std::exp(std::log(double(prev.spp)) + t * (std::log(double(step.spp)) - std::log(double(prev.spp))));
}

}  // namespace

equal_error_point equal_error_by_rel_rms(const mc_sweep& sweep, double target) {
    require(std::isfinite(target) && target > 0.0, "target", "must be a positive error");
    return read_off(
        sweep, [&](const sweep_step& s) { return s.error.rel_rms_debiased <= target; },
        [&](const sweep_step& prev, const sweep_step& step) {
            const double e0 = prev.error.rel_rms_debiased, e1 = step.error.rel_rms_debiased;
            // e0 > target > 0 here. A run lost in the reference's noise (e1 <= 0) has no
            // logarithm: continue the run before as spp^-1/2.
            if (!(e1 > 0.0) || e1 >= e0) return double(prev.spp) * (e0 / target) * (e0 / target);
            return log_interpolated_spp(prev, step, std::log(e0), std::log(e1), std::log(target));
        });
}

equal_error_point equal_error_by_ssim(const mc_sweep& sweep, double target) {
    require(std::isfinite(target) && target > -1.0 && target <= 1.0, "target", "must be an SSIM in (-1, 1]");
    return read_off(
        sweep, [&](const sweep_step& s) { return s.error.ssim >= target; },
        [&](const sweep_step& prev, const sweep_step& step) {
            const double d0 = 1.0 - prev.error.ssim, d1 = 1.0 - step.error.ssim, dt = 1.0 - target;
            if (!(d1 > 0.0) || !(dt > 0.0) || d1 >= d0) return double(step.spp);
            return log_interpolated_spp(prev, step, std::log(d0), std::log(d1), std::log(dt));
        });
}

namespace {

ojson point_json(const equal_error_point& p, double target, double technique_ms) {
    ojson j = {{"spp", number_or_null(p.spp)},
               {"ms", number_or_null(p.ms)},
               {"reached", p.reached},
               {"speedup", number_or_null(p.ms / technique_ms)},
               {"target", number_or_null(target)}};
    // Which way the figure is bounded when Monte Carlo's sweep did not bracket it.
    if (!p.reached) j["bound"] = "lower";  // Monte Carlo needs more than its largest run
    else if (p.at_first_step) j["bound"] = "upper";  // one sample per pixel already does better
    return j;
}

}  // namespace

ojson mc_equal_error_json(const mc_sweep& sweep, const measured_error& technique, double technique_ms) {
    ojson j = ojson::object();
    const double target = technique.rel_rms_debiased;
    if (target > 0.0 && std::isfinite(target)) {
        const equal_error_point p = equal_error_by_rel_rms(sweep, target);
        j["rel_rms"] = point_json(p, target, technique_ms);
        // Outside the sweep, Monte Carlo's error ~ spp^-1/2 from its nearest run says about
        // where it would meet the target: an estimate beside the measured bound.
        const sweep_step& nearest = p.reached ? sweep.front() : sweep.back();
        const double e = nearest.error.rel_rms_debiased;
        if ((!p.reached || p.at_first_step) && e > 0.0 && std::isfinite(e)) {
            const double spp = double(nearest.spp) * (e / target) * (e / target);
            const double ms = nearest.ms * spp / double(nearest.spp);
            j["rel_rms"]["spp_extrapolated"] = number_or_null(spp);
            j["rel_rms"]["ms_extrapolated"] = number_or_null(ms);
            j["rel_rms"]["speedup_extrapolated"] = number_or_null(ms / technique_ms);
        }
    } else {
        j["rel_rms"] = {{"skipped", "the debiased error is not above 0: lost in the reference's noise"}};
    }
    if (std::isfinite(technique.ssim) && technique.ssim > -1.0)
        j["ssim"] = point_json(equal_error_by_ssim(sweep, technique.ssim), technique.ssim, technique_ms);
    else
        j["ssim"] = {{"skipped", "no SSIM"}};
    return j;
}

}  // namespace bounce::study::bench
