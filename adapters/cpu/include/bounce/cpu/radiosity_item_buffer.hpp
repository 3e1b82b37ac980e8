#pragma once
/// \file radiosity_item_buffer.hpp
/// Visibility for progressive radiosity on the CPU: a software rasterizer of the scene's
/// triangles into an item buffer (chart id and depth per pixel) seen from the shooter, in
/// the stereographic ("hemispherical") projection of Coombe and Harris 2005 (section 39.2.1)
/// or on the five faces of a hemicube (Cohen and Greenberg 1985), or along parallel rays for
/// a directional light; and the lookup that tells whether an element is seen.
///
/// The scan converter is the one GPUs use: vertices snapped to 1/256 pixel, integer edge
/// functions, pixel centres at (x + 1/2, y + 1/2), and the top-left rule for centres exactly
/// on an edge, so two triangles sharing an edge cover each pixel on it exactly once and a
/// mesh without T-junctions covers every pixel inside its outline exactly once.
///
/// The stereographic projection bends straight edges into arcs (Figure 39-5), so before
/// rasterizing with straight edges each triangle is split in four at its edges' midpoints,
/// recursively, until the sagitta of each edge (distance, in pixels, between the projected
/// midpoint of an edge and the midpoint of its projected chord) is below `tolerance_px`
/// (halving an edge quarters its sagitta); the pieces gather next to the shooter, where the
/// projection bends most (a wall through the shooter's corner). Neighbouring triangles may
/// split a shared edge differently; the T-junctions this leaves open cracks narrower than
/// the tolerance (the tests measure the pixels that differ from an exact per-pixel ray cast).
/// The clipping and this tessellation are the core's (radiosity/stereographic_tessellation.hpp), which
/// gl::progressive_radiosity draws from too, so both backends rasterize the same pieces.
/// The hemicube's faces are perspective projections, where straight edges stay straight and
/// 1/depth is linear in screen space, so they need no tessellation and their depth is exact.
///
/// Depth is exact at every pixel centre: the distance along the centre's direction to the
/// triangle's plane (stereographic), 1/depth interpolated (hemicube faces), the distance along
/// the light (parallel).
///
/// Lookup: an element is visible when the item buffer shows its chart (or nothing) at its
/// pixel, or when the surface shown there, extended as a plane, is met along the element's
/// own ray beyond the element: the id test alone (Listing 39-3) would darken a row of
/// elements along every concave corner, where the pixel's centre falls on the neighbouring
/// wall at the same depth. A GPU backend can do the same with the triangle's plane in the
/// item buffer.

#include <bounce/errors.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/radiosity/kernels.hpp>
#include <bounce/radiosity/options.hpp>
#include <bounce/sampling.hpp>
#include <bounce/scene_view.hpp>
#include <bounce/radiosity/stereographic_tessellation.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <tbb/parallel_for.h>

namespace bounce::cpu {

/// Where a shot comes from, as the visibility pass needs it.
struct shot_frame {
    static constexpr std::uint32_t none = lightmap_atlas::none;
    glm::vec3 position{0.f};        ///< the shooter (world); unused for parallel shots
    glm::vec3 axis{0.f, 0.f, 1.f};  ///< unit normal of the hemisphere seen; for parallel shots
                                    ///< the direction the light travels
    bool parallel = false;          ///< a directional light: rays along `axis`, not from a point
    std::uint32_t chart = none;     ///< the shooter's own chart, left out of the item buffer
};

/// What the solver asks of a visibility method: prepare for one shot, then answer for any
/// receiving point (an element's position, world space, and its chart, which does not occlude
/// it) with a value in [0, 1]; `visible` is const and called from many threads at once. Only
/// points in front of the shot (local z > 0, or any point for a parallel shot) are asked.
/// Elements are passed as points, not indices, so a method needs no element array and
/// survives adaptive subdivision.
template <class V>
concept shot_visibility = requires(V& v, const V& cv, const shot_frame& s, const glm::vec3& p, std::uint32_t chart) {
    v.begin_shot(s);
    { cv.visible(p, chart) } -> std::convertible_to<float>;
};

/// Every element sees every shooter: form factors without occlusion (open scenes, tests
/// against the dense solve, and the unoccluded bound of a visibility method).
struct all_visible {
    void begin_shot(const shot_frame&) noexcept {}
    float visible(const glm::vec3&, std::uint32_t) const noexcept { return 1.f; }
    float visible_from(const glm::vec3&, std::uint32_t, const glm::vec3&, std::uint32_t) const noexcept { return 1.f; }
};

/// Chart id, depth and the drawing's own primitive number per pixel; `none` where nothing
/// was drawn.
struct item_buffer {
    static constexpr std::uint32_t none = lightmap_atlas::none;
    int width = 0, height = 0;
    std::vector<std::uint32_t> id, primitive;
    std::vector<float> depth;

