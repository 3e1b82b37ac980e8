#pragma once
/// \file cache/gradients.hpp
/// Irradiance, its rotation and translation gradients and the harmonic mean distance from
/// one stratified hemisphere of radiance samples (Ward and Heckbert 1992; the improved
/// translation gradient of Krivanek et al. 2005).
///
/// Strata: M rings in theta with equal projected solid angle (theta_j^- = asin sqrt(j/M)),
/// N wedges in phi (phi_k^- = 2 pi k / N); sample (j, k) lies inside cell (j, k) and is
/// stored at index j * N + k. Radiance is taken as constant over each cell (the assumption
/// behind both gradient formulas), so each cell's weights are its exact integrals: the
/// irradiance weight pi / (M N), and the rotation weight int sin^2(theta) dtheta *
/// int v(phi) dphi. That keeps the rotation gradient finite for samples at grazing angles,
/// where the per-sample form tan(theta) diverges.
///
/// Conventions (derived in docs/irradiance-splatting.md, tested in tests/core):
///  - rotation gradient grad_r: for a normal turned by a small angle alpha about a unit
///    tangent axis t, E changes by alpha * dot(t, grad_r); the new normal n satisfies
///    n_k x n = alpha t, hence E(n) ~ E_k + dot(n_k x n, grad_r) (Gautron 2008, Algorithm 4).
///  - translation gradient grad_t: E(p) ~ E_k + dot(p - p_k, grad_t).

#include <bounce/errors.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include <glm/glm.hpp>

namespace bounce::inline cache {

/// Radiance and hit distance of a stratified set of hemisphere directions around a normal,
/// in the local frame (z along the normal).
struct hemisphere_samples {
    std::uint32_t rings = 0;              ///< M: strata in theta (equal projected solid angle)
    std::uint32_t wedges = 0;             ///< N: strata in phi
    std::vector<glm::vec3> direction;     ///< unit local direction of sample j * N + k
    std::vector<glm::vec3> radiance;      ///< incoming radiance (RGB) of each sample
    std::vector<float> distance;          ///< hit distance, +infinity where the ray escaped

    std::size_t size() const noexcept { return std::size_t(rings) * wedges; }
    /// Throws parameter_error on inconsistent sizes, non-finite radiance or a non-positive
    /// distance.
    void validate() const;
};

/// Cell (j, k) directions for an M x N stratification, jittered from `u` (one [0,1)^2 point
/// per cell, row-major), as local unit vectors: theta = asin(sqrt((j + u.y) / M)),
/// phi = 2 pi (k + u.x) / N; cosine-distributed within the hemisphere.
std::vector<glm::vec3> stratified_cosine_directions(std::uint32_t rings, std::uint32_t wedges,
                                                    const std::vector<glm::vec2>& u);

/// Which translation-gradient formula to use.
enum class translation_gradient_kind {
    ward_heckbert_1992,  ///< Ward and Heckbert 1992, Eq. for stratified samples
    krivanek_2005,       ///< Krivanek et al. 2005: the azimuthal walls weighted by projected solid angle
};

/// What a record needs from its hemisphere, in the LOCAL frame (x, y tangent, z normal).
struct hemisphere_estimate {
    glm::dvec3 irradiance{0};                    ///< E per channel (W/m^2)
    std::array<glm::dvec3, 3> rotation{};        ///< grad_r per channel (R, G, B)
    std::array<glm::dvec3, 3> translation{};     ///< grad_t per channel
    double harmonic_mean_distance = std::numeric_limits<double>::infinity();  ///< R; inf if nothing was hit
    /// Translation Hessian per channel in the tangent plane (local x, y), occlusion-aware:
    /// see translation_hessian. Zero from samplers that do not estimate it.
    std::array<glm::dmat2, 3> hessian{glm::dmat2(0.0), glm::dmat2(0.0), glm::dmat2(0.0)};
    /// Mean hit distance of the rays that hit (each cell once: the cosine-weighted mean over
    /// the hemisphere's geometry), +infinity if nothing was hit: the length over which the
    /// Hessian radius budgets its error (hessian_radius). Set by add_translation_hessian.
    double mean_distance = std::numeric_limits<double>::infinity();
};

/// The second derivative of irradiance under translation in the tangent plane, from the
/// record's own hemisphere samples with their hit distances (the occlusion Hessian of
/// Schwarzhaupt, Jensen and Jarosz 2012, which builds on the Hessians of Jarosz,
/// Schoenefeld, Kobbelt and Jensen 2012; the per-sample form here is bounce's, derived in
/// docs/irradiance-splatting.md). Each cell's hit is a small patch at distance r along its
/// local direction w, facing the point, whose projected solid angle h dA / |q - x|^3
/// changes as the point moves by d in the tangent plane; its Hessian at d = 0 is
/// dOmega (15 w_t w_t^T - 3 I) / r^2 (w_t: the tangential part of w, dOmega = pi / (M N)).
/// Each cell contributes that times (L_k - E / pi): radiance equal to the hemisphere's mean
/// moves no irradiance however near it is (a uniformly lit enclosure has constant E), so
/// only occluders that differ from what they hide count. Escaped rays contribute nothing.
/// Needs e.irradiance already estimated.
void add_translation_hessian(const hemisphere_samples& s, hemisphere_estimate& e);

/// What estimate_hemisphere needs of an M x N grid alone: the trigonometry of its ring and
/// wedge boundaries, O(M + N) square roots, arcsines, sines and cosines. A sampler that
/// measures many hemispheres on one grid builds it once (estimating from it is bitwise the
/// same as without it, and costs no trigonometry per cell).
struct hemisphere_strata {
    struct ring {
        double sin2_integral;  ///< int over the ring of sin^2(theta) dtheta (the rotation weight's theta part)
        double wall_rate;      ///< sin cos^2 at its lower wall theta_j^- (0 for j = 0)
        double sin_step;       ///< sin(theta_j^+) - sin(theta_j^-) (= int cos(theta) dtheta)
        double cos_step;       ///< cos(theta_j^-) - cos(theta_j^+)
    };
    struct wedge {
        glm::dvec3 v_integral;  ///< int over the wedge of (-sin phi, cos phi, 0) dphi
        glm::dvec3 centre;      ///< (cos, sin, 0) of the wedge's middle azimuth
        glm::dvec3 wall;        ///< (-sin, cos, 0) of its lower wall phi_k^- (the wall's normal)
    };
    std::uint32_t rings = 0, wedges = 0;
    double cell_weight = 0;      ///< pi / (M N)
    double azimuth_krivanek = 0; ///< 2 sin(dphi / 2) = |int u(phi) dphi| over a wedge
    double dphi = 0;             ///< 2 pi / N
    std::vector<ring> ring_terms;    ///< M entries
    std::vector<wedge> wedge_terms;  ///< N entries

