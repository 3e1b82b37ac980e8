#pragma once
/// \file indirect/vpl_sampling.hpp
/// A reflective shadow map as views, and the virtual point lights (VPLs) taken from it for
/// splatting indirect illumination (Dachsbacher and Stamminger 2006, section 3): texels on
/// a regular grid, or texels drawn by hierarchical importance warping on the flux.
///
/// Both are estimators of the sum over every texel of the map: a VPL's `flux` is its
/// texel's flux divided by the probability (per texel) of choosing that texel and by the
/// number of VPLs, so sum_k E_k(x) has the expected value sum_p E_p(x) (indirect/rsm.hpp's
/// pixel-light irradiance is linear in the flux).

#include <bounce/errors.hpp>
#include <bounce/image.hpp>
#include <bounce/luminance.hpp>
#include <bounce/sampling.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline indirect {

/// A reflective shadow map (DS05 section 3.1) as views of the renderer's own buffers, all
/// the same size: per texel the world position, the unit normal and the reflected flux (W
/// per channel, indirect/rsm.hpp's texel-flux kernels). A texel that sees nothing has flux 0.
/// `light_view_projection` maps world positions to the map's clip space (OpenGL
/// conventions; u = ndc.x / 2 + 1/2, v = 1/2 - ndc.y / 2, row 0 at the top as image.hpp),
/// which the RSM gather needs to find a receiver's texel; a point light's cube map is six
/// of these.
struct rsm_view {
    image_view<const glm::vec3> position;
    image_view<const glm::vec3> normal;
    image_view<const glm::vec3> flux;
    glm::mat4 light_view_projection{1.f};

    std::size_t width() const noexcept { return flux.width(); }
    std::size_t height() const noexcept { return flux.height(); }

    /// Throws parameter_error naming `name` unless the three views are non-empty and the same size.
    void validate(const char* name = "rsm") const {
        require(!flux.empty(), name, "flux map is empty");
        require(position.width() == flux.width() && position.height() == flux.height() &&
                    normal.width() == flux.width() && normal.height() == flux.height(),
                name, "position, normal and flux maps differ in size");
    }
};

/// A virtual point light: a texel of a reflective shadow map with the flux it stands for.
struct vpl {
    glm::vec3 position{0.f};          ///< world position of the texel's surface point
    glm::vec3 normal{0.f, 0.f, 1.f};  ///< its unit normal
    glm::vec3 flux{0.f};              ///< W per channel, already divided by the sampling probability
    /// World area (m^2) it stands for: its texel's (texel_world_area) divided like its flux
    /// by count x probability, so the VPLs' areas sum to the lit area the map sees. The
    /// footprint clamp (pixel_light_params::min_distance2_for, indirect/options.hpp) makes it
    /// a disc of this area.
    float area = 0.f;
};

/// The world area of texel (x, y) of `map`: the texel's square of the map's image plane
/// carried onto the tangent plane of its surface point (position, normal) through
/// `inverse_view_projection` = inverse(map.light_view_projection), so it holds for the
/// perspective maps of point and spot lights and the orthographic maps of directional ones.
/// A plane seen edge-on is taken at a grazing cosine of 1e-3 (the area 1000 times the
/// face-on one at most), which keeps it finite.
inline double texel_world_area(const rsm_view& map, const glm::dmat4& inverse_view_projection, std::size_t x,
                               std::size_t y) {
    const glm::dvec3 p(map.position(x, y)), n(map.normal(x, y));
    const double cx = 2.0 * (double(x) + 0.5) / double(map.width()) - 1.0;
    const double cy = 1.0 - 2.0 * (double(y) + 0.5) / double(map.height());
    const auto on_plane = [&](double ndc_x, double ndc_y) {
        const glm::dvec4 a = inverse_view_projection * glm::dvec4(ndc_x, ndc_y, -1.0, 1.0);
        const glm::dvec4 b = inverse_view_projection * glm::dvec4(ndc_x, ndc_y, 1.0, 1.0);
        const glm::dvec3 from = glm::dvec3(a) / a.w, dir = glm::dvec3(b) / b.w - from;
        const double grazing = 1e-3 * glm::length(dir), along = glm::dot(dir, n);
        const double den = std::abs(along) >= grazing ? along : std::copysign(grazing, along);
        return from + dir * (glm::dot(p - from, n) / den);
    };
    const double hx = 1.0 / double(map.width()), hy = 1.0 / double(map.height());
    const glm::dvec3 across = on_plane(cx + hx, cy) - on_plane(cx - hx, cy);
    const glm::dvec3 down = on_plane(cx, cy + hy) - on_plane(cx, cy - hy);
    const double area = glm::length(glm::cross(across, down));
    return std::isfinite(area) ? area : 0.0;
}