    void reset(int w, int h) {
        width = w;
        height = h;
        id.assign(std::size_t(w) * std::size_t(h), none);
        primitive.assign(std::size_t(w) * std::size_t(h), none);
        depth.assign(std::size_t(w) * std::size_t(h), std::numeric_limits<float>::infinity());
    }
};

/// A vertex ready for the scan converter: pixel coordinates and the attribute interpolated
/// linearly in screen space (depth for the stereographic and parallel projections, 1/depth
/// for a hemicube face).
struct raster_vertex {
    glm::vec2 pixel;
    float attribute;
};

/// Draws one triangle into `buffer` with id `id` (and `primitive`, the caller's own number
/// for it): fixed-point edge functions (8 bits of
/// sub-pixel precision, vertices within +-2^20 pixels), top-left rule, nearest depth wins
/// (ties keep the earlier triangle). `depth_at(x, y, attribute)` gives the depth stored at
/// pixel (x, y) from the attribute interpolated there. Either winding is drawn; only rows
/// [row_begin, row_end) are touched.
template <class DepthAt>
void scan_triangle_with(item_buffer& buffer, raster_vertex a, raster_vertex b, raster_vertex c, std::uint32_t id,
                        const DepthAt& depth_at, std::uint32_t primitive = item_buffer::none, int row_begin = 0,
                        int row_end = std::numeric_limits<int>::max()) {
    constexpr double sub = 256.0;
    constexpr double limit = double(1 << 20);
    const auto fixed = [&](glm::vec2 p, std::int64_t& x, std::int64_t& y) {
        x = std::int64_t(std::llround(std::clamp(double(p.x), -limit, limit) * sub));
        y = std::int64_t(std::llround(std::clamp(double(p.y), -limit, limit) * sub));
    };
    std::int64_t ax, ay, bx, by, cx, cy;
    fixed(a.pixel, ax, ay);
    fixed(b.pixel, bx, by);
    fixed(c.pixel, cx, cy);
    // Twice the signed area; orient counter-clockwise in (x right, y down) so inside is E >= 0.
    std::int64_t area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
    if (area == 0) return;
    if (area < 0) {
        std::swap(bx, cx);
        std::swap(by, cy);
        std::swap(b, c);
        area = -area;
    }
    const int x0 = std::max(0, int(std::floor(double(std::min({ax, bx, cx})) / sub)));
    const int x1 = std::min(buffer.width - 1, int(std::ceil(double(std::max({ax, bx, cx})) / sub)));
    const int y0 = std::max({0, row_begin, int(std::floor(double(std::min({ay, by, cy})) / sub))});
    const int y1 = std::min({buffer.height - 1, row_end - 1, int(std::ceil(double(std::max({ay, by, cy})) / sub))});
    if (x0 > x1 || y0 > y1) return;
    // Edge (p -> q): E(s) = (q.x - p.x)(s.y - p.y) - (q.y - p.y)(s.x - p.x). With this
    // orientation a left edge has q.y < p.y and a top edge q.y == p.y, q.x > p.x; other edges
    // do not own the centres exactly on them (bias -1). The rule flips with the edge's
    // direction, so of two triangles sharing an edge exactly one owns it.
    struct edge {
        std::int64_t dx, dy, px, py, bias;
        std::int64_t at(std::int64_t sx, std::int64_t sy) const { return dx * (sy - py) - dy * (sx - px) + bias; }
    };
    const auto make = [](std::int64_t px, std::int64_t py, std::int64_t qx, std::int64_t qy) {
        const std::int64_t dx = qx - px, dy = qy - py;
        const bool owner = dy < 0 || (dy == 0 && dx > 0);
        return edge{dx, dy, px, py, owner ? 0 : -1};
    };
    const edge e0 = make(bx, by, cx, cy), e1 = make(cx, cy, ax, ay), e2 = make(ax, ay, bx, by);
    const double inv_area = 1.0 / double(area);
    const std::int64_t half = std::int64_t(sub / 2), step = std::int64_t(sub);
    for (int y = y0; y <= y1; ++y) {
        const std::int64_t sy = std::int64_t(y) * step + half;
        std::int64_t sx = std::int64_t(x0) * step + half;
        std::int64_t w0 = e0.at(sx, sy), w1 = e1.at(sx, sy), w2 = e2.at(sx, sy);
        for (int x = x0; x <= x1; ++x, w0 -= e0.dy * step, w1 -= e1.dy * step, w2 -= e2.dy * step) {
            if ((w0 | w1 | w2) < 0) continue;
            // Barycentric weights from the unbiased edge functions (the bias is 0 or -1).
            const double l0 = double(w0 - e0.bias) * inv_area, l1 = double(w1 - e1.bias) * inv_area;
            const double attr = l0 * a.attribute + l1 * b.attribute + (1.0 - l0 - l1) * c.attribute;
            const float depth = depth_at(x, y, attr);
            const std::size_t i = std::size_t(y) * std::size_t(buffer.width) + std::size_t(x);
            if (depth < buffer.depth[i]) {
                buffer.depth[i] = depth;
                buffer.id[i] = id;
                buffer.primitive[i] = primitive;
            }
        }
    }
}

/// scan_triangle_with storing the interpolated attribute as depth, or, with `reciprocal`,
/// its reciprocal (the attribute is then 1/depth, linear in screen space under a
/// perspective projection: perspective-correct depth).
inline void scan_triangle(item_buffer& buffer, raster_vertex a, raster_vertex b, raster_vertex c, std::uint32_t id,
                          bool reciprocal = false, std::uint32_t primitive = item_buffer::none) {
    if (reciprocal)
        scan_triangle_with(buffer, a, b, c, id, [](int, int, double attr) { return float(1.0 / attr); }, primitive);
    else scan_triangle_with(buffer, a, b, c, id, [](int, int, double attr) { return float(attr); }, primitive);
}

namespace detail {
// The clipping of radiosity/stereographic_tessellation.hpp, shared with the GL solver.
using bounce::canonical_lerp;
using bounce::clip_polygon;
}  // namespace detail

/// The projections an item buffer can hold.
enum class item_projection { stereographic, hemicube };

/// Item-buffer visibility (see the file comment). Copies the scene's triangles (positions,
/// chart from the atlas, plane); one set of buffers, redrawn each shot.
class item_buffer_visibility {
public:
    struct options {
        item_projection projection = item_projection::stereographic;
        int resolution = 256;          ///< item buffer side, pixels (hemicube: per face; typical: 128-512)
        float tolerance_px = 0.25f;    ///< largest sagitta of a tessellated edge, pixels (stereographic;
                                       ///< at least stereographic_tolerance_floor, radiosity/options.hpp)
        int max_tessellation_depth = 10; ///< cap on the halvings of one triangle's edges (4^depth pieces at most)
        int parallel_resolution = 1024; ///< side of the directional light's buffer, pixels
    };

