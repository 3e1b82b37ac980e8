// The CPU item buffers of radiosity visibility: the scan converter's fill rule, and the
// stereographic and hemicube buffers against an exact per-pixel ray cast.
#include "radiosity_scenes.hpp"
#include "ray_cast_visibility.hpp"

#include <bounce/cpu/radiosity_item_buffer.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/radiosity/kernels.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <iostream>
#include <numbers>

using namespace bounce;
using namespace bounce::radiosity_test;

namespace {

// Coverage count per pixel of a set of triangles drawn one by one into fresh buffers.
std::vector<int> coverage(const std::vector<std::array<glm::vec2, 3>>& tris, int w, int h) {
    std::vector<int> count(std::size_t(w) * std::size_t(h), 0);
    cpu::item_buffer buf;
    for (const auto& t : tris) {
        buf.reset(w, h);
        cpu::scan_triangle(buf, {t[0], 0.f}, {t[1], 0.f}, {t[2], 0.f}, 7);
        for (std::size_t i = 0; i < count.size(); ++i) count[i] += buf.id[i] == 7 ? 1 : 0;
    }
    return count;
}

// Sum over the scene's triangle edges of their length in pixels once projected by `project`
// (sampled at 64 points; pieces with an end outside `keep` are left out).
template <class Project, class Keep>
double projected_edge_length(const owned_scene& s, const Project& project, const Keep& keep) {
    double total = 0;
    for (const auto& tri : s.triangles)
        for (int k = 0; k < 3; ++k) {
            const glm::vec3 a = s.positions[tri[k]], b = s.positions[tri[(k + 1) % 3]];
            for (int i = 0; i < 64; ++i) {
                const glm::vec3 p = a + (b - a) * (float(i) / 64), q = a + (b - a) * (float(i + 1) / 64);
                if (keep(p) && keep(q)) total += glm::length(project(p) - project(q));
            }
        }
    return total;
}

}  // namespace

TEST_CASE("the top-left rule covers each pixel of a mesh exactly once, whatever its triangulation",
          "[radiosity][raster]") {
    // An octagon with vertices and centre on pixel centres and on pixel corners, so that many
    // centres lie exactly on edges: triangulated as a fan around its centre and as a fan from
    // its first vertex. Each covers every pixel at most once, and both cover the same pixels.
    const int w = 40, h = 40;
    const glm::vec2 c(20.5f, 20.5f);
    std::vector<glm::vec2> ring;
    for (int k = 0; k < 8; ++k) {
        const double a = 2 * std::numbers::pi * k / 8;
        ring.emplace_back(std::round(c.x + 15 * std::cos(a)) + (k % 2 ? 0.5f : 0.f),
                          std::round(c.y + 15 * std::sin(a)) + (k % 2 ? 0.5f : 0.f));
    }
    std::vector<std::array<glm::vec2, 3>> around_centre, from_vertex;
    for (int k = 0; k < 8; ++k) around_centre.push_back({c, ring[std::size_t(k)], ring[std::size_t((k + 1) % 8)]});
    for (int k = 1; k + 1 < 8; ++k) from_vertex.push_back({ring[0], ring[std::size_t(k)], ring[std::size_t(k + 1)]});
    // The other winding for half of them: the rule must not depend on it.
    for (std::size_t k = 0; k < from_vertex.size(); k += 2) std::swap(from_vertex[k][1], from_vertex[k][2]);
    const auto a = coverage(around_centre, w, h), b = coverage(from_vertex, w, h);
    int covered = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        CHECK(a[i] <= 1);
        CHECK(b[i] <= 1);
        CHECK(a[i] == b[i]);
        covered += a[i];
    }
    // The octagon's area is about 2 * 15^2 * sqrt(2) = 636 pixels.
    CHECK(covered > 550);
    CHECK(covered < 720);
}

TEST_CASE("two triangles sharing an edge through pixel centres split those pixels between them",
          "[radiosity][raster]") {
    // A square split along its diagonal, the diagonal passing through every centre (i + 1/2, i + 1/2).
    const std::vector<std::array<glm::vec2, 3>> halves = {{glm::vec2(0, 0), glm::vec2(16, 0), glm::vec2(16, 16)},
                                                          {glm::vec2(0, 0), glm::vec2(16, 16), glm::vec2(0, 16)}};
    const auto n = coverage(halves, 16, 16);
    for (int v : n) CHECK(v == 1);
}

TEST_CASE("the nearer triangle wins the item buffer", "[radiosity][raster]") {
    cpu::item_buffer buf;
    buf.reset(8, 8);
    cpu::scan_triangle(buf, {{0, 0}, 2.f}, {{8, 0}, 2.f}, {{0, 8}, 2.f}, 1);
    cpu::scan_triangle(buf, {{0, 0}, 1.f}, {{8, 0}, 1.f}, {{0, 8}, 1.f}, 2);
    cpu::scan_triangle(buf, {{0, 0}, 3.f}, {{8, 0}, 3.f}, {{0, 8}, 3.f}, 3);
    CHECK(buf.id[0] == 2);
    CHECK(buf.depth[0] == 1.f);
}

