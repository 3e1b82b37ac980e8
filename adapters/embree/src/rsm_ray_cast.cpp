// Reflective shadow maps by ray casting from the light (Dachsbacher and Stamminger 2005,
// section 3.1, with Embree in place of the rasterizer).
#include <bounce/embree/rsm_ray_cast.hpp>

#include <bounce/camera.hpp>
#include <bounce/rectangle_solid_angle.hpp>
#include <bounce/rsm.hpp>

#include <array>
#include <cmath>
#include <variant>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/trigonometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bounce::embree {

void rsm_ray_cast_settings::validate() const {
    require(resolution >= 1 && resolution <= 8192, "resolution", "must lie in [1, 8192]");
    require(std::isfinite(max_single_map_cone_deg) && max_single_map_cone_deg > 0.f && max_single_map_cone_deg < 90.f,
            "max_single_map_cone_deg", "must lie in (0, 90)");
}

rsm_ray_caster::rsm_ray_caster(const accel& bvh, const scene_view& scene, rsm_ray_cast_settings settings)
    : bvh_(bvh), scene_(scene), settings_(settings) {
    settings_.validate();
    require_match(bvh_, scene_);
}

namespace {

struct face {
    glm::vec3 forward, up;
};
// +x, -x, +y, -y, +z, -z; each up is orthogonal to its axis.
constexpr std::array<face, 6> cube_faces{{{{1, 0, 0}, {0, 1, 0}},
                                          {{-1, 0, 0}, {0, 1, 0}},
                                          {{0, 1, 0}, {0, 0, -1}},
                                          {{0, -1, 0}, {0, 0, 1}},
                                          {{0, 0, 1}, {0, 1, 0}},
                                          {{0, 0, -1}, {0, 1, 0}}}};

// What a point-like light reflects through a texel of solid angle dw at a surface.
using texel_flux = glm::vec3 (*)(const packed_light&, const surface&, double dw);

glm::vec3 point_flux(const packed_light& l, const surface& s, double dw) {
    return point_light_texel_flux<float, glm::vec3>(s.albedo, s.position, s.normal, l.position(), l.intensity(),
                                                    float(dw));
}

glm::vec3 spot_flux(const packed_light& l, const surface& s, double dw) {
    return spot_light_texel_flux<float, glm::vec3>(s.albedo, s.position, s.normal, l.position(), l.direction(),
                                                   l.intensity(), l.cos_cone(), l.cosine_falloff(), float(dw));
}

void allocate(reflective_shadow_map& m, std::size_t r) {
    if (m.flux.width() == r && m.flux.height() == r) return;
    m.position = image<glm::vec3>(r, r);
    m.normal = image<glm::vec3>(r, r);
    m.flux = image<glm::vec3>(r, r);
}

// Fills `m` with one perspective map seen from `l`'s position along `forward`, field of
// view `fov_deg`, each texel's flux from `flux_of`.
void cast_perspective(const accel& bvh, const scene_view& scene, const packed_light& l, glm::vec3 forward,
                      glm::vec3 up, float fov_deg, std::size_t r, texel_flux flux_of, reflective_shadow_map& m) {
    camera cam;
    cam.position = l.position();
    cam.look_at = l.position() + forward;
    cam.up = up;
    cam.fov_y_deg = fov_deg;
    allocate(m, r);
    m.light_view_projection = cam.projection_matrix(r, r) * cam.view_matrix();
    m.orthographic = false;
    const double t = std::tan(glm::radians(double(fov_deg)) * 0.5);
    m.texel_size = float(2.0 * t / double(r));
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, r), [&](const tbb::blocked_range<std::size_t>& rows) {
        std::vector<ray> rays(r);
        std::vector<hit> hits(r);
        for (std::size_t y = rows.begin(); y != rows.end(); ++y) {
            for (std::size_t x = 0; x < r; ++x) {
                rays[x].origin = cam.position;
                rays[x].direction = cam.direction(float(x) + 0.5f, float(y) + 0.5f, r, r);
                rays[x].tnear = 0.f;
            }
            bvh.intersect(rays, hits, /*coherent=*/true);
            // Texel (x, y) spans [x0, x1] x [y0, y1] of the image plane at unit distance
            // (row 0 at the top, so y decreases down the map).
            const double y1 = (1.0 - 2.0 * double(y) / double(r)) * t, y0 = (1.0 - 2.0 * double(y + 1) / double(r)) * t;
            for (std::size_t x = 0; x < r; ++x) {
                if (!hits[x].found()) {
                    m.position(x, y) = glm::vec3(0.f);
                    m.normal(x, y) = -forward;
                    m.flux(x, y) = glm::vec3(0.f);
                    continue;
                }
                const surface s = surface_at(scene, rays[x], hits[x]);
                const double x0 = (2.0 * double(x) / double(r) - 1.0) * t, x1 = (2.0 * double(x + 1) / double(r) - 1.0) * t;
                const double dw = rectangle_solid_angle<double>(x0, y0, x1, y1);
                m.position(x, y) = s.position;
                m.normal(x, y) = s.normal;
                m.flux(x, y) = flux_of(l, s, dw);
            }
        }
    });
}