    /// Throws parameter_error on bad options or a scene the atlas was not built from.
    item_buffer_visibility(const scene_view& scene, const lightmap_atlas& atlas, options opt)
        : opt_(opt) {
        require(opt.resolution >= 8 && opt.resolution <= 8192, "options.resolution", "must lie in [8, 8192]");
        require(opt.projection != item_projection::hemicube || opt.resolution % 2 == 0, "options.resolution",
                "a hemicube needs an even resolution (its side faces keep half the rows)");
        require(opt.tolerance_px > 0.f && std::isfinite(opt.tolerance_px), "options.tolerance_px", "must be positive");
        require(opt.max_tessellation_depth >= 0 && opt.max_tessellation_depth <= 16, "options.max_tessellation_depth",
                "must lie in [0, 16]");
        require(opt.parallel_resolution >= 8 && opt.parallel_resolution <= 16384, "options.parallel_resolution",
                "must lie in [8, 16384]");
        require(atlas.chart_of_triangle.size() == scene.triangles.size(), "atlas",
                "was not built from this scene (triangle counts differ)");
        if (opt.projection == item_projection::stereographic) {
            const float finest = stereographic_tolerance_floor(scene, atlas.size(), opt.resolution);
            if (opt.tolerance_px < finest)
                throw parameter_error("options.tolerance_px", bounce::detail::radiosity_number(opt.tolerance_px) +
                                                                  " px is below what the item buffer resolves here (" +
                                                                  bounce::detail::radiosity_number(finest) +
                                                                  " px: its 1/256-pixel vertex snap, or float32 "
                                                                  "positions at this scene's scale), so it would only "
                                                                  "tessellate deeper for nothing");
        }
        item_triangles triangles = item_buffer_triangles(scene, atlas);
        corners_ = std::move(triangles.corners);
        triangle_chart_ = std::move(triangles.chart);
        world_plane_ = std::move(triangles.world_plane);
        if (opt.projection == item_projection::stereographic) {
            // The unit direction through each pixel centre (inverse projection), for depths.
            const int res = opt.resolution;
            pixel_direction_.resize(std::size_t(res) * std::size_t(res));
            for (int y = 0; y < res; ++y)
                for (int x = 0; x < res; ++x) {
                    pixel_direction_[std::size_t(y) * std::size_t(res) + std::size_t(x)] =
                        glm::vec3(stereographic_texel_direction<double, glm::dvec3, glm::dvec2>(
                            glm::dvec2(x + 0.5, y + 0.5), double(res)));
                }
        }
        const auto [lo, hi] = scene.bounds();
        lo_ = lo;
        hi_ = hi;
        diagonal_ = std::max(glm::length(hi - lo), 1e-30f);
    }