    /// Throws parameter_error unless rings and wedges are positive.
    hemisphere_strata(std::uint32_t m, std::uint32_t n);
};

/// Irradiance, gradients and harmonic mean distance of one hemisphere (see file comment).
/// Throws parameter_error on the samples validate() rejects.
hemisphere_estimate estimate_hemisphere(const hemisphere_samples& s,
                                        translation_gradient_kind kind = translation_gradient_kind::krivanek_2005);
/// As above (bitwise) with the grid's trigonometry precomputed; throws parameter_error also
/// when `strata` is not of the samples' grid. `hessian` false skips add_translation_hessian,
/// leaving hessian zero and mean_distance infinite, for callers whose radius needs neither
/// (every radius_policy but hessian).
hemisphere_estimate estimate_hemisphere(const hemisphere_samples& s, const hemisphere_strata& strata,
                                        translation_gradient_kind kind = translation_gradient_kind::krivanek_2005,
                                        bool hessian = true);

// ---------------------------------------------------------------------------------------
// Definitions

inline void hemisphere_samples::validate() const {
    require(rings > 0 && wedges > 0, "rings/wedges", "need at least one stratum in each direction");
    require(direction.size() == size() && radiance.size() == size() && distance.size() == size(), "samples",
            "direction, radiance and distance must hold rings * wedges entries");
    for (std::size_t i = 0; i < size(); ++i) {
        const auto& L = radiance[i];
        require(std::isfinite(L.x) && std::isfinite(L.y) && std::isfinite(L.z), "radiance",
                "non-finite radiance sample");
        require(distance[i] > 0.f && !std::isnan(distance[i]), "distance", "hit distance must be positive");
    }
}

inline std::vector<glm::vec3> stratified_cosine_directions(std::uint32_t rings, std::uint32_t wedges,
                                                           const std::vector<glm::vec2>& u) {
    require(rings > 0 && wedges > 0, "rings/wedges", "need at least one stratum in each direction");
    require(u.size() == std::size_t(rings) * wedges, "u", "need one jitter point per cell");
    std::vector<glm::vec3> dirs(u.size());
    for (std::uint32_t j = 0; j < rings; ++j)
        for (std::uint32_t k = 0; k < wedges; ++k) {
            const auto& uj = u[j * wedges + k];
            const double sin2 = (j + double(uj.y)) / rings, sin_t = std::sqrt(sin2);
            const double cos_t = std::sqrt(std::max(0.0, 1.0 - sin2));
            const double phi = 2 * std::numbers::pi * (k + double(uj.x)) / wedges;
            dirs[j * wedges + k] = glm::vec3(float(sin_t * std::cos(phi)), float(sin_t * std::sin(phi)), float(cos_t));
        }
    return dirs;
}

inline hemisphere_strata::hemisphere_strata(std::uint32_t m, std::uint32_t n) : rings(m), wedges(n) {
    require(m > 0 && n > 0, "rings/wedges", "need at least one stratum in each direction");
    const double pi = std::numbers::pi;
    cell_weight = pi / (double(m) * n);
    dphi = 2 * pi / n;
    azimuth_krivanek = 2 * std::sin(dphi / 2);
    // Ring boundaries: sin^2(theta_j^-) = j / M.
    auto sin_lo = [&](std::uint32_t j) { return std::sqrt(double(j) / m); };
    auto cos_lo = [&](std::uint32_t j) { return std::sqrt(1.0 - double(j) / m); };
    auto theta_lo = [&](std::uint32_t j) { return std::asin(sin_lo(j)); };
    ring_terms.resize(m);
    for (std::uint32_t j = 0; j < m; ++j) {
        ring& r = ring_terms[j];
        // int_{theta^-}^{theta^+} sin^2 = [theta/2 - sin(2 theta)/4], sin(2t) = 2 sin cos.
        const double t0 = theta_lo(j), t1 = theta_lo(j + 1);
        r.sin2_integral = (t1 - t0) / 2 - (sin_lo(j + 1) * cos_lo(j + 1) - sin_lo(j) * cos_lo(j)) / 2;
        const double sl = sin_lo(j), cl = cos_lo(j);
        r.wall_rate = sl * cl * cl;
        r.sin_step = sin_lo(j + 1) - sin_lo(j);
        r.cos_step = cos_lo(j) - cos_lo(j + 1);
    }
    wedge_terms.resize(n);
    for (std::uint32_t k = 0; k < n; ++k) {
        wedge& w = wedge_terms[k];
        // int v(phi) dphi with v = (-sin phi, cos phi, 0): (cos phi+ - cos phi-, sin phi+ - sin phi-).
        const double p0 = dphi * k, p1 = dphi * (k + 1);
        w.v_integral = glm::dvec3(std::cos(p1) - std::cos(p0), std::sin(p1) - std::sin(p0), 0);
        const double phi_lo = dphi * k, phi_c = dphi * (k + 0.5);
        w.centre = glm::dvec3(std::cos(phi_c), std::sin(phi_c), 0);   // into wedge k, horizontal
        w.wall = glm::dvec3(-std::sin(phi_lo), std::cos(phi_lo), 0);  // normal to the wall at phi_k^-
    }
}

inline hemisphere_estimate estimate_hemisphere(const hemisphere_samples& s, translation_gradient_kind kind) {
    return estimate_hemisphere(s, hemisphere_strata(s.rings, s.wedges), kind);
}

inline hemisphere_estimate estimate_hemisphere(const hemisphere_samples& s, const hemisphere_strata& strata,
                                               translation_gradient_kind kind, bool hessian) {
    require(s.rings > 0 && s.wedges > 0, "rings/wedges", "need at least one stratum in each direction");
    require(s.direction.size() == s.size() && s.radiance.size() == s.size() && s.distance.size() == s.size(), "samples",
            "direction, radiance and distance must hold rings * wedges entries");
    require(strata.rings == s.rings && strata.wedges == s.wedges && strata.ring_terms.size() == s.rings &&
                strata.wedges == strata.wedge_terms.size(),
            "strata", "must be of the samples' grid (rings x wedges)");
    const std::uint32_t M = s.rings, N = s.wedges;
    auto L = [&](std::uint32_t j, std::uint32_t k) { return glm::dvec3(s.radiance[j * N + k]); };
    auto r = [&](std::uint32_t j, std::uint32_t k) { return double(s.distance[j * N + k]); };
    const hemisphere_strata::ring* rings = strata.ring_terms.data();
    const hemisphere_strata::wedge* wedges = strata.wedge_terms.data();

    // What hemisphere_samples::validate checks of each sample, in one branch-free pass.
    bool valid = true;
    constexpr float largest = std::numeric_limits<float>::max();
    for (const glm::vec3& x : s.radiance)  // false for infinities and NaN
        valid &= std::abs(x.x) <= largest && std::abs(x.y) <= largest && std::abs(x.z) <= largest;
    for (const float d : s.distance) valid &= d > 0.f;
    if (!valid) s.validate();  // throws, naming the first bad sample's field

    // The z components of the rotation and translation gradients stay exactly 0 (every
    // term's direction lies in the tangent plane, times a finite number), so only x and y
    // are summed.
    hemisphere_estimate e;
    double inverse_distance_sum = 0;
    for (std::uint32_t j = 0; j < M; ++j) {
        const double sin2_integral = rings[j].sin2_integral;
        for (std::uint32_t k = 0; k < N; ++k) {
            const glm::dvec3 Ljk = L(j, k);
            e.irradiance += Ljk * strata.cell_weight;
            const glm::dvec3& v_integral = wedges[k].v_integral;
            for (int c = 0; c < 3; ++c) {
                const double w = sin2_integral * Ljk[c];
                e.rotation[c].x += v_integral.x * w;
                e.rotation[c].y += v_integral.y * w;
            }
            inverse_distance_sum += 1.0 / r(j, k);  // 0 for escaped rays
        }
    }
    if (inverse_distance_sum > 0) e.harmonic_mean_distance = double(M) * N / inverse_distance_sum;

    // Translation: each wall between neighbouring cells sweeps over the geometry at the
    // nearer of the two hit distances as the point moves; the radiance difference across the
    // wall times the rate of change of projected solid angle gives the gradient.
    const bool krivanek = kind == translation_gradient_kind::krivanek_2005;
    const double azimuth = krivanek ? strata.azimuth_krivanek  // |int u(phi) dphi| over the wedge
                                    : strata.dphi;
    for (std::uint32_t k = 0; k < N; ++k) {
        const glm::dvec3& u_c = wedges[k].centre;
        const glm::dvec3& v_lo = wedges[k].wall;
        const std::uint32_t km = (k + N - 1) % N;
        // Walls between rings j-1 and j (at theta_j^-): rate sin cos^2 / r per unit azimuth.
        for (std::uint32_t j = 1; j < M; ++j) {
            const double rate = rings[j].wall_rate / std::min(r(j, k), r(j - 1, k));
            const glm::dvec3 dL = L(j, k) - L(j - 1, k);
            for (int c = 0; c < 3; ++c) {
                const double w = azimuth * rate * dL[c];
                e.translation[c].x += u_c.x * w;
                e.translation[c].y += u_c.y * w;
            }
        }
        // Walls between wedges k-1 and k (at phi_k^-), one per ring.
        for (std::uint32_t j = 0; j < M; ++j) {
            const double rmin = std::min(r(j, k), r(j, km));
            double rate;
            if (krivanek) {
                rate = rings[j].sin_step / rmin;  // int cos(theta) dtheta / r
            } else {
                const auto& d = s.direction[j * N + k];
                const double sin_t = std::max(std::sqrt(double(d.x) * d.x + double(d.y) * d.y), 1e-12);
                rate = rings[j].cos_step / (sin_t * rmin);
            }
            const glm::dvec3 dL = L(j, k) - L(j, km);
            for (int c = 0; c < 3; ++c) {
                const double w = rate * dL[c];
                e.translation[c].x += v_lo.x * w;
                e.translation[c].y += v_lo.y * w;
            }
        }
    }
    if (hessian) add_translation_hessian(s, e);
    return e;
}

inline void add_translation_hessian(const hemisphere_samples& s, hemisphere_estimate& e) {
    const double d_omega = std::numbers::pi / double(s.size());
    const glm::dvec3 mean = e.irradiance / std::numbers::pi;
    glm::dmat2 h[3] = {glm::dmat2(0.0), glm::dmat2(0.0), glm::dmat2(0.0)};
    double distance_sum = 0;
    std::size_t hits = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const double r = s.distance[i];
        if (!std::isfinite(r)) continue;
        distance_sum += r;
        ++hits;
        const glm::dvec3 w(s.direction[i]);
        const double xx = 15 * w.x * w.x - 3, yy = 15 * w.y * w.y - 3, xy = 15 * w.x * w.y;
        const glm::dvec3 dl = (glm::dvec3(s.radiance[i]) - mean) * (d_omega / (r * r));
        for (int c = 0; c < 3; ++c) {
            h[c][0][0] += dl[c] * xx;
            h[c][1][1] += dl[c] * yy;
            h[c][0][1] += dl[c] * xy;
        }
    }
    for (int c = 0; c < 3; ++c) {
        h[c][1][0] = h[c][0][1];
        e.hessian[c] = h[c];
    }
    e.mean_distance = hits > 0 ? distance_sum / double(hits) : std::numeric_limits<double>::infinity();
}

}  // namespace bounce::cache