TEST_CASE("the stereographic item buffer matches an exact ray cast except within the tolerance of edges",
          "[radiosity][raster]") {
    // Pixels can differ from the exact answer only where the tessellated edges (chords of the
    // projected arcs, within tolerance_px of them, T-junction cracks included) or the
    // 1/256-pixel snapping put a centre on the wrong side: within tol + 1/128 px of a
    // projected edge. A band that wide on both sides of every edge holds at most
    // 2 (tol + 1/128) L centres in expectation, L the projected edge length in pixels, plus
    // a few at vertices; the check allows that.
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 2000});
    const int res = 256;
    struct case_ {
        glm::vec3 position, normal;
        float tolerance;
    };
    for (const case_ shot : {case_{{0.f, 1.98f, -0.03f}, {0, -1, 0}, 0.25f}, case_{{0.f, 1.98f, -0.03f}, {0, -1, 0}, 0.05f},
                             case_{{-1.0f, 1.0f, 0.2f}, glm::normalize(glm::vec3(1, -0.2f, 0)), 0.25f},
                             case_{{0.3f, 0.01f, 0.9f}, glm::normalize(glm::vec3(0, 1, -1)), 0.25f}}) {
        cpu::item_buffer_visibility vis(scene.view(), atlas,
                                        {.projection = cpu::item_projection::stereographic, .resolution = res,
                                         .tolerance_px = shot.tolerance});
        vis.begin_shot({shot.position, shot.normal, false, cpu::shot_frame::none});
        const cpu::item_buffer& buf = vis.buffers()[0];
        const auto tb = orthonormal_basis<float, glm::vec3>(shot.normal);
        int differ = 0, inside = 0;
        for (int y = 0; y < res; ++y)
            for (int x = 0; x < res; ++x) {
                const glm::dvec2 q((x + 0.5) / res * 2 - 1, (y + 0.5) / res * 2 - 1);
                if (glm::dot(q, q) >= 1) continue;
                ++inside;
                const glm::dvec3 l = stereographic_direction<double, glm::dvec3, glm::dvec2>(q);
                const glm::dvec3 d = glm::dvec3(tb[0]) * l.x + glm::dvec3(tb[1]) * l.y + glm::dvec3(shot.normal) * l.z;
                const auto exact = nearest_chart(scene, atlas, glm::dvec3(shot.position), glm::normalize(d), lightmap_atlas::none);
                differ += exact.first != buf.id[std::size_t(y) * res + std::size_t(x)] ? 1 : 0;
            }
        const auto project = [&](glm::vec3 p) {
            const glm::vec3 l = to_shooter_frame<float, glm::vec3>(p, shot.position, tb[0], tb[1], shot.normal);
            return stereographic_item_coords<float, glm::vec3, glm::vec2>(l) * float(res);
        };
        const auto in_front = [&](glm::vec3 p) { return glm::dot(p - shot.position, shot.normal) > 1e-4f; };
        const double length = projected_edge_length(scene, project, in_front);
        const double bound = 2 * (shot.tolerance + 1.0 / 128) * length + 16;
        std::cout << "stereographic " << res << "^2, tolerance " << shot.tolerance << " px: " << differ << " of "
                  << inside << " pixels differ from the ray cast (bound " << bound << "), " << vis.drawn_triangles()
                  << " triangles drawn\n";
        CHECK(differ <= bound);
    }
}

TEST_CASE("the hemicube's faces match an exact ray cast except at snapped edges", "[radiosity][raster]") {
    // Perspective faces draw straight edges exactly; only the 1/256-pixel snapping and depth
    // rounding at contact lines remain: centres within 1/128 px of a projected edge.
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 2000});
    const int res = 128;
    const glm::vec3 position(0.2f, 1.2f, 0.4f), normal = glm::normalize(glm::vec3(-0.3f, -1.f, 0.2f));
    cpu::item_buffer_visibility vis(scene.view(), atlas, {.projection = cpu::item_projection::hemicube, .resolution = res});
    vis.begin_shot({position, normal, false, cpu::shot_frame::none});
    const auto tb = orthonormal_basis<float, glm::vec3>(normal);
    int differ = 0, pixels = 0;
    double length = 0;
    for (int face = 0; face < 5; ++face) {
        const cpu::item_buffer& buf = vis.buffers()[std::size_t(face)];
        for (int y = 0; y < buf.height; ++y)
            for (int x = 0; x < buf.width; ++x) {
                const glm::dvec3 l = hemicube_direction<double, glm::dvec3>(double(face), (x + 0.5) / buf.width,
                                                                           (y + 0.5) / buf.height);
                const glm::dvec3 d = glm::dvec3(tb[0]) * l.x + glm::dvec3(tb[1]) * l.y + glm::dvec3(normal) * l.z;
                const auto exact = nearest_chart(scene, atlas, glm::dvec3(position), glm::normalize(d), lightmap_atlas::none);
                differ += exact.first != buf.id[std::size_t(y) * std::size_t(buf.width) + std::size_t(x)] ? 1 : 0;
                ++pixels;
            }
        const auto axes = hemicube_face_axes<glm::vec3>(face);
        const auto local = [&](glm::vec3 p) {
            const glm::vec3 l = to_shooter_frame<float, glm::vec3>(p, position, tb[0], tb[1], normal);
            return frame_coords<float, glm::vec3>(l, axes[0], axes[1], axes[2]);
        };
        const auto project = [&](glm::vec3 p) {
            const glm::vec3 q = local(p);
            return glm::vec2(q.x / q.z, q.y / q.z) * (float(res) / 2);
        };
        // Edges seen on this face (a generous test: in front of it, within twice its frustum).
        const auto on_face = [&](glm::vec3 p) {
            const glm::vec3 q = local(p);
            return q.z > 1e-3f && std::abs(q.x) < 2 * q.z && std::abs(q.y) < 2 * q.z;
        };
        length += projected_edge_length(scene, project, on_face);
    }
    const double bound = 2 * (1.0 / 128) * length + 16;
    std::cout << "hemicube " << res << "^2 per face: " << differ << " of " << pixels
              << " pixels differ from the ray cast (bound " << bound << ")\n";
    CHECK(differ <= bound);
}

