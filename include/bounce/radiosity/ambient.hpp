#pragma once
/// \file radiosity/ambient.hpp
/// The ambient term shaped by the solve's own shots (issue 30), beside Cohen et al. 1988's
/// uniform one (radiosity_options::ambient_shape).
///
/// Cohen's term spreads the unshot power U over the whole area as U / (A (1 - rho_avg)): in
/// an open scene most of U escapes, and in any scene it lands where the geometry sends it,
/// not evenly. The shaped term measures both from recent shots instead. Over a window of
/// shots (exponentially decayed sums), with S the power they shot, D the power they delivered
/// to elements and R the reflected power they created (rho times what was delivered):
///   capture c = D / S, interreflection rho_eff = R / S,
/// so U will deliver U c (1 + rho_eff + rho_eff^2 + ...) = U c / (1 - rho_eff) in all. It
/// lands as the window's deliveries did: h_i, the window's irradiance at element i (its
/// decayed sum of W/m^2 received), whose area integral is D. Element i's ambient irradiance is
/// then h_i / D times that total:
///   a_i = h_i U / (S - R),
/// per channel (c cancels). U = 0 gives 0; a closed box (c = 1) with a uniform albedo gives
/// U / (1 - rho) delivered in all, as the converged solve will. Displayed as B + rho a_i
/// (radiosity_with_ambient, kernels.hpp); the indirect irradiance output adds a_i.

#include <bounce/concepts.hpp>

#include <algorithm>

namespace bounce::inline radiosity {

/// The factor that turns the window's irradiance h_i into the ambient irradiance a_i = h_i *
/// factor, per channel: unshot / (shot - reflected), 0 where the window shot nothing.
/// `unshot`, `shot`, `reflected`: W per channel (the same decayed weights for the last two).
template <floating T, class V>
V shot_ambient_factor(const V& unshot, const V& shot, const V& reflected) {
    V f(T(0));
    for (int c = 0; c < 3; ++c) {
        const T kept = shot[c] - reflected[c];
        if (shot[c] > T(0) && kept > T(0)) f[c] = std::max(unshot[c], T(0)) / kept;
    }
    return f;
}

/// The power the unshot power will deliver to elements in all, U c / (1 - rho_eff) with
/// c = delivered / shot and rho_eff = reflected / shot (per channel; 0 where nothing was shot):
/// the area integral of the shaped ambient irradiance.
template <floating T, class V>
V future_delivered_power(const V& unshot, const V& shot, const V& delivered, const V& reflected) {
    return shot_ambient_factor<T, V>(unshot, shot, reflected) * delivered;
}

/// The mixed term's floor (radiosity_ambient::mixed), W/m^2 per channel. Of the shaped term's
/// total E = U D / (S - R), the first bounce, U D / S, lands as the window's shots delivered
/// theirs; the rest, E R / S (its reflections, bounced on from wherever it landed), is light
/// whose landing the window does not show, and Cohen et al.'s assumption spreads it evenly:
/// (R / S) E / A over `area` = A, every side's area that shows the ambient. 0 where nothing
/// was shot. `factor` = shot_ambient_factor, so E = factor D.
template <floating T, class V>
V mixed_ambient_floor(const V& factor, const V& shot, const V& delivered, const V& reflected, T area) {
    V f(T(0));
    for (int c = 0; c < 3; ++c)
        if (shot[c] > T(0) && area > T(0)) f[c] = factor[c] * delivered[c] * std::max(reflected[c], T(0)) / shot[c] / area;
    return f;
}

/// The mixed ambient irradiance of an element-side (W/m^2 per channel): the larger of the
/// shaped term `shaped` = h_i factor and the floor, times `scale`, which keeps the total at E:
///   a_i = scale max(h_i factor, floor),  scale = E / (E + sum_j A_j max(0, floor - h_j factor)),
/// the sum over every element-side (mixed_ambient_deficit, mixed_ambient_scale). Where the shots
/// delivered more than the floor, their shape; elsewhere (an element no shot reached included)
/// Cohen's even level. Emitted as GLSL for the GL solver's lightmap pass.
template <real T, class V>
V mixed_ambient(const V& shaped, const V& floor, const V& scale) {
    return scale * max(shaped, floor);
}

/// One element-side's term of mixed_ambient_scale's deficit: its area `area` times the floor's
/// excess over its shaped term, A_j max(0, floor - h_j factor), per channel. Emitted as GLSL
/// for the GL solver's sum.
template <real T, class V>
V mixed_ambient_deficit(const V& shaped, const V& floor, const T& area) {
    return max(floor - shaped, T(0)) * area;
}

/// mixed_ambient's scale from the total E (`total`, = factor D) and `deficit`, the floor's
/// excess over the shaped term summed over every side, sum_j A_j max(0, floor - h_j factor): 1
/// where both are 0.
template <floating T, class V>
V mixed_ambient_scale(const V& total, const V& deficit) {
    V k(T(1));
    for (int c = 0; c < 3; ++c)
        if (total[c] + deficit[c] > T(0)) k[c] = total[c] / (total[c] + deficit[c]);
    return k;
}

}  // namespace bounce::radiosity
