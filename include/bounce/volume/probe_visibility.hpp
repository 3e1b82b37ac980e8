#pragma once
/// \file volume/probe_visibility.hpp
/// Visibility-aware irradiance-volume lookups (DDGI: Majercik et al. 2019, with the
/// self-shadow bias of Majercik et al. 2021): each probe of an `irradiance_volume` gets an
/// N x N octahedral map of the mean and the mean square of the distance to the first hit
/// (`probe_visibility`, filled from ray distances by `filter_ray_distances`; Embree bakes it
/// in embree/probe_visibility_baker.hpp), and `trilinear_visible` weighs the 8 corners of
/// the leaf holding a point by the visibility kernels (volume/visibility_kernels.hpp), so
/// that a probe behind a wall does not light the other side. The GL lookup
/// (gl/irradiance_volume.hpp) runs the same kernels.

#include <bounce/errors.hpp>
#include <bounce/volume/probe_octree.hpp>
#include <bounce/volume/visibility_kernels.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline volume {

/// Whether a lookup tests the visibility of each probe from the shading point.
enum class volume_visibility {
    none,       ///< plain trilinear (light leaks through walls thinner than a cell)
    chebyshev,  ///< DDGI's Chebyshev test against each probe's distance moments
};

/// A visibility-aware lookup's choices.
struct visibility_lookup {
    /// Chebyshev by default where the probes have moments: it lowers the error at the
    /// surface points of 11 of 14 volumes over the shared scenes and is within 2% on the
    /// others (docs/sh-and-irradiance-volumes.md, "Visibility-aware probes").
    volume_visibility mode = volume_visibility::chebyshev;
    /// Majercik et al. 2021's self-shadow bias: the tested point moves by
    /// (0.2 n + 0.8 view) * 0.75 * cell edge * this. Typical: 0.3; >= 0.
    float self_shadow_bias = 0.3f;
};

/// Per-probe distance moments: an N x N octahedral map (octahedral_encode; texel (x, y) at
/// index y * N + x) of (mean, mean square) of the distance to the first hit, for each probe
/// of a volume in the order of `irradiance_volume::probes()`, and optionally each probe's
/// actual position: where a relocated probe (embree::relocating_probe_source, Majercik et
/// al. 2021) was baked, which the visibility test measures from while the trilinear
/// weights keep its lattice position.
class probe_visibility {
public:
    probe_visibility() = default;
    /// Throws parameter_error naming "resolution" outside 1 .. 64, "moments" when its size
    /// is not a multiple of 2 N^2 or a value is negative or not finite, and "positions"
    /// when not empty and not one finite position per probe.
    probe_visibility(std::uint32_t resolution, std::vector<float> moments, std::vector<glm::vec3> positions = {})
        : resolution_(resolution), moments_(std::move(moments)), positions_(std::move(positions)) {
        require(resolution >= 1 && resolution <= 64, "resolution", "must lie in 1 .. 64");
        require(moments_.size() % texel_floats() == 0, "moments", "2 N^2 values (mean, mean square) per probe");
        for (const float m : moments_) require(std::isfinite(m) && m >= 0, "moments", "must be finite and >= 0");
        require(positions_.empty() || positions_.size() == probe_count(), "positions", "one position per probe");
        for (const glm::vec3& q : positions_)
            require(std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z), "positions", "must be finite");
    }

    std::uint32_t resolution() const noexcept { return resolution_; }
    std::size_t probe_count() const noexcept { return resolution_ ? moments_.size() / texel_floats() : 0; }
    /// Every probe's map, probe-major, (mean, mean square) per texel: the GPU's buffer.
    const std::vector<float>& moments() const noexcept { return moments_; }
    /// The probes' actual positions (empty: their lattice positions).
    const std::vector<glm::vec3>& positions() const noexcept { return positions_; }
    /// Probe `probe`'s actual position, `lattice` (its position in the volume) when none is kept.
    glm::vec3 position(std::size_t probe, glm::vec3 lattice) const {
        return positions_.empty() ? lattice : positions_[probe];
    }

    /// (mean, mean square) of texel `index` (y * N + x) of probe `probe`.
    std::pair<float, float> texel(std::size_t probe, std::size_t index) const {
        const std::size_t at = probe * texel_floats() + 2 * index;
        return {moments_[at], moments_[at + 1]};
    }

    /// The moments of probe `probe` in direction `d` (unit), bilinear over the map with
    /// its edges wrapped (octahedral_bilinear, octahedral_texel_index, bilinear_moments).
    std::pair<float, float> sample(std::size_t probe, glm::vec3 d) const {
        const auto [u, v] = octahedral_encode<float, glm::vec3>(d);
        const float n = float(resolution_);
        const auto b = octahedral_bilinear<float>(u, v, n);
        std::array<float, 4> mean{}, square{};
        for (int k = 0; k < 4; ++k) {
            const float index = octahedral_texel_index<float>(b[0] + float(k & 1), b[1] + float(k >> 1), n);
            std::tie(mean[std::size_t(k)], square[std::size_t(k)]) = texel(probe, std::size_t(index));
        }
        return bilinear_moments<float>(mean, square, b[2], b[3]);
    }

