#include <bounce/study/volume_sweep.hpp>

#include <bounce/errors.hpp>

#include <bit>
#include <cmath>
#include <cstdio>
#include <utility>

namespace bounce::study {

std::size_t probe_memo::key_hash::operator()(const std::array<std::uint32_t, 3>& k) const noexcept {
    std::uint64_t h = 0x9e3779b97f4a7c15ull;
    for (const std::uint32_t v : k) h = (h ^ v) * 0x100000001b3ull, h ^= h >> 29;
    return std::size_t(h);
}

probe_memo::probe_memo(source_type source) : source_(std::move(source)) {
    require(bool(source_), "source", "a probe_memo needs a source to bake the probes it has not seen");
}

void probe_memo::operator()(std::span<const glm::vec3> positions, std::span<irradiance_probe> out) {
    require(out.size() == positions.size(), "out", "one probe per position");
    const auto key = [](glm::vec3 p) {
        return std::array<std::uint32_t, 3>{std::bit_cast<std::uint32_t>(p.x), std::bit_cast<std::uint32_t>(p.y),
                                            std::bit_cast<std::uint32_t>(p.z)};
    };
    std::vector<glm::vec3> missing;
    std::vector<std::size_t> where;
    for (std::size_t i = 0; i < positions.size(); ++i) {
        const auto it = memo_.find(key(positions[i]));
        if (it != memo_.end()) {
            out[i] = it->second, ++reused_;
        } else {
            missing.push_back(positions[i]), where.push_back(i);
        }
    }
    if (missing.empty()) return;
    std::vector<irradiance_probe> baked(missing.size());
    source_(missing, baked);
    baked_ += missing.size();
    for (std::size_t k = 0; k < missing.size(); ++k) {
        out[where[k]] = baked[k];
        memo_.emplace(key(missing[k]), baked[k]);
    }
}

std::vector<volume_sweep_point> bias_budget_sweep(const scene_view& scene, glm::vec3 lo, glm::vec3 hi,
                                                  irradiance_volume_settings settings, probe_memo& source,
                                                  const volume_sphere_study& sphere, std::span<const float> budgets,
                                                  std::span<const float> sigmas) {
    for (const float b : budgets) require(std::isfinite(b) && b > 0, "budgets", "every bias budget must be positive and finite");
    for (const float k : sigmas) require(std::isfinite(k) && k >= 0, "sigmas", "every noise_sigmas must be finite and >= 0");
    settings.refinement = volume_refinement::merge;
    const std::vector<float> ks = sigmas.empty() ? std::vector<float>{settings.noise_sigmas}
                                                 : std::vector<float>(sigmas.begin(), sigmas.end());
    std::vector<volume_sweep_point> out;
    for (const float b : budgets) {
        for (const float k : ks) {
            settings.bias_budget = b;
            settings.noise_sigmas = k;
            irradiance_volume_build_stats stats;
            const irradiance_volume volume = irradiance_volume::build(scene, lo, hi, settings, source, &stats);
            volume_sweep_point p;
            p.bias_budget = b;
            p.noise_sigmas = k;
            p.probes = volume.probes().size();
            p.probes_inside = stats.probes_inside;
            p.leaves = volume.leaf_count();
            p.trilinear = sphere.measure(volume, "trilinear", cpu::volume_lookup{});
            std::printf("sweep bias_budget %-6.3g sigmas %-4.3g %5zu probes, %5zu leaves  rel_rms %.4f  popping %.4f (excess %.4f)\n",
                        double(b), double(k), p.probes, p.leaves, p.trilinear.error.rel_rms, p.trilinear.popping,
                        p.trilinear.popping_excess);
            out.push_back(std::move(p));
        }
    }
    return out;
}

nlohmann::ordered_json to_json(std::span<const volume_sweep_point> sweep) {
    nlohmann::ordered_json j = nlohmann::ordered_json::array();
    for (const auto& p : sweep)
        j.push_back({{"bias_budget", p.bias_budget}, {"noise_sigmas", p.noise_sigmas}, {"probes", p.probes}, {"probes_inside", p.probes_inside},
                     {"leaves", p.leaves}, {"rel_rms", p.trilinear.error.rel_rms}, {"popping", p.trilinear.popping},
                     {"popping_excess", p.trilinear.popping_excess}});
    return j;
}

}  // namespace bounce::study
