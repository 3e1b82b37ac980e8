#pragma once
/// \file irradiance_splatter.hpp
/// `gl::irradiance_splatter`: a frame of irradiance caching by splatting with the GPU doing
/// what it does best (Gautron, "Hardware Implementation", SIGGRAPH 2008 course on irradiance
/// caching, ch. 8, Algorithm 5), on the caller's G-buffer textures in the caller's context:
///   1. splat every record the GPU holds over the G-buffer (records appended as the cache
///      grows: only new ones travel);
///   2. read the splat buffer and the G-buffer back;
///   3. the cache-miss scan, on the CPU, by the caller's `scan` (cpu::irradiance_cache::scan:
///      it appends records and splats them into the read-back buffer), and with it the
///      verification pass where the cache has one (cpu::irradiance_cache::scan_and_verify:
///      its rounds' records shrink older ones, so every record is splatted again on the GPU
///      and read back, `resplat`, before the round's scan);
///   4. upload the new records and splat them on top of step 1's buffer;
///   5. normalize (and, with a budget, fill holes from a wider splat) into `indirect()`:
///      irradiance E by default, or radiance rho/pi * E with the G-buffer's albedo
///      (output.hpp); `compose` adds the caller's direct radiance to the latter.
/// The splatter keeps the GPU copy of the cache in step with the caller's record list. It
/// restores the GL state it changes (as splat_pass and compose_pass do).
///
/// `frame` is a whole frame as a renderer runs it: its G-buffer (gl::gbuffer_pass), its
/// direct light (gl::direct_light), the steps above with a cpu::irradiance_cache's scan (and
/// its verification pass: the CPU frame's defaults are the GL frame's) and any record
/// sampler, and the indirect and composed images read back, as a bounce::cache_frame (what
/// cpu::walkthrough and the cache studies take).
///
/// Why the verification's residual test reads the splat buffer back instead of running as a
/// shader: its probes are ray-traced on the CPU (as the records are), and the scan that
/// follows each round reads the whole splat buffer anyway, so a shader would add an upload
/// of the probes (a frame-sized buffer) and save no read-back; what stays on the GPU is the
/// splat, the per-round cost that grows with the records (docs/gl-splatting.md).

#include <bounce/cache/frame.hpp>
#include <bounce/camera.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/image.hpp>
#include <bounce/output.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/cache/record_sampler.hpp>
#include <bounce/cache/weighting.hpp>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <type_traits>
#include <utility>
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

/// The renderer's passes a whole frame (irradiance_splatter::frame) draws with besides the
/// splatter: the scene on the GPU, its G-buffer pass and its direct light. Borrowed.
struct splatting_passes {
    const scene_mesh& mesh;
    gbuffer_pass& gbuffer;
    direct_light& light;
};

/// irradiance_splatter::frame's default: records are measured at the rasterized points.
struct raster_record_points {
    void operator()(gbuffer_view<float>) const noexcept {}
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
    /// `quantity` is what indirect() holds (output.hpp): irradiance (W/m^2, the default) or
    /// radiance rho/pi * E with g's albedo (W/(m^2 sr)).
    /// Throws parameter_error on bad textures; whatever `scan` throws passes through.
    template <class Scan>
    splatter_frame_stats render(const gbuffer_textures& g, const camera& cam,
                                const std::vector<irradiance_record>& records, Scan&& scan,
                                output_quantity quantity = output_quantity::irradiance) {
        splatter_frame_stats stats;
        output_ = quantity;
        splat_existing(g, cam, records, stats);
        const std::size_t before = records.size();
        const auto t0 = clock::now();
        scan(gbuffer_.view(), splat_.view());
        stats.scan_ms = ms_since(t0);
        require(records.size() >= before, "records", "the scan may only append records");
        stats.new_records = records.size() - before;
        splat_new(g, cam, records, stats);
        return stats;
    }

