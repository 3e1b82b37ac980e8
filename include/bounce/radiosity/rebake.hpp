#pragma once
/// \file radiosity/rebake.hpp
/// Re-baking what changed (issue 30; Chen 1990, "Incremental radiosity", and George et al.
/// 1990): after one light changes or one object moves rigidly, a progressive solver continues
/// from its previous solution instead of starting from zero. The CPU solver's re-bakes are
/// cpu::rebake_light and cpu::rebake_move (cpu/radiosity_rebake.hpp); this file has what they
/// share with any backend: the rigid move, the moved charts, the atlas moved with them, and
/// the test that tells which shooter-receiver pairs a move can change.
///
/// The state. A progressive solver keeps per element (and side) its radiosity B and its unshot
/// radiosity dB; S = B - dB is what the element has shot. Every shot keeps
///     B = E + rho F S                                                      (1)
/// (E: emission plus the lights' direct deposit rho E_d), and the solve converges to
/// B* = E + rho F B* as dB -> 0, from any state that satisfies (1). A change makes E' and F'.
/// The re-bake keeps S and sets
///     B' = B + (E' - E) + rho (F' - F) S,   dB' = dB + (the same),         (2)
/// which satisfies (1) for the changed scene; the solve then shoots the new unshot power, of
/// either sign, and converges to the changed scene's B* as a fresh solve does: exact in the
/// limit, whatever the previous solve's convergence. The correction is the difference of
/// what every shooter's S delivers with the new and with the old geometry:
///  - a light: F' = F, and E' - E is rho times the change of the lights' direct irradiance,
///    re-evaluated at every element (one light shot);
///  - a moved object (its charts: a rigid move keeps their texels, so the atlas is reused):
///    F changes in the rows and columns of the moved elements (all their pairs), and between
///    two other elements only where the segment between them (the shot's visibility ray, from
///    the shooter's centre to the receiver) meets the object's box before or after the move.
///    Every shooter that shot re-shoots its S to exactly those receivers, negatively with the
///    old geometry and visibility and positively with the new; every other pair's delivery is
///    the same both times and is skipped (segment_meets_box). Between two unmoved elements the
///    form factor is the same both times and V_old = V_rest and not blocked by the object where
///    it was, V_new = V_rest and not blocked where it is: a pair blocked in both places or in
///    neither delivers the same both times too, one blocked only after the move needs only its
///    old delivery taken away, one blocked only before only its new one; tested against the
///    object alone, the rays the solver casts (cpu::rebake_move with an object visibility,
///    embree::object_visibility). The moved object's own shooters
///    are re-shot with the old geometry only: their S returns to their unshot radiosity
///    (S = 0, dB = B there), which (1) allows, and the solve shoots it with the new geometry,
///    together with what else they hold, the largest first. What the moved elements received
///    before needs no re-shot: it is the irradiance the shots delivered to them, which the
///    solver keeps. The lights' direct deposit is re-evaluated as for a light change (shadows
///    of the object).
/// The deliveries use the solver's own shot (block discs, near-field trees, one visibility
/// ray from the block's centre), linear in the shot radiosity. A shot scaled down to its power
/// (shot_scale) delivered only its scale's share of what it took from dB, so S = B - dB is
/// not what (1) holds for; the solver keeps, per element-side, each shot's radiosity times its
/// scale, summed (S_e, its effective_shot_), for which (1) holds exactly, and the re-bake
/// re-shoots S_e unscaled: the old pass takes away exactly what was delivered. Left inexact:
/// a move that changes which shots a fresh solve would scale (the re-shots keep the bake's
/// scales), and grouped shooters' sampled visibility (radiosity_options::shooter_groups: the
/// correction uses the blocks' shot). The tests and docs/radiosity.md measure what is left
/// against a fresh solve on the same elements.
///
/// The ambient term shown before convergence (Cohen et al.) estimates the light still to
/// come from the unshot power, negative after a dimming; the converged indirect irradiance is
/// not, so the solver shows at least 0 of it (the ambient clamped at minus what the shots
/// delivered): a projection onto a set that holds the converged answer, never farther from it.
///
/// The solve after a re-bake selects shooters by |unshot power| and checks that the unshot
/// power in magnitude never rises (radiosity/solve.hpp), so negative shots stay conservative.

