#pragma once
/// \file provenance.hpp
/// Where and on what a measurement ran: the one provenance record of the programs and
/// studies (sh_study, irradiance_volume, the benchmark), written beside their figures so
/// that a number can be traced to the source, the machine and the kernels that made it.

#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace bounce::study {

/// The run's provenance. Fields that cannot be found read "unknown".
struct provenance {
    std::string commit;       ///< `git rev-parse --short HEAD` of the source tree, "+dirty" when modified
    std::string date;         ///< UTC, ISO 8601 ("2026-12-03T21:04:00Z")
    std::string cpu;          ///< /proc/cpuinfo's model name
    unsigned cores = 0;       ///< std::thread::hardware_concurrency()
    std::string gl_renderer;  ///< the GL context's renderer string; empty when GL did not run
    /// The SIMD kernels Embree uses: the `isa`/`max_isa` of BOUNCE_EMBREE_CONFIG when set,
    /// else the widest this CPU has of AVX-512 (SKX), AVX2, AVX, SSE4.2, SSE2 (Embree's
    /// default choice), with Embree's version ("AVX2, Embree 3.13.5").
    std::string embree_isa;

    /// {"commit", "date", "cpu", "cores", "gl_renderer" (when set), "embree_isa"}.
    nlohmann::ordered_json to_json() const;
};

/// Collects the provenance now. `source_dir` is the git tree to name the commit of (empty:
/// the tree this library was built from); `gl_renderer` the GL context's renderer string
/// (gl::context::renderer()) when the run used GL.
provenance collect_provenance(const std::filesystem::path& source_dir = {}, std::string gl_renderer = {});

}  // namespace bounce::study
