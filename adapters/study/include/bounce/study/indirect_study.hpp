#pragma once
/// \file indirect_study.hpp
/// Measuring one-bounce indirect renderers of the RSM / SII family (cpu::indirect_renderer,
/// gl::offscreen_indirect_renderer) against the references of the quantity they compute:
/// the references with and without indirect visibility, cached on disk; one measured run
/// (medians of repeated frames, errors against both references and against the same
/// technique without interleaving); and Hahn 2012's grid of VPL counts by interleave
/// patterns (`rsm_sii --study`, docs/rsm-sii-interleaved.md). A run reaches the renderer
/// through `indirect_frame`, so one study serves either backend.

#include <bounce/camera.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/indirect/options.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/study/stage_timer.hpp>

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace bounce::study {

/// The two one-bounce references an indirect run is measured against (radiance, rho / pi E).
struct indirect_references {
    embree::reference_images occluded;  ///< with indirect visibility (embree::render_reference)
    image<glm::vec3> unoccluded;        ///< without it (embree::render_unoccluded_reference)
    double unoccluded_noise = 0;        ///< the unoccluded image's measured relative RMS noise
    std::uint32_t spp = 0;              ///< rays per pixel of each
    bool occluded_from_cache = false, unoccluded_from_cache = false;
    double occluded_ms = 0, unoccluded_ms = 0;  ///< time spent computing (or loading) each
};

/// Throws parameter_error naming `option` unless `spp` rays per pixel make both references:
/// even (the unoccluded one is two halves of spp / 2, at least 2 each) and in [4, 2^20]. Call it with the
/// program's flag before any work.
void check_indirect_reference_spp(std::uint32_t spp, std::string_view option = "spp");

/// Both references of `scene` seen by `cam` over its G-buffer `g` (ray cast by
/// embree::ray_cast_gbuffer for `cam`), each from the cache folder `dir` when present, else
/// computed and stored there (the unoccluded one under the occluded one's key +
/// "-unoccluded-v1"). Checks `spp` and the cache folder (check_cache_dir) before computing.
indirect_references cached_indirect_references(const embree::accel& bvh, const io::scene& scene,
                                               const camera& cam, const gbuffer_view<float>& g, std::uint32_t spp,
                                               const std::filesystem::path& dir = default_cache_dir());

/// Outgoing radiance rho / pi E per pixel of irradiance `e` over `g` (what the references hold).
image<glm::vec3> radiance_image(const gbuffer_view<float>& g, image_view<const glm::vec3> e);

/// Hahn 2012 section 5.2: the sum over the pixels of `mask` of the squared difference of
/// intensity 0.2989 R + 0.5870 G + 0.1140 B.
double ssd_intensity(image_view<const glm::vec3> a, image_view<const glm::vec3> b, image_view<const float> mask);

/// Renders one frame of indirect irradiance with the given options into the image (the
/// G-buffer's size) and returns its stage times: a backend's render bound to its G-buffer,
/// camera and maps.
using indirect_frame = std::function<indirect_timings(const indirect_options&, image_view<glm::vec3>)>;

/// What a measurement needs besides the options.
struct indirect_bench {
    indirect_frame frame;
    gbuffer_view<float> g;                  ///< the G-buffer the frames are rendered on
    const indirect_references* refs = nullptr;
    image_view<const float> mask;           ///< pixels compared (coverage_mask(g))
    double rsm_ms = 0;                      ///< time of making the maps, reported as stage "rsm"
    int repeat = 1;                         ///< frames per run; timings are their medians
};

/// One measured run.
struct indirect_run {
    indirect_options options;
    stage_timer timer;     ///< rsm, split, shade, gather, blur, upsample, total per frame
    indirect_timings last; ///< the last frame's
    image<glm::vec3> radiance;
    error_figures vs_unoccluded, vs_occluded;
    std::optional<error_figures> vs_plain;  ///< against the same run without interleaving
    double plain_ssd = 0, plain_total_ms = 0;

    double total_ms() const { return timer.median_ms("total"); }
    /// technique, vpls, pattern, energy_correct, vpls_used, timings_ms, error {rel_rms,
    /// max_abs, sum_sq, pixels, rel_rms_occluded[, vs_plain {ssd_intensity, rel_rms}]}
    /// [, speedup_vs_plain].
    nlohmann::ordered_json to_json() const;
    /// One line: technique, count, pattern, total and shade ms, errors.
    std::string summary() const;
};

/// "rsm" or "sii".
std::string technique_name(indirect_technique t);
/// "NxM".
std::string pattern_name(interleave_pattern p);

/// Renders `options` bench.repeat times and measures the result; `plain` (optional) is the
/// same configuration without interleaving, compared against and timed beside.
indirect_run measure_indirect(const indirect_bench& bench, const indirect_options& options,
                              const indirect_run* plain = nullptr, std::optional<int> repeat = {});

/// The share of a frame's light that its singularity clamps (options.light) remove: 1 minus
/// the luminance it sums over bench.mask against the same frame with no clamp at all, both
/// without visibility (the pairs a clamp acts on are close neighbours that see each other).
double clamp_removed_fraction(const indirect_bench& bench, indirect_options options);

/// Hahn 2012's grid (section 5: 64 ... 1024 VPLs by patterns none, 2x2, 2x4, 4x4, 8x8, both
/// techniques) from `base` (its other fields kept), plus plain runs at 16, 32 and 4096 and SII
/// with the thesis's weight 1 at 128 and 1024 (4x4); then the targets of the issue that
/// asked for it (speedups at 8x8, errors against plain, equal-time partners).
/// Returns {"grid": [run...], "targets": {...}}; `on_run` sees every run as it ends.
nlohmann::ordered_json interleaving_study(const indirect_bench& bench, const indirect_options& base,
                                          const std::function<void(const indirect_run&)>& on_run = {});

}  // namespace bounce::study