    /// Within render()'s scan, after the caller shrank records (as the verification pass's
    /// rounds do: the `resplat` of cpu::irradiance_cache::scan_and_verify): every record of
    /// `records` (the list render() was given) uploaded and splatted again over `g` (render()'s
    /// textures) seen by `cam`, and the splat buffer read back into `splat` (the scan's
    /// buffer); render() then splats only the records added after this on top. Throws
    /// parameter_error on bad textures or sizes.
    void resplat(const gbuffer_textures& g, const camera& cam, const std::vector<irradiance_record>& records,
                 image_view<glm::vec4> splat);

    /// A whole frame of `cache` (a cpu::irradiance_cache with splatting: any type with its
    /// options(), records(), generation(), clamp_to_neighbours() and scan_and_verify()) seen by `cam` at
    /// `width` x `height`:
    ///   - the splatter takes the cache's splat parameters and hole filling (its a included;
    ///     the weighting stays this splatter's, which must be the cache's Weight), clamps the
    ///     cache's older records to its neighbours and restarts the GPU's copy of the records
    ///     when the cache replaced or shrank them (its generation changed) or is another cache
    ///     (told apart by address: call reset() when a new cache takes a destroyed one's place);
    ///   - passes.gbuffer renders the G-buffer of passes.mesh, passes.light its direct light;
    ///   - render() with cache.scan_and_verify(g, cam, sampler, splat, resplat) as the scan
    ///     (the verification pass where the cache has one: options().verify and a probe; its
    ///     rounds splat every record again here, resplat()), as radiance (the quantity of
    ///     cache_frame::indirect). `record_points(points)`
    ///     may first move the read-back G-buffer's points to where `sampler` should measure the
    ///     records (a ray tracer's own hits of the pixels: embree::snap_to_ray_hits); its time
    ///     counts as record computation, and the verification's probes start there too;
    ///   - the indirect image and direct + indirect (compose) are read back.
    /// The frame's stages (cache_frame::stages_ms): gbuffer, direct, splat_existing,
    /// readback, scan, compute_records, verify (where the pass ran: its probes and tests; its
    /// records count in compute_records, its splats and scans in scan), interpolate,
    /// normalize (the read-backs and compose).
    /// Stage times are the GPU's only with options().time_stages. Throws parameter_error as
    /// render() and the cache's scan do.
    template <class Cache, record_sampler Sampler, class RecordPoints = raster_record_points>
    cache_frame frame(const splatting_passes& passes, Cache& cache, const camera& cam, std::size_t width,
                      std::size_t height, Sampler& sampler, RecordPoints&& record_points = {}) {
        follow(cache);
        cache_frame f;
        auto t0 = clock::now();
        passes.gbuffer.render(passes.mesh, cam, width, height);
        if (options_.time_stages) finish();
        f.stages_ms.emplace_back("gbuffer", ms_since(t0));
        const gbuffer_textures tex = textures_of(passes.gbuffer);
        t0 = clock::now();
        passes.light.render(tex);
        if (options_.time_stages) finish();
        f.stages_ms.emplace_back("direct", ms_since(t0));
        double scan_ms = 0, records_ms = 0, verify_ms = 0;
        const auto resplat = [&](image_view<glm::vec4> s) { this->resplat(tex, cam, cache.records(), s); };
        const splatter_frame_stats st =
            render(tex, cam, cache.records(), [&](gbuffer_view<float> g, image_view<glm::vec4> splat) {
                const auto took = [&](const auto& s) {
                    scan_ms += s.scan_ms;
                    records_ms += s.records_ms;
                    verify_ms += s.verify_ms;
                    f.take_scan_counts(s);
                };
                if constexpr (std::is_same_v<std::remove_cvref_t<RecordPoints>, raster_record_points>) {
                    took(cache.scan_and_verify(g, cam, sampler, splat, resplat));
                } else {
                    const auto t1 = clock::now();
                    gbuffer<float> points = gbuffer_;
                    record_points(points.view());
                    records_ms += ms_since(t1);
                    const gbuffer_view<float> where = points.view();
                    took(cache.scan_and_verify(g, cam, sampler, splat, resplat, &where));
                }
            }, output_quantity::radiance);
        generation_ = cache.generation();  // the GPU's copy holds the radii the verification left
        f.new_records = st.new_records;
        f.stages_ms.emplace_back("splat_existing", st.splat_existing_ms);
        f.stages_ms.emplace_back("readback", st.readback_ms);
        f.stages_ms.emplace_back("scan", scan_ms);
        f.stages_ms.emplace_back("compute_records", records_ms);
        if (f.verify_tiles > 0) f.stages_ms.emplace_back("verify", verify_ms);
        f.stages_ms.emplace_back("interpolate", st.interpolate_ms);
        t0 = clock::now();
        f.indirect = image<glm::vec3>(width, height);
        f.combined.emplace(width, height);
        read_indirect(f.indirect.view());
        read_texture(compose(passes.light.radiance()), f.combined->view());
        f.stages_ms.emplace_back("normalize", ms_since(t0));
        f.g = gbuffer_;
        return f;
    }

