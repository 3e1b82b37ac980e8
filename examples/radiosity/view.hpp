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

// automatic: direct+indirect where the solver keeps the direct deposit apart (the CPU
// solver), else the lightmap (the GL solver); measured lower on every shared scene
// (docs/radiosity.md, "Where the error is").
enum class view_kind { automatic, lightmap, direct_indirect };
inline const choices<view_kind> view_names{{"auto", view_kind::automatic}, {"lightmap", view_kind::lightmap},
                                           {"direct+indirect", view_kind::direct_indirect}};

// Whether the solver keeps its lights' direct deposit apart per side (the CPU solver).
template <class Solver>
concept splits_direct = requires(const Solver& s) {
    s.display_radiosity(0);
    s.output(output_quantity::irradiance, light_paths::direct, 0);
};

// Per element of `side`, the lights' direct deposit rho E_d (W/m^2): what the direct light
// per pixel replaces.
template <splits_direct Solver>
std::vector<glm::vec3> direct_deposit(const Solver& solver, int side) {
    std::vector<glm::vec3> d = solver.output(output_quantity::irradiance, light_paths::direct, side);
    for (std::size_t i = 0; i < d.size(); ++i) d[i] *= solver.atlas().albedo[i];
    return d;
}

// The lightmap of `side` at `level`: B (direct = false) or the lights' direct deposit alone
// (direct = true), or B less it (rest = true).
template <splits_direct Solver>
image<glm::vec3> split_lightmap(const Solver& solver, int level, int side, bool rest) {
    std::vector<glm::vec3> b = solver.display_radiosity(side);
    const std::vector<glm::vec3> d = direct_deposit(solver, side);
    for (std::size_t i = 0; i < b.size(); ++i) b[i] = rest ? b[i] - d[i] : d[i];
    return solver.atlas().to_fine_texels(std::span<const glm::vec3>(b), level, glm::vec3(0.f), true);
}

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
        const image<glm::vec3> front = split_lightmap(solver, level, 0, true);
        const image<glm::vec3> back = solver.sides() == 2 ? split_lightmap(solver, level, 1, true) : front;
        return embree::lightmap_direct_view(bvh, scene, solver.atlas(), front.view(), back.view(), level, cam,
                                            width, height);
    } else {
        throw parameter_error("--view", "'direct+indirect' needs the CPU backend (its solver keeps the lights' direct "
                                        "deposit apart)");
    }
}

}  // namespace bounce::examples
