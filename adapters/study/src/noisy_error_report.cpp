// An error against a reference in halves, as JSON and as text.
#include <bounce/study/noisy_error_report.hpp>

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace bounce::study {

noisy_error measure_error(image_view<const glm::vec3> indirect, const reference_halves& ref,
                          image_view<const float> mask) {
    return {compare_luminance(indirect, ref.whole.indirect.view(), mask),
            compare_luminance_debiased(indirect, ref.indirect_a.view(), ref.indirect_b.view(), mask)};
}

nlohmann::ordered_json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nullptr; }

void add_debiased(nlohmann::ordered_json& j, const noisy_reference_error& d) {
    j["rel_rms_debiased"] = finite_or_null(d.rel_rms_debiased);
    j["rel_rms_debiased_se"] = finite_or_null(d.rel_rms_debiased_se);
    j["rel_sq_debiased"] = finite_or_null(d.rel_sq_debiased);
    j["rel_sq_debiased_se"] = finite_or_null(d.rel_sq_debiased_se);
    j["debiased_resolved"] = d.resolved();
    j["reference_noise_rel_rms"] = finite_or_null(d.reference_noise_rel_rms);
}

nlohmann::ordered_json error_json(const noisy_error& e) {
    nlohmann::ordered_json j = {{"rel_rms", finite_or_null(e.raw.rel_rms)},
                                {"max_abs", finite_or_null(e.raw.max_abs)},
                                {"sum_sq", finite_or_null(e.raw.sum_sq)},
                                {"pixels", e.raw.pixels}};
    add_debiased(j, e.debiased);
    return j;
}

std::string error_text(const noisy_error& e) {
    const auto& d = e.debiased;
    if (d.resolved())
        return fmt::format("{:.4f} (debiased {:.4f} +- {:.4f})", e.raw.rel_rms, d.rel_rms_debiased,
                           d.rel_rms_debiased_se);
    return fmt::format("{:.4f} (debiased < {:.4f}, unresolved)", e.raw.rel_rms,
                       std::sqrt(std::max(0.0, d.rel_sq_debiased) + 2.0 * d.rel_sq_debiased_se));
}

}  // namespace bounce::study
