#pragma once
/// \file radiosity/solve.hpp
/// A progressive radiosity solve to a target, as a renderer, a baker or a study runs it, the
/// same on every backend: cpu::progressive_radiosity::solve(radiosity_solve_options) and
/// gl::progressive_radiosity::solve(radiosity_solve_options) both drive their step() through
/// run_radiosity_solve below.
///  - Stops at a converged fraction of the emitted power, or after a time limit, or when a
///    callback says so, or when nothing is left to shoot; says which (radiosity_stop).
///  - Calls `progress` after every step (a progress line) and `checkpoint` at points of a
///    convergence curve (k / checkpoints of the target, after the first step and at the end);
///    the solve's clock is paused while `checkpoint` runs, so a caller may render a view and
///    measure its error there without the measurement counting as solving.
///  - Checks what a solve must never do silently: the unshot power may not exceed the emitted
///    power nor become non-finite (energy created: the disc form factor summing above 1 next
///    to tiny elements, issue 30), and a scene whose emitted power all escapes without
///    reaching the front side of any surface (one-sided surfaces facing away from the
///    emitters: reversed winding) is an error, not a black lightmap. Both throw
///    radiosity_error with the step and the figures.
/// check_lights_reach_surfaces does the same for point, spot and directional lights, in the
/// solvers' constructors; check_lights_face_surfaces is its cheap form for before any work.

#include <bounce/errors.hpp>
#include <bounce/light.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/direct_light.hpp>
#include <bounce/image.hpp>
#include <bounce/output.hpp>
#include <bounce/radiosity/options.hpp>
#include <bounce/scene_view.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <functional>
#include <string>
#include <span>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline radiosity {

/// A solve that went wrong in a way a caller must hear about: energy created, or no light
/// reaching any surface (the message names the cause and the figures).
struct radiosity_error : error {
    using error::error;
};

/// Why a solve stopped.
enum class radiosity_stop {
    converged,   ///< the unshot fraction reached 1 - converge
    exhausted,   ///< nothing was left to shoot
    time_limit,  ///< max_seconds of solving passed
    callback     ///< `progress` returned false
};

/// The name of `s` ("converged", "exhausted", "time_limit", "callback") for reports.
inline const char* to_string(radiosity_stop s) noexcept {
    switch (s) {
        case radiosity_stop::converged: return "converged";
        case radiosity_stop::exhausted: return "exhausted";
        case radiosity_stop::time_limit: return "time_limit";
        case radiosity_stop::callback: return "callback";
    }
    return "?";
}

/// What `converge` is a fraction of (radiosity/options.hpp).
enum class radiosity_measure {
    emitted,   ///< the emitted power (lights' direct light included): unshot_fraction
    indirect   ///< the power surfaces reflect, bounces to come included: indirect_unshot_fraction
};

/// How far a solve goes and what it reports on the way.
struct radiosity_solve_options {
    double converge = 0.9;      ///< stop once this fraction of the `measure` has been shot
                                ///< (its unshot fraction <= 1 - converge), in [0, 1]
    radiosity_measure measure = radiosity_measure::emitted;
    double max_seconds = 0;     ///< also stop after this many seconds of solving (checkpoints
                                ///< excluded), checked before each step; 0: no limit
    int checkpoints = 0;        ///< `checkpoint` after the first step, each time the converged
                                ///< fraction passes k / checkpoints * converge (k = 1 ..
                                ///< checkpoints) and at the end; 0: never (typical: 8-32)
    /// After every step, with the solve's time so far (elapsed_ms); false stops the solve.
    std::function<bool(const radiosity_progress&)> progress;
    /// At the checkpoints, with the solve's time so far; the clock is paused while it runs.
    std::function<void(const radiosity_progress&)> checkpoint;

    /// Throws parameter_error naming the option ("radiosity_solve_options.converge" ...).
    void validate() const {
        require(converge >= 0 && converge <= 1, "radiosity_solve_options.converge", "must lie in [0, 1]");
        require(max_seconds >= 0 && std::isfinite(max_seconds), "radiosity_solve_options.max_seconds",
                "must be finite and non-negative");
        require(checkpoints >= 0 && checkpoints <= 100000, "radiosity_solve_options.checkpoints",
                "must lie in [0, 100000]");
    }
};

/// What a solve did.
struct radiosity_solve_report {
    radiosity_stop stop = radiosity_stop::converged;
    std::size_t steps = 0;         ///< steps taken by this solve
    std::size_t splits = 0;        ///< leaves split by adaptive subdivision during it (CPU)
    double solve_ms = 0;           ///< wall-clock time of the solve less the checkpoints'
    double checkpoint_ms = 0;      ///< time spent in `checkpoint` (not in solve_ms)
    std::vector<double> converged; ///< 1 - the measure's unshot fraction after each step
    std::vector<double> step_ms;   ///< solve time (checkpoints excluded) at the end of each step
    double unshot_fraction = 1;    ///< at the end: unshot / emitted power
    double indirect_unshot_fraction = 1;  ///< at the end: indirect_unshot_fraction
};

}  // namespace bounce::radiosity