private:
    std::size_t texel_floats() const noexcept { return 2 * std::size_t(resolution_) * resolution_; }
    std::uint32_t resolution_ = 0;
    std::vector<float> moments_;
    std::vector<glm::vec3> positions_;
};

/// One probe's map from its rays (Majercik et al. 2019, section 5: "cosine-power"
/// filtering): texel t, whose centre has direction c_t (octahedral_decode), gets
/// mean = sum_j w_j r_j / sum_j w_j and mean square = sum_j w_j r_j^2 / sum_j w_j with
/// w_j = max(0, c_t . d_j)^sharpness over the rays (unit `directions`, `distances` >= 0,
/// misses given as the caller's maximum distance); a texel no ray reaches with weight takes
/// the ray nearest its direction. Writes 2 N^2 floats to `out`. Throws parameter_error
/// naming "distances" or "out" for sizes that do not match, "directions" when empty,
/// "sharpness" when not positive and finite.
inline void filter_ray_distances(std::span<const glm::vec3> directions, std::span<const float> distances,
                                 std::uint32_t resolution, float sharpness, std::span<float> out) {
    require(!directions.empty(), "directions", "at least one ray");
    require(distances.size() == directions.size(), "distances", "one distance per direction");
    require(out.size() == 2 * std::size_t(resolution) * resolution, "out", "2 N^2 floats");
    require(std::isfinite(sharpness) && sharpness > 0, "sharpness", "must be finite and > 0");
    const float cut = std::pow(1e-4f, 1.f / sharpness);  // below this cosine a weight is < 1e-4
    const float n = float(resolution);
    for (std::uint32_t y = 0; y < resolution; ++y)
        for (std::uint32_t x = 0; x < resolution; ++x) {
            const glm::vec3 c = octahedral_decode<float, glm::vec3>(2 * (float(x) + 0.5f) / n - 1, 2 * (float(y) + 0.5f) / n - 1);
            double w_sum = 0, m = 0, m2 = 0;
            float best = -2;
            std::size_t nearest = 0;
            for (std::size_t j = 0; j < directions.size(); ++j) {
                const float cosine = glm::dot(c, directions[j]);
                if (cosine > best) best = cosine, nearest = j;
                if (cosine <= cut) continue;
                const double w = std::pow(double(cosine), double(sharpness)), r = distances[j];
                w_sum += w, m += w * r, m2 += w * r * r;
            }
            const std::size_t at = 2 * (std::size_t(y) * resolution + x);
            if (w_sum > 0) {
                out[at] = float(m / w_sum), out[at + 1] = float(m2 / w_sum);
            } else {
                out[at] = distances[nearest], out[at + 1] = distances[nearest] * distances[nearest];
            }
        }
}

/// Trilinear lookup of `volume` at p (normal n, unit) with each of the leaf's 8 corner
/// probes (at vis.position: where it was baked) weighed by its visibility
/// (visibility_probe_weight) from the point biased towards
/// the viewer (`view`: unit direction from p to the eye, view_direction; n when there is none) by
/// how.self_shadow_bias times the leaf's shortest edge; renormalized over the usable
/// corners, 0 if none is. With how.mode = none it is `volume.trilinear(p, n)`. Throws
/// parameter_error naming "visibility" when `vis` does not hold one map per probe of
/// `volume`, "volume" when it computes its hanging corners (irradiance_volume::require_stored_corners), "self_shadow_bias" when negative or not finite.
inline glm::vec3 trilinear_visible(const irradiance_volume& volume, const probe_visibility& vis, glm::vec3 p, glm::vec3 n,
                                   glm::vec3 view, const visibility_lookup& how) {
    require(std::isfinite(how.self_shadow_bias) && how.self_shadow_bias >= 0, "self_shadow_bias", "must be finite and >= 0");
    if (how.mode == volume_visibility::none) return volume.trilinear(p, n);
    volume.require_stored_corners("the visibility test");
    require(vis.probe_count() == volume.probes().size(), "visibility", "one distance map per probe of the volume");
    const irradiance_volume::node& leaf = volume.nodes()[volume.find_leaf(p)];
    const auto w = trilinear_weights<float, glm::vec3>(p, leaf.lo, leaf.size);
    const glm::vec3 biased =
        self_shadow_biased<float, glm::vec3>(p, n, view, cell_spacing<float, glm::vec3>(leaf.size), how.self_shadow_bias);
    glm::vec3 sum(0.f);
    float wsum = 0.f;
    for (std::size_t k = 0; k < 8; ++k) {
        const std::uint32_t idx = leaf.corner[k];
        const irradiance_probe& pr = volume.probes()[idx];
        const glm::vec3 s = vis.position(idx, pr.position);
        const auto [dir, distance] = probe_to_point<float, glm::vec3>(s, biased);
        const auto [mean, square] = vis.sample(idx, dir);
        const float weight = visibility_probe_weight<float, glm::vec3>(p, n, s, distance, mean, square, w[k]);
        std::tie(sum, wsum) = trilinear_probe_accumulate<irradiance_volume_bands, float, glm::vec3>(
            sum, wsum, n, weight, pr.inside ? 0.f : 1.f, pr.radiance);
    }
    return probe_average<float, glm::vec3>(sum, wsum);
}

}  // namespace bounce::volume
