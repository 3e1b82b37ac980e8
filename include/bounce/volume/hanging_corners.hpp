#pragma once
/// \file volume/hanging_corners.hpp
/// Hanging corners computed in the lookup (issue 31, fifth session). A corner of a leaf that
/// lies on a face or an edge of a coarser leaf (a T-junction) holds, with conforming
/// corners, that leaf's trilinear interpolation there: no information of its own. Stored
/// (hanging_corner_storage::stored, the default) it costs a probe like any other; computed,
/// the volume stores no probe there and the leaf's corner refers to a list of terms
/// (stored probe, weight) whose weighted sum is that interpolation, resolved through
/// nested T-junctions at build time, so the lookup (irradiance_volume::trilinear) sums the
/// terms with the probe_combination_add kernel and weighs the sum as a corner. The values
/// are the stored ones (tested), so is the error; only the probe count changes.

#include <bounce/volume/kernels.hpp>

#include <array>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

namespace bounce::inline volume {

/// Where an adaptive volume keeps its hanging corners (irradiance_volume_settings::hanging_corners).
enum class hanging_corner_storage {
    stored,    ///< a probe each, set to the coarser leaf's interpolation (conforming corners)
    computed,  ///< no probe: the lookup interpolates the coarser leaf's stored corners
};

/// One term of a computed hanging corner: a stored probe (index into probes()) and its weight.
struct hanging_term {
    std::uint32_t probe = 0;
    float weight = 0.f;
};

/// A computed hanging corner: terms [first, first + count) of irradiance_volume::hanging_terms(),
/// and valid = 0 where no usable probe has a weight there (then, like a probe inside
/// geometry, the lookup skips it), else 1.
struct hanging_corner {
    std::uint32_t first = 0, count = 0;
    float valid = 0.f;
};

}  // namespace bounce::volume

namespace bounce::detail {

/// A node corner that refers to hanging_corners()[corner & ~hanging_flag] instead of a probe.
inline constexpr std::uint32_t hanging_flag = 0x80000000u;

/// A hanging corner's terms over lattice probes that are not hanging, and its validity.
struct hanging_expansion {
    std::vector<hanging_term> terms;
    float valid = 0.f;
};

/// The expansion of every hanging corner (samples with probe, corner[8] and weight[8], the
/// weights renormalized over the usable corners, in order coarsest leaf first so that a
/// hanging corner of the coarser leaf is expanded before it is used), keyed by its lattice
/// index: the weights through nested T-junctions multiplied out, equal terms merged.
template <class Sample>
std::unordered_map<std::uint32_t, hanging_expansion> expand_hanging(const std::vector<Sample>& hanging) {
    std::unordered_map<std::uint32_t, hanging_expansion> out;
    const auto add = [](std::vector<hanging_term>& terms, std::uint32_t probe, float w) {
        for (auto& t : terms)
            if (t.probe == probe) return void(t.weight += w);
        terms.push_back({probe, w});
    };
    for (const Sample& h : hanging) {
        hanging_expansion e;
        float wsum = 0;
        for (std::size_t k = 0; k < 8; ++k) {
            const float w = h.weight[k];
            if (w <= 0) continue;
            wsum += w;
            const auto it = out.find(h.corner[k]);
            if (it == out.end()) add(e.terms, h.corner[k], w);
            else
                for (const hanging_term& t : it->second.terms) add(e.terms, t.probe, w * t.weight);
        }
        e.valid = wsum > 0 ? 1.f : 0.f;
        out[h.probe] = std::move(e);
    }
    return out;
}

/// A volume's computed hanging corners: the table the leaves' flagged corners index.
struct hanging_table {
    std::vector<hanging_corner> corners;
    std::vector<hanging_term> terms;
};

/// The probes some leaf uses, renumbered in order of first use, and every node's corners
/// renumbered to them (inner nodes keep a corner only where its probe survived, else 0).
/// With `hanging` (computed hanging corners), a corner in it is not a probe: it becomes
/// hanging_flag | its index in `table`, whose terms are renumbered to the stored probes.
template <class Probe, class Node>
std::vector<Probe> used_probes(const std::vector<Probe>& all, std::vector<Node>& nodes,
                               const std::unordered_map<std::uint32_t, hanging_expansion>* hanging = nullptr,
                               hanging_table* table = nullptr) {
    constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    std::vector<Probe> used;
    std::vector<std::uint32_t> remap(all.size(), none), slot(all.size(), none);
    const auto use = [&](std::uint32_t idx) {
        if (remap[idx] == none) remap[idx] = std::uint32_t(used.size()), used.push_back(all[idx]);
        return remap[idx];
    };
    for (auto& nd : nodes) {
        if (!nd.leaf()) continue;
        for (auto& idx : nd.corner) {
            const auto h = hanging ? hanging->find(idx) : decltype(hanging->end()){};
            if (!hanging || h == hanging->end()) {
                idx = use(idx);
                continue;
            }
            if (slot[idx] == none) {
                slot[idx] = std::uint32_t(table->corners.size());
                table->corners.push_back({std::uint32_t(table->terms.size()), std::uint32_t(h->second.terms.size()), h->second.valid});
                table->terms.insert(table->terms.end(), h->second.terms.begin(), h->second.terms.end());
            }
            idx = hanging_flag | slot[idx];
        }
    }
    if (table)
        for (auto& t : table->terms) t.probe = use(t.probe);  // corners of leaves: already used
    for (auto& nd : nodes) {
        if (nd.leaf()) continue;
        for (auto& idx : nd.corner) idx = remap[idx] != none ? remap[idx] : slot[idx] != none ? hanging_flag | slot[idx] : 0u;
    }
    return used;
}

}  // namespace bounce::detail
