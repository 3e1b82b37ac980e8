#pragma once
/// \file indirect/imperfect_shadow_maps.hpp
/// Imperfect shadow maps (Ritschel, Grosch, Kim, Seidel, Dachsbacher and Kautz 2008,
/// "Imperfect Shadow Maps for Efficient Computation of Indirect Illumination"): approximate
/// visibility between the receivers of one-bounce indirect light and its VPLs
/// (indirect_visibility::ism, docs/rsm-sii-interleaved.md section 17).
///
///   1. The scene is sampled once by area into a point set (ism_point_sampler); VPL j of a
///      frame of V VPLs uses its own subset, the points j, j + V, j + 2V, ... (the paper's
///      "different subset per VPL"), points_per_vpl of them.
///   2. Each VPL has a small paraboloid depth map of its front hemisphere (res x res texels,
///      all maps in one atlas, ism_atlas_layout); every point of its subset in front of it
///      is splatted into the one texel its direction falls into, keeping the nearest
///      distance (ism_splat_texel, min depth).
///   3. The holes the sparse points leave are filled by pull-push (ism_pull, ism_push): the
///      pull averages the filled texels of each 2 x 2 block into the next coarser level,
///      down to one texel per map; the push fills each empty texel with its parent's value,
///      from the coarsest level up. Maps are powers of two aligned in the atlas, so no block
///      straddles two maps.
///   4. A receiver looks up the texel its direction from the VPL falls into (ism_map_texel)
///      and sees the VPL unless it lies beyond the stored depth by more than a bias
///      (ism_visible, ism_bias) that follows the map's texel size and the points' spacing.
///
/// The paraboloid projection of a direction d around the VPL's normal (local frame:
/// orthonormal_basis(n), n = +z), (d.x, d.y) / (1 + d.z) for unit d (Heidrich and Seidel
/// 1998), is the stereographic projection the radiosity item buffer already uses
/// (radiosity/kernels.hpp's stereographic_item_texel): the front hemisphere onto the unit
/// disc, the normal onto the centre, the horizon onto the rim. Its texel spans 4 / res
/// radians at the centre and 2 / res at the rim.
///
/// Every function marked kernel is a template over (T, V, V2): the CPU instantiates it with
/// float and glm, the GL adapter prints it as GLSL (gl::emitted_kernels). The host parts
/// (point sampling, layout, parameters) are shared by both renderers.
///
/// Units: positions and depths in scene units.

#include <bounce/concepts.hpp>
#include <bounce/errors.hpp>
#include <bounce/radiosity/kernels.hpp>
#include <bounce/sampling.hpp>
#include <bounce/scene_view.hpp>
#include <bounce/vocabulary.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline indirect {

/// The depth of a texel no point reached (and, after pull-push, of a map no point reached):
/// larger than any distance, so every receiver passes the depth test against it.
inline constexpr float ism_empty = std::numeric_limits<float>::max();

/// Parameters of imperfect shadow maps (indirect_options::ism).
struct ism_params {
    /// Texels per side of each VPL's paraboloid map: a power of two in [4, 256] (typical
    /// 16-64; the paper's 1024 maps had 128 x 128 texels on a GPU).
    int map_size = 32;
    /// Points splatted into each VPL's map, in [1, 65536] (the paper: 8k). With V VPLs the
    /// point set holds V points_per_vpl points, at most 2^24.
    std::uint32_t points_per_vpl = 2048;
    /// Multiplies the depth test's bias (ism_bias), >= 0 (0: no bias). 0.5 by default: on the
    /// conference room (SII 1024 4x4) 1 leaks (0.57 rel_rms against the occluded reference,
    /// 0.33 at 0.5) and on the cornell-box 0.25 shadows falsely (0.175 against 0.136 at 0.5;
    /// docs/rsm-sii-interleaved.md section 17).
    float bias_scale = 0.5f;
    bool pull_push = true;  ///< fill the holes (false leaves them empty: they see everything)
    std::uint64_t seed = 7;  ///< the point set's sampling

    bool operator==(const ism_params&) const = default;

    /// Throws parameter_error naming the field ("ism.map_size", ...); `vpls` is the frame's
    /// VPL count (indirect_options::count).
    void validate(std::size_t vpls) const {
        require(map_size >= 4 && map_size <= 256 && (map_size & (map_size - 1)) == 0, "ism.map_size",
                "must be a power of two in [4, 256]");
        require(points_per_vpl >= 1 && points_per_vpl <= 65536, "ism.points_per_vpl", "must lie in [1, 65536]");
        if (double(points_per_vpl) * double(vpls) > double(std::size_t(1) << 24))
            throw parameter_error("ism.points_per_vpl", std::to_string(points_per_vpl) + " points for each of " +
                                                            std::to_string(vpls) +
                                                            " VPLs exceed the point set's 2^24 points");
        require(std::isfinite(bias_scale) && bias_scale >= 0.f, "ism.bias_scale", "must be finite and >= 0");
    }
};

