#include <bounce/study/volume_sweep.hpp>

#include <bounce/errors.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <iterator>
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

namespace {

// The octree's figures: trilinear on the sphere, and at the surface points when given.
volume_sweep_point measure_point(const irradiance_volume& volume, const irradiance_volume_build_stats& stats,
                                 const volume_sphere_study& sphere, const volume_surface_study* surface) {
    volume_sweep_point p;
    p.max_depth = volume.depth();
    p.probes = volume.probes().size();
    p.probes_inside = stats.probes_inside;
    p.leaves = volume.leaf_count();
    p.hanging = stats.hanging_corners;
    p.hanging_computed = !volume.hanging_corners().empty();
    p.scene_light = stats.scene_light, p.median_noise = stats.median_noise;
    p.trilinear = sphere.measure(volume, "trilinear", cpu::volume_lookup{});
    if (surface) p.surface = surface->measure(volume, nullptr, cpu::volume_lookup{});
    return p;
}

void print_point(const char* what, const volume_sweep_point& p) {
    std::printf("%s rays %u depth %d bias_budget %-6.3g tolerance %-6.3g sigmas %-4.3g %6zu probes, %6zu leaves  rel_rms %.4f  popping %.4f (excess %.4f)",
                what, p.rays_per_probe, p.max_depth, double(p.bias_budget), double(p.bias_tolerance), double(p.noise_sigmas), p.probes, p.leaves, p.trilinear.error.rel_rms,
                p.trilinear.popping, p.trilinear.popping_excess);
    if (p.surface) std::printf("  surface %.4f (debiased %.4f)", p.surface->all.rel_rms, p.surface->all.rel_rms_debiased);
    std::printf("\n");
    std::fflush(stdout);
}

}  // namespace

namespace {

// The merged octree of every value (set by `set`) at every slack, measured.
template <class Set>
std::vector<volume_sweep_point> merge_sweep(const scene_view& scene, glm::vec3 lo, glm::vec3 hi, irradiance_volume_settings settings,
                                            probe_memo& source, const volume_sphere_study& sphere, std::span<const float> values,
                                            std::span<const float> sigmas, const volume_surface_study* surface,
                                            const volume_rebake* rebake, Set set) {
    for (const float k : sigmas) require(std::isfinite(k) && k >= 0, "sigmas", "every noise_sigmas must be finite and >= 0");
    settings.refinement = volume_refinement::merge;
    const std::vector<float> ks = sigmas.empty() ? std::vector<float>{settings.noise_sigmas}
                                                 : std::vector<float>(sigmas.begin(), sigmas.end());
    std::vector<volume_sweep_point> out;
    for (const float v : values) {
        for (const float k : ks) {
            set(settings, v);
            settings.noise_sigmas = k;
            irradiance_volume_build_stats stats;
            const irradiance_volume volume = irradiance_volume::build(scene, lo, hi, settings, source, &stats);
            volume_sweep_point p = measure_point(volume, stats, sphere, surface);
            p.max_depth = settings.max_depth;  // the lattice merged from (the octree may be shallower)
            p.bias_budget = settings.bias_budget;
            p.bias_tolerance = settings.bias_tolerance;
            p.noise_sigmas = k;
            print_point("sweep", p);
            out.push_back(p);
            if (!rebake || !rebake->bake) continue;  // rebake refuses stored hanging corners by name
            const auto total = std::uint32_t(std::max<std::uint64_t>(1, rebake->total_rays / std::max<std::size_t>(1, volume.probes().size())));
            for (const std::uint32_t rays : {total, rebake->fixed_rays}) {
                if (rays == 0) continue;
                irradiance_volume again = volume;  // the same layout, its probes baked with `rays` each
                again.rebake([&](std::span<const glm::vec3> at, std::span<irradiance_probe> baked) { rebake->bake(rays, at, baked); });
                volume_sweep_point q = measure_point(again, stats, sphere, surface);
                q.max_depth = p.max_depth, q.bias_budget = p.bias_budget, q.bias_tolerance = p.bias_tolerance, q.noise_sigmas = k;
                q.rays_per_probe = rays;
                print_point("rebaked", q);
                out.push_back(std::move(q));
            }
        }
    }
    return out;
}

}  // namespace

