#pragma once
/// \file radiosity_ambient.hpp
/// The CPU solver's state for the ambient term shaped by its shots (radiosity/ambient.hpp,
/// radiosity_ambient::shots and ::mixed): over an exponentially decayed window of recent shots, each
/// element-side's received irradiance h_i and the shots' power S, delivered power D and
/// reflected power R. The window is measured in power, not in shots: a shot's weight falls by
/// exp(-p / (window U)) for each later shot of power p, U the unshot power then, so it spans
/// the recent shots that shot about `window` times the power still to shoot. Their capture
/// and reflection are those of the power left (early shots from sunlit open floors lose most
/// of their light; late ones, deeper inside, keep it), whatever the scene's shot count. A
/// window of a fixed number of shots measured worse (docs/radiosity.md). Weights grow instead
/// of the old sums shrinking, so a shot costs one pass over the elements; all sums are
/// rescaled when the weight grows large.

#include <bounce/radiosity/ambient.hpp>
#include <bounce/radiosity/options.hpp>

#include <algorithm>
#include <cmath>
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

    /// Of the unshot power, the share whose worth of recent shots the window spans (see the file
    /// comment; 0.5 measured best of 0.25, 0.5 and 1 on Sponza, docs/radiosity.md).
    static constexpr double window = 0.5;

    /// Adds one shot, nothing unless `options` ask for the shaped ambient term: `received` (per
    /// element-side, W/m^2 before the shot's `scale`), the shot's `power`, what it `intercepted`
    /// and `absorbed` (W per channel), and the unshot power `unshot` left after it (W, channels
    /// summed). A change of the element count (subdivision) starts the window again.
    void record(const radiosity_options& options, std::span<const vec> received, const glm::dvec3& scale,
                const glm::dvec3& power, const glm::dvec3& intercepted, const glm::dvec3& absorbed, double unshot) {
        if (!shaped(options)) return;
        if (recent_.size() != received.size()) {
            recent_.assign(received.size(), vec(0));
            shot_ = delivered_ = reflected_ = glm::dvec3(0);
            weight_ = 1;
        }
        const vec w = vec(scale * weight_);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, received.size(), 4096), [&](const auto& r) {
            for (std::size_t j = r.begin(); j != r.end(); ++j)
                if (received[j] != vec(0)) recent_[j] += received[j] * w;
        });
        shot_ += power * weight_;
        delivered_ += intercepted * weight_;
        reflected_ += (intercepted - absorbed) * weight_;
        // Older shots fall by exp(-p / (window U)) for each later shot of power p.
        const double p = std::abs(power.x) + std::abs(power.y) + std::abs(power.z);
        weight_ *= std::exp(unshot > 0 ? std::min(40.0, p / (window * unshot)) : 40.0);
        if (weight_ > 1e12) rescale(1.0 / weight_);
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
        if (!shaped(options) || recent_.size() < o + n || shot_ == glm::dvec3(0))
            return std::vector<glm::vec3>(n, glm::vec3(solver.ambient()));
        const glm::dvec3 f = shot_ambient_factor<double, glm::dvec3>(solver.unshot_power(), shot_, reflected_);
        std::vector<glm::vec3> out(n);
        if (options.ambient_shape == radiosity_ambient::shots) {
            for (std::size_t i = 0; i < n; ++i) out[i] = glm::vec3(glm::dvec3(recent_[o + i]) * f);
            return out;
        }
        // Mixed: the floor over every side's area, and the scale that keeps the total at f D.
        const std::span<const float> area = solver.atlas().area;
        double total_area = 0;
        for (float a : area) total_area += double(a);
        const glm::dvec3 floor = mixed_ambient_floor<double, glm::dvec3>(f, shot_, delivered_, reflected_,
                                                                         total_area * double(recent_.size() / n));
        glm::dvec3 deficit(0);
        for (std::size_t j = 0; j < recent_.size(); ++j)
            deficit += double(area[j % n]) * glm::max(floor - glm::dvec3(recent_[j]) * f, glm::dvec3(0));
        const glm::dvec3 scale = mixed_ambient_scale<double, glm::dvec3>(f * delivered_, deficit);
        for (std::size_t i = 0; i < n; ++i)
            out[i] = glm::vec3(mixed_ambient<double, glm::dvec3>(glm::dvec3(recent_[o + i]) * f, floor, scale));
        return out;
    }

    /// The window's decayed sums at the current weight, W per channel: shot, delivered, reflected.
    glm::dvec3 shot() const { return shot_ / weight_; }
    glm::dvec3 delivered() const { return delivered_ / weight_; }
    glm::dvec3 reflected() const { return reflected_ / weight_; }

private:
    static bool shaped(const radiosity_options& o) { return o.ambient && o.ambient_shape != radiosity_ambient::uniform; }
    void rescale(double k) {
        for (vec& h : recent_) h *= Real(k);
        shot_ *= k, delivered_ *= k, reflected_ *= k, weight_ *= k;
    }
    std::vector<vec> recent_;  // per element-side, the window's irradiance times weight_ (W/m^2)
    glm::dvec3 shot_{0}, delivered_{0}, reflected_{0};
    double weight_ = 1;
};

}  // namespace bounce::cpu
