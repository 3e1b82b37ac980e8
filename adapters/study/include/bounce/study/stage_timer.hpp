#pragma once
/// \file stage_timer.hpp
/// Wall-clock timing of a run's named stages, repeated; run_report takes the medians.

#include <bounce/errors.hpp>

#include <chrono>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bounce::study {

/// Milliseconds of wall-clock time (std::chrono::steady_clock) since `t0`: the one stopwatch
/// of the programs and studies, for spans that are not a stage_timer stage.
inline double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// Wall-clock samples per named stage (std::chrono::steady_clock, milliseconds); the
/// report takes their medians, which a single slow repeat (page faults, a shader compile)
/// does not move.
class stage_timer {
public:
    /// Times from construction to destruction (or `stop()`) and adds the sample to its stage.
    class scope {
    public:
        scope(stage_timer& timer, std::string stage);
        scope(scope&& other) noexcept;
        scope(const scope&) = delete;
        scope& operator=(const scope&) = delete;
        scope& operator=(scope&&) = delete;
        ~scope();
        /// Ends the sample now; later calls and the destructor do nothing. Returns its ms.
        double stop();

    private:
        stage_timer* timer_;
        std::string stage_;
        std::chrono::steady_clock::time_point start_;
    };

    /// Starts a sample of `stage` ("gbuffer", "interpolate", "total" ...) that ends when the
    /// returned scope does.
    [[nodiscard]] scope measure(std::string stage) { return scope(*this, std::move(stage)); }

    /// Calls `f()`, adds its duration to `stage`, and returns what `f` returns.
    template <class F>
    decltype(auto) time(std::string_view stage, F&& f) {
        scope s(*this, std::string(stage));
        return std::forward<F>(f)();
    }

    /// Adds one sample of `ms` milliseconds (finite, >= 0) to `stage`.
    /// Throws parameter_error otherwise or when `stage` is empty.
    void add_sample(std::string_view stage, double ms);
    /// The samples of `stage` in the order they were taken (empty if never timed).
    std::vector<double> samples(std::string_view stage) const;
    /// Median of the samples of `stage` (mean of the middle two for an even count).
    /// Throws parameter_error when `stage` has no sample.
    double median_ms(std::string_view stage) const;
    /// Names of the stages with samples, in the order they were first started.
    std::vector<std::string> stages() const;
    /// The largest number of samples of any stage (the `--repeat` count in practice).
    std::size_t repeats() const;
    /// Forgets every sample.
    void clear() noexcept { stages_.clear(); }

private:
    std::vector<double>& open_stage(std::string_view stage);
    std::vector<std::pair<std::string, std::vector<double>>> stages_;
};

}  // namespace bounce::study