/// The importance of a texel's flux: its Rec. 709 luminance (W, luminance-weighted).
inline float flux_importance(const glm::vec3& flux) noexcept { return rec709_luminance<float, glm::vec3>(flux); }

/// VPLs at the centres of a `grid_x` x `grid_y` grid of cells over the map (Hahn 2012
/// section 4.1.2, "a regular grid of sample positions"): each stands for the
/// width x height / (grid_x grid_y) texels of its cell. Texels with zero flux give no VPL
/// (they light nothing), so fewer than grid_x grid_y may come back.
inline std::vector<vpl> vpls_on_grid(const rsm_view& map, std::size_t grid_x, std::size_t grid_y) {
    map.validate();
    require(grid_x > 0 && grid_y > 0, "grid_x/grid_y", "must be positive");
    const double scale = double(map.width()) * double(map.height()) / (double(grid_x) * double(grid_y));
    const glm::dmat4 inverse = glm::inverse(glm::dmat4(map.light_view_projection));
    std::vector<vpl> out;
    out.reserve(grid_x * grid_y);
    for (std::size_t j = 0; j < grid_y; ++j)
        for (std::size_t i = 0; i < grid_x; ++i) {
            const auto x = std::size_t((double(i) + 0.5) * double(map.width()) / double(grid_x));
            const auto y = std::size_t((double(j) + 0.5) * double(map.height()) / double(grid_y));
            const glm::vec3 f = map.flux(x, y);
            if (!(f.x > 0.f || f.y > 0.f || f.z > 0.f)) continue;
            out.push_back({map.position(x, y), map.normal(x, y), glm::vec3(glm::dvec3(f) * scale),
                           float(texel_world_area(map, inverse, x, y) * scale)});
        }
    return out;
}

/// Hierarchical sample warping on the flux (DS06 section 3.3, after Clarberg et al. 2005):
/// a sample u in [0, 1)^2 descends from the whole map to one texel, at each level first
/// splitting its rectangle into upper and lower halves (choosing one with the probability
/// of its share of the importance and rescaling u.y into [0, 1) within it), then the chosen
/// half into left and right (u.x likewise). The texel is reached with probability
/// importance(texel) / total, exactly, for any map size (halves are split by a summed-area
/// table, so no power-of-two padding is needed).
class flux_warping {
public:
    explicit flux_warping(const rsm_view& map) : width_(map.width()), height_(map.height()) {
        map.validate();
        sat_.assign((width_ + 1) * (height_ + 1), 0.0);
        for (std::size_t y = 0; y < height_; ++y) {
            double row = 0;
            for (std::size_t x = 0; x < width_; ++x) {
                const glm::vec3 f = map.flux(x, y);
                require(std::isfinite(f.x) && std::isfinite(f.y) && std::isfinite(f.z) && f.x >= 0.f && f.y >= 0.f &&
                            f.z >= 0.f,
                        "rsm.flux", "must be finite and non-negative");
                row += double(flux_importance(f));
                at(x + 1, y + 1) = at(x + 1, y) + row;
            }
        }
    }