    void begin_shot(const shot_frame& s) {
        shot_ = s;
        if (s.parallel) {
            draw_parallel();
            return;
        }
        const auto tb = orthonormal_basis<float, glm::vec3>(s.axis);
        t_ = tb[0];
        b_ = tb[1];
        if (opt_.projection == item_projection::stereographic) draw_stereographic();
        else draw_hemicube();
    }

    /// 1 if the point `p` (world) of chart `chart` is seen from the current shot, else 0.
    /// Its texel is radiosity/kernels.hpp's (the GL passes emit the same kernels).
    float visible(const glm::vec3& p, std::uint32_t chart) const {
        if (shot_.parallel) {
            const glm::vec2 xy = parallel_item_texel<float, glm::vec3, glm::vec2>(p, t_, b_, ortho_lo_, ortho_scale_,
                                                                                float(opt_.parallel_resolution));
            return seen(buffers_[0], int(xy.x), int(xy.y), chart, p, true) ? 1.f : 0.f;
        }
        const glm::vec3 l = to_shooter_frame<float, glm::vec3>(p, shot_.position, t_, b_, shot_.axis);
        const float res = float(opt_.resolution);
        if (opt_.projection == item_projection::stereographic) {
            const glm::vec2 xy = stereographic_item_texel<float, glm::vec3, glm::vec2>(l, res);
            return seen(buffers_[0], int(xy.x), int(xy.y), chart, l, false) ? 1.f : 0.f;
        }
        const glm::vec3 f = hemicube_item_texel<float, glm::vec3>(l, res);
        return seen(buffers_[std::size_t(f.x)], int(f.y), int(f.z), chart, l, false) ? 1.f : 0.f;
    }

