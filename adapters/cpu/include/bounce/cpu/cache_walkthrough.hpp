#pragma once
/// \file cache_walkthrough.hpp
/// Frames of a `cpu::irradiance_cache` as a renderer runs them: `render_frame` (one CPU frame
/// on a G-buffer made for the camera) and `walkthrough` (a camera path rendered with one cache
/// kept and grown from frame to frame, optionally each frame also from an empty cache to see
/// what growing costs or gains). A walkthrough takes frames of either backend: the CPU one
/// here, or gl::irradiance_splatter::frame, through `bounce::cache_frame`.
///
/// Between frames the cache clamps the radii of earlier frames' records to the later ones
/// (irradiance_cache::clamp_to_neighbours, with neighbour_clamp on): in one frame a large
/// record made before a small neighbour costs little, from another camera it would cover the
/// small one's surroundings with the wrong irradiance (docs/irradiance-splatting.md, "Many
/// frames").

#include <bounce/cache/frame.hpp>
#include <bounce/camera.hpp>
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/cache/record_sampler.hpp>

#include <chrono>
#include <concepts>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

namespace bounce::cpu {

/// A camera path: `frames()` cameras, `at(f)` the one of frame f (study::camera_path is one).
template <class P>
concept camera_sequence = requires(const P& p, std::size_t f) {
    { p.frames() } -> std::convertible_to<std::size_t>;
    { p.at(f) } -> std::convertible_to<camera>;
};

/// One CPU frame of `cache` seen by `cam`: the G-buffer `gbuffer_for(cam)` returns (a
/// gbuffer<float>, e.g. embree::ray_cast_gbuffer; timed as the stage "gbuffer"), then
/// cache.render with `sampler` as radiance, cache_frame::indirect's quantity (the stages of
/// cache_frame_stats: splat_existing, scan, compute_records, verify where the verification pass
/// ran, interpolate, normalize). The frame's accuracy and policies are the cache's options,
/// the verification pass among them: a cache with options().verify and a probe (set_probe)
/// verifies every frame, and the records it adds stay in the cache for the frames after.
template <class Weight, record_sampler Sampler, class GBufferFor>
    requires std::invocable<GBufferFor&, const camera&>
cache_frame render_frame(irradiance_cache<Weight>& cache, const camera& cam, GBufferFor&& gbuffer_for, Sampler& sampler) {
    cache_frame f;
    const auto t0 = std::chrono::steady_clock::now();
    f.g = gbuffer_for(cam);
    f.stages_ms.emplace_back(
        "gbuffer", std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    f.indirect = image<glm::vec3>(f.g.width(), f.g.height());
    // cache_frame holds radiance: the image a renderer shows (and the GL frame composes).
    const cache_frame_stats s = cache.render(f.g.view(), cam, sampler, f.indirect.view(), output_quantity::radiance);
    f.new_records = s.new_records;
    f.take_scan_counts(s);
    f.reclamped = s.reclamped;
    f.stages_ms.emplace_back("splat_existing", s.splat_existing_ms);
    f.stages_ms.emplace_back("scan", s.scan_ms);
    f.stages_ms.emplace_back("compute_records", s.records_ms);
    if (s.verify_tiles > 0) f.stages_ms.emplace_back("verify", s.verify_ms);
    f.stages_ms.emplace_back("interpolate", s.interpolate_ms);
    f.stages_ms.emplace_back("normalize", s.normalize_ms);
    return f;
}

/// What a walkthrough does besides growing the cache.
struct walkthrough_options {
    /// Also render every frame from an empty cache (then put the grown cache back): what the
    /// grown cache must not lose to. Not part of the grown frames' times.
    bool fresh = false;
};

/// One frame of a walkthrough, as `visit` receives it.
struct walkthrough_step {
    std::size_t index = 0;    ///< frame number in [0, path.frames())
    camera cam;               ///< its camera
    cache_frame frame;        ///< rendered with the cache grown over the frames before it
    double ms = 0;            ///< its wall time (the G-buffer included)
    std::size_t records = 0;  ///< the cache's records after it
    /// With walkthrough_options::fresh: the same camera from an empty cache, its wall time
    /// and the records it made.
    std::optional<cache_frame> fresh;
    double fresh_ms = 0;
    std::size_t fresh_records = 0;
};

/// Renders every camera of `path` in order with `cache`, which keeps and grows its records
/// from frame to frame: `frame(cam)` renders one frame with the cache (the CPU's
/// render_frame, or the GL frame) and returns its cache_frame. After each frame (and its
/// fresh twin) `visit(walkthrough_step&&)` gets it, untimed: a study measures its error there.
/// Whatever `frame` or `visit` throws passes through (the cache then holds the records made
/// so far).
template <class Weight, camera_sequence Path, class Frame, class Visit>
    requires std::invocable<Frame&, const camera&> && std::invocable<Visit&, walkthrough_step&&>
void walkthrough(irradiance_cache<Weight>& cache, const Path& path, Frame&& frame, const walkthrough_options& options,
                 Visit&& visit) {
    using clock = std::chrono::steady_clock;
    const auto ms_since = [](clock::time_point t0) {
        return std::chrono::duration<double, std::milli>(clock::now() - t0).count();
    };
    for (std::size_t f = 0; f < path.frames(); ++f) {
        walkthrough_step step;
        step.index = f;
        step.cam = path.at(f);
        auto t0 = clock::now();
        step.frame = frame(std::as_const(step.cam));
        step.ms = ms_since(t0);
        step.records = cache.records().size();
        if (options.fresh) {
            std::vector<irradiance_record> kept = cache.records();
            cache.assign({});
            t0 = clock::now();
            step.fresh = frame(std::as_const(step.cam));
            step.fresh_ms = ms_since(t0);
            step.fresh_records = cache.records().size();
            cache.assign(std::move(kept));
        }
        visit(std::move(step));
    }
}

/// The CPU walkthrough: every frame is render_frame(cache, cam, gbuffer_for, sampler).
template <class Weight, camera_sequence Path, class GBufferFor, record_sampler Sampler, class Visit>
    requires std::invocable<GBufferFor&, const camera&>
void walkthrough(irradiance_cache<Weight>& cache, const Path& path, GBufferFor&& gbuffer_for, Sampler& sampler,
                 const walkthrough_options& options, Visit&& visit) {
    walkthrough(
        cache, path, [&](const camera& cam) { return render_frame(cache, cam, gbuffer_for, sampler); }, options,
        std::forward<Visit>(visit));
}

}  // namespace bounce::cpu
