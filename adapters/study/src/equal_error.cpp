// Monte Carlo at equal error: doubling sample counts, then log-log interpolation.
#include <bounce/study/equal_error.hpp>
#include <bounce/study/image_comparison.hpp>

#include <bounce/embree/reference.hpp>

#include <chrono>
#include <cmath>

namespace bounce::study {

monte_carlo_equal_error monte_carlo_at_equal_error(const embree::accel& bvh, const scene_view& scene,
                                                   const gbuffer_view<float>& g, image_view<const glm::vec3> reference,
                                                   image_view<const float> mask, double target, std::uint32_t max_spp,
                                                   const std::function<void(const monte_carlo_step&)>& progress) {
    require(std::isfinite(target) && target > 0.0, "target", "must be a positive error");
    require(max_spp > 0, "max_spp", "must be positive");
    monte_carlo_equal_error r;
    r.target = target;
    for (std::uint32_t spp = 1; spp <= max_spp; spp *= 2) {
        embree::reference_settings settings;
        settings.hemisphere_samples = spp;
        settings.seed = 99;  // independent of the references' seed 1
        const embree::reference_integrator mc(bvh, scene, settings);
        const auto t0 = std::chrono::steady_clock::now();
        const image<glm::vec3> indirect = mc.indirect_image(g);
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        const monte_carlo_step step{spp, ms, compare_luminance(indirect.view(), reference, mask).rel_rms};
        r.sweep.push_back(step);
        if (progress) progress(step);
        if (step.rel_rms <= target) {
            r.reached = true;
            r.spp = spp;
            r.ms = ms;
            if (r.sweep.size() >= 2) {
                const monte_carlo_step& prev = r.sweep[r.sweep.size() - 2];
                const double t = (std::log(target) - std::log(prev.rel_rms)) / (std::log(step.rel_rms) - std::log(prev.rel_rms));
                r.spp = std::exp(std::log(double(prev.spp)) + t * (std::log(double(spp)) - std::log(double(prev.spp))));
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

nlohmann::ordered_json monte_carlo_equal_error::equal_error_json(double technique_ms) const {
    if (sweep.empty()) return nlohmann::ordered_json::object();
    const monte_carlo_step& last = sweep.back();
    nlohmann::ordered_json j;
    if (reached) {
        j = {{"spp", spp}, {"ms", ms}, {"rel_rms", target}};
    } else {
        j = {{"rel_rms", target}, {"lower_bound", true}};
    }
    j["measured_spp"] = last.spp;
    j["measured_ms"] = last.ms;
    j["measured_rel_rms"] = last.rel_rms;
    j["speedup"] = ms / technique_ms;
    return j;
}

nlohmann::ordered_json monte_carlo_equal_error::sweep_json() const {
    nlohmann::ordered_json j = nlohmann::ordered_json::array();
    for (const auto& s : sweep) j.push_back({{"spp", s.spp}, {"ms", s.ms}, {"rel_rms", s.rel_rms}});
    return j;
}

}  // namespace bounce::study