    /// The buffers of the last shot: one (stereographic, parallel) or five (hemicube faces,
    /// top then +x, -x, +y, -y).
    std::span<const item_buffer> buffers() const noexcept {
        return {buffers_.data(), shot_.parallel || opt_.projection == item_projection::stereographic ? 1u : 5u};
    }
    /// Sub-triangles drawn in the last shot (tessellation included).
    std::size_t drawn_triangles() const noexcept { return drawn_; }
    const options& settings() const noexcept { return opt_; }

private:
    // Whether the element at `p` (shooter frame, or world for a parallel shot) of chart `chart`
    // is seen through pixel (x, y): the pixel shows its chart, or nothing, or a surface whose
    // plane, met along the element's own ray, lies beyond the element (less a relative 1e-4
    // and 1e-6 of the scene's diagonal). Comparing along the element's ray rather than the
    // pixel centre's keeps a surface seen at a grazing angle from hiding elements just in
    // front of it (concave corners, where the pixel's centre falls on the other wall) and
    // from letting through elements just behind it (a ceiling behind a light 1 cm below it).
    bool seen(const item_buffer& buf, int x, int y, std::uint32_t chart, glm::vec3 p, bool parallel) const {
        const std::size_t i = std::size_t(y) * std::size_t(buf.width) + std::size_t(x);
        if (buf.id[i] == chart || buf.id[i] == item_buffer::none) return true;
        // The plane tests of radiosity/kernels.hpp (the GL passes emit the same kernels).
        const std::uint32_t k = buf.primitive[i];
        if (parallel) {
            // Distance along the light from p to the plane: upstream occludes.
            const glm::vec4 plane = world_plane_[k];
            return parallel_plane_beyond<float, glm::vec3>(p, glm::vec3(plane), plane.w, buf.depth[i], shot_.axis,
                                                           diagonal_);
        }
        const glm::vec4 plane = local_plane_[k];
        return item_plane_beyond<float, glm::vec3>(p, glm::vec3(plane), plane.w, buf.depth[i], diagonal_);
    }

    void to_local() {
        local_.clear();
        local_chart_.clear();
        local_plane_.clear();
        for (std::size_t k = 0; k < corners_.size(); ++k) {
            if (triangle_chart_[k] == shot_.chart) continue;
            std::array<glm::vec3, 3> l;
            for (int m = 0; m < 3; ++m)
                l[std::size_t(m)] =
                    to_shooter_frame<float, glm::vec3>(corners_[k][std::size_t(m)], shot_.position, t_, b_, shot_.axis);
            // Wholly behind the shooter's plane (both projections clip at this height): unseen.
            const float z_min = 1e-6f * diagonal_;
            if (l[0].z < z_min && l[1].z < z_min && l[2].z < z_min) continue;
            local_.push_back(l);
            local_chart_.push_back(triangle_chart_[k]);
            // Its plane n . x = d in the shooter's frame, d >= 0.
            local_plane_.push_back(shooter_plane<float, glm::vec3, glm::vec4>(glm::vec3(world_plane_[k]), l[0], t_, b_,
                                                                              shot_.axis));
        }
    }