namespace bounce::detail {

inline double channel_total(const glm::dvec3& v) { return v.x + v.y + v.z; }

/// The solve loop of every backend. `Solver` has step(), unshot_fraction(), progress(),
/// emitted_power(), unshot_power() and intercepted_power(); `after_step(step_index)` runs after each step inside the
/// solve's clock and returns the leaves it split (adaptive subdivision; 0 otherwise).
/// The unshot and the emitted power of a solver, channels summed (W).
struct energy_sums {
    double unshot = 0, emitted = 0;
};
template <class Solver>
energy_sums energy_of(const Solver& solver) {
    const double emitted = channel_total(solver.emitted_power());
    return {solver.unshot_fraction() * emitted, emitted};
}

/// Throws radiosity_error when a step raised the unshot power by more than the power the
/// lights added (adaptive subdivision re-gathers them), beyond float rounding: each element's
/// unshot radiosity is a float (2^-24 relative), so the sum may drift by 2^-20 of what it held
/// and was added. A shot hands out at most its power (shot_scale) times albedos at most 1,
/// so the unshot power can only fall; a rise, or a non-finite sum, means energy was created.
/// The message names the step, the shot's shooter and the element that took the most.
/// Unshot power is counted in magnitude (|dB| A per channel: a re-bake shoots negative power,
/// radiosity/rebake.hpp), and may not exceed `ceiling` (the larger of the emitted power and
/// the unshot power when the solve began: a re-bake may start above the emitted power).
template <class Solver>
void check_energy(const Solver& solver, const energy_sums& before, const energy_sums& after, double ceiling = 0) {
    const double added = after.emitted - before.emitted;
    const double rise = after.unshot - before.unshot - added;
    const double tolerance = std::ldexp(before.unshot + std::abs(added), -20);
    if (std::isfinite(after.unshot) && std::isfinite(after.emitted) && rise <= tolerance &&
        after.unshot <= std::max(after.emitted, ceiling) * (1.0 + 1e-6))
        return;
    std::string where;
    if constexpr (requires { solver.last_shot(); }) {
        const radiosity_shot_record& s = solver.last_shot();
        where = " (shot " + std::to_string(s.shot) + " from shooter " + std::to_string(s.shooter) + ", element " +
                std::to_string(s.first_element) + "; element " + std::to_string(s.top_receiver) + " took " +
                radiosity_number(s.top_share) + " of its power)";
    }
    throw radiosity_error("bounce: radiosity: the solve created energy at step " + std::to_string(solver.progress().steps) +
                          where + ": the unshot power rose from " + radiosity_number(before.unshot) + " to " +
                          radiosity_number(after.unshot) + " W (" + radiosity_number(after.unshot / after.emitted) +
                          " of the emitted power); it can only fall");
}

/// The unshot fraction of `o.measure` (a solver without indirect_unshot_fraction() has only
/// the emitted measure).
template <class Solver>
double measured_unshot(const Solver& solver, const radiosity_solve_options& o) {
    if constexpr (requires { solver.indirect_unshot_fraction(); })
        if (o.measure == radiosity_measure::indirect) return solver.indirect_unshot_fraction();
    return solver.unshot_fraction();
}

template <class Solver, class AfterStep>
radiosity_solve_report run_radiosity_solve(Solver& solver, const radiosity_solve_options& o, AfterStep&& after_step) {
    o.validate();
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    const auto ms_since = [](clock::time_point t) {
        return std::chrono::duration<double, std::milli>(clock::now() - t).count();
    };
    radiosity_solve_report r;
    const auto elapsed = [&] { return ms_since(start) - r.checkpoint_ms; };
    const auto now = [&] {
        radiosity_progress p = solver.progress();
        p.elapsed_ms = elapsed();
        return p;
    };
    const double target = 1.0 - o.converge;
    std::size_t next_mark = 1;
    bool checked_here = false;  // a checkpoint at the current step already
    const auto checkpoint = [&](bool force) {
        if (!o.checkpoint || o.checkpoints <= 0 || checked_here) return;
        const double converged = 1.0 - measured_unshot(solver, o);
        bool due = force || r.steps == 1;
        while (next_mark <= std::size_t(o.checkpoints) &&
               converged >= o.converge * double(next_mark) / double(o.checkpoints)) {
            due = true;
            ++next_mark;
        }
        if (!due) return;
        const radiosity_progress p = now();
        const auto t0 = clock::now();
        o.checkpoint(p);
        r.checkpoint_ms += ms_since(t0);
        checked_here = true;
    };
    r.stop = radiosity_stop::converged;
    energy_sums before = energy_of(solver);
    const double ceiling = std::max(before.emitted, before.unshot);
    while (measured_unshot(solver, o) > target) {
        if (o.max_seconds > 0 && elapsed() > o.max_seconds * 1e3) {
            r.stop = radiosity_stop::time_limit;
            break;
        }
        if (!solver.step()) {
            r.stop = radiosity_stop::exhausted;
            break;
        }
        ++r.steps;
        checked_here = false;
        r.splits += after_step(r.steps);
        const double f = measured_unshot(solver, o);
        const energy_sums after = energy_of(solver);
        check_energy(solver, before, after, ceiling);
        before = after;
        r.converged.push_back(1.0 - f);
        r.step_ms.push_back(elapsed());
        checkpoint(false);
        if (o.progress && !o.progress(now())) {
            r.stop = radiosity_stop::callback;
            break;
        }
    }
    checkpoint(true);
    r.solve_ms = elapsed();
    r.unshot_fraction = solver.unshot_fraction();
    r.indirect_unshot_fraction = solver.progress().indirect_unshot_fraction;
    // Shots were made (in this solve or before) and none of their power, nor any light's,
    // reached the front of a surface.
    const double emitted = channel_total(solver.emitted_power());
    bool two_sided = false;
    if constexpr (requires { solver.two_sided(); }) two_sided = solver.two_sided();
    if (solver.progress().steps > 0 && emitted > 0 && !(channel_total(solver.intercepted_power()) > 0) && two_sided)
        throw radiosity_error("bounce: radiosity: all of the power shot (" +
                              radiosity_number(emitted - channel_total(solver.unshot_power())) + " of " +
                              radiosity_number(emitted) + " W emitted) left the scene without reaching any surface");
    if (solver.progress().steps > 0 && emitted > 0 && !(channel_total(solver.intercepted_power()) > 0))
        throw radiosity_error(
            "bounce: radiosity: all of the power shot (" + radiosity_number(emitted - channel_total(solver.unshot_power())) +
            " of " + radiosity_number(emitted) +
            " W emitted) left the scene without reaching the front side of any surface: surfaces are one-sided "
            "(front: counter-clockwise), and no emitter's front faces another surface's front. Are the triangles "
            "wound the other way (reversed winding)?");
    return r;
}

}  // namespace bounce::detail

