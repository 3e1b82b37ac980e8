#pragma once
/// \file radiosity_rebake.hpp
/// Re-baking what changed with cpu::progressive_radiosity (issue 30): after a light changes
/// (rebake_light) or one object moves rigidly (rebake_move), the solver's state is corrected
/// as radiosity/rebake.hpp derives, its equation (2): B and the unshot radiosity dB change by
/// the same amount, so what every element has shot (S = B - dB) is kept, and the unshot power
/// may turn negative where light is taken away. Then solve(radiosity_solve_options) again:
/// it shoots by |unshot power| and converges to the changed scene's solution, what a fresh
/// solve converges to. The atlas is reused (a rigid move keeps the charts' texels).
///
///   cpu::progressive_radiosity solver(scene, atlas, embree::radiosity_visibility(bvh, atlas.chart_of_triangle));
///   solver.solve(o);                                         // the bake
///   // ... the object's vertices moved in `moved` (a copy of the scene), its BVH built:
///   cpu::rebake_move(solver, moved, object_triangles, move,
///                    embree::radiosity_visibility(moved_bvh, solver.atlas().chart_of_triangle));
///   solver.solve(o);                                         // the re-bake
///
/// The cost of a move's correction: every block-side that has shot re-shoots its S (what its
/// shots delivered from, their scales applied) twice, old and new geometry, each time only to
/// the receivers whose delivery can differ: those whose visibility ray from the shooter's
/// centre meets the object's box before or after the move, and, with the new geometry, the
/// moved object's elements (what they received before is their gathered irradiance, taken
/// away as it is); a moved block re-shoots to every other element with the old geometry only:
/// what it shot returns to its unshot radiosity, for the solve. Then one shot per light. With the item buffers, each of
/// those shots draws its item buffer whole. rebake_move's `share` < 1 re-shoots only the
/// largest block-sides holding that share of the shot power.

#include <bounce/cpu/radiosity.hpp>
#include <bounce/radiosity/rebake.hpp>

#include <atomic>
#include <chrono>
#include <numeric>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bounce::cpu {

/// The re-bakes' access to the solver's state (a friend of progressive_radiosity).
template <class Solver>
struct rebake_access {
    using vec = typename Solver::vec;

    // One pass of a move's correction: every block-side whose S (the solver's effective_shot_:
    // what its shots delivered from, each shot's scale applied) holds power shoots it, as the
    // solver's shot does but unscaled, to the receivers keep(shooter centre, element, moved
    // shooter) asks for, and `sign` times what it delivers is added to `delta` (incident
    // radiosity per element and side). The deliveries are linear in S, so the old pass takes
    // away exactly what the past shots delivered to those receivers.
    static rebake_filter filter_of(const Solver& s, const moved_boxes& boxes, float margin) {
        return rebake_filter(s.atlas_, s.first_, s.centre_, boxes, margin);
    }

