#pragma once
/// \file view_selection.hpp
/// SII's VPLs of a CPU frame chosen by what the camera sees (indirect/view_selection.hpp):
/// a pool of candidates measured at a sparse grid of G-buffer pixels with visibility, the
/// candidates measured in parallel. cpu::indirect_renderer calls it when its options ask for
/// visibility rays and view_selection is enabled (docs/rsm-sii-interleaved.md, section 15;
/// the RSM gather keeps its disc pattern: given the same treatment it did not improve).

#include <bounce/gbuffer.hpp>
#include <bounce/indirect/interleaved_sampling.hpp>
#include <bounce/indirect/options.hpp>
#include <bounce/indirect/rsm.hpp>
#include <bounce/indirect/rsm_sampling.hpp>
#include <bounce/indirect/view_selection.hpp>
#include <bounce/indirect/vpl_sampling.hpp>
#include <bounce/luminance.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace bounce::cpu {

/// view_importance of every candidate (`terms(candidate, receiver, add)` as view_importance's
/// terms for one candidate), in parallel; one value per candidate.
template <class Candidate, class Terms>
std::vector<double> view_importances(std::span<const Candidate> candidates, std::span<const view_receiver> receivers,
                                     const occlusion_query* occlusion, Terms&& terms) {
    std::vector<double> t(candidates.size(), 0.0);
    tbb::enumerable_thread_specific<view_importance_scratch> scratches;
    tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t j) {
        t[j] = view_importance(
            receivers, [&](const view_receiver& r, auto&& add) { terms(candidates[j], r, add); }, occlusion,
            scratches.local());
    });
    return t;
}

/// The covered pixels of a G-buffer as view receivers, bucketed on a uniform grid of `cell`
/// (world units) for the near field of each candidate (view_selection_params::near_field).
class near_pixels {
public:
    near_pixels(const gbuffer_view<float>& gb, float cell) : cell_(cell > 0.f && std::isfinite(cell) ? cell : 1.f) {
        for (std::size_t y = 0; y < gb.height(); ++y)
            for (std::size_t x = 0; x < gb.width(); ++x)
                if (gb.covered(x, y))
                    pixels_.push_back({glm::vec3(gb.position(x, y)), glm::vec3(gb.normal(x, y)),
                                       rec709_luminance<float, glm::vec3>(glm::vec3(gb.albedo(x, y)))});
        key_.resize(pixels_.size());
        for (std::size_t i = 0; i < pixels_.size(); ++i) key_[i] = key(cell_of(pixels_[i].position));
        std::vector<std::uint32_t> order(pixels_.size());
        std::iota(order.begin(), order.end(), 0u);
        std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key_[a] < key_[b]; });
        std::vector<view_receiver> p;
        std::vector<std::uint64_t> k;
        for (const std::uint32_t i : order) {
            p.push_back(pixels_[i]);
            k.push_back(key_[i]);
        }
        pixels_ = std::move(p);
        key_ = std::move(k);
    }

    /// Appends the pixels within `radius` of `centre` to `out` (at most `cap`, evenly taken,
    /// each weighted by near_field_weight(stride, found, taken) times its albedo's luminance).
    void within(const glm::vec3& centre, float radius, double stride, std::size_t cap,
                std::vector<view_receiver>& out) const {
        out.clear();
        if (!(radius > 0.f) || pixels_.empty()) return;
        const glm::ivec3 lo = cell_of(centre - glm::vec3(radius)), hi = cell_of(centre + glm::vec3(radius));
        const auto take = [&](const view_receiver& r) {
            if (glm::dot(r.position - centre, r.position - centre) < radius * radius) out.push_back(r);
        };
        if (glm::any(glm::greaterThan(hi - lo, glm::ivec3(16)))) {  // a ball of many cells: every pixel
            for (const view_receiver& r : pixels_) take(r);
        } else {
            for (int z = lo.z; z <= hi.z; ++z)
                for (int y = lo.y; y <= hi.y; ++y)
                    for (int x = lo.x; x <= hi.x; ++x) {
                        const auto [b, e] = std::equal_range(key_.begin(), key_.end(), key({x, y, z}));
                        for (auto it = b; it != e; ++it) take(pixels_[std::size_t(it - key_.begin())]);
                    }
        }
        const std::size_t found = out.size(), taken = std::min(found, cap);
        if (taken < found) {
            for (std::size_t i = 0; i < taken; ++i) out[i] = out[i * found / taken];
            out.resize(taken);
        }
        const float w = near_field_weight(stride, found, taken);
        for (view_receiver& r : out) r.weight *= w;
    }

private:
    glm::ivec3 cell_of(const glm::vec3& p) const { return glm::ivec3(glm::floor(p / cell_)); }
    static std::uint64_t key(const glm::ivec3& c) {
        const auto part = [](int v) { return std::uint64_t(std::uint32_t(v + (1 << 20)) & 0x1fffffu); };
        return part(c.x) | part(c.y) << 21 | part(c.z) << 42;
    }

    float cell_;
    std::vector<view_receiver> pixels_;
    std::vector<std::uint64_t> key_;
};

