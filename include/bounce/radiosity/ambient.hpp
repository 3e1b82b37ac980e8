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

}  // namespace bounce::radiosity
