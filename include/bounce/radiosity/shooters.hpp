#pragma once
/// \file radiosity/shooters.hpp
/// What a shot comes from, the same on both backends: the shooters (the atlas's blocks, or
/// one element each) and a shooter's near-field tree (a substructuring refinement of Cohen et
/// al. 1986, the mipmap pyramid of the residual texture in Coombe and Harris 2005): its
/// elements, then groups of 2 x 2, 4 x 4 ... cells of its block's grid, the whole block last.
/// A node's position and unshot radiosity are its elements' area-weighted means, so every
/// level carries the same power. cpu::progressive_radiosity and gl::progressive_radiosity
/// build both here, in the same order, and walk the tree the same way (near_field_opens,
/// radiosity/kernels.hpp): a receiver takes a node as one disc unless it lies in the node's
/// near field, where it takes the node's children.

#include <bounce/radiosity/lightmap_atlas.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce::inline radiosity {

/// The shooters' element ranges: shooter k is the elements [first[k], first[k + 1]) of
/// `atlas`, its blocks with `blocks` (substructuring), else one element each.
inline std::vector<std::uint32_t> shooter_ranges(const lightmap_atlas& atlas, bool blocks) {
    if (blocks) return {atlas.block_first.begin(), atlas.block_first.end()};
    std::vector<std::uint32_t> first(atlas.size() + 1);
    std::iota(first.begin(), first.end(), std::uint32_t(0));
    return first;
}

/// Per element of `atlas`, 1 when it is a whole texel of the base grid (its overlap with its
/// chart is the texel's full area, and its block was never subdivided): the elements whose
/// texel square lies on the chart, so points sampled over it (light_sample_point) are on the
/// surface (on a curved chart, after light_sample_point's lift). Partial texels at a chart's
/// edge are 0 (their square leaves the chart); on a curved chart, whose elements carry their
/// surface area, a texel counts as whole from 1 / stretch of its square (stretch <= 1.155).
inline std::vector<std::uint8_t> whole_texels(const lightmap_atlas& atlas) {
    std::vector<std::uint8_t> whole(atlas.size(), 0);
    for (std::size_t k = 0; k < atlas.blocks(); ++k) {
        if (!atlas.block_level.empty() && atlas.block_level[k] != 0) continue;
        for (std::uint32_t e = atlas.block_first[k]; e < atlas.block_first[k + 1]; ++e) {
            const lightmap_chart& ch = atlas.charts[atlas.chart[e]];
            // A cluster's texel spans the air between its tiny charts: never whole.
            whole[e] = !ch.cluster() && atlas.area[e] >= 0.9999f * glm::length(glm::cross(ch.axis_u, ch.axis_v)) ? 1 : 0;
        }
    }
    return whole;
}

/// Point (a, b) of a k x k grid over element e's texel square (world): the centre of cell
/// (a, b), cells in [0, k)^2. For whole_texels only. A curved chart's texel square lies on the
/// chart's plane, off the surface by up to the chart's sag (points there biased the bunny's
/// solve, 0.097 -> 0.200 rel_rms): its point moves along the chart's normal onto the element's
/// tangent plane (its point on the surface, its mean normal), off the surface only by the
/// surface's bend within one texel.
inline glm::vec3 light_sample_point(const lightmap_atlas& atlas, std::uint32_t e, int a, int b, int k) {
    const lightmap_chart& ch = atlas.charts[atlas.chart[e]];
    const glm::vec2 t = glm::vec2(atlas.texel[e] - glm::uvec2(ch.atlas_x, ch.atlas_y)) +
                        (glm::vec2(float(a), float(b)) + 0.5f) / float(k);
    const glm::vec3 q = ch.origin + ch.axis_u * t.x + ch.axis_v * t.y;
    if (ch.planar) return q;
    const glm::vec3 n = atlas.normal[e];  // within the chart's cone (atlas_options::cone_degrees < 90) of its normal
    return q + ch.normal * (glm::dot(atlas.position[e] - q, n) / glm::dot(ch.normal, n));
}

/// A shooter as one disc: the area-weighted mean position of its elements [i0, i1) (world)
/// and their total area (m^2), summed in double in element order.
struct shooter_disc {
    glm::vec3 centre{0.f};
    double area = 0;
};
inline shooter_disc shooter_disc_of(const lightmap_atlas& atlas, std::uint32_t i0, std::uint32_t i1) {
    glm::dvec3 moment(0);
    double area = 0;
    for (std::uint32_t i = i0; i < i1; ++i) {
        moment += glm::dvec3(atlas.position[i]) * double(atlas.area[i]);
        area += double(atlas.area[i]);
    }
    return {glm::vec3(moment / area), area};
}