#include <bounce/errors.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/scene_view.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline radiosity {

/// A rigid move: p -> rotation p + translation (rotation orthonormal, determinant +1).
struct rigid_move {
    glm::mat3 rotation{1.f};
    glm::vec3 translation{0.f};

    glm::vec3 point(const glm::vec3& p) const { return rotation * p + translation; }
    glm::vec3 direction(const glm::vec3& d) const { return rotation * d; }
    /// The point that `point` moved here.
    glm::vec3 before(const glm::vec3& p) const { return glm::transpose(rotation) * (p - translation); }

    /// Throws parameter_error ("rigid_move.rotation", "rigid_move.translation") unless the
    /// rotation is orthonormal with determinant +1 (to 1e-4) and everything is finite.
    void validate() const {
        const glm::mat3 e = glm::transpose(rotation) * rotation - glm::mat3(1.f);
        float off = 0;
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) off = std::max(off, std::abs(e[c][r]));
        require(off <= 1e-4f && std::abs(glm::determinant(rotation) - 1.f) <= 1e-4f, "rigid_move.rotation",
                "must be a rotation (orthonormal, determinant +1)");
        require(std::isfinite(translation.x) && std::isfinite(translation.y) && std::isfinite(translation.z),
                "rigid_move.translation", "must be finite");
    }
};

/// An axis-aligned box (world).
struct world_box {
    glm::vec3 lo{std::numeric_limits<float>::max()}, hi{-std::numeric_limits<float>::max()};
    void add(const glm::vec3& p) { lo = glm::min(lo, p), hi = glm::max(hi, p); }
    bool empty() const { return lo.x > hi.x; }
};

/// Whether the segment from `a` to `b` meets `box` (slab test, the box widened by `margin`
/// on every side): a visibility ray between two points that misses the box of an object, in
/// either of its places, sees the same occluders before and after the object moves.
inline bool segment_meets_box(const glm::vec3& a, const glm::vec3& b, const world_box& box, float margin) {
    float t0 = 0, t1 = 1;
    for (int k = 0; k < 3; ++k) {
        const float lo = box.lo[k] - margin, hi = box.hi[k] + margin, d = b[k] - a[k];
        if (d == 0.f) {
            if (a[k] < lo || a[k] > hi) return false;
            continue;
        }
        float u = (lo - a[k]) / d, v = (hi - a[k]) / d;
        if (u > v) std::swap(u, v);
        t0 = std::max(t0, u), t1 = std::min(t1, v);
        if (t0 > t1) return false;
    }
    return true;
}

/// Per chart of `atlas`, 1 when it holds the triangles `moved` (scene triangle indices).
/// Throws parameter_error ("moved_triangles") when an index is out of range, or a chart holds
/// both moved and unmoved triangles (a rigid move must carry whole charts: the object's
/// triangles share no chart with the rest of the scene).
inline std::vector<std::uint8_t> moved_charts(const lightmap_atlas& atlas, std::span<const std::uint32_t> moved) {
    std::vector<std::uint8_t> tri(atlas.chart_of_triangle.size(), 0), charts(atlas.charts.size(), 0);
    for (const std::uint32_t t : moved) {
        if (t >= tri.size()) throw parameter_error("moved_triangles", "triangle " + std::to_string(t) + " is not in the scene");
        tri[t] = 1;
        if (atlas.chart_of_triangle[t] != lightmap_atlas::none) charts[atlas.chart_of_triangle[t]] = 1;
    }
    for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
        if (!charts[c]) continue;
        const lightmap_chart& ch = atlas.charts[c];
        for (std::uint32_t k = ch.first_triangle; k < ch.first_triangle + ch.triangle_count; ++k)
            if (tri[atlas.chart_triangles[k]] == 0)
                throw parameter_error("moved_triangles", "chart " + std::to_string(c) +
                                                             " holds moved and unmoved triangles (triangle " +
                                                             std::to_string(atlas.chart_triangles[k]) + " stays): " +
                                                             (ch.cluster() ? "it is a cluster of tiny charts; build the "
                                                                             "atlas with atlas_options::clusters = never"
                                                                           : "move whole objects"));
    }
    return charts;
}