namespace bounce::inline radiosity {

/// The back sides' radiosity lightmap of a two-sided solver (`solver.radiosity_lightmap(level,
/// 1)`, CPU or GL), else an empty image: what embree::lightmap_view takes for back sides.
template <class Solver>
auto back_radiosity_lightmap(const Solver& solver, int level) -> decltype(solver.radiosity_lightmap(level, 1)) {
    return solver.sides() == 2 ? solver.radiosity_lightmap(level, 1) : decltype(solver.radiosity_lightmap(level, 1)){};
}

/// Whether a solver keeps its lights' direct deposit apart per side (the CPU and the GL
/// solvers do): what a view that computes the direct light per pixel needs.
template <class Solver>
concept splits_direct = requires(const Solver& s) {
    s.display_radiosity(0);
    s.output(output_quantity::irradiance, light_paths::direct, 0);
};

/// Per element of `side`, the lights' direct deposit rho E_d (W/m^2): the part of B that a
/// view computing the direct light per pixel replaces.
template <splits_direct Solver>
std::vector<glm::vec3> direct_deposit(const Solver& solver, int side) {
    std::vector<glm::vec3> d = solver.output(output_quantity::irradiance, light_paths::direct, side);
    for (std::size_t i = 0; i < d.size(); ++i) d[i] *= solver.atlas().albedo[i];
    return d;
}

/// The lightmap of `side` at `level` with the lights' direct deposit taken out (B - rho E_d):
/// the bounced light alone, what embree::lightmap_direct_view (or a renderer's own direct
/// lighting) adds its per-pixel direct light to.
template <splits_direct Solver>
image<glm::vec3> bounced_radiosity_lightmap(const Solver& solver, int level, int side) {
    std::vector<glm::vec3> b = solver.display_radiosity(side);
    const std::vector<glm::vec3> d = direct_deposit(solver, side);
    for (std::size_t i = 0; i < b.size(); ++i) b[i] -= d[i];
    return solver.atlas().to_fine_texels(std::span<const glm::vec3>(b), level, glm::vec3(0.f), true);
}

/// Triangles of `scene` whose front side (counter-clockwise) and whose back side some point,
/// spot or directional light of the scene would light, judged at each triangle's centroid
/// with its face normal and without visibility: O(lights x triangles), no atlas needed.
struct light_sides {
    std::size_t front = 0, back = 0, triangles = 0;
};
inline light_sides triangles_lit_by_lights(const scene_view& scene) {
    light_sides s;
    std::vector<packed_light> lights;
    for (const light& l : scene.lights) lights.push_back(pack(l));
    const auto positive = [](glm::vec3 v) { return v.x > 0.f || v.y > 0.f || v.z > 0.f; };
    for (const glm::uvec3& t : scene.triangles) {
        const glm::vec3 a = scene.positions[t.x], b = scene.positions[t.y], c = scene.positions[t.z];
        const glm::vec3 cr = glm::cross(b - a, c - a);
        if (!(glm::length(cr) > 0.f)) continue;
        const glm::vec3 n = glm::normalize(cr), p = (a + b + c) / 3.f;
        bool front = false, back = false;
        for (const packed_light& l : lights) {
            front = front || positive(light_irradiance(l, p, n));
            back = back || positive(light_irradiance(l, p, -n));
        }
        ++s.triangles;
        s.front += front ? 1 : 0;
        s.back += back ? 1 : 0;
    }
    return s;
}

}  // namespace bounce::radiosity

