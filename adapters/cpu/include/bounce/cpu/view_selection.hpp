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
    const std::vector<double> t = view_importances<vpl>(candidates, receivers, occlusion, terms);
    return select_for_view<vpl>(candidates, t, o.count, cells, vs.defensive, o.seed, cells == 1,
                                [](vpl l, double s) {
                                    l.flux = glm::vec3(glm::dvec3(l.flux) * s);
                                    l.area = float(double(l.area) * s);
                                    return l;
                                });
}

}  // namespace bounce::cpu
