#pragma once
// The camera's view of a solve (--view): the lightmap alone (lightmap: B / pi looked up
// bilinearly, direct light included), or the lights' direct light per pixel with shadow rays
// and only the rest of B from the lightmap (direct+indirect: embree::lightmap_direct_view).
#include <bounce/embree/lightmap_view.hpp>
#include <bounce/errors.hpp>
#include <bounce/output.hpp>
#include <bounce/radiosity/solve.hpp>

#include "../common/cli_choices.hpp"

#include <span>
#include <vector>

namespace bounce::examples {

// automatic: direct+indirect where the solver keeps the direct deposit apart (both the CPU
// and the GL solver do), else the lightmap; measured lower on every shared scene
// (docs/radiosity.md, "Where the error is").
enum class view_kind { automatic, lightmap, direct_indirect };
inline const choices<view_kind> view_names{{"auto", view_kind::automatic}, {"lightmap", view_kind::lightmap},
                                           {"direct+indirect", view_kind::direct_indirect}};

// The view `kind` of `solver`'s solution (both sides where it has two).
template <class Solver>
image<glm::vec3> render_view(const embree::accel& bvh, const scene_view& scene, const bounce::camera& cam, const Solver& solver,
                             int level, view_kind kind, std::size_t width, std::size_t height) {
    if (kind == view_kind::lightmap || (kind == view_kind::automatic && !splits_direct<Solver>)) {
        const image<glm::vec3> front = solver.radiosity_lightmap(level), back = back_radiosity_lightmap(solver, level);
        return embree::lightmap_view(bvh, scene, solver.atlas(), front.view(), back.width() ? back.view() : front.view(),
                                     level, cam, width, height);
    }
    if constexpr (splits_direct<Solver>) {
        const image<glm::vec3> front = bounced_radiosity_lightmap(solver, level, 0);
        const image<glm::vec3> back = solver.sides() == 2 ? bounced_radiosity_lightmap(solver, level, 1) : front;
        return embree::lightmap_direct_view(bvh, scene, solver.atlas(), front.view(), back.view(), level, cam,
                                            width, height);
    } else {
        throw parameter_error("--view", "'direct+indirect' needs a solver that keeps the lights' direct deposit apart");
    }
}

}  // namespace bounce::examples