// Fills `m` with an orthographic map across the beam of the directional light `l`, covering
// the sphere of radius `radius` around `centre`.
void cast_orthographic(const accel& bvh, const scene_view& scene, const packed_light& l, glm::vec3 centre,
                       float radius, std::size_t r, reflective_shadow_map& m) {
    const glm::vec3 d = l.direction();
    const glm::vec3 up = std::abs(d.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 eye = centre - d * (2.f * radius);
    // glm::lookAt's frame: s = normalize(cross(f, up)), u = cross(s, f).
    const glm::vec3 right = glm::normalize(glm::cross(d, up));
    const glm::vec3 true_up = glm::cross(right, d);
    allocate(m, r);
    m.light_view_projection =
        glm::ortho(-radius, radius, -radius, radius, 0.f, 4.f * radius) * glm::lookAt(eye, centre, up);
    m.orthographic = true;
    const double side = 2.0 * double(radius) / double(r);
    m.texel_size = float(side);
    const float area = float(side * side);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, r), [&](const tbb::blocked_range<std::size_t>& rows) {
        std::vector<ray> rays(r);
        std::vector<hit> hits(r);
        for (std::size_t y = rows.begin(); y != rows.end(); ++y) {
            const float v = float(double(radius) - (double(y) + 0.5) * side);
            for (std::size_t x = 0; x < r; ++x) {
                const float u = float(-double(radius) + (double(x) + 0.5) * side);
                rays[x].origin = eye + u * right + v * true_up;
                rays[x].direction = d;
                rays[x].tnear = 0.f;
            }
            bvh.intersect(rays, hits, /*coherent=*/true);
            for (std::size_t x = 0; x < r; ++x) {
                if (!hits[x].found()) {
                    m.position(x, y) = glm::vec3(0.f);
                    m.normal(x, y) = -d;
                    m.flux(x, y) = glm::vec3(0.f);
                    continue;
                }
                const surface s = surface_at(scene, rays[x], hits[x]);
                m.position(x, y) = s.position;
                m.normal(x, y) = s.normal;
                m.flux(x, y) = directional_light_texel_flux<float, glm::vec3>(s.albedo, s.normal, d, l.intensity(), area);
            }
        }
    });
}

bool any_flux(const reflective_shadow_map& m) {
    for (std::size_t y = 0; y < m.flux.height(); ++y)
        for (const glm::vec3& f : m.flux.view().row(y))
            if (f.x > 0.f || f.y > 0.f || f.z > 0.f) return true;
    return false;
}

}  // namespace

void rsm_ray_caster::render(std::span<const light> lights) {
    validate_lights(lights, "lights");
    const std::size_t r = settings_.resolution;
    const auto [lo, hi] = scene_.bounds();
    const glm::vec3 centre = 0.5f * (lo + hi);
    // A little beyond the bounding sphere, so that rays start outside the scene.
    const float radius = std::max(0.5f * glm::length(hi - lo) * 1.001f, 1e-3f);
    std::size_t used = 0;
    auto next_map = [&](std::size_t light_index) -> reflective_shadow_map& {
        if (used == maps_.size()) maps_.emplace_back();
        reflective_shadow_map& m = maps_[used++];
        m.light = light_index;
        return m;
    };
    for (std::size_t i = 0; i < lights.size(); ++i) {
        const packed_light l = pack(lights[i]);
        if (l.kind() == light_kind::directional) {
            cast_orthographic(bvh_, scene_, l, centre, radius, r, next_map(i));
            continue;
        }
        const bool spot = l.kind() == light_kind::spot;
        const auto* sl = std::get_if<spot_light>(&lights[i]);
        if (spot && sl->cone_deg <= settings_.max_single_map_cone_deg) {
            const glm::vec3 axis = l.direction();
            const glm::vec3 up = std::abs(axis.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
            cast_perspective(bvh_, scene_, l, axis, up, 2.f * sl->cone_deg, r, spot_flux, next_map(i));
            continue;
        }
        for (const face& f : cube_faces) {
            reflective_shadow_map& m = next_map(i);
            cast_perspective(bvh_, scene_, l, f.forward, f.up, 90.f, r, spot ? spot_flux : point_flux, m);
            // A face the cone does not reach (or that sees nothing lit) adds nothing but work.
            if (!any_flux(m)) --used;
        }
    }
    maps_.resize(used);
    views_.clear();
    for (const auto& m : maps_) views_.push_back(m.view());
}

}  // namespace bounce::embree