namespace bounce::detail {
inline bool lights_emit(const scene_view& scene) {
    for (const light& l : scene.lights) {
        const glm::vec3 v = pack(l).intensity();
        if (v.x > 0.f || v.y > 0.f || v.z > 0.f) return true;
    }
    return false;
}
// "1 light reaches" / "2 lights reach" ...
inline std::string lights_verb(const scene_view& scene, const char* one, const char* many) {
    return std::to_string(scene.lights.size()) + (scene.lights.size() == 1 ? std::string(" light ") + one
                                                                           : std::string(" lights ") + many);
}
inline void throw_reversed(const scene_view& scene, const light_sides& s) {
    throw radiosity_error("bounce: radiosity: the scene's " + lights_verb(scene, "reaches", "reach") +
                          " no surface's front side, but would light the back of " + std::to_string(s.back) +
                          " of its " + std::to_string(s.triangles) +
                          " triangles: surfaces are one-sided (front: counter-clockwise), so the triangles are "
                          "probably wound the other way (reversed winding)");
}
}  // namespace bounce::detail

namespace bounce::inline radiosity {

/// A check a program can run before any work (no atlas, no visibility): throws
/// radiosity_error when `scene`'s point, spot and directional lights, its only light (no
/// emissive material in use), face the back side of some triangles and the front of none:
/// reversed winding. check_lights_reach_surfaces, in the solvers' constructors, is the full
/// check.
inline void check_lights_face_surfaces(const scene_view& scene) {
    if (scene.lights.empty() || !detail::lights_emit(scene)) return;
    if (scene.use_emission)
        for (const material& m : scene.materials)
            if (m.emission.r > 0.f || m.emission.g > 0.f || m.emission.b > 0.f) return;
    const light_sides s = triangles_lit_by_lights(scene);
    if (s.front == 0 && s.back > 0) detail::throw_reversed(scene, s);
}

/// For a solver's constructor: throws radiosity_error when `scene` has point, spot or
/// directional lights of some intensity, nothing else emits (no emissive element in
/// `atlas`), and the power the lights delivered to the elements (`delivered`, W per
/// channel, visibility included) is zero, naming the cause: the lights face only the back
/// sides of surfaces (reversed winding), or no surface at all (outside the scene or aimed
/// away), or every surface they face is occluded from them. With `two_sided` surfaces
/// (radiosity_options::two_sided) both sides count as faced and reversed winding is no error.
inline void check_lights_reach_surfaces(const scene_view& scene, const lightmap_atlas& atlas, const glm::dvec3& delivered,
                                        bool two_sided = false) {
    if (scene.lights.empty() || detail::channel_total(delivered) > 0 || !detail::lights_emit(scene)) return;
    for (const glm::vec3& e : atlas.emission)
        if (e.x > 0.f || e.y > 0.f || e.z > 0.f) return;
    light_sides s = triangles_lit_by_lights(scene);
    if (two_sided) s.front = std::max(s.front, s.back);
    if (s.front == 0 && s.back > 0) detail::throw_reversed(scene, s);
    if (s.front == 0)
        throw radiosity_error("bounce: radiosity: the scene's " + detail::lights_verb(scene, "reaches", "reach") +
                              " no surface (outside the scene's geometry or aimed away from it)");
    throw radiosity_error("bounce: radiosity: the scene's " + detail::lights_verb(scene, "faces", "face") + " the front of " +
                          std::to_string(s.front) + " triangles but every one is occluded from them: no light reaches a surface");
}

}  // namespace bounce::radiosity