TEST_CASE("item-buffer visibility disagrees with exact visibility only at the buffer's boundaries",
          "[radiosity][raster]") {
    // An element the item buffer gets wrong lies in a pixel next to (3 x 3) a pixel of another
    // chart: the item buffer's error is confined to its edges, never a whole region.
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 3000});
    for (const auto projection : {cpu::item_projection::stereographic, cpu::item_projection::hemicube}) {
        cpu::item_buffer_visibility vis(scene.view(), atlas, {.projection = projection, .resolution = 256});
        ray_cast_visibility exact{&scene, &atlas};
        std::size_t asked = 0, wrong = 0;
        for (std::size_t shooter : {std::size_t(0), atlas.size() / 3, atlas.size() / 2, atlas.size() - 1}) {
            const cpu::shot_frame shot{atlas.position[shooter], atlas.normal[shooter], false, atlas.chart[shooter]};
            vis.begin_shot(shot);
            exact.begin_shot(shot);
            for (std::size_t e = 0; e < atlas.size(); ++e) {
                if (glm::dot(atlas.position[e] - shot.position, shot.axis) <= 1e-4f) continue;
                ++asked;
                if (vis.visible(atlas.position[e], atlas.chart[e]) == exact.visible(atlas.position[e], atlas.chart[e]))
                    continue;
                ++wrong;
                // Find its pixel and look around it.
                const auto tb = orthonormal_basis<float, glm::vec3>(shot.axis);
                const glm::vec3 l = to_shooter_frame<float, glm::vec3>(atlas.position[e], shot.position, tb[0], tb[1], shot.axis);
                const cpu::item_buffer* buf;
                glm::vec2 xy;
                if (projection == cpu::item_projection::stereographic) {
                    buf = &vis.buffers()[0];
                    xy = stereographic_item_texel<float, glm::vec3, glm::vec2>(l, 256.f);
                } else {
                    const glm::vec3 f = hemicube_item_texel<float, glm::vec3>(l, 256.f);
                    buf = &vis.buffers()[std::size_t(f.x)];
                    xy = {f.y, f.z};
                }
                const int x = int(xy.x), y = int(xy.y);
                bool boundary = false;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int xx = std::clamp(x + dx, 0, buf->width - 1), yy = std::clamp(y + dy, 0, buf->height - 1);
                        boundary = boundary || buf->id[std::size_t(yy) * std::size_t(buf->width) + std::size_t(xx)] !=
                                                   buf->id[std::size_t(y) * std::size_t(buf->width) + std::size_t(x)];
                    }
                CHECK(boundary);
            }
        }
        std::cout << (projection == cpu::item_projection::stereographic ? "stereographic" : "hemicube")
                  << " 256: " << wrong << " of " << asked << " element visibilities differ from the ray cast\n";
        CHECK(asked > 0);
    }
}

TEST_CASE("bad item-buffer options raise parameter_error naming them", "[radiosity][raster][errors]") {
    const auto scene = cornell_box();
    const auto atlas = build_lightmap_atlas(scene.view(), {.elements = 200});
    using opts = cpu::item_buffer_visibility::options;
    const auto named = [&](const opts& o, const char* name) {
        try {
            cpu::item_buffer_visibility vis(scene.view(), atlas, o);
            FAIL("no exception");
        } catch (const parameter_error& e) {
            CHECK(e.parameter() == name);
        }
    };
    named({.resolution = 4}, "options.resolution");
    named({.projection = cpu::item_projection::hemicube, .resolution = 129}, "options.resolution");
    named({.tolerance_px = 0.f}, "options.tolerance_px");
    named({.max_tessellation_depth = 17}, "options.max_tessellation_depth");
    const auto other = closed_box(1.f, 0.5f, 1.f);
    try {
        cpu::item_buffer_visibility vis(other.view(), atlas, {});
        FAIL("no exception");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "atlas");
    }
}