    template <class Keep>
    static void reshoot(Solver& s, const std::vector<vec>& S, const std::vector<std::uint8_t>& chosen,
                        const std::vector<std::uint8_t>& moved_block, rebake_filter& filter, const Keep& keep, double sign,
                        std::vector<glm::dvec3>& delta, radiosity_rebake_report& r) {
        const lightmap_atlas& at = s.atlas_;
        const std::size_t blocks = s.first_.size() - 1, n = at.size();
        std::atomic<std::size_t> pairs{0};
        for (std::size_t k = 0; k < s.sides_ * blocks; ++k) {
            if (!chosen[k]) continue;
            const std::size_t b = k % blocks, side = k / blocks;
            const std::uint32_t i0 = s.first_[b];
            const vec* from = S.data() + side * n;
            ++r.shooters;
            const std::size_t pairs_before = pairs.load();
            s.build_near_tree(std::uint32_t(b), from);
            const glm::vec3 normal = side == 0 ? at.normal[i0] : -at.normal[i0], centre = s.centre_[b];
            s.visibility_.begin_shot(shot_frame{centre, normal, false, at.chart[i0]});
            const bool whole = moved_block[b] != 0;
            if (!whole) filter.begin(centre);
            s.gather_shot(at.chart[i0], vec(normal), [&](std::uint32_t i) {
                if (!keep(centre, i, whole)) return false;
                pairs.fetch_add(1, std::memory_order_relaxed);
                return true;
            });
            if (!whole) r.pairs_tested += n;
            else ++r.moved_shooters, r.moved_pairs += pairs.load() - pairs_before;
            // Only the blocks asked for hold deliveries (a moved shooter's: every block).
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.sides_ * blocks, 64), [&](const tbb::blocked_range<std::size_t>& q) {
                for (std::size_t kb = q.begin(); kb != q.end(); ++kb) {
                    const std::size_t bb = kb % blocks, o = (kb / blocks) * n;
                    if (!whole && !filter.near(bb) && !moved_block[bb]) continue;
                    for (std::uint32_t i = s.first_[bb]; i < s.first_[bb + 1]; ++i)
                        if (s.received_[o + i] != vec(0)) delta[o + i] += sign * glm::dvec3(s.received_[o + i]);
                }
            });
        }
        r.pairs += pairs.load();
    }

    // The lights' direct irradiance at every element again, from the solver's lights, atlas
    // and visibility as they are now; returns what it was.
    static std::vector<vec> regather_direct(Solver& s) {
        const auto start = Solver::clock::now();
        std::vector<vec> old = s.direct_;
        s.direct_.assign(old.size(), vec(0));
        for (const packed_light& l : s.lights_) s.shoot_light(l, true);
        s.timings_.lights_ms += Solver::ms_since(start);
        return old;
    }

    // Equation (2): B and dB raised by rho (delta + the change of the direct irradiance), the
    // irradiance the shots delivered by delta; the balance's sums kept (emitted: the direct
    // light's change; the deliveries' change moves power between intercepted and escaped).
    static void apply(Solver& s, const std::vector<glm::dvec3>& delta, const std::vector<vec>& old_direct) {
        const lightmap_atlas& at = s.atlas_;
        const std::size_t n = at.size();
        glm::dvec3 added(0), corrected(0), absorbed(0);
        for (std::size_t j = 0; j < s.direct_.size(); ++j) {
            const glm::dvec3 d = delta.empty() ? glm::dvec3(0) : delta[j];
            const glm::dvec3 e = glm::dvec3(s.direct_[j]) - glm::dvec3(old_direct[j]);
            if (d == glm::dvec3(0) && e == glm::dvec3(0)) continue;
            const glm::dvec3 rho(at.albedo[j % n]);
            const double area = double(at.area[j % n]);
            const vec gain = vec(rho * (d + e));
            s.radiosity_[j] += gain;
            s.unshot_[j] += gain;
            s.gathered_[j] += vec(d);
            added += e * area;
            corrected += d * area;
            absorbed += (glm::dvec3(1.0) - rho) * (d + e) * area;
        }
        s.emitted_ += added;
        s.intercepted_ += added + corrected;
        s.escaped_ -= corrected;
        s.absorbed_ += absorbed;
        s.refresh_powers();
    }

    // The shot radiosity of the moved block-sides `chosen` handed back to the solve as unshot
    // radiosity: their deliveries with the old geometry were taken away and none made with the
    // new, so they have shot nothing (S = 0, dB = B); the power, counted as escaped when taken
    // away, is unshot.
    static void unshoot(Solver& s, const std::vector<std::uint8_t>& chosen, const std::vector<std::uint8_t>& moved_block) {
        const std::size_t n = s.atlas_.size(), blocks = s.first_.size() - 1;
        glm::dvec3 returned(0);
        for (std::size_t k = 0; k < chosen.size(); ++k) {
            if (!chosen[k] || !moved_block[k % blocks]) continue;
            for (std::size_t j = (k / blocks) * n + s.first_[k % blocks]; j < (k / blocks) * n + s.first_[k % blocks + 1]; ++j) {
                returned += glm::dvec3(s.radiosity_[j] - s.unshot_[j]) * double(s.atlas_.area[j % n]);
                s.unshot_[j] = s.radiosity_[j], s.effective_shot_[j] = vec(0);
            }
        }
        s.escaped_ -= returned;
        s.shot_power_ -= returned.x + returned.y + returned.z;
        s.refresh_powers();
    }

    static radiosity_rebake_report change_light(Solver& s, std::size_t index, const bounce::light& changed) {
        if (index >= s.lights_.size())
            throw parameter_error("index", "is light " + std::to_string(index) + " of the scene's " +
                                               std::to_string(s.lights_.size()) + " (point, spot, directional)");
        validate_lights(std::span<const bounce::light>(&changed, 1), "changed");
        const auto start = Solver::clock::now();
        radiosity_rebake_report r;
        r.unshot_before = s.unshot_fraction();
        s.lights_[index] = pack(changed);
        apply(s, {}, regather_direct(s));
        r.unshot_after = s.unshot_fraction();
        r.ms = Solver::ms_since(start);
        return r;
    }

    template <class Visibility>
    static radiosity_rebake_report move_object(Solver& s, const scene_view& moved_scene, std::span<const std::uint32_t> moved,
                                        const rigid_move& m, Visibility&& visibility, double share) {
        require(share > 0 && share <= 1, "share", "must lie in (0, 1]");
        m.validate();
        moved_scene.validate();
        require(moved_scene.triangles.size() == s.atlas_.chart_of_triangle.size(), "moved_scene",
                "is not the solver's scene moved (triangle counts differ)");
        const auto start = Solver::clock::now();
        radiosity_rebake_report r;
        r.unshot_before = s.unshot_fraction();
        const std::vector<std::uint8_t> charts = moved_charts(s.atlas_, moved);
        const moved_boxes boxes = boxes_of_move(moved_scene, moved, m);
        const float margin = rebake_margin(boxes, m);
        const lightmap_atlas& at = s.atlas_;
        const std::size_t n = at.size(), blocks = s.first_.size() - 1;
        std::vector<std::uint8_t> moved_element(n), moved_block(blocks);
        for (std::size_t i = 0; i < n; ++i) moved_element[i] = charts[at.chart[i]], r.moved_elements += charts[at.chart[i]];
        for (std::size_t b = 0; b < blocks; ++b) moved_block[b] = charts[at.chart[s.first_[b]]];
        // A pair's delivery can change only with a moved end or a ray through either box.
        rebake_filter filter = filter_of(s, boxes, margin);
        const auto through = [&](const glm::vec3& c, std::uint32_t i) { return filter.through(c, i); };
        const std::vector<vec>& S = s.effective_shot_;
        // What the moved elements received is known: the irradiance the shots delivered
        // (gathered_), taken away as it is. The old pass leaves them out; a moved shooter's
        // old pass reaches every other element.
        std::vector<glm::dvec3> delta(S.size(), glm::dvec3(0));
        for (std::size_t j = 0; j < delta.size(); ++j)
            if (moved_element[j % n]) delta[j] = -glm::dvec3(s.gathered_[j]);
        const std::vector<std::uint8_t> chosen =
            chosen_rebake_shooters<vec>(at, s.first_, std::span<const vec>(S), s.sides_, share, r.uncorrected);
        reshoot(s, S, chosen, moved_block, filter,
                [&](const glm::vec3& c, std::uint32_t i, bool whole) { return !moved_element[i] && (whole || through(c, i)); }, -1.0,
                delta, r);  // the old geometry and visibility
        move_charts(s.atlas_, charts, m);
        s.visibility_ = std::forward<Visibility>(visibility);
        s.build_shooters();  // the moved blocks' centres, the groups' boxes
        // The moved object's own S is not re-shot with the new geometry: it goes back to the
        // solve as unshot radiosity (unshoot), which shoots it with the rest of its dB, the
        // largest first (0.62 of a fresh solve's pairs on the Cornell box against 0.76 re-shot).
        std::vector<std::uint8_t> unmoved = chosen;
        for (std::size_t k = 0; k < unmoved.size(); ++k) unmoved[k] = chosen[k] && !moved_block[k % blocks];
        reshoot(s, S, unmoved, moved_block, filter,
                [&](const glm::vec3& c, std::uint32_t i, bool) { return moved_element[i] || through(c, i); }, 1.0, delta,
                r);  // the new
        apply(s, delta, regather_direct(s));
        unshoot(s, chosen, moved_block);
        r.unshot_after = s.unshot_fraction();
        r.ms = Solver::ms_since(start);
        return r;
    }
};

