#pragma once
/// \file gpu_timer.hpp
/// GPU times of GL passes: two timestamp queries (glQueryCounter(GL_TIMESTAMP)) around a
/// call, read back when the GPU has passed the second, repeated and summarized by the
/// median. Timestamps rather than one GL_TIME_ELAPSED query, because the library's passes
/// may run queries of their own inside a call (the RSM upsampling counts its fallback
/// pixels with an occlusion query) and elapsed-time queries do not nest.
///
/// What a figure covers: the GPU clock from the first to the last command of the call,
/// including the time the GPU waits inside it for the host (a pass that reads a texture
/// back and decides on the CPU, as SII's VPL selection and radiosity's shooter read-back
/// do). Each repetition starts on an idle GPU (glFinish before it).

#include <bounce/gl/errors.hpp>
#include <bounce/gl/objects.hpp>

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace bounce::gpu_timings {

/// One pass's figures: per repetition, in milliseconds, and how they were taken.
struct pass_timing {
    std::string name;
    std::string method = "gl_timestamp";  ///< or "wall_clock_finish": host clock between glFinish calls
    std::vector<double> ms;               ///< one per repetition, in the order run
    /// Host clock per repetition, from before the call to the GPU's passing its end (the
    /// second timestamp's result): a check on the GPU's figure (empty for wall_clock_finish).
    std::vector<double> wall_ms;
    std::vector<std::pair<std::string, double>> extra;  ///< derived figures (planes per second ...)
    std::string covers;                   ///< what one repetition does, for the results file
};

/// Median, smallest and largest of `v` (all 0 for an empty v).
struct summary {
    double median_ms = 0, min_ms = 0, max_ms = 0;
};
inline summary summarize(std::vector<double> v) {
    if (v.empty()) return {};
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    return {median, v.front(), v.back()};
}

/// The pair of timestamp queries. A context must be current; throws gl_error when it has no
/// timestamp counter (GL_QUERY_COUNTER_BITS of GL_TIMESTAMP is 0).
class timestamp_timer {
public:
    timestamp_timer() {
        GLint bits = 0;
        glGetQueryiv(GL_TIMESTAMP, GL_QUERY_COUNTER_BITS, &bits);
        if (bits <= 0) throw gl::gl_error("gpu_timings: this GL context has no timestamp counter (GL_QUERY_COUNTER_BITS 0)");
        glGenQueries(2, queries_);
        gl::check_error("glGenQueries");
    }
    ~timestamp_timer() { glDeleteQueries(2, queries_); }
    timestamp_timer(const timestamp_timer&) = delete;
    timestamp_timer& operator=(const timestamp_timer&) = delete;

    /// GPU milliseconds from the first to the last command `call` issues, and the host's
    /// milliseconds from before the call until the GPU has passed its end.
    std::pair<double, double> time_ms(const std::function<void()>& call) {
        const auto start = std::chrono::steady_clock::now();
        glQueryCounter(queries_[0], GL_TIMESTAMP);
        call();
        glQueryCounter(queries_[1], GL_TIMESTAMP);
        GLuint64 begin = 0, end = 0;
        glGetQueryObjectui64v(queries_[0], GL_QUERY_RESULT, &begin);
        glGetQueryObjectui64v(queries_[1], GL_QUERY_RESULT, &end);
        const double wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        gl::check_error("glQueryCounter(GL_TIMESTAMP)");
        return {end >= begin ? double(end - begin) * 1e-6 : 0.0, wall};
    }

    /// `warm_up` untimed calls (programs compiled, textures allocated), then `repetitions`
    /// timed ones, each after `prepare` (untimed) and on an idle GPU.
    pass_timing repeat(std::string name, std::string covers, int warm_up, int repetitions,
                       const std::function<void()>& call, const std::function<void()>& prepare = {}) {
        pass_timing t;
        t.name = std::move(name);
        t.covers = std::move(covers);
        for (int i = 0; i < warm_up; ++i) {
            if (prepare) prepare();
            call();
        }
        for (int i = 0; i < repetitions; ++i) {
            if (prepare) prepare();
            gl::finish();
            const auto [gpu, wall] = time_ms(call);
            t.ms.push_back(gpu);
            t.wall_ms.push_back(wall);
        }
        return t;
    }

private:
    GLuint queries_[2] = {0, 0};
};

}  // namespace bounce::gpu_timings
