// Stage timing: samples per named stage and their medians.
#include <bounce/study/stage_timer.hpp>

#include <algorithm>
#include <cmath>

namespace bounce::study {

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

}  // namespace bounce::study