/// Moves the charts marked in `charts` (moved_charts) and their elements by `move`: positions,
/// normals and chart frames; texels, areas, blocks and the layout stay.
inline void move_charts(lightmap_atlas& atlas, const std::vector<std::uint8_t>& charts, const rigid_move& move) {
    for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
        if (!charts[c]) continue;
        lightmap_chart& ch = atlas.charts[c];
        ch.origin = move.point(ch.origin);
        ch.axis_u = move.direction(ch.axis_u), ch.axis_v = move.direction(ch.axis_v), ch.normal = move.direction(ch.normal);
    }
    for (std::size_t i = 0; i < atlas.size(); ++i) {
        if (!charts[atlas.chart[i]]) continue;
        atlas.position[i] = move.point(atlas.position[i]);
        atlas.normal[i] = move.direction(atlas.normal[i]);
    }
}

/// The boxes of the triangles `moved` of `moved_scene` (the scene after the move) where they
/// are and where they were before `move`.
struct moved_boxes {
    world_box before, after;
};
inline moved_boxes boxes_of_move(const scene_view& moved_scene, std::span<const std::uint32_t> moved, const rigid_move& move) {
    moved_boxes b;
    for (const std::uint32_t t : moved) {
        if (t >= moved_scene.triangles.size())
            throw parameter_error("moved_triangles", "triangle " + std::to_string(t) + " is not in the scene");
        for (int k = 0; k < 3; ++k) {
            const glm::vec3 p = moved_scene.positions[moved_scene.triangles[t][k]];
            b.after.add(p);
            b.before.add(move.before(p));
        }
    }
    return b;
}

/// The margin the boxes of a move are widened by in rebake_filter: float rounding of the
/// segment test at the scale of the object and of its move.
inline float rebake_margin(const moved_boxes& boxes, const rigid_move& move) {
    const glm::vec3 extent = glm::max(boxes.before.hi - boxes.before.lo, glm::vec3(0.f));
    return 1e-4f * (glm::length(extent) + glm::length(move.translation)) + 1e-6f;
}

/// Which receivers a shooter's re-shot after a move must reach (besides the moved elements):
/// those whose visibility segment from the shooter's centre meets the object's box before or
/// after the move. Tested by block first (the segment to the block's centre against the boxes
/// widened by the block's radius: no element of a block that misses can have a segment that
/// meets them), then by element. `first`: the shooters' element ranges (blocks), `centre`
/// their centres, as the solvers keep them (before the move).
class rebake_filter {
public:
    rebake_filter(const lightmap_atlas& atlas, std::span<const std::uint32_t> first, std::span<const glm::vec3> centre,
                  const moved_boxes& boxes, float margin)
        : atlas_(atlas), boxes_(boxes), margin_(margin), centre_(centre.begin(), centre.end()),
          radius_(centre.size(), 0.f), block_of_(atlas.size()), near_(centre.size()) {
        for (std::size_t k = 0; k + 1 < first.size(); ++k)
            for (std::uint32_t i = first[k]; i < first[k + 1]; ++i)
                block_of_[i] = std::uint32_t(k), radius_[k] = std::max(radius_[k], glm::length(atlas.position[i] - centre_[k]));
    }
    /// Starts a shooter at `c`: which blocks can hold receivers whose segment meets a box
    /// (blocks [first, last) of them: a caller may split the blocks over threads).
    void begin(const glm::vec3& c) { begin(c, 0, near_.size()); }
    void begin(const glm::vec3& c, std::size_t first, std::size_t last) {
        for (std::size_t k = first; k < last; ++k) near_[k] = meets(c, centre_[k], margin_ + radius_[k] * 1.0001f);
    }
    /// Whether block `block` may hold such receivers (after begin), per block.
    bool near(std::size_t block) const { return near_[block] != 0; }
    const std::vector<std::uint8_t>& near_blocks() const noexcept { return near_; }
    std::size_t blocks() const noexcept { return near_.size(); }
    std::uint32_t block_of(std::uint32_t i) const { return block_of_[i]; }
    /// Whether element i's segment from `c` (the shooter begun) meets either box.
    bool through(const glm::vec3& c, std::uint32_t i) const { return near_[block_of_[i]] && meets(c, atlas_.position[i], margin_); }
    /// Whether the segment from a to b meets either box widened by m.
    bool meets(const glm::vec3& a, const glm::vec3& b, float m) const {
        return segment_meets_box(a, b, boxes_.before, m) || segment_meets_box(a, b, boxes_.after, m);
    }
    const lightmap_atlas& atlas() const noexcept { return atlas_; }
    const moved_boxes& boxes() const noexcept { return boxes_; }
    float margin() const noexcept { return margin_; }

private:
    const lightmap_atlas& atlas_;
    moved_boxes boxes_;
    float margin_;
    std::vector<glm::vec3> centre_;  // per block: its elements' bounding sphere
    std::vector<float> radius_;
    std::vector<std::uint32_t> block_of_;  // per element
    std::vector<std::uint8_t> near_;       // per block, for the shooter begun
};

