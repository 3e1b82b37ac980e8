#pragma once
/// \file irradiance_splatter.hpp
/// `gl::irradiance_splatter`: a frame of irradiance caching by splatting with the GPU doing
/// what it does best (Gautron, "Hardware Implementation", SIGGRAPH 2008 course on irradiance
/// caching, ch. 8, Algorithm 5), on the caller's G-buffer textures in the caller's context:
///   1. splat every record the GPU holds over the G-buffer (records appended as the cache
///      grows: only new ones travel);
///   2. read the splat buffer and the G-buffer back;
///   3. the cache-miss scan, on the CPU, by the caller's `scan` (cpu::irradiance_cache::scan:
///      it appends records and splats them into the read-back buffer);
///   4. upload the new records and splat them on top of step 1's buffer;
///   5. normalize (and, with a budget, fill holes from a wider splat) into `indirect()`;
///      `compose` adds the caller's direct radiance.
/// The splatter keeps the GPU copy of the cache in step with the caller's record list. It
/// restores the GL state it changes (as splat_pass and compose_pass do).

#include <bounce/camera.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/image.hpp>
#include <bounce/irradiance_record.hpp>
#include <bounce/weighting.hpp>

#include <chrono>
#include <cstddef>
#include <vector>

namespace bounce::gl {

/// What a splatter's frames depend on.
struct irradiance_splatter_options {
    splat_params splat{};  ///< a (typical 0.1-0.4), gradients, extrapolation clamp, in-front test
    weighting_kind weighting = weighting_kind::ward_smooth;
    /// Hole filling (with a per-frame record budget): pixels no record reaches take the
    /// records splatted with zones this many times wider; 0: off (typical 4 with a budget).
    float fill_holes = 0.f;
    /// Wait for the GPU after each stage, so the stage times are the GPU's (measurement
    /// only: a renderer leaves it off).
    bool time_stages = false;
    /// Throws parameter_error naming the first bad field.
    void validate() const;
};

/// Milliseconds per stage of one frame (wall time; GPU time when time_stages).
struct splatter_frame_stats {
    double splat_existing_ms = 0;  ///< step 1
    double readback_ms = 0;        ///< step 2
    double scan_ms = 0;            ///< step 3 (the caller's scan, records included)
    double interpolate_ms = 0;     ///< step 4 (and the wide splat for hole filling)
    double normalize_ms = 0;       ///< step 5
    std::size_t new_records = 0;
};

class irradiance_splatter {
public:
    /// Creates the passes (a context must be current; it must outlive the splatter).
    explicit irradiance_splatter(const irradiance_splatter_options& options = {});

    const irradiance_splatter_options& options() const noexcept { return options_; }
    void set_options(const irradiance_splatter_options& options);

    /// One frame over the caller's G-buffer textures `g` (gbuffer_textures' layout) seen by
    /// `cam`. `records` is the cache's record list; `scan(gbuffer_view<float> g,
    /// image_view<glm::vec4> splat)` must append the records of the misses it finds to that
    /// same list (and splat them into `splat`), e.g.
    ///   [&](auto g, auto splat) { cache.scan(g, cam, sampler, splat); }.
    /// Throws parameter_error on bad textures; whatever `scan` throws passes through.
    template <class Scan>
    splatter_frame_stats render(const gbuffer_textures& g, const camera& cam,
                                const std::vector<irradiance_record>& records, Scan&& scan) {
        splatter_frame_stats stats;
        splat_existing(g, cam, records, stats);
        const std::size_t before = records.size();
        const auto t0 = clock::now();
        scan(gbuffer_.view(), splat_.view());
        stats.scan_ms = ms_since(t0);
        require(records.size() >= before, "records", "the scan may only append records");
        stats.new_records = records.size() - before;
        splat_new(g, cam, records, before, stats);
        return stats;
    }

    /// The G-buffer and the splat buffer the last frame's scan saw (row 0 at the top).
    const gbuffer<float>& scanned_gbuffer() const noexcept { return gbuffer_; }
    /// The last frame's indirect radiance (RGBA32F, rgb; alpha 1).
    const texture& indirect() const { return compose_.result(); }
    /// indirect() plus `direct` (RGBA32F rgb, e.g. direct_light::radiance()) into result().
    const texture& compose(const texture& direct);
    /// Copies the indirect image of the last frame into `out` (row 0 at the top). Call
    /// before compose, which replaces the result.
    void read_indirect(image_view<glm::vec3> out) const { compose_.read(out); }
    /// The records the GPU holds are dropped: the next frame uploads the list it is given
    /// (after the caller replaced or shrank its records, as when
    /// cpu::irradiance_cache::clamp_to_neighbours returns more than 0).
    void reset() noexcept { on_gpu_ = wide_on_gpu_ = 0; }

private:
    using clock = std::chrono::steady_clock;
    static double ms_since(clock::time_point t0) {
        return std::chrono::duration<double, std::milli>(clock::now() - t0).count();
    }
    void splat_existing(const gbuffer_textures& g, const camera& cam, const std::vector<irradiance_record>& records,
                        splatter_frame_stats& stats);
    void splat_new(const gbuffer_textures& g, const camera& cam, const std::vector<irradiance_record>& records,
                   std::size_t before, splatter_frame_stats& stats);

    irradiance_splatter_options options_;
    splat_pass splats_, wide_splats_;
    compose_pass compose_;
    std::size_t on_gpu_ = 0, wide_on_gpu_ = 0;
    gbuffer<float> gbuffer_;
    image<glm::vec4> splat_;
};

}  // namespace bounce::gl
