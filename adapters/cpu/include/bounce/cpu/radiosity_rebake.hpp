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
///                    embree::radiosity_visibility(moved_bvh, solver.atlas().chart_of_triangle),
///                    embree::object_visibility(scene, old_visibility, moved, new_visibility, object_triangles,
///                                              solver.atlas().chart_of_triangle));  // optional
///   solver.solve(o);                                         // the re-bake
///
/// The cost of a move's correction: every block-side that has shot re-shoots its S (what its
/// shots delivered from, their scales applied) only to the receivers whose delivery can
/// differ: a moved block to every other element with the old geometry only (what it shot
/// returns to its unshot radiosity, for the solve); every other block to the moved object's
/// elements with the new geometry (what they received before is their gathered irradiance,
/// taken away as it is), and to the receivers whose visibility ray from its centre meets the
/// object's box before or after the move, old and new. Given the object alone (its triangles
/// before and after, cast as the solver's rays), those rays are tested against it first and
/// only the pairs it blocks in one place are re-shot, in the one pass that delivers (exact:
/// the rest deliver the same both times). Then one shot per light. With the item buffers,
/// each of those shots draws its item buffer whole. rebake_move's `share` < 1 re-shoots only
/// the largest block-sides holding that share of the shot power.

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
    // rebake_filter::begin over the blocks, split over threads.
    static void begin_filter(rebake_filter& filter, const glm::vec3& c) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, filter.blocks(), 256),
                          [&](const tbb::blocked_range<std::size_t>& q) { filter.begin(c, q.begin(), q.end()); });
    }

    // One block-side k re-shoots its S (side `k / blocks`), as the solver's shot does but
    // unscaled, to the receivers keep(i) asks for (their count added to `pairs`), and `sign`
    // times what it delivers is added to `delta` (incident radiosity per element and side), in
    // the blocks near[] marks and the moved ones (all when `every`). The deliveries are linear
    // in S, so an old pass takes away exactly what the past shots delivered to those receivers.
    template <class Keep>
    static void reshoot_one(Solver& s, const std::vector<vec>& S, std::size_t k, const std::vector<std::uint8_t>& near,
                            const std::vector<std::uint8_t>& moved_block, bool every, const Keep& keep, double sign,
                            std::vector<glm::dvec3>& delta, std::atomic<std::size_t>& pairs) {
        const lightmap_atlas& at = s.atlas_;
        const std::size_t blocks = s.first_.size() - 1, n = at.size(), b = k % blocks;
        const std::uint32_t i0 = s.first_[b];
        const vec normal = vec(k / blocks == 0 ? at.normal[i0] : -at.normal[i0]);
        s.build_near_tree(std::uint32_t(b), S.data() + (k / blocks) * n);
        s.visibility_.begin_shot(shot_frame{s.centre_[b], glm::vec3(normal), false, at.chart[i0]});
        s.gather_shot(at.chart[i0], normal, [&](std::uint32_t i) {
            if (!keep(i)) return false;
            pairs.fetch_add(1, std::memory_order_relaxed);
            return true;
        });
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.sides_ * blocks, 64), [&](const tbb::blocked_range<std::size_t>& q) {
            for (std::size_t kb = q.begin(); kb != q.end(); ++kb) {
                const std::size_t bb = kb % blocks, o = (kb / blocks) * n;
                if (!every && !near[bb] && !moved_block[bb]) continue;
                for (std::uint32_t i = s.first_[bb]; i < s.first_[bb + 1]; ++i)
                    if (s.received_[o + i] != vec(0)) delta[o + i] += sign * glm::dvec3(s.received_[o + i]);
            }
        });
    }

    // Which passes each unmoved element of the blocks near[] marks needs from shooter centre
    // `c` (need: bit 0 the old, bit 1 the new). Without an object visibility, both where the
    // ray meets a box (rebake_filter). With one (the object alone before and after: the solver's
    // rays through its triangles only), a pair whose ray the object blocks in both places or in
    // neither has the same form factor and visibility both times: none; blocked only after,
    // its old delivery goes (the new is 0); blocked only before, its new delivery comes. A ray
    // that misses a place's box (widened by the margin) is not blocked there, untested; the
    // others are tested in packets where the visibility has them. Visibilities between 0 and 1
    // take both passes.
    struct no_object {
        static constexpr bool tests = false;
        void begin(const shot_frame&) {}
        void classify(const Solver& s, const rebake_filter& filter, const glm::vec3& c, const std::vector<std::uint8_t>& moved_element,
                      std::vector<std::uint8_t>& need) {
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, filter.blocks(), 16), [&](const tbb::blocked_range<std::size_t>& q) {
                for (std::size_t b = q.begin(); b != q.end(); ++b)
                    for (std::uint32_t i = s.first_[b]; filter.near(b) && i < s.first_[b + 1]; ++i)
                        need[i] = !moved_element[i] && filter.meets(c, filter.atlas().position[i], filter.margin()) ? 3 : 0;
            });
        }
    };
    template <class Object>
    struct object_test {
        static constexpr bool tests = true;
        Object& object;
        std::atomic<std::size_t>& count;
        std::vector<glm::vec3> point[2]{};  // per place, the elements whose ray meets its box
        std::vector<std::uint32_t> chart[2]{};
        std::vector<float> seen[2]{};
        void begin(const shot_frame& f) { object.before.begin_shot(f), object.after.begin_shot(f); }
        template <class V>
        static void visible_all(const V& v, const std::vector<glm::vec3>& p, const std::vector<std::uint32_t>& c, std::vector<float>& out) {
            out.resize(p.size());
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, p.size(), 256), [&](const tbb::blocked_range<std::size_t>& q) {
                if constexpr (requires { v.visible(std::span<const glm::vec3>(p), std::span<const std::uint32_t>(c), std::span<float>(out)); })
                    v.visible(std::span<const glm::vec3>(p).subspan(q.begin(), q.size()),
                              std::span<const std::uint32_t>(c).subspan(q.begin(), q.size()), std::span<float>(out).subspan(q.begin(), q.size()));
                else
                    for (std::size_t k = q.begin(); k != q.end(); ++k) out[k] = float(v.visible(p[k], c[k]));
            });
        }
        void classify(const Solver& s, const rebake_filter& filter, const glm::vec3& c, const std::vector<std::uint8_t>& moved_element,
                      std::vector<std::uint8_t>& need) {
            const lightmap_atlas& at = filter.atlas();
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, filter.blocks(), 16), [&](const tbb::blocked_range<std::size_t>& q) {
                for (std::size_t b = q.begin(); b != q.end(); ++b)
                    for (std::uint32_t i = s.first_[b]; filter.near(b) && i < s.first_[b + 1]; ++i)
                        need[i] = moved_element[i] ? 0
                                                   : std::uint8_t(segment_meets_box(c, at.position[i], filter.boxes().before, filter.margin())) |
                                                         std::uint8_t(segment_meets_box(c, at.position[i], filter.boxes().after, filter.margin()) << 1);
            });
            for (int place = 0; place < 2; ++place) point[place].clear(), chart[place].clear();
            for (std::size_t b = 0; b < filter.blocks(); ++b)
                for (std::uint32_t i = s.first_[b]; filter.near(b) && i < s.first_[b + 1]; ++i)
                    for (int place = 0; place < 2; ++place)
                        if (need[i] & (1 << place)) point[place].push_back(at.position[i]), chart[place].push_back(at.chart[i]);
            visible_all(object.before, point[0], chart[0], seen[0]);
            visible_all(object.after, point[1], chart[1], seen[1]);
            std::size_t k[2] = {0, 0};
            for (std::size_t b = 0; b < filter.blocks(); ++b)
                for (std::uint32_t i = s.first_[b]; filter.near(b) && i < s.first_[b + 1]; ++i) {
                    if (need[i] == 0) continue;
                    count.fetch_add(1, std::memory_order_relaxed);
                    const float was = need[i] & 1 ? seen[0][k[0]++] : 1.f, is = need[i] & 2 ? seen[1][k[1]++] : 1.f;
                    need[i] = was == is && (was == 0.f || was == 1.f) ? 0 : was == 1.f && is == 0.f ? 1 : was == 0.f && is == 1.f ? 2 : 3;
                }
        }
    };

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

    // The unmoved block-sides `chosen` re-shoot their S twice, with the old visibility (in the
    // solver) and with the new (`other`), both on the moved atlas: an unmoved shooter's old
    // pass leaves the moved elements out (their old deliveries are their gathered_), so its
    // receivers and near-field tree are the same in both. Per element the passes it needs
    // (test.passes) are found in the old pass and kept for the new one.
    template <class Visibility, class Test>
    static void reshoot_unmoved(Solver& s, const std::vector<vec>& S, const std::vector<std::uint8_t>& chosen,
                                const std::vector<std::uint8_t>& moved_element, const std::vector<std::uint8_t>& moved_block,
                                rebake_filter& filter, Visibility& other, Test& test, std::vector<glm::dvec3>& delta,
                                radiosity_rebake_report& r) {
        const lightmap_atlas& at = s.atlas_;
        const std::size_t blocks = s.first_.size() - 1, n = at.size();
        std::vector<std::uint8_t> need(n, 0);
        std::atomic<std::size_t> pairs{0};
        for (std::size_t k = 0; k < chosen.size(); ++k) {
            const std::size_t b = k % blocks;
            if (!chosen[k] || moved_block[b]) continue;
            const std::uint32_t i0 = s.first_[b];
            const glm::vec3 centre = s.centre_[b];
            begin_filter(filter, centre);
            test.begin(shot_frame{centre, k / blocks == 0 ? at.normal[i0] : -at.normal[i0], false, at.chart[i0]});
            test.classify(s, filter, centre, moved_element, need);
            const auto old_pass = [&](std::uint32_t i) { return filter.near(filter.block_of(i)) && (need[i] & 1) != 0; };
            bool any = false;  // an old pass with no receiver is skipped (its walk of every element)
            for (std::size_t bb = 0; bb < blocks && !any; ++bb)
                for (std::uint32_t i = s.first_[bb]; filter.near(bb) && i < s.first_[bb + 1] && !any; ++i) any = (need[i] & 1) != 0;
            if (any) reshoot_one(s, S, k, filter.near_blocks(), moved_block, false, old_pass, -1.0, delta, pairs);
            std::swap(s.visibility_, other);
            const auto new_pass = [&](std::uint32_t i) { return moved_element[i] || (filter.near(filter.block_of(i)) && (need[i] & 2) != 0); };
            reshoot_one(s, S, k, filter.near_blocks(), moved_block, false, new_pass, 1.0, delta, pairs);
            std::swap(s.visibility_, other);
            r.shooters += any ? 2 : 1, r.pairs_tested += 2 * n;
        }
        r.pairs += pairs.load();
    }

    template <class Visibility, class Test>
    static radiosity_rebake_report move_object(Solver& s, const scene_view& moved_scene, std::span<const std::uint32_t> moved,
                                               const rigid_move& m, Visibility&& visibility, Test& test, double share) {
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
        const std::vector<vec>& S = s.effective_shot_;
        // What the moved elements received is known: the irradiance the shots delivered
        // (gathered_), taken away as it is. The old pass leaves them out; a moved shooter's
        // old pass reaches every other element.
        std::vector<glm::dvec3> delta(S.size(), glm::dvec3(0));
        for (std::size_t j = 0; j < delta.size(); ++j)
            if (moved_element[j % n]) delta[j] = -glm::dvec3(s.gathered_[j]);
        const std::vector<std::uint8_t> chosen =
            chosen_rebake_shooters<vec>(at, s.first_, std::span<const vec>(S), s.sides_, share, r.uncorrected);
        // The moved object's own S is re-shot with the old geometry only: it goes back to the
        // solve as unshot radiosity (unshoot), which shoots it with the rest of its dB, the
        // largest first (0.62 of a fresh solve's pairs on the Cornell box against 0.76 re-shot).
        std::atomic<std::size_t> moved_pairs{0};
        for (std::size_t k = 0; k < chosen.size(); ++k)
            if (chosen[k] && moved_block[k % blocks])
                reshoot_one(s, S, k, filter.near_blocks(), moved_block, true, [&](std::uint32_t i) { return !moved_element[i]; }, -1.0, delta,
                            moved_pairs),
                    ++r.shooters, ++r.moved_shooters;
        r.moved_pairs = moved_pairs.load(), r.pairs = r.moved_pairs;
        r.moved_ms = Solver::ms_since(start);
        move_charts(s.atlas_, charts, m);
        Visibility other = std::forward<Visibility>(visibility);
        s.build_shooters();  // the moved blocks' centres, the groups' boxes
        auto stage = Solver::clock::now();
        reshoot_unmoved(s, S, chosen, moved_element, moved_block, filter, other, test, delta, r);
        r.unmoved_ms = Solver::ms_since(stage);
        s.visibility_ = std::move(other);
        stage = Solver::clock::now();
        apply(s, delta, regather_direct(s));
        r.lights_ms = Solver::ms_since(stage);
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
/// state is corrected as radiosity/rebake.hpp derives; then solve() again.
/// `share` < 1 re-shoots only the block-sides that hold that share of the shot power, the
/// largest first: cheaper, and no longer exact (what the rest would correct is left out; the
/// report's `uncorrected`). Throws parameter_error ("moved_triangles": out of range, or
/// sharing a chart with unmoved triangles; "moved_scene"; "rigid_move.*"; "share").
template <shot_visibility Visibility, floating Real>
radiosity_rebake_report rebake_move(progressive_radiosity<Visibility, Real>& solver, const scene_view& moved_scene,
                                    std::span<const std::uint32_t> moved, const rigid_move& move, Visibility visibility,
                                    double share = 1.0) {
    static_assert(std::is_move_assignable_v<Visibility>, "the solver takes the moved scene's visibility in place of its own");
    using access = rebake_access<progressive_radiosity<Visibility, Real>>;
    typename access::no_object test;
    return access::move_object(solver, moved_scene, moved, move, std::move(visibility), test, share);
}

/// The moved object alone before and after the move (members `before` and `after`, each a
/// shot_visibility): the solver's rays, the same origins, ends and offsets, through the
/// object's triangles only (embree::object_visibility; for the tests, the brute-force caster
/// with the other triangles left without a chart), answering 0 or 1.
template <class O>
concept moved_object_visibility = shot_visibility<decltype(O::before)> && shot_visibility<decltype(O::after)>;

/// rebake_move, its unmoved pairs tested against the moved object alone (`object`): a pair
/// whose ray the object blocks in both places or in neither delivers the same before and
/// after and is skipped; a pair blocked in one place only is re-shot in the one pass that
/// delivers (the old when blocked after, the new when blocked before). Exact when `object`
/// answers as the whole scene's rays do triangle by triangle; the report's object_tests
/// counts its pairs (each tested in both places).
template <shot_visibility Visibility, floating Real, moved_object_visibility Object>
radiosity_rebake_report rebake_move(progressive_radiosity<Visibility, Real>& solver, const scene_view& moved_scene,
                                    std::span<const std::uint32_t> moved, const rigid_move& move, Visibility visibility,
                                    Object object, double share = 1.0) {
    static_assert(std::is_move_assignable_v<Visibility>, "the solver takes the moved scene's visibility in place of its own");
    using access = rebake_access<progressive_radiosity<Visibility, Real>>;
    std::atomic<std::size_t> tests{0};
    typename access::template object_test<Object> test{object, tests};
    radiosity_rebake_report r = access::move_object(solver, moved_scene, moved, move, std::move(visibility), test, share);
    r.object_tests = tests.load();
    return r;
}

}  // namespace bounce::cpu