    void draw_stereographic() {
        item_buffer& buf = buffers_[0];
        buf.reset(opt_.resolution, opt_.resolution);
        to_local();
        pieces_.clear();
        // Clipped just above the shooter's plane and tessellated by the sagitta rule
        // (radiosity/stereographic_tessellation.hpp, which the GL solver draws from too).
        const stereographic_tessellation how{float(opt_.resolution), opt_.tolerance_px, opt_.max_tessellation_depth};
        const float z_min = 1e-6f * diagonal_;
        std::vector<glm::vec3> poly, scratch;
        for (std::size_t k = 0; k < local_.size(); ++k)
            clip_and_tessellate_stereographic(
                local_[k], z_min, how, poly, scratch,
                [&](const std::array<glm::vec3, 3>& l, const std::array<glm::vec2, 3>& px) {
                    const float y0 = std::min({px[0].y, px[1].y, px[2].y}) - 1.f;
                    const float y1 = std::max({px[0].y, px[1].y, px[2].y}) + 1.f;
                    pieces_.push_back({{raster_vertex{px[0], glm::length(l[0])}, raster_vertex{px[1], glm::length(l[1])},
                                        raster_vertex{px[2], glm::length(l[2])}},
                                       std::uint32_t(k), y0, y1});
                });
        drawn_ = pieces_.size();
        // Scan the pieces in bands of rows, one task per band: each pixel sees the pieces in
        // the same order whatever the thread count.
        const int width = buf.width, band = 16;
        tbb::parallel_for(0, (buf.height + band - 1) / band, [&](int b) {
            const int y0 = b * band, y1 = std::min(buf.height, y0 + band);
            for (const piece& pc : pieces_) {
                if (pc.y1 < float(y0) || pc.y0 > float(y1)) continue;
                const glm::vec4 plane = local_plane_[pc.k];
                const glm::vec3 n(plane);
                // Depth: the distance along the pixel centre's direction w to the triangle's
                // plane, d / (n . w), exact where the interpolated radial distance would be off
                // by up to the triangle's bulge (centimetres for a ceiling light seen from the
                // floor); the interpolated one only where the plane is seen edge-on.
                scan_triangle_with(
                    buf, pc.v[0], pc.v[1], pc.v[2], local_chart_[pc.k],
                    [&](int x, int y, double attr) {
                        return item_plane_depth<float, glm::vec3>(
                            n, plane.w, pixel_direction_[std::size_t(y) * std::size_t(width) + std::size_t(x)],
                            float(attr));
                    },
                    pc.k, y0, y1);
            }
        });
    }

