#pragma once
/// \file benchmark_parts.hpp
/// The pieces of the benchmark runner (benchmark.hpp): references in halves, Monte Carlo
/// sweeps and the equal-error figures read off them, and one function per technique. Split
/// over src/benchmark_*.cpp by technique; the runner and the tests call them.

#include <bounce/embree/accel.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/benchmark.hpp>
#include <bounce/indirect/visibility.hpp>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace bounce::study::bench {

using ojson = nlohmann::ordered_json;

/// A number, or null when it is not finite (JSON has no infinity).
ojson number_or_null(double v);

// ---- errors ----------------------------------------------------------------------------------

/// A reference in two independent halves A and B of spp / 2 samples each, and their mean.
struct halves_reference {
    image<glm::vec3> a, b, mean;
    std::uint32_t spp = 0;     ///< samples (paths) per pixel, both halves together
    double ms = 0;             ///< spent computing it in this run (0 when it came from the cache)
    bool cached = false;
    double noise_rel_rms = 0;  ///< the mean's own relative RMS noise (compare_luminance_debiased's)
    /// {"spp", "ms", "cached", "noise_rel_rms"}.
    ojson to_json() const;
};

/// An image's error against a reference in halves, over a mask: rel_rms against the mean, the
/// debiased error with its standard error (compare_luminance_debiased), and the SSIM of the
/// tone-mapped luminance against the mean (tonemapped_ssim).
struct measured_error {
    double rel_rms = 0, rel_rms_debiased = 0, rel_rms_debiased_se = 0, ssim = 0;
    bool resolved = false;  ///< the debiased error stands out of its standard error (noisy_reference_error::resolved)
    /// {"rel_rms", "rel_rms_debiased", "rel_rms_debiased_se", "ssim", "debiased_resolved"}.
    ojson to_json() const;
};
measured_error measure_error(image_view<const glm::vec3> x, const halves_reference& ref, image_view<const float> mask);

/// How a frame with visibility's error splits against the same frame without it (issue 29's ratio for the RSM gather): with b_rays =
/// x_rays - r_occluded and b_none = x_none - r_unoccluded per pixel (luminance, over the mask,
/// the references' noise taken out as compare_luminance_debiased does), |b_none| / |r_occluded|
/// is the frame without visibility's error in the units of the occluded reference, and
/// |b_rays - b_none| / |r_occluded| what visibility changes; the ratio the headline asks is
/// |b_rays| / |b_none| times |r_unoccluded| / |r_occluded|, the last the references' own.
/// {"none_error_in_occluded_units", "visibility_change", "references_rms_ratio"}.
ojson visibility_error_split(image_view<const glm::vec3> rays, image_view<const glm::vec3> none,
                             const halves_reference& occluded, const halves_reference& unoccluded,
                             image_view<const float> mask);

// ---- Monte Carlo sweeps and equal error --------------------------------------------------------

/// One Monte Carlo run of a sweep.
struct sweep_step {
    std::uint32_t spp = 0;
    double ms = 0;
    measured_error error;
};
using mc_sweep = std::vector<sweep_step>;

/// Monte Carlo at spp = first_spp, 2 first_spp, 4 first_spp ... up to max_spp: `render(spp)`
/// timed (its wall time is the step's ms), each image measured against `ref` over `mask`;
/// `before(spp)` (optional) is called before each step. Throws parameter_error for
/// first_spp 0 or max_spp below it.
mc_sweep monte_carlo_sweep(const std::function<image<glm::vec3>(std::uint32_t spp)>& render,
                           const halves_reference& ref, image_view<const float> mask, std::uint32_t max_spp,
                           const std::function<void(std::uint32_t spp)>& before = {}, std::uint32_t first_spp = 1);
/// [{"spp", "ms", "rel_rms", "rel_rms_debiased", "rel_rms_debiased_se", "ssim"}, ...].
ojson sweep_to_json(const mc_sweep& sweep);

/// Where a sweep meets a technique's figure.
struct equal_error_point {
    double spp = 0, ms = 0;
    /// False: Monte Carlo's largest run stayed short of the figure, so spp and ms are its
    /// last run's and lower bounds.
    bool reached = false;
    /// The figure is already met by the sweep's first run (1 spp; 2 for the unoccluded
    /// estimator): spp and ms are that run's, upper bounds.
    bool at_first_step = false;
};
/// The spp at which Monte Carlo's debiased error falls to `target` (> 0): interpolated
/// between the two runs around it in log error against log spp (error ~ spp^-1/2 away from
/// the reference's noise); a run whose debiased error is at or below 0 (lost in the
/// reference's noise) continues the run before it as spp^-1/2. ms scales with spp from the
/// run reached. Throws parameter_error for an empty sweep or a target that is not positive.
equal_error_point equal_error_by_rel_rms(const mc_sweep& sweep, double target);
/// The spp at which Monte Carlo's SSIM rises to `target`: log(1 - SSIM) interpolated
/// linearly in log spp between the runs around it. Throws parameter_error for an empty
/// sweep or a target outside (-1, 1].
equal_error_point equal_error_by_ssim(const mc_sweep& sweep, double target);
/// {"rel_rms": {"spp", "ms", "reached", "speedup", "target", "bound"}, "ssim": {...}}, the
/// speedup being Monte Carlo's ms over `technique_ms` and "bound" ("lower" / "upper") present
/// when the sweep did not bracket the target. rel_rms then also has "spp_extrapolated",
/// "ms_extrapolated" and "speedup_extrapolated": error ~ spp^-1/2 from the sweep's nearest
/// run, an estimate. A debiased error not above 0 (no error to match) gives
/// {"skipped": why} for rel_rms.
ojson mc_equal_error_json(const mc_sweep& sweep, const measured_error& technique, double technique_ms);