/// The block-sides (side-major: k = side * blocks + block) a re-bake re-shoots: those whose
/// shot radiosity `shot` (per element-side, side-major) holds power, the largest first until
/// they hold `share` of it (all with share 1). Writes the share left out to `uncorrected`.
template <class V>
std::vector<std::uint8_t> chosen_rebake_shooters(const lightmap_atlas& atlas, std::span<const std::uint32_t> first,
                                                 std::span<const V> shot, std::size_t sides, double share, double& uncorrected) {
    const std::size_t blocks = first.size() - 1, n = atlas.size();
    std::vector<double> magnitude(sides * blocks, 0.0);
    for (std::size_t k = 0; k < magnitude.size(); ++k)
        for (std::uint32_t i = first[k % blocks]; i < first[k % blocks + 1]; ++i) {
            const V& s = shot[(k / blocks) * n + i];
            magnitude[k] += (double(std::abs(s.x)) + double(std::abs(s.y)) + double(std::abs(s.z))) * double(atlas.area[i]);
        }
    std::vector<std::uint32_t> order(magnitude.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return magnitude[a] > magnitude[b]; });
    const double total = std::accumulate(magnitude.begin(), magnitude.end(), 0.0);
    std::vector<std::uint8_t> chosen(magnitude.size(), 0);
    double taken = 0, left = 0;
    for (const std::uint32_t k : order) {
        if (!(magnitude[k] > 0)) break;
        if (share < 1 && taken >= share * total) left += magnitude[k];
        else chosen[k] = 1, taken += magnitude[k];
    }
    uncorrected = total > 0 ? left / total : 0.0;
    return chosen;
}

/// What a re-bake did (cpu::rebake_light, cpu::rebake_move, gl::progressive_radiosity::rebake_*); the solve that follows is the
/// caller's (solve(radiosity_solve_options) again).
struct radiosity_rebake_report {
    double ms = 0;                  ///< wall-clock time of the correction (2), lights included
    std::size_t moved_elements = 0; ///< elements of the moved charts (0 for a light)
    std::size_t shooters = 0;       ///< block-sides that had shot and re-shot their S, both passes counted
    std::size_t moved_shooters = 0; ///< of them the moved object's (to every other element, old geometry only)
    std::size_t moved_pairs = 0;    ///< pairs the moved object's shooters re-evaluated
    std::size_t pairs = 0;          ///< receiver-shooter pairs re-evaluated, both passes counted
    std::size_t pairs_tested = 0;   ///< receiver-shooter pairs tested against the boxes
    std::size_t object_tests = 0;   ///< of them, pairs tested against the moved object alone (rebake_move with an object)
    double moved_ms = 0;            ///< of ms: the moved object's shooters' old pass
    double unmoved_ms = 0;          ///< the other shooters' two passes (the object tests included)
    double lights_ms = 0;           ///< the lights' direct deposit re-evaluated, and the state corrected
    double unshot_before = 0;       ///< |unshot| power / emitted power before the correction
    double unshot_after = 0;        ///< the same after it (may exceed 1: a dimmed light)
    double uncorrected = 0;         ///< of the shot power, the share whose re-shots were left out (rebake_move's share)
};

}  // namespace bounce::radiosity