// ---------------------------------------------------------------------------------------
// Kernels

/// Kernel. (x, y, distance): the texel (0..res-1 each, as numbers) of the `res` x `res`
/// paraboloid map of the VPL at `origin` (unit normal `n`) that the direction to `p` falls
/// into, and p's distance from the VPL. A point behind or on the VPL's plane is looked up
/// in the direction of the normal (its texel is never used: the VPL gives it no light), a
/// point at the VPL itself likewise (distance 0). Directions at the horizon land on the
/// rim texels; the square's corners outside the disc are never reached.
template <real T, vec3_of<T> V, vec2_of<T> V2>
V ism_map_texel(const V& p, const V& origin, const V& n, T res) {
    const auto tb = orthonormal_basis<T, V>(n);
    const V local = to_shooter_frame<T, V>(p, origin, tb[0], tb[1], n);
    const V safe = select(local.z > T(0), local, V(T(0), T(0), T(1)));
    const V2 texel = stereographic_item_texel<T, V, V2>(safe, res);
    return V(texel.x, texel.y, length(local));
}

/// Kernel. (x, y, depth) of a point of the VPL's subset splatted into its map: the texel
/// and distance of ism_map_texel, the depth ism_empty (nothing stored) where the point is
/// not in front of the VPL: such a point cannot lie between the VPL and a receiver it lights.
template <real T, vec3_of<T> V, vec2_of<T> V2>
V ism_splat_texel(const V& p, const V& origin, const V& n, T res) {
    const V t = ism_map_texel<T, V, V2>(p, origin, n, res);
    return V(t.x, t.y, select(dot(p - origin, n) > T(0), t.z, T(ism_empty)));
}

/// Kernel. The pull of pull-push: the mean of the filled (below ism_empty) of four texels of
/// a 2 x 2 block, summed in the order a, b, c, d; ism_empty when none is filled.
template <real T>
T ism_pull(T a, T b, T c, T d) {
    const T empty = T(ism_empty);
    const T count = select(a < empty, T(1), T(0)) + select(b < empty, T(1), T(0)) + select(c < empty, T(1), T(0)) +
                    select(d < empty, T(1), T(0));
    const T sum = select(a < empty, a, T(0)) + select(b < empty, b, T(0)) + select(c < empty, c, T(0)) +
                  select(d < empty, d, T(0));
    return select(count > T(0), sum / max(count, T(1)), empty);
}

/// Kernel. The push of pull-push: a texel keeps its own depth where filled, else takes its
/// parent's (the coarser level's texel over it, itself already pushed).
template <real T>
T ism_push(T fine, T coarse) {
    return select(fine < T(ism_empty), fine, coarse);
}

/// Kernel. The depth test's bias at distance `distance` from the VPL (scene units): a
/// texel of a `res` map spans up to 4 / res radians, distance 4 / res across, stretched along
/// a receiver's surface by 1 / cos of its angle to the VPL's direction (`cos_receiver`, taken
/// at least 0.2, 78 degrees), and a texel's nearest point lies up to the points' own spacing
/// (`spacing`, ism_point_spacing) off the receiver's surface point; `scale` multiplies both.
template <real T>
T ism_bias(T distance, T cos_receiver, T res, T spacing, T scale) {
    const T stretch = T(1) / max(abs(cos_receiver), T(0.2));
    return scale * (spacing + distance * (T(4) / res) * stretch);
}

/// Kernel. Whether the receiver at `receiver` (unit normal `receiver_normal`, either side)
/// sees the VPL at `origin` through its map: 1 when its distance is at most the stored
/// depth `stored_depth` (the texel ism_map_texel names) plus ism_bias, else 0. A receiver at
/// the VPL itself (distance 0) sees it.
template <real T, vec3_of<T> V>
T ism_visible(const V& receiver, const V& receiver_normal, const V& origin, T stored_depth, T res, T spacing,
              T scale) {
    const V d = origin - receiver;
    const T distance = length(d);
    const T cos_receiver = dot(receiver_normal, d) / max(distance, T(1e-30));
    const T bias = ism_bias<T>(distance, cos_receiver, res, spacing, scale);
    return select(distance <= stored_depth + bias, T(1), T(0));
}