// ---- one scene ----------------------------------------------------------------------------------

/// The run's clock: stages report through it; the time left is estimated from the work done
/// so far (in units of samples per pixel of one-bounce rays, see benchmark.cpp).
class run_clock {
public:
    run_clock(std::function<void(const benchmark_progress&)> sink, std::size_t scenes, double work_per_scene);
    void begin_scene(std::string name, std::size_t index);
    /// Reports a stage of `technique` ("reference", "monte carlo", a technique's name).
    void report(const std::string& technique, const std::string& stage) const;
    /// Marks `work` units done.
    void advance(double work) { done_ += work; }
    double elapsed_s() const;

private:
    std::function<void(const benchmark_progress&)> sink_;
    std::size_t scenes_ = 1, index_ = 0;
    std::string scene_;
    double total_ = 1, done_ = 0;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// What every part of one scene's run reads.
struct scene_setup {
    const io::scene& scene;
    const embree::accel& bvh;
    const benchmark_settings& settings;
    run_clock& clock;
    /// The camera's ray-cast G-buffer at the run's size (mutable: gbuffer::view() is not
    /// const, and every part only reads it).
    mutable gbuffer<float> g;
    image<float> mask;          ///< 1 where g sees geometry
    float diagonal = 0;         ///< the scene's bounding diagonal
    std::filesystem::path cache_dir;
};
/// The G-buffer, mask and diagonal of `scene` at the settings' size.
scene_setup make_scene_setup(const io::scene& scene, const embree::accel& bvh, const benchmark_settings& settings,
                             run_clock& clock);

// ---- references and Monte Carlo per quantity (benchmark_references.cpp) ---------------------

halves_reference one_bounce_reference(const scene_setup& s);
halves_reference unoccluded_reference(const scene_setup& s);
halves_reference all_bounces_reference(const scene_setup& s);
/// The volume's points (see benchmark.hpp): g's covered pixels moved off their surfaces.
gbuffer<float> volume_points(const scene_setup& s);
halves_reference volume_points_reference(const scene_setup& s, const gbuffer_view<float>& points);
/// The quantity's Monte Carlo sweep up to settings' mc_max (`points` for volume_points).
mc_sweep quantity_monte_carlo(const scene_setup& s, bench_quantity q, const halves_reference& ref,
                              const gbuffer_view<float>* points);

/// The cache key of a reference other than the one-bounce one: "<scene>-<W>x<H>-<spp>spp-<kind>-<hash>",
/// the hash over the scene's view (hash_scene_view), `kind`, `settings_text` and the Embree configuration.
std::string halves_cache_key(const scene_setup& s, const std::string& kind, std::uint32_t spp,
                             const std::string& settings_text);
/// The halves under `key` in the cache folder, or computed by `render(half)` (half 0: A,
/// 1: B) and stored there (temporary names renamed).
halves_reference cached_halves(const scene_setup& s, const std::string& key, std::uint32_t spp,
                               const std::function<image<glm::vec3>(int half)>& render);

// ---- techniques (benchmark_cache.cpp, benchmark_rsm.cpp, benchmark_radiosity.cpp,
// benchmark_volume.cpp) ---------------------------------------------------------------------------

/// A technique's run: its image of its quantity and its cost.
struct technique_run {
    bench_technique technique = bench_technique::irradiance_cache;
    bench_quantity quantity = bench_quantity::one_bounce;
    /// What the equal-error speedups divide: the technique's work for this view (its set-up
    /// that depends on the scene, records, maps, solve or bake, included; the shared G-buffer
    /// not, as Monte Carlo's time has none).
    double ms = 0;
    ojson parameters = ojson::object(), counts = ojson::object(), timings_ms = ojson::object();
    image<glm::vec3> radiance;  ///< the view's image of the quantity (g's size)
    /// The RSM techniques' receiver-sender visibility (none for the others).
    indirect_visibility visibility = indirect_visibility::none;
};

/// The CPU irradiance cache (cpu::irradiance_cache, Ward's smooth weight, Embree's record
/// sampler) with ic_splatting's defaults: one frame from an empty cache.
technique_run run_irradiance_cache(const scene_setup& s);
/// The RSM gather (1,024 disc samples), SII (1,024 VPLs) or SII interleaved 4 x 4 on maps
/// embree::rsm_ray_caster casts, through cpu::indirect_renderer with rsm_sii's defaults and
/// `visibility` (rays: embree::occlusion_rays on the scene's accel). Throws parameter_error
/// for a scene without a point, spot or directional light.
technique_run run_rsm_sii(const scene_setup& s, bench_technique t, indirect_visibility visibility);
/// cpu::progressive_radiosity with radiosity's defaults (10,000 elements in 8 x 8 blocks,
/// the stereographic item buffer, 90% of the power shot), seen through embree::lightmap_view.
technique_run run_radiosity(const scene_setup& s);
/// An adaptive irradiance volume baked by embree::probe_baker with irradiance_volume's
/// defaults, looked up (weighted, with gradients) at `points`; rho / pi times it per pixel.
technique_run run_irradiance_volume(const scene_setup& s, const gbuffer_view<float>& points);

/// Which quantities `techniques` need, in all_bench_quantities' order.
std::vector<bench_quantity> quantities_for(const std::vector<bench_technique>& techniques);

}  // namespace bounce::study::bench
