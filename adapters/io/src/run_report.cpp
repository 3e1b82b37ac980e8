// The run report of design.md section 6 and the stage timer behind its timings.
#include <bounce/io/report.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>

namespace bounce::io {

namespace fs = std::filesystem;
using ojson = nlohmann::ordered_json;

report_error::report_error(fs::path file, const std::string& what)
    : bounce::error("bounce: " + file.string() + ": " + what), file_(std::move(file)) {}

stage_timer::scope::scope(stage_timer& timer, std::string stage) : timer_(&timer), stage_(std::move(stage)) {
    require(!stage_.empty(), "stage", "empty stage name");
    timer.open_stage(stage_);  // the report lists stages in the order they started
    start_ = std::chrono::steady_clock::now();
}

stage_timer::scope::scope(scope&& other) noexcept
    : timer_(std::exchange(other.timer_, nullptr)), stage_(std::move(other.stage_)), start_(other.start_) {}

stage_timer::scope::~scope() {
    if (timer_) stop();
}

double stage_timer::scope::stop() {
    if (!timer_) return 0.0;
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
    stage_timer* t = std::exchange(timer_, nullptr);
    t->add_sample(stage_, ms);
    return ms;
}

std::vector<double>& stage_timer::open_stage(std::string_view stage) {
    const auto it = std::find_if(stages_.begin(), stages_.end(), [&](const auto& s) { return s.first == stage; });
    if (it != stages_.end()) return it->second;
    return stages_.emplace_back(std::string(stage), std::vector<double>{}).second;
}

void stage_timer::add_sample(std::string_view stage, double ms) {
    require(!stage.empty(), "stage", "empty stage name");
    require(std::isfinite(ms) && ms >= 0.0, "ms", "a duration must be finite and >= 0");
    open_stage(stage).push_back(ms);
}

std::vector<double> stage_timer::samples(std::string_view stage) const {
    const auto it = std::find_if(stages_.begin(), stages_.end(), [&](const auto& s) { return s.first == stage; });
    return it == stages_.end() ? std::vector<double>{} : it->second;
}

double stage_timer::median_ms(std::string_view stage) const {
    std::vector<double> v = samples(stage);
    if (v.empty()) throw parameter_error("stage", "no sample of stage '" + std::string(stage) + "'");
    const std::size_t mid = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(mid), v.end());
    const double upper = v[mid];
    if (v.size() % 2 == 1) return upper;
    const double lower = *std::max_element(v.begin(), v.begin() + std::ptrdiff_t(mid));
    return 0.5 * (lower + upper);
}

std::vector<std::string> stage_timer::stages() const {
    std::vector<std::string> out;
    for (const auto& s : stages_)
        if (!s.second.empty()) out.push_back(s.first);
    return out;
}

std::size_t stage_timer::repeats() const {
    std::size_t n = 0;
    for (const auto& s : stages_) n = std::max(n, s.second.size());
    return n;
}

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
    const ojson j = to_json();
    std::error_code ec;
    if (file.has_parent_path()) fs::create_directories(file.parent_path(), ec);
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    if (!out) throw report_error(file, "cannot open for writing");
    out << j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
    out.flush();
    if (!out) throw report_error(file, "write failed");
}

}  // namespace bounce::io
