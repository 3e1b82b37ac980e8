#pragma once
/// \file run_report.hpp
/// The run report every example writes with `--json PATH` (docs/architecture.md,
/// "Measurement"); stage_timer.hpp's medians fill its `timings_ms`.
///
/// The JSON object, keys in this order:
/// ```
/// { "technique": "ic_splatting", "scene": "cornell", "width": 512, "height": 512,
///   "backend": "cpu", "gl_renderer": "llvmpipe (LLVM 15.0.6, 256 bits)",  // when GL ran
///   "parameters": { "a": 0.15, "weight": "ward", ... },     // whatever the run was given
///   "repeat": 5,                                            // samples per stage
///   "timings_ms": { "gbuffer": 3.1, "interpolate": 8.2, ..., "total": 40.2 },  // medians
///   "error": { "rel_rms": 0.041, "max_abs": 0.8, "sum_sq": 12.5, "pixels": 251234 },
///   "records": 1834, "vpls": 0, ... }                       // counts, top level
/// ```
/// `error` is absent when the run had no reference. Non-finite numbers are written as null
/// (JSON has no infinity). Timings keep the order in which the stages first started.

#include <bounce/errors.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/stage_timer.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace bounce::study {

/// The measurement record of one run of one technique.
struct run_report {
    std::string technique;  ///< the program, e.g. "ic_splatting", "reference"
    std::string scene;      ///< scene name: "cornell", "sponza" ...
    std::size_t width = 0;  ///< image width in pixels
    std::size_t height = 0; ///< image height in pixels
    std::string backend;    ///< "cpu", "gl", "embree" ...
    /// The GL renderer string of the run's context (gl::context::renderer(), e.g.
    /// "llvmpipe (LLVM 15.0.6, 256 bits)"), part of the run's provenance; written as
    /// `gl_renderer` after `backend` when not empty (runs without GL leave it empty).
    std::string gl_renderer;
    /// The run's parameters as given, e.g. `parameters["a"] = 0.15`.
    nlohmann::ordered_json parameters = nlohmann::ordered_json::object();
    /// Per stage, the median in milliseconds over the repeats (see set_timings).
    std::vector<std::pair<std::string, double>> timings_ms;
    std::size_t repeat = 1;  ///< samples behind each timing
    std::optional<error_figures> error;  ///< against the reference, when one was computed
    /// Counts written at the top level: "records", "vpls", "probes", "elements" ...
    std::vector<std::pair<std::string, std::uint64_t>> counts;

    /// Fills timings_ms with the medians of `timer`'s stages and repeat with its repeats().
    void set_timings(const stage_timer& timer);
    /// Sets (or replaces) the count `name`.
    void set_count(std::string name, std::uint64_t value);
    /// The JSON object above. Throws parameter_error when technique, scene or backend is
    /// empty, a size is 0, or a count's name is one of the other keys.
    nlohmann::ordered_json to_json() const;
    /// Writes to_json() to `file`, indented, creating its parent folder.
    /// Throws io::output_error when the file cannot be written (io::write_text_file).
    void write(const std::filesystem::path& file) const;
};

}  // namespace bounce::study