    /// Sum of the importance over the map.
    double total() const noexcept { return sat_.back(); }

    /// The texel sample `u` warps to and the probability of choosing it.
    struct texel_choice {
        std::size_t x = 0, y = 0;
        double probability = 0;
    };
    texel_choice warp(glm::dvec2 u) const {
        require(total() > 0, "rsm.flux", "is zero everywhere: nothing to sample");
        std::size_t x0 = 0, y0 = 0, x1 = width_, y1 = height_;
        const double below_one = std::nextafter(1.0, 0.0);
        // Splits [lo, hi) at its middle, choosing a side with probability proportional to
        // its importance `first` / `whole`, and rescales t into the chosen side.
        const auto choose = [&](double first, double whole, double& t) {
            const double p = first / whole;
            const bool take_first = t < p;
            t = take_first ? t / p : (t - p) / (1.0 - p);
            t = std::clamp(t, 0.0, below_one);
            return take_first;
        };
        while (x1 - x0 > 1 || y1 - y0 > 1) {
            if (y1 - y0 > 1) {
                const std::size_t ym = (y0 + y1) / 2;
                if (choose(rect(x0, y0, x1, ym), rect(x0, y0, x1, y1), u.y))
                    y1 = ym;
                else
                    y0 = ym;
            }
            if (x1 - x0 > 1) {
                const std::size_t xm = (x0 + x1) / 2;
                if (choose(rect(x0, y0, xm, y1), rect(x0, y0, x1, y1), u.x))
                    x1 = xm;
                else
                    x0 = xm;
            }
        }
        return {x0, y0, rect(x0, y0, x1, y1) / total()};
    }

private:
    double& at(std::size_t x, std::size_t y) { return sat_[y * (width_ + 1) + x]; }
    double at(std::size_t x, std::size_t y) const { return sat_[y * (width_ + 1) + x]; }
    double rect(std::size_t x0, std::size_t y0, std::size_t x1, std::size_t y1) const {
        return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);
    }

    std::size_t width_, height_;
    std::vector<double> sat_;  // summed-area table of the importance, (width+1) x (height+1)
};

/// `count` VPLs drawn by flux_warping from the points of the Halton sequence (bases 2, 3;
/// rotated by a shift derived from `seed`), so their density follows the flux, listed in a
/// shuffled order: every (N M)-th Halton point has the same low base-2 digits, so dealing
/// the sequence in order to N M sub-buffers would give each one a strip of the map instead
/// of a random subset (indirect/interleaved_sampling.hpp's light_assignment). Each VPL's
/// flux is its texel's divided by (count x probability): every VPL carries total / count of
/// the importance, and the sum of the VPL fluxes estimates the map's total without bias
/// (DS06's rescaled sample weights, "the total weight remains equal").
inline std::vector<vpl> vpls_by_flux_warping(const rsm_view& map, std::size_t count, std::uint64_t seed = 0) {
    require(count > 0, "count", "must be positive");
    const flux_warping warping(map);
    if (!(warping.total() > 0)) return {};
    pcg32 rng(seed);
    const glm::dvec2 shift(rng.next_double(), rng.next_double());
    const glm::dmat4 inverse = glm::inverse(glm::dmat4(map.light_view_projection));
    std::vector<vpl> out;
    out.reserve(count);
    for (std::size_t k = 0; k < count; ++k) {
        const auto c = warping.warp(halton2(k, shift));
        const double scale = 1.0 / (double(count) * c.probability);
        out.push_back({map.position(c.x, c.y), map.normal(c.x, c.y), glm::vec3(glm::dvec3(map.flux(c.x, c.y)) * scale),
                       float(texel_world_area(map, inverse, c.x, c.y) * scale)});
    }
    for (std::size_t k = count; k > 1; --k) std::swap(out[k - 1], out[rng.next_u32() % k]);
    return out;
}

}  // namespace bounce::indirect
