// The run report every example writes with --json.
#include <bounce/study/run_report.hpp>

#include <bounce/io/output_files.hpp>

#include <algorithm>
#include <cmath>

namespace bounce::study {

namespace fs = std::filesystem;
using ojson = nlohmann::ordered_json;

void run_report::set_timings(const stage_timer& timer) {
    timings_ms.clear();
    for (const auto& stage : timer.stages()) timings_ms.emplace_back(stage, timer.median_ms(stage));
    repeat = std::max<std::size_t>(1, timer.repeats());
}

void run_report::set_count(std::string name, std::uint64_t value) {
    const auto it = std::find_if(counts.begin(), counts.end(), [&](const auto& c) { return c.first == name; });
    if (it == counts.end()) counts.emplace_back(std::move(name), value);
    else it->second = value;
}

namespace {
// JSON has no infinity or NaN; null says "no finite value" honestly.
ojson number_or_null(double v) { return std::isfinite(v) ? ojson(v) : ojson(nullptr); }
}  // namespace

ojson run_report::to_json() const {
    require(!technique.empty(), "technique", "empty");
    require(!scene.empty(), "scene", "empty");
    require(!backend.empty(), "backend", "empty");
    require(width > 0 && height > 0, "width/height", "must be positive");
    require(parameters.is_object(), "parameters", "must be a JSON object");
    ojson j;
    j["technique"] = technique;
    j["scene"] = scene;
    j["width"] = width;
    j["height"] = height;
    j["backend"] = backend;
    if (!gl_renderer.empty()) j["gl_renderer"] = gl_renderer;
    j["parameters"] = parameters;
    j["repeat"] = repeat;
    ojson t = ojson::object();
    for (const auto& [stage, ms] : timings_ms) t[stage] = number_or_null(ms);
    j["timings_ms"] = t;
    if (error) {
        j["error"] = {{"rel_rms", number_or_null(error->rel_rms)},
                      {"max_abs", number_or_null(error->max_abs)},
                      {"sum_sq", number_or_null(error->sum_sq)},
                      {"pixels", error->pixels}};
    }
    for (const auto& [name, value] : counts) {
        require(!name.empty(), "counts", "empty count name");
        if (j.contains(name)) throw parameter_error("counts", "count '" + name + "' collides with a report key");
        j[name] = value;
    }
    return j;
}

void run_report::write(const fs::path& file) const {
    io::write_text_file(file, to_json().dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + '\n');
}

}  // namespace bounce::study