/// The factor, per channel, by which a shot's deliveries are scaled so that it hands out at
/// most the power it shoots: min(1, power / intercepted), `power` the shooter's unshot power
/// and `intercepted` what its form factors (times visibility) would deliver, both in W per
/// channel. A shooter's form factors to everything it sees sum to at most 1 (they tile its
/// hemisphere); the disc approximation, evaluated at receivers' centres, can sum above it
/// where receivers lie close to a shooter (slivers, near-touching elements), and a shot that
/// delivered more than it shot would create energy. Both solvers apply it. It is 1 unless
/// receivers lie close to the shooter: in a closed box the near field's discs over-deliver
/// into the corners and many block shots are scaled. After a re-bake (radiosity/rebake.hpp)
/// power may be negative: the bound holds for magnitudes (a delivery of the other sign than
/// the power, possible only where a shooter's elements hold both signs, is not scaled).
inline glm::dvec3 shot_scale(const glm::dvec3& power, const glm::dvec3& intercepted) {
    const auto one = [](double p, double got) {
        return std::abs(got) > std::abs(p) && p * got > 0 ? std::abs(p) / std::abs(got) : 1.0;
    };
    return {one(power.x, intercepted.x), one(power.y, intercepted.y), one(power.z, intercepted.z)};
}

/// Builds the near-field tree of the shooter made of the elements [i0, i1) of `atlas` (one
/// chart's): with `block` (the shooter is atlas block `block_index`, shot as one) its cells
/// are the block's grid cells, else the shooter is one element, a tree of one node.
/// `unshot(i)` gives element i's unshot radiosity (W/m^2 per channel, as glm::dvec3). Calls
/// `node(position, area, unshot, first_child, child_count)` once per node, in the order the
/// nodes are numbered (children before parents, siblings together, the root last), with the
/// node's area-weighted mean position (world), its area (m^2), its area-weighted mean unshot
/// radiosity (all in double), and the number of its first child and its child count (0: an
/// element). The sums are in double and in element order, so both backends get the same
/// nodes from the same unshot radiosities.
template <class Unshot, class Node>
void build_near_field_tree(const lightmap_atlas& atlas, std::uint32_t i0, std::uint32_t i1, bool block,
                           std::size_t block_index, const Unshot& unshot, const Node& node) {
    struct pending {
        glm::uvec2 cell;
        glm::dvec3 moment, power;
        double area;
        std::uint32_t first_child, child_count;
    };
    std::vector<pending> level, next;
    glm::vec4 rect(0.f, 0.f, 1.f, 1.f);
    glm::uvec2 grid(1u);
    if (block) {
        rect = atlas.block_rect[block_index];
        grid = atlas.block_grid[block_index];
    }
    const lightmap_chart& ch = atlas.charts[atlas.chart[i0]];
    for (std::uint32_t i = i0; i < i1; ++i) {
        const glm::vec3 d = atlas.position[i] - ch.origin;
        const glm::vec2 g((glm::dot(d, ch.axis_u) / glm::dot(ch.axis_u, ch.axis_u) - rect.x) / (rect.z / float(grid.x)),
                          (glm::dot(d, ch.axis_v) / glm::dot(ch.axis_v, ch.axis_v) - rect.y) / (rect.w / float(grid.y)));
        const glm::uvec2 cell(std::uint32_t(std::clamp(int(std::floor(g.x)), 0, int(grid.x) - 1)),
                              std::uint32_t(std::clamp(int(std::floor(g.y)), 0, int(grid.y) - 1)));
        const double a = double(atlas.area[i]);
        level.push_back({cell, glm::dvec3(atlas.position[i]) * a, glm::dvec3(unshot(i)) * a, a, 0, 0});
    }
    const auto key = [](glm::uvec2 c) { return std::uint64_t(c.y) << 32 | c.x; };
    std::uint32_t count = 0;
    while (true) {
        // Siblings next to each other, then this level's nodes numbered.
        std::stable_sort(level.begin(), level.end(),
                         [&](const pending& a, const pending& b) { return key(a.cell / 2u) < key(b.cell / 2u); });
        const std::uint32_t base = count;
        for (const pending& p : level) node(p.moment / p.area, p.area, p.power / p.area, p.first_child, p.child_count);
        count += std::uint32_t(level.size());
        if (level.size() == 1) break;
        next.clear();
        for (std::size_t j = 0; j < level.size(); ++j) {
            const glm::uvec2 parent = level[j].cell / 2u;
            if (next.empty() || key(next.back().cell) != key(parent))
                next.push_back({parent, glm::dvec3(0), glm::dvec3(0), 0.0, base + std::uint32_t(j), 0});
            pending& q = next.back();
            q.moment += level[j].moment;
            q.power += level[j].power;
            q.area += level[j].area;
            ++q.child_count;
        }
        level.swap(next);
    }
}

}  // namespace bounce::radiosity
