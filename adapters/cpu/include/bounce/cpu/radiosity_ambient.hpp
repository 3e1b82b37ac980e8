#pragma once
/// \file radiosity_ambient.hpp
/// The CPU solver's state for the ambient term shaped by its shots (radiosity/ambient.hpp,
/// radiosity_ambient::shots and ::mixed): each element-side's received irradiance h_i over the
/// window of recent shots, in a vector; the window's sums and weights are
/// radiosity/ambient_window.hpp's (the GL solver keeps h_i in a texture and shares them).

#include <bounce/radiosity/ambient_window.hpp>
#include <bounce/radiosity/options.hpp>

#include <cstddef>
#include <span>
#include <vector>

#include <glm/vec3.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bounce::cpu {

template <floating Real>
class shot_ambient_state {
public:
    using vec = glm::vec<3, Real>;

    /// Adds one shot, nothing unless `options` ask for the shaped ambient term: `received` (per
    /// element-side, W/m^2 before the shot's `scale`), the shot's `power`, what it `intercepted`
    /// and `absorbed` (W per channel), and the unshot power `unshot` left after it (W, channels
    /// summed). A change of the element count (subdivision) starts the window again.
    void record(const radiosity_options& options, std::span<const vec> received, const glm::dvec3& scale,
                const glm::dvec3& power, const glm::dvec3& intercepted, const glm::dvec3& absorbed, double unshot) {
        if (!shot_ambient_window::shaped(options)) return;
        if (recent_.size() != received.size()) {
            recent_.assign(received.size(), vec(0));
            window_.restart();
        }
        const vec w = vec(scale * window_.weight());
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, received.size(), 4096), [&](const auto& r) {
            for (std::size_t j = r.begin(); j != r.end(); ++j)
                if (received[j] != vec(0)) recent_[j] += received[j] * w;
        });
        if (const double k = window_.record(power, intercepted, absorbed, unshot); k != 1.0)
            for (vec& h : recent_) h *= Real(k);
    }

    /// The ambient irradiance per element of `side` of `solver` (W/m^2): 0 unless `on` and
    /// `options` ask for the term; Cohen's uniform solver.ambient() when they ask for it, and
    /// also before the first shot or after the atlas changed; else h_i U / (S - R) for the
    /// unshot power U = solver.unshot_power() (shots), or the larger of that and the floor
    /// of the reflections spread evenly, scaled to keep the total (mixed, radiosity/ambient.hpp).
    template <class Solver>
    std::vector<glm::vec3> field(bool on, const radiosity_options& options, const Solver& solver, int side) const {
        const std::size_t n = solver.atlas().size(), o = std::size_t(side) * n;
        if (!on || !options.ambient) return std::vector<glm::vec3>(n, glm::vec3(0.f));
        if (!shot_ambient_window::shaped(options) || recent_.size() < o + n || window_.empty())
            return std::vector<glm::vec3>(n, glm::vec3(solver.ambient()));
        const std::span<const float> area = solver.atlas().area;
        double total_area = 0;
        for (float a : area) total_area += double(a);
        shot_ambient_terms t = window_.terms(options.ambient_shape, solver.unshot_power(),
                                             total_area * double(recent_.size() / n));
        if (t.shape == radiosity_ambient::mixed) t.with_deficit(t.deficit(std::span<const vec>(recent_), area));
        std::vector<glm::vec3> out(n);
        for (std::size_t i = 0; i < n; ++i) out[i] = t.at(recent_[o + i]);
        return out;
    }

    /// The window's decayed sums at the current weight, W per channel: shot, delivered, reflected.
    glm::dvec3 shot() const { return window_.shot(); }
    glm::dvec3 delivered() const { return window_.delivered(); }
    glm::dvec3 reflected() const { return window_.reflected(); }

private:
    std::vector<vec> recent_;  // per element-side, the window's irradiance times its weight (W/m^2)
    shot_ambient_window window_;
};

}  // namespace bounce::cpu
