#pragma once
/// \file cache/frame.hpp
/// `bounce::cache_frame`: what one frame of an irradiance cache gives its caller, whichever
/// backend made it (the CPU frame of cpu::render_frame, the GL frame of
/// gl::irradiance_splatter::frame): the G-buffer the cache-miss scan saw, the indirect image,
/// the scan's counts and the frame's stage times. Walkthroughs (cpu::walkthrough) and studies
/// (bounce::study's cache studies) take frames of either backend through it.

#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::inline cache {

struct cache_frame {
    gbuffer<float> g;           ///< the G-buffer the frame's scan saw (row 0 at the top)
    image<glm::vec3> indirect;  ///< rho/pi * E per pixel (0 where no record reaches or g sees nothing)
    /// direct + indirect, where the backend composes them itself (the GL frame); empty otherwise.
    std::optional<image<glm::vec3>> combined;
    std::size_t new_records = 0;  ///< records the scan added
    std::size_t measured = 0;     ///< records the batched scan measured (new + wasted + refused)
    std::size_t wasted = 0;       ///< guesses dropped because covered by the time the scan got there
    std::size_t filter_merged = 0;   ///< new records the neighbour filter merged (cache/record_filter.hpp)
    std::size_t filter_refused = 0;  ///< new records it left alone, beyond k standard errors
    /// Earlier records whose radius the frame's start clamped to their neighbours (the CPU frame).
    std::size_t reclamped = 0;
    /// The verification pass, where it ran (the CPU frame with a probe): tiles tested, tiles
    /// that disagreed (one record measured at each, counted in new_records) and older records
    /// shrunk to those records.
    std::size_t verify_tiles = 0, verify_disagreed = 0, verify_shrunk = 0;
    /// The frame's stages in the order they ran, in milliseconds of wall time: "gbuffer",
    /// ("direct",) "splat_existing", ("readback",) "scan", "compute_records", ("verify",)
    /// "interpolate", "normalize" (the GL frame only has "direct" and "readback"; "verify", the
    /// verification's probes and tests, is there when the pass ran).
    std::vector<std::pair<std::string, double>> stages_ms;

    /// The milliseconds of `stage`, 0 when the frame has no such stage.
    double ms(std::string_view stage) const noexcept {
        for (const auto& [name, ms] : stages_ms)
            if (name == stage) return ms;
        return 0.0;
    }

    /// The counts of a frame's scan and verification (`s`: cpu::irradiance_cache's
    /// cache_frame_stats) into this frame: what the CPU and the GL frame both report.
    template <class ScanStats>
    void take_scan_counts(const ScanStats& s) {
        measured = s.measured;
        wasted = s.wasted;
        filter_merged = s.filter_merged;
        filter_refused = s.filter_refused;
        verify_tiles = s.verify_tiles;
        verify_disagreed = s.verify_disagreed;
        verify_shrunk = s.verify_shrunk;
    }
};

}  // namespace bounce::cache
