#pragma once
/// \file imperfect_shadow_maps.hpp
/// Imperfect shadow maps on the CPU (indirect/imperfect_shadow_maps.hpp, Ritschel et al.
/// 2008): one frame's paraboloid depth maps of its VPLs in one atlas, splatted from the
/// VPLs' point subsets, holes filled by pull-push, and the receivers' lookup. The kernels
/// are the core's, instantiated with float and glm; gl::indirect_renderer prints the same
/// ones, so both backends store the same depths and make the same decisions.

#include <bounce/errors.hpp>
#include <bounce/indirect/imperfect_shadow_maps.hpp>
#include <bounce/indirect/vpl_sampling.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <tbb/parallel_for.h>

namespace bounce::cpu {

class imperfect_shadow_maps {
public:
    /// The maps of `vpls` (the frame's VPLs in selection order): VPL j is splatted from the
    /// points i of `points` with i % vpls.size() == j (ism_point_sampler's subsets), each
    /// point into the nearest depth of its texel (ism_splat_texel); then, with
    /// params.pull_push, the holes are filled (ism_pull, ism_push). `spacing` is the points'
    /// spacing for one VPL (ism_point_spacing), which the lookup's bias uses.
    void build(std::span<const vpl> vpls, std::span<const glm::vec3> points, const ism_params& params,
               float spacing) {
        params.validate(std::max<std::size_t>(vpls.size(), 1));
        require(std::isfinite(spacing) && spacing >= 0.f, "spacing", "must be finite and >= 0");
        layout_ = ism_atlas_layout(params.map_size, vpls.size());
        spacing_ = spacing;
        scale_ = params.bias_scale;
        depth_.assign(layout_.width() * layout_.height(), ism_empty);
        const std::size_t v = vpls.size();
        if (v == 0) return;
        const int s = params.map_size;
        const float res = float(s);
        tbb::parallel_for(std::size_t(0), v, [&](std::size_t j) {
            const vpl& l = vpls[j];
            for (std::size_t i = j; i < points.size(); i += v) {
                const glm::vec3 t = ism_splat_texel<float, glm::vec3, glm::vec2>(points[i], l.position, l.normal, res);
                float& d = depth_[layout_.index(j, int(t.x), int(t.y))];
                d = std::min(d, t.z);
            }
            if (params.pull_push) pull_push(j);
        });
    }

    const ism_atlas_layout& layout() const noexcept { return layout_; }
    /// The finest level's depths, row-major over the atlas (ism_atlas_layout::index).
    std::span<const float> depths() const noexcept { return depth_; }
    float spacing() const noexcept { return spacing_; }

    /// 1 where the receiver at `receiver` (unit normal `receiver_normal`) sees VPL j (`l`,
    /// the VPL the maps were built for, at any flux) through its map, 0 where hidden.
    float visible(std::size_t j, const glm::vec3& receiver, const glm::vec3& receiver_normal, const vpl& l) const {
        const float res = float(layout_.map_size);
        const glm::vec3 t = ism_map_texel<float, glm::vec3, glm::vec2>(receiver, l.position, l.normal, res);
        const float stored = depth_[layout_.index(j, int(t.x), int(t.y))];
        return ism_visible<float, glm::vec3>(receiver, receiver_normal, l.position, stored, res, spacing_, scale_);
    }

private:
    /// Pull-push on map j alone (its block of the atlas): levels of size map_size / 2^l.
    void pull_push(std::size_t j) {
        const int s = layout_.map_size;
        std::vector<std::vector<float>> levels;
        levels.emplace_back(std::size_t(s) * std::size_t(s));
        for (int y = 0; y < s; ++y)
            for (int x = 0; x < s; ++x) levels[0][std::size_t(y * s + x)] = depth_[layout_.index(j, x, y)];
        for (int size = s / 2; size >= 1; size /= 2) {
            const std::vector<float>& fine = levels.back();
            const int fs = size * 2;
            std::vector<float> coarse(std::size_t(size) * std::size_t(size));
            for (int y = 0; y < size; ++y)
                for (int x = 0; x < size; ++x) {
                    const auto at = [&](int fx, int fy) { return fine[std::size_t(fy * fs + fx)]; };
                    coarse[std::size_t(y * size + x)] = ism_pull<float>(at(2 * x, 2 * y), at(2 * x + 1, 2 * y),
                                                                        at(2 * x, 2 * y + 1), at(2 * x + 1, 2 * y + 1));
                }
            levels.push_back(std::move(coarse));
        }
        for (std::size_t l = levels.size() - 1; l-- > 0;) {
            const int fs = s >> l, cs = fs / 2;
            for (int y = 0; y < fs; ++y)
                for (int x = 0; x < fs; ++x) {
                    float& f = levels[l][std::size_t(y * fs + x)];
                    f = ism_push<float>(f, levels[l + 1][std::size_t((y / 2) * cs + x / 2)]);
                }
        }
        for (int y = 0; y < s; ++y)
            for (int x = 0; x < s; ++x) depth_[layout_.index(j, x, y)] = levels[0][std::size_t(y * s + x)];
    }

    ism_atlas_layout layout_;
    std::vector<float> depth_;
    float spacing_ = 0.f, scale_ = 1.f;
};

}  // namespace bounce::cpu
