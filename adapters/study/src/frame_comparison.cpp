// Masks of the pixels where a frame and its reference can be compared.
#include <bounce/study/frame_comparison.hpp>

#include <bounce/errors.hpp>

#include <cmath>

namespace bounce::study {

image<float> coverage_mask(const gbuffer_view<float>& g) {
    image<float> m(g.width(), g.height(), 0.f);
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x) m(x, y) = std::isfinite(g.depth(x, y)) ? 1.f : 0.f;
    return m;
}

image<float> comparable_mask(const gbuffer_view<float>& g, const gbuffer_view<float>& reference_g, float scene_size) {
    require(g.width() == reference_g.width() && g.height() == reference_g.height(), "reference_g",
            "size differs from the frame's G-buffer");
    image<float> m = coverage_mask(g);
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x)
            if (m(x, y) > 0.f && !same_surface(g, reference_g, x, y, scene_size)) m(x, y) = 0.f;
    return m;
}

}  // namespace bounce::study
