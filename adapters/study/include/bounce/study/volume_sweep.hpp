#pragma once
/// \file volume_sweep.hpp
/// Adaptive irradiance volumes against the uniform grid at equal error (issue 31, third
/// session): every probe of the finest lattice is baked once (probe_memo), then one merged
/// octree per bias budget (irradiance_volume_settings::bias_budget) is built from those
/// same probes and measured on the moving sphere, so that the share of the grid's probes at
/// the grid's error can be read off the sweep (docs/studies/irradiance_volume_table.py
/// interpolates it). Fourth session: the same at several finest depths and the uniform grid
/// of each depth (volume_depth_sweep), so that octrees merged from a lattice deeper than the
/// grid (refined deeper where the light changes, fewer probes elsewhere) meet the grid at
/// equal probes, optionally measured at the camera's surface points as well.

#include <bounce/scene_view.hpp>
#include <bounce/study/volume_sphere.hpp>
#include <bounce/study/volume_surface.hpp>
#include <bounce/volume/probe_octree.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace bounce::study {

/// A probe_source that bakes each position once: a later batch takes the probes already
/// baked at the same position (bit for bit) and passes only the others to `source`.
class probe_memo {
public:
    using source_type = std::function<void(std::span<const glm::vec3>, std::span<irradiance_probe>)>;
    /// Throws parameter_error naming "source" when it is empty.
    explicit probe_memo(source_type source);
    /// Throws parameter_error naming "out" when its size is not the positions'.
    void operator()(std::span<const glm::vec3> positions, std::span<irradiance_probe> out);
    std::size_t baked() const noexcept { return baked_; }    ///< positions passed to the source
    std::size_t reused() const noexcept { return reused_; }  ///< positions answered from memory

private:
    struct key_hash {
        std::size_t operator()(const std::array<std::uint32_t, 3>& k) const noexcept;
    };
    source_type source_;
    std::unordered_map<std::array<std::uint32_t, 3>, irradiance_probe, key_hash> memo_;
    std::size_t baked_ = 0, reused_ = 0;
};

/// One octree of a sweep (merged, or the uniform grid of max_depth) and its trilinear lookup
/// on the sphere, and at the surface points of a view when the sweep was given them.
struct volume_sweep_point {
    int max_depth = 0;     ///< the lattice it was built on (merged from, or the grid's depth)
    bool uniform = false;  ///< the uniform grid (bias_budget and noise_sigmas then 0)
    float bias_budget = 0, bias_tolerance = 0, noise_sigmas = 0;
    std::size_t probes = 0, probes_inside = 0, leaves = 0;
    std::size_t hanging = 0;  ///< T-junction corners, the coarser leaf's interpolation (conforming corners)
    bool hanging_computed = false;  ///< hanging corners computed by the lookup, not among `probes`
    /// 0: the probes of the lattice's bake (equal rays per probe); else every stored probe
    /// baked again with this many rays, the sweep's total over the probes (volume_rebake)
    std::uint32_t rays_per_probe = 0;
    float scene_light = 0, median_noise = 0;  ///< the units of bias_tolerance (irradiance_volume_build_stats)
    volume_lookup_figures trilinear;
    std::optional<volume_surface_figures> surface;  ///< trilinear, no visibility
};

/// Equal total rays: each merged octree (built with settings.hanging_corners = computed) is
/// measured a second time with its stored probes baked again by `bake(rays, positions, out)`
/// with rays = total_rays / its probes (irradiance_volume::rebake), its layout unchanged.
struct volume_rebake {
    std::function<void(std::uint32_t, std::span<const glm::vec3>, std::span<irradiance_probe>)> bake;
    std::uint64_t total_rays = 0;  ///< e.g. the uniform grid's probes times its rays per probe
    /// > 0: each octree is also measured with its stored probes baked again with this many
    /// rays each (equal rays per probe, nothing pooled by the refit)
    std::uint32_t fixed_rays = 0;
};

/// For every budget (> 0, finite) and every noise_sigmas (>= 0, finite; empty: settings'
/// own), the merged octree over [lo, hi] (`settings` with refinement = merge, that
/// bias_budget and noise_sigmas: the slack of the bias test) built from `source`, and its
/// trilinear lookup measured on `sphere`; prints a line each ("sweep bias_budget ...").
/// Throws parameter_error naming "budgets" or "sigmas" for a value out of range. With
/// `surface`, each octree is measured at its points too (volume_sweep_point::surface); with
/// `rebake`, each is measured again at equal total rays (a second point, rays_per_probe > 0).
std::vector<volume_sweep_point> bias_budget_sweep(const scene_view& scene, glm::vec3 lo, glm::vec3 hi,
                                                  irradiance_volume_settings settings, probe_memo& source,
                                                  const volume_sphere_study& sphere, std::span<const float> budgets,
                                                  std::span<const float> sigmas = {},
                                                  const volume_surface_study* surface = nullptr,
                                                  const volume_rebake* rebake = nullptr);

/// The same with settings.bias_tolerance (an error target in units of the scene's light)
/// set to each of `tolerances` (> 0, finite; parameter_error naming "tolerances") in place
/// of bias_budget.
std::vector<volume_sweep_point> bias_tolerance_sweep(const scene_view& scene, glm::vec3 lo, glm::vec3 hi,
                                                     irradiance_volume_settings settings, probe_memo& source,
                                                     const volume_sphere_study& sphere, std::span<const float> tolerances,
                                                     std::span<const float> sigmas = {},
                                                     const volume_surface_study* surface = nullptr,
                                                  const volume_rebake* rebake = nullptr);

/// For every depth of `depths` (0 .. irradiance_volume::depth_limit), the uniform grid of that
/// depth over [lo, hi] built from `source` (a lattice point of depth d is one of depth d + 1:
/// after the deepest, the others bake nothing new), then, for every depth, the merged
/// octrees of bias_budget_sweep and of bias_tolerance_sweep with settings.max_depth = that
/// depth (none for an empty list); grids first, then merges by depth, as given. Prints a line each ("grid depth
/// ...", "sweep depth ..."). Throws parameter_error naming "depths" for a depth out of range.
std::vector<volume_sweep_point> volume_depth_sweep(const scene_view& scene, glm::vec3 lo, glm::vec3 hi,
                                                   const irradiance_volume_settings& settings, probe_memo& source,
                                                   const volume_sphere_study& sphere, std::span<const int> depths,
                                                   std::span<const float> budgets, std::span<const float> tolerances,
                                                   std::span<const float> sigmas = {},
                                                   const volume_surface_study* surface = nullptr,
                                                  const volume_rebake* rebake = nullptr);

/// [{"max_depth", "uniform", "bias_budget", "bias_tolerance", "noise_sigmas", "probes", "probes_inside",
/// "leaves", "hanging", "hanging_computed", "rays_per_probe", "scene_light", "median_noise", "rel_rms", "popping", "popping_excess"[, "surface": volume_surface_figures::
/// to_json()]}, ...]
nlohmann::ordered_json to_json(std::span<const volume_sweep_point> sweep);

}  // namespace bounce::study