/// The near-field part of view_importance of every candidate (`radius(candidate)` its ball,
/// near_field_radius; `terms` as view_importances'), in parallel.
template <class Candidate, class Radius, class Terms>
std::vector<double> near_field_importances(std::span<const Candidate> candidates, const near_pixels& pixels,
                                           double stride, const occlusion_query* occlusion, Radius&& radius,
                                           Terms&& terms) {
    std::vector<double> t(candidates.size(), 0.0);
    struct scratch {
        view_importance_scratch s;
        std::vector<view_receiver> near;
    };
    tbb::enumerable_thread_specific<scratch> scratches;
    tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t j) {
        scratch& s = scratches.local();
        pixels.within(candidates[j].position, radius(candidates[j]), stride, 1024, s.near);
        t[j] = view_importance(
            std::span<const view_receiver>(s.near),
            [&](const view_receiver& r, auto&& add) { terms(candidates[j], r, add); }, occlusion, s.s);
    });
    return t;
}

/// Candidates in the order of the Morton code of `key(c)` over their bounding box, so that
/// the systematic draw (draw_for_view) takes them as spatial strata.
template <class Candidate, class Key>
void sort_along_curve(std::vector<Candidate>& c, Key&& key) {
    std::vector<glm::vec3> positions;
    positions.reserve(c.size());
    for (const auto& x : c) positions.push_back(key(x));
    const std::vector<std::uint32_t> code = bounce::detail::morton_codes(positions);
    std::vector<std::uint32_t> order(c.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return code[a] < code[b]; });
    std::vector<Candidate> sorted;
    sorted.reserve(c.size());
    for (const std::uint32_t k : order) sorted.push_back(c[k]);
    c = std::move(sorted);
}

/// SII's VPLs of a frame chosen by the view: options.view_selection.candidates x count
/// candidates (select_vpls), measured at the covered pixels of a regular grid over `gb` (the
/// split G-buffer when interleaved: the same pixels reordered) with `occlusion`, count of
/// them drawn for the `cells` sub-buffers. A candidate is measured with the clamp the VPL it
/// becomes would have under a uniform draw (its area times candidates, times cells).
inline std::vector<vpl> select_vpls_for_view(std::span<const rsm_view> maps, const indirect_options& o,
                                             const gbuffer_view<float>& gb, const occlusion_query* occlusion,
                                             int cells) {
    const view_selection_params& vs = o.view_selection;
    std::vector<vpl> candidates = select_vpls(maps, o.count * std::size_t(vs.candidates), o.selection, o.seed);
    if (candidates.empty()) return candidates;
    sort_along_curve(candidates, [](const vpl& l) { return l.position; });
    const std::vector<view_receiver> receivers = view_receivers(gb, vs.receivers);
    const pixel_light_params& lp = o.light;
    const float area_scale = float(vs.candidates) * float(cells);
    const auto terms = [&](const vpl& c, const view_receiver& r, auto&& add) {
        if (!(glm::dot(c.normal, r.position - (c.position - c.normal * lp.offset)) > 0.f)) return;
        const glm::vec3 e = pixel_light_irradiance<float, glm::vec3>(r.position, r.normal, c.position, c.normal, c.flux,
                                                                     lp.offset, lp.min_distance2_for(c.area * area_scale));
        add(rec709_luminance<float, glm::vec3>(e), visibility_segment{r.position, r.normal, c.position, c.normal});
    };
    // The grid's receivers outside each candidate's near field, and the pixels inside it.
    const auto radius = [&](const vpl& c) {
        return near_field_radius(vs.near_field, lp.min_distance2_for(c.area * area_scale));
    };
    const auto far_terms = [&](const vpl& c, const view_receiver& r, auto&& add) {
        const float rc = radius(c);
        if (glm::dot(r.position - c.position, r.position - c.position) >= rc * rc) terms(c, r, add);
    };
    std::vector<double> t = view_importances<vpl>(candidates, receivers, occlusion, far_terms);
    if (vs.near_field > 0.f) {
        std::vector<float> radii;
        for (const vpl& c : candidates) radii.push_back(radius(c));
        std::nth_element(radii.begin(), radii.begin() + std::ptrdiff_t(radii.size() / 2), radii.end());
        const near_pixels pixels(gb, radii[radii.size() / 2]);
        const double stride = receiver_stride(gb.width(), gb.height(), vs.receivers);
        const std::vector<double> near =
            near_field_importances<vpl>(candidates, pixels, stride, occlusion, radius, terms);
        for (std::size_t j = 0; j < t.size(); ++j) t[j] = combined_importance(t[j], near[j]);
    }
    return select_for_view<vpl>(candidates, t, o.count, cells, vs.defensive, o.seed, cells == 1,
                                [](vpl l, double s) {
                                    l.flux = glm::vec3(glm::dvec3(l.flux) * s);
                                    l.area = float(double(l.area) * s);
                                    return l;
                                });
}

}  // namespace bounce::cpu
