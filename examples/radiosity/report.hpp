#pragma once
// What one radiosity solve gives the report, and its JSON beside study::run_report's fields;
// the reference's summary (reference_json).
#include <bounce/image.hpp>
#include <bounce/luminance.hpp>
#include <bounce/radiosity/solve.hpp>

#include <nlohmann/json.hpp>
#include <sys/resource.h>

#include <algorithm>
#include <cstddef>
#include <vector>

#include <glm/vec3.hpp>

#include "options.hpp"

namespace bounce::examples {

/// A point of the convergence curve: where the solve stood, its time, and the view's error.
struct checkpoint {
    std::size_t step = 0, shots = 0, elements = 0;
    double time_ms = 0, unshot_fraction = 1, rel_rms = 0;
};

/// What a solve gives the report.
struct solve_result {
    radiosity_solve_report report;  // the library's (steps, why it stopped, per-step figures)
    std::vector<checkpoint> curve;
    double setup_ms = 0;  // atlas and solver construction (lights shot), before the solve
    std::size_t shots = 0, shooters = 0, elements = 0, charts = 0;
    std::size_t clamped_shots = 0;  // shots scaled down to their power (shot_scale)
    std::size_t base_elements = 0;  // the atlas's, before adaptive subdivision
    glm::dvec3 emitted{0}, absorbed{0}, escaped{0};
    image<glm::vec3> lightmap, unshot, view;
    image<glm::vec3> lightmap_back;  // two-sided solves: the back sides' radiosity, laid out as lightmap
    std::size_t black_pixels = 0;    // view pixels black where the reference is lit (comparison::black_pixels)
};

/// The reference's mean luminance over `mask`: black_pixels' scale.
inline double reference_mean(const image<glm::vec3>& reference, const image<float>& mask) {
    double mean = 0, n = 0;
    for (std::size_t y = 0; y < reference.height(); ++y)
        for (std::size_t x = 0; x < reference.width(); ++x)
            if (mask(x, y) > 0.f) mean += rec709_luminance<float, glm::vec3>(reference(x, y)), n += 1;
    return mean / std::max(n, 1.0);
}

/// Whether pixel (x, y) of `view` is black (luminance below 1e-3 of `mean`, reference_mean)
/// where the reference is lit (above 1% of it): a hole in the lightmap (issue 30).
inline bool black_pixel(const image<glm::vec3>& view, const image<glm::vec3>& reference, const image<float>& mask,
                        double mean, std::size_t x, std::size_t y) {
    const auto lum = [](const glm::vec3& c) { return rec709_luminance<float, glm::vec3>(c); };
    return mask(x, y) > 0.f && lum(reference(x, y)) > 0.01 * mean && lum(view(x, y)) < 1e-3 * mean;
}

/// The pixels of `view` that are black_pixel.
inline std::size_t black_pixels(const image<glm::vec3>& view, const image<glm::vec3>& reference, const image<float>& mask) {
    const double mean = reference_mean(reference, mask);
    std::size_t black = 0;
    for (std::size_t y = 0; y < view.height(); ++y)
        for (std::size_t x = 0; x < view.width(); ++x) black += black_pixel(view, reference, mask, mean, x, y) ? 1 : 0;
    return black;
}

/// The solve's figures for the report: why it stopped, energy, memory, and the curves (times
/// from the atlas on, checkpoints excluded).
inline void add_solve_json(nlohmann::ordered_json& j, const solve_result& r) {
    j["unshot_fraction"] = r.report.unshot_fraction;  // of the emitted power (the older measure)
    j["indirect_unshot_fraction"] = r.report.indirect_unshot_fraction;
    j["stopped"] = to_string(r.report.stop);
    j["clamped_shots"] = r.clamped_shots;
    const auto sum = [](const glm::dvec3& v) { return v.x + v.y + v.z; };
    j["energy"] = {{"emitted_w", sum(r.emitted)},
                   {"absorbed_fraction", sum(r.absorbed) / sum(r.emitted)},
                   {"escaped_fraction", sum(r.escaped) / sum(r.emitted)}};
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    j["peak_rss_mb"] = double(usage.ru_maxrss) / 1024.0;
    j["ms_per_iteration"] = r.report.steps ? r.report.solve_ms / double(r.report.steps) : 0.0;
    j["converged_fraction"] = r.report.converged;
    std::vector<double> iteration_ms = r.report.step_ms;
    for (double& t : iteration_ms) t += r.setup_ms;
    j["iteration_ms"] = iteration_ms;
    nlohmann::ordered_json curve = nlohmann::ordered_json::array();
    for (const auto& c : r.curve)
        curve.push_back({{"step", c.step}, {"shots", c.shots}, {"elements", c.elements}, {"time_ms", c.time_ms},
                         {"unshot_fraction", c.unshot_fraction}, {"rel_rms", c.rel_rms}});
    j["convergence"] = curve;
}

/// The reference's settings, each bounce's share of the view's luminance (rec709_luminance),
/// and how many bounces reach 1% and 0.1% of it (the rest of the series after them).
inline nlohmann::ordered_json reference_json(const options& o, const embree::multi_bounce_image& ref) {
    const auto luminance = [](const glm::dvec3& c) { return rec709_luminance<double, glm::dvec3>(c); };
    double total = 0;
    for (const auto& b : ref.per_bounce) total += luminance(b);
    nlohmann::ordered_json shares = nlohmann::ordered_json::array();
    for (const auto& b : ref.per_bounce) shares.push_back(total > 0 ? luminance(b) / total : 0.0);
    const auto needed = [&](double tol) {
        double rest = total;
        for (std::size_t k = 0; k < ref.per_bounce.size(); ++k) {
            rest -= luminance(ref.per_bounce[k]);
            if (rest <= tol * total) return int(k);
        }
        return int(ref.per_bounce.size());
    };
    const auto s = reference_settings_for(o);
    return {{"kind", "multi-bounce path tracing"}, {"paths", s.paths}, {"max_bounces", s.max_bounces},
            {"roulette_after", s.roulette_after}, {"area_samples", s.area_samples}, {"seed", s.seed},
            {"bounce_share", shares}, {"bounces_for_1pct", needed(1e-2)}, {"bounces_for_0.1pct", needed(1e-3)}};
}

}  // namespace bounce::examples