std::vector<volume_sweep_point> bias_budget_sweep(const scene_view& scene, glm::vec3 lo, glm::vec3 hi,
                                                  irradiance_volume_settings settings, probe_memo& source,
                                                  const volume_sphere_study& sphere, std::span<const float> budgets,
                                                  std::span<const float> sigmas, const volume_surface_study* surface,
                                                  const volume_rebake* rebake) {
    for (const float b : budgets) require(std::isfinite(b) && b > 0, "budgets", "every bias budget must be positive and finite");
    settings.bias_tolerance = 0;
    return merge_sweep(scene, lo, hi, settings, source, sphere, budgets, sigmas, surface, rebake,
                       [](irradiance_volume_settings& s, float b) { s.bias_budget = b; });
}

std::vector<volume_sweep_point> bias_tolerance_sweep(const scene_view& scene, glm::vec3 lo, glm::vec3 hi,
                                                     irradiance_volume_settings settings, probe_memo& source,
                                                     const volume_sphere_study& sphere, std::span<const float> tolerances,
                                                     std::span<const float> sigmas, const volume_surface_study* surface,
                                                     const volume_rebake* rebake) {
    for (const float t : tolerances)
        require(std::isfinite(t) && t > 0, "tolerances", "every bias tolerance must be positive and finite");
    settings.bias_budget = 0;
    return merge_sweep(scene, lo, hi, settings, source, sphere, tolerances, sigmas, surface, rebake,
                       [](irradiance_volume_settings& s, float t) { s.bias_tolerance = t; });
}

std::vector<volume_sweep_point> volume_depth_sweep(const scene_view& scene, glm::vec3 lo, glm::vec3 hi,
                                                   const irradiance_volume_settings& settings, probe_memo& source,
                                                   const volume_sphere_study& sphere, std::span<const int> depths,
                                                   std::span<const float> budgets, std::span<const float> tolerances,
                                                   std::span<const float> sigmas, const volume_surface_study* surface,
                                                   const volume_rebake* rebake) {
    for (const int d : depths)
        require(d >= 0 && d <= irradiance_volume::depth_limit, "depths", "every depth must be within 0 .. depth_limit");
    std::vector<volume_sweep_point> out;
    for (const int d : depths) {
        irradiance_volume_settings grid = settings;
        grid.min_depth = grid.max_depth = d;
        irradiance_volume_build_stats stats;
        volume_sweep_point p = measure_point(irradiance_volume::build(scene, lo, hi, grid, source, &stats), stats, sphere, surface);
        p.uniform = true;
        print_point("grid", p);
        out.push_back(std::move(p));
    }
    for (const int d : depths) {
        irradiance_volume_settings merged = settings;
        merged.max_depth = d;
        merged.min_depth = std::min(merged.min_depth, d);
        for (auto points : {bias_budget_sweep(scene, lo, hi, merged, source, sphere, budgets, sigmas, surface, rebake),
                            bias_tolerance_sweep(scene, lo, hi, merged, source, sphere, tolerances, sigmas, surface, rebake)})
            out.insert(out.end(), std::make_move_iterator(points.begin()), std::make_move_iterator(points.end()));
    }
    return out;
}

nlohmann::ordered_json to_json(std::span<const volume_sweep_point> sweep) {
    nlohmann::ordered_json j = nlohmann::ordered_json::array();
    for (const auto& p : sweep) {
        nlohmann::ordered_json e = {{"max_depth", p.max_depth}, {"uniform", p.uniform}, {"bias_budget", p.bias_budget},
                                    {"bias_tolerance", p.bias_tolerance},
                                    {"noise_sigmas", p.noise_sigmas}, {"probes", p.probes}, {"probes_inside", p.probes_inside},
                                    {"leaves", p.leaves}, {"hanging", p.hanging}, {"hanging_computed", p.hanging_computed},
                                    {"rays_per_probe", p.rays_per_probe}, {"scene_light", p.scene_light},
                                    {"median_noise", p.median_noise}, {"rel_rms", p.trilinear.error.rel_rms},
                                    {"popping", p.trilinear.popping},
                                    {"popping_excess", p.trilinear.popping_excess}};
        if (p.surface) e["surface"] = p.surface->to_json();
        j.push_back(std::move(e));
    }
    return j;
}

}  // namespace bounce::study