/// Light `index` of the solver's scene (its point, spot and directional lights, in the
/// scene's order) becomes `changed` (any kind, anywhere): the change of every element's direct
/// irradiance, times its albedo, is added to its radiosity and unshot radiosity (negative
/// where the light dimmed). Then solve() again. Throws parameter_error ("index", "changed").
template <shot_visibility Visibility, floating Real>
radiosity_rebake_report rebake_light(progressive_radiosity<Visibility, Real>& solver, std::size_t index, const light& changed) {
    return rebake_access<progressive_radiosity<Visibility, Real>>::change_light(solver, index, changed);
}

/// The triangles `moved` of the solver's scene moved by `move`: `moved_scene` is the scene
/// after the move (the same triangles, those vertices moved) and `visibility` the visibility
/// of it (built with the solver's atlas's chart_of_triangle), which the solver keeps. The
/// state is corrected as radiosity/rebake.hpp derives; then solve() again. Throws
/// `share` < 1 re-shoots only the block-sides that hold that share of the shot power, the
/// largest first: cheaper, and no longer exact (what the rest would correct is left out; the
/// report's `uncorrected`). Throws parameter_error ("moved_triangles": out of range, or
/// sharing a chart with unmoved triangles; "moved_scene"; "rigid_move.*"; "share").
template <shot_visibility Visibility, floating Real>
radiosity_rebake_report rebake_move(progressive_radiosity<Visibility, Real>& solver, const scene_view& moved_scene,
                                    std::span<const std::uint32_t> moved, const rigid_move& move, Visibility visibility,
                                    double share = 1.0) {
    static_assert(std::is_move_assignable_v<Visibility>, "the solver takes the moved scene's visibility in place of its own");
    return rebake_access<progressive_radiosity<Visibility, Real>>::move_object(solver, moved_scene, moved, move, std::move(visibility),
                                                                              share);
}

}  // namespace bounce::cpu