// ---------------------------------------------------------------------------------------
// Host side: the atlas, the point set

/// Where each VPL's map lies in the atlas: `maps` maps of `map_size` texels a side, in
/// rows of `columns` (ceil(sqrt(maps))), map j at column j % columns, row j / columns.
/// Texel (x, y) of map j is atlas texel (column x map_size + x, row x map_size + y), row
/// `y` counted from the atlas's first row (both backends index one linear array).
struct ism_atlas_layout {
    int map_size = 32;
    std::size_t maps = 0;
    std::size_t columns = 0;

    ism_atlas_layout() = default;
    ism_atlas_layout(int size, std::size_t count) : map_size(size), maps(count) {
        columns = std::size_t(std::ceil(std::sqrt(double(count))));
        while (columns * columns < count) ++columns;
        if (columns == 0) columns = 1;
    }
    std::size_t rows() const noexcept { return (maps + columns - 1) / columns; }
    std::size_t width() const noexcept { return columns * std::size_t(map_size); }
    std::size_t height() const noexcept { return rows() * std::size_t(map_size); }
    /// Pull-push levels below the finest: log2(map_size) (down to one texel a map).
    int levels() const noexcept { return std::countr_zero(unsigned(map_size)); }
    /// Index of texel (x, y) of map j in the finest level, row-major over the atlas.
    std::size_t index(std::size_t j, int x, int y) const noexcept {
        const std::size_t ax = (j % columns) * std::size_t(map_size) + std::size_t(x);
        const std::size_t ay = (j / columns) * std::size_t(map_size) + std::size_t(y);
        return ay * width() + ax;
    }
};

/// The mean spacing of one VPL's points: sqrt(area / points_per_vpl) for points spread by
/// area over surfaces of total area `area`.
inline float ism_point_spacing(double area, std::uint32_t points_per_vpl) {
    return float(std::sqrt(area / double(std::max<std::uint32_t>(points_per_vpl, 1))));
}

/// The scene's surfaces sampled by area, deterministically: point i of a set of `count`
/// lies in stratum [i, i + 1) / count of the cumulative area, so every subset {j, j + V,
/// j + 2V, ...} is itself stratified over the whole scene. Copies the triangles it needs;
/// the scene may change afterwards.
class ism_point_sampler {
public:
    explicit ism_point_sampler(const scene_view& scene) {
        scene.validate_mesh();
        corners_.reserve(scene.triangles.size() * 3);
        cumulative_.reserve(scene.triangles.size());
        double total = 0;
        for (const auto& t : scene.triangles) {
            const glm::dvec3 a(scene.positions[t.x]), b(scene.positions[t.y]), c(scene.positions[t.z]);
            const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
            if (!(area > 0.0) || !std::isfinite(area)) continue;
            total += area;
            cumulative_.push_back(total);
            corners_.push_back(scene.positions[t.x]);
            corners_.push_back(scene.positions[t.y]);
            corners_.push_back(scene.positions[t.z]);
        }
        area_ = total;
    }

    /// Total surface area (scene units^2) of the triangles sampled.
    double area() const noexcept { return area_; }

    /// `count` points (empty for a scene of no area), point i in stratum i of the area.
    std::vector<glm::vec3> points(std::size_t count, std::uint64_t seed) const {
        std::vector<glm::vec3> out;
        if (cumulative_.empty()) return out;
        out.reserve(count);
        for (std::size_t i = 0; i < count; ++i) {
            const std::uint64_t h0 = splitmix64(seed * 0x9e3779b97f4a7c15ULL + i);
            const std::uint64_t h1 = splitmix64(h0);
            const double u0 = (double(i) + double(h0 >> 11) * 0x1p-53) / double(count) * area_;
            const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), u0);
            const std::size_t t = std::min<std::size_t>(std::size_t(it - cumulative_.begin()), cumulative_.size() - 1);
            const glm::vec2 u(float(h1 >> 40) * 0x1p-24f, float((h1 >> 16) & 0xffffffu) * 0x1p-24f);
            const glm::vec2 b = uniform_triangle<float, glm::vec2>(u);
            const glm::vec3* c = &corners_[3 * t];
            out.push_back(c[0] * (1.f - b.x - b.y) + c[1] * b.x + c[2] * b.y);
        }
        return out;
    }

private:
    std::vector<glm::vec3> corners_;
    std::vector<double> cumulative_;
    double area_ = 0;
};

}  // namespace bounce::indirect
