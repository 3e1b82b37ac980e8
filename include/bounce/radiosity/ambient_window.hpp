#pragma once
/// \file radiosity/ambient_window.hpp
/// The window of recent shots behind the shaped ambient terms (radiosity/ambient.hpp,
/// radiosity_ambient::shots and ::mixed), whatever keeps its per element-side irradiance h_i:
/// cpu::shot_ambient_state keeps h_i in a vector, gl::progressive_radiosity in a texture.
/// shot_ambient_window holds the rest: the window's shot, delivered and reflected power sums
/// S, D, R and the weight new shots are added with.
///
/// The window is measured in power, not in shots: a shot's weight falls by exp(-p / (window U))
/// for each later shot of power p, U the unshot power then, so it spans the recent shots that
/// shot about `window` times the power still to shoot. Their capture and reflection are those
/// of the power left (early shots from sunlit open floors lose most of their light; late ones,
/// deeper inside, keep it), whatever the scene's shot count. A window of a fixed number of
/// shots measured worse (docs/radiosity.md). Weights grow instead of the old sums shrinking, so
/// a shot costs one pass over the elements (h_i += received_i scale weight()); every sum, h_i
/// included, is rescaled when the weight grows large (record's return value).
///
/// Lights' direct light is not recorded: the window holds surface shots only.

#include <bounce/radiosity/ambient.hpp>
#include <bounce/radiosity/options.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline radiosity {

/// What turns an element-side's window irradiance h_i into its ambient irradiance a_i (W/m^2
/// per channel): a_i = h_i factor (shots), or mixed_ambient(h_i factor, floor, scale) (mixed).
struct shot_ambient_terms {
    radiosity_ambient shape = radiosity_ambient::shots;
    glm::dvec3 factor{0.0};  ///< shot_ambient_factor: U / (S - R)
    glm::dvec3 floor{0.0};   ///< mixed: mixed_ambient_floor over every element-side's area
    glm::dvec3 total{0.0};   ///< E = factor D, the area integral of the ambient irradiance
    glm::dvec3 scale{1.0};   ///< mixed: mixed_ambient_scale, once the deficit is known (with_deficit)

    /// The mixed term's scale from the deficit sum_j A_j max(0, floor - h_j factor) over every
    /// element-side (mixed_ambient_deficit summed).
    void with_deficit(const glm::dvec3& deficit) { scale = mixed_ambient_scale<double, glm::dvec3>(total, deficit); }
    /// a_i of an element-side whose window irradiance is `h`.
    template <class V> glm::vec3 at(const V& h) const {
        const glm::dvec3 shaped = glm::dvec3(h) * factor;
        return glm::vec3(shape == radiosity_ambient::mixed ? mixed_ambient<double, glm::dvec3>(shaped, floor, scale) : shaped);
    }
    /// The deficit of every element-side of `h` (side-major: area.size() per side).
    template <class V> glm::dvec3 deficit(std::span<const V> h, std::span<const float> area) const {
        glm::dvec3 d(0.0);
        const std::size_t n = area.size();
        for (std::size_t j = 0; j < h.size(); ++j)
            d += mixed_ambient_deficit<double, glm::dvec3>(glm::dvec3(h[j]) * factor, floor, double(area[j % n]));
        return d;
    }
};

/// The window's sums and weight (see the file comment).
class shot_ambient_window {
public:
    /// Of the unshot power, the share whose worth of recent shots the window spans (0.5 measured
    /// best of 0.25, 0.5 and 1 on Sponza, docs/radiosity.md).
    static constexpr double window = 0.5;

    /// Whether `options` ask for a term the window shapes (shots or mixed, the ambient on).
    static bool shaped(const radiosity_options& o) { return o.ambient && o.ambient_shape != radiosity_ambient::uniform; }

    /// The weight a new shot's per element-side irradiance is added with: h_i += received_i
    /// scale weight(), before record().
    double weight() const noexcept { return weight_; }
    /// Whether no shot was recorded since construction or restart().
    bool empty() const noexcept { return shot_ == glm::dvec3(0.0); }
    /// Forgets every shot (the element count changed): the caller zeroes its h_i.
    void restart() noexcept { shot_ = delivered_ = reflected_ = glm::dvec3(0.0), weight_ = 1; }

    /// Adds a shot of `power` that delivered `intercepted` to elements, which absorbed
    /// `absorbed` of it (W per channel, after its scale), then decays the older shots by the
    /// unshot power `unshot` left after it (W, channels summed). Returns the factor every h_i
    /// must be multiplied by: 1, or less when the weight grew large and the sums were rescaled.
    [[nodiscard]] double record(const glm::dvec3& power, const glm::dvec3& intercepted, const glm::dvec3& absorbed,
                                double unshot) {
        shot_ += power * weight_;
        delivered_ += intercepted * weight_;
        reflected_ += (intercepted - absorbed) * weight_;
        // Older shots fall by exp(-p / (window U)) for each later shot of power p.
        const double p = std::abs(power.x) + std::abs(power.y) + std::abs(power.z);
        weight_ *= std::exp(unshot > 0 ? std::min(40.0, p / (window * unshot)) : 40.0);
        if (weight_ <= 1e12) return 1.0;
        const double k = 1.0 / weight_;
        shot_ *= k, delivered_ *= k, reflected_ *= k, weight_ *= k;
        return k;
    }

    /// The terms of `shape` (shots or mixed) for the unshot power `unshot` (W per channel),
    /// `area` every element-side's area that shows the ambient. The mixed scale still needs the
    /// deficit (shot_ambient_terms::with_deficit).
    shot_ambient_terms terms(radiosity_ambient shape, const glm::dvec3& unshot, double area) const {
        shot_ambient_terms t;
        t.shape = shape;
        t.factor = shot_ambient_factor<double, glm::dvec3>(unshot, shot_, reflected_);
        t.total = t.factor * delivered_;
        if (shape == radiosity_ambient::mixed)
            t.floor = mixed_ambient_floor<double, glm::dvec3>(t.factor, shot_, delivered_, reflected_, area);
        return t;
    }

    /// The window's decayed sums at the current weight, W per channel: shot, delivered, reflected.
    glm::dvec3 shot() const { return shot_ / weight_; }
    glm::dvec3 delivered() const { return delivered_ / weight_; }
    glm::dvec3 reflected() const { return reflected_ / weight_; }

private:
    glm::dvec3 shot_{0.0}, delivered_{0.0}, reflected_{0.0};  // times weight_
    double weight_ = 1;
};

}  // namespace bounce::radiosity