    void draw_hemicube() {
        to_local();
        const int res = opt_.resolution;
        std::array<std::size_t, 5> counts{};
        // Faces are independent: one task each, so the result does not depend on threads.
        tbb::parallel_for(0, 5, [&](int face) {
            item_buffer& buf = buffers_[std::size_t(face)];
            buf.reset(res, int(hemicube_face_rows(float(face), float(res))));
            const auto axes = hemicube_face_axes<glm::vec3>(face);
            // Clip to the face's frustum widened by two pixels (so no covered centre is lost),
            // and in front of the near plane; side faces keep the half above the horizon.
            const float near_z = 1e-6f * diagonal_;
            const float k = 1.f + 4.f / float(res);
            std::vector<glm::vec3> poly, scratch;
            const float bottom = face == 0 ? k : 4.f / float(res);
            for (std::size_t t = 0; t < local_.size(); ++t) {
                poly.clear();
                for (const glm::vec3& l : local_[t])
                    poly.push_back(frame_coords<float, glm::vec3>(l, axes[0], axes[1], axes[2]));
                // Most triangles miss most faces: reject those wholly outside one clip plane
                // before clipping.
                const auto outside = [&](auto plane_value) {
                    return plane_value(poly[0]) < 0.f && plane_value(poly[1]) < 0.f && plane_value(poly[2]) < 0.f;
                };
                if (outside([&](glm::vec3 q) { return q.z - near_z; }) || outside([&](glm::vec3 q) { return k * q.z - q.x; }) ||
                    outside([&](glm::vec3 q) { return k * q.z + q.x; }) || outside([&](glm::vec3 q) { return k * q.z - q.y; }) ||
                    outside([&](glm::vec3 q) { return bottom * q.z + q.y; }))
                    continue;
                detail::clip_polygon(poly, glm::vec3(0, 0, 1), near_z, scratch);
                detail::clip_polygon(poly, glm::vec3(-1, 0, k), 0.f, scratch);
                detail::clip_polygon(poly, glm::vec3(1, 0, k), 0.f, scratch);
                detail::clip_polygon(poly, glm::vec3(0, -1, k), 0.f, scratch);
                detail::clip_polygon(poly, glm::vec3(0, 1, bottom), 0.f, scratch);
                if (poly.size() < 3) continue;
                // (u, v) on the face (radiosity/kernels.hpp, as the lookup finds it) times its texels.
                const auto project = [&](glm::vec3 q) {
                    const glm::vec3 f = hemicube_coords_on_face<float, glm::vec3>(q, float(face));
                    return raster_vertex{glm::vec2(f.y * float(res), f.z * float(buf.height)), 1.f / q.z};
                };
                for (std::size_t f = 1; f + 1 < poly.size(); ++f) {
                    scan_triangle(buf, project(poly[0]), project(poly[f]), project(poly[f + 1]), local_chart_[t], true,
                                  std::uint32_t(t));
                    ++counts[std::size_t(face)];
                }
            }
        });
        drawn_ = counts[0] + counts[1] + counts[2] + counts[3] + counts[4];
    }

    void draw_parallel() {
        // Orthographic view along the light: the scene's bounding box projected across it
        // (radiosity/kernels.hpp, the GL solver's buffer too).
        const auto tb = orthonormal_basis<float, glm::vec3>(shot_.axis);
        t_ = tb[0];
        b_ = tb[1];
        const int res = opt_.parallel_resolution;
        std::tie(ortho_lo_, ortho_scale_) =
            parallel_item_window<float, glm::vec3, glm::vec2>(lo_, hi_, t_, b_, float(res));
        item_buffer& buf = buffers_[0];
        buf.reset(res, res);
        drawn_ = 0;
        for (std::size_t k = 0; k < corners_.size(); ++k) {
            std::array<raster_vertex, 3> v;
            for (int m = 0; m < 3; ++m) {
                const glm::vec3 p = corners_[k][std::size_t(m)];
                v[std::size_t(m)] = {parallel_item_coords<float, glm::vec3, glm::vec2>(p, t_, b_, ortho_lo_, ortho_scale_),
                                     glm::dot(p, shot_.axis)};
            }
            scan_triangle(buf, v[0], v[1], v[2], triangle_chart_[k], false, std::uint32_t(k));
            ++drawn_;
        }
    }

    options opt_;
    std::vector<std::array<glm::vec3, 3>> corners_;
    std::vector<std::uint32_t> triangle_chart_;
    std::vector<std::array<glm::vec3, 3>> local_;
    std::vector<std::uint32_t> local_chart_;
    std::vector<glm::vec3> pixel_direction_;
    struct piece {
        std::array<raster_vertex, 3> v;
        std::uint32_t k;   // local triangle
        float y0, y1;      // rows it may touch (widened by a pixel)
    };
    std::vector<piece> pieces_;
    std::vector<glm::vec4> world_plane_, local_plane_;  // (unit normal, offset) per triangle
    glm::vec3 lo_{0.f}, hi_{0.f};
    float diagonal_ = 1.f;
    shot_frame shot_{};
    glm::vec3 t_{1, 0, 0}, b_{0, 1, 0};
    glm::vec2 ortho_lo_{0.f};
    float ortho_scale_ = 1.f;
    std::array<item_buffer, 5> buffers_{};
    std::size_t drawn_ = 0;
};

}  // namespace bounce::cpu