    /// The G-buffer the last frame's scan saw (row 0 at the top; for irradiance, render()'s
    /// default, with an albedo of pi everywhere: what the splat weighs, as the CPU cache does).
    const gbuffer<float>& scanned_gbuffer() const noexcept { return gbuffer_; }
    /// The last frame's indirect light as render() was asked for it (RGBA32F, rgb; alpha 1).
    const texture& indirect() const { return compose_.result(); }
    /// What indirect() holds: the quantity of the last render().
    output_quantity output() const noexcept { return output_; }
    /// indirect() plus `direct` (RGBA32F rgb, e.g. direct_light::radiance()) into result().
    /// Throws parameter_error naming "output" unless the last render() made radiance.
    const texture& compose(const texture& direct);
    /// Copies the indirect image of the last frame into `out` (row 0 at the top). Call
    /// before compose, which replaces the result.
    void read_indirect(image_view<glm::vec3> out) const { compose_.read(out); }
    /// The records the GPU holds are dropped: the next frame uploads the list it is given
    /// (after the caller replaced or shrank its records, as when
    /// cpu::irradiance_cache::clamp_to_neighbours returns more than 0).
    void reset() noexcept { on_gpu_ = wide_on_gpu_ = 0; }

    /// frame()'s first step: this splatter takes `cache`'s splat parameters and hole filling,
    /// and its GPU copy follows the cache's records (reset when they were replaced or shrunk).
    template <class Cache>
    void follow(Cache& cache) {
        irradiance_splatter_options o = options_;
        o.splat = cache.options().splat;
        o.fill_holes = cache.options().fills_holes() ? cache.options().fill_holes : 0.f;
        set_options(o);
        const std::size_t shrunk = cache.clamp_to_neighbours();
        if (shrunk > 0 || followed_ != static_cast<const void*>(&cache) || generation_ != cache.generation()) reset();
        followed_ = &cache;
        generation_ = cache.generation();
    }

private:
    using clock = std::chrono::steady_clock;
    static double ms_since(clock::time_point t0) {
        return std::chrono::duration<double, std::milli>(clock::now() - t0).count();
    }
    void splat_existing(const gbuffer_textures& g, const camera& cam, const std::vector<irradiance_record>& records,
                        splatter_frame_stats& stats);
    // The records from on_gpu_ on (those the scan added since the last splat of all) on top.
    void splat_new(const gbuffer_textures& g, const camera& cam, const std::vector<irradiance_record>& records,
                   splatter_frame_stats& stats);
    // g as the splat passes read it: for irradiance, its albedo replaced by pi everywhere
    // (the splat kernel weighs rho/pi * E).
    gbuffer_textures splatted(const gbuffer_textures& g);

    irradiance_splatter_options options_;
    splat_pass splats_, wide_splats_;
    compose_pass compose_;
    std::size_t on_gpu_ = 0, wide_on_gpu_ = 0;
    const void* followed_ = nullptr;  // the cache frame() followed last, and its generation then
    std::uint64_t generation_ = 0;
    gbuffer<float> gbuffer_;
    image<glm::vec4> splat_;
    output_quantity output_ = output_quantity::irradiance;
    std::optional<texture> pi_albedo_;  // RGBA32F filled with pi, the G-buffer's size
};

}  // namespace bounce::gl
