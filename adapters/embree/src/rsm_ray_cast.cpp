// Reflective shadow maps by ray casting from the light (Dachsbacher and Stamminger 2005,
// section 3.1, with Embree in place of the rasterizer).
#include <bounce/embree/rsm_ray_cast.hpp>

#include <bounce/camera.hpp>
#include <bounce/indirect/rsm.hpp>
#include <bounce/indirect/rsm_layout.hpp>

#include <array>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/trigonometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bounce::embree {

rsm_ray_caster::rsm_ray_caster(const accel& bvh, const scene_view& scene, rsm_ray_cast_settings settings)
    : bvh_(bvh), scene_(scene), settings_(settings) {
    settings_.validate();
    require_match(bvh_, scene_);
}

namespace {

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

// Fills the r x r texels of `m`, rows on every core: texel (x, y) is what ray_of(x, y)
// hits, its flux flux_at(surface, x, y); a texel whose ray hits nothing is empty (no
// position, flux or light: normal `empty_normal`).
template <class RayOf, class FluxAt>
void cast_texels(const accel& bvh, const scene_view& scene, std::size_t r, glm::vec3 empty_normal, RayOf ray_of,
                 FluxAt flux_at, reflective_shadow_map& m) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, r), [&](const tbb::blocked_range<std::size_t>& rows) {
        std::vector<ray> rays(r);
        std::vector<hit> hits(r);
        for (std::size_t y = rows.begin(); y != rows.end(); ++y) {
            for (std::size_t x = 0; x < r; ++x) rays[x] = ray_of(x, y);
            bvh.intersect(rays, hits, /*coherent=*/true);
            for (std::size_t x = 0; x < r; ++x) {
                if (!hits[x].found()) {
                    m.position(x, y) = glm::vec3(0.f);
                    m.normal(x, y) = empty_normal;
                    m.flux(x, y) = glm::vec3(0.f);
                    continue;
                }
                const surface s = surface_at(scene, rays[x], hits[x]);
                m.position(x, y) = s.position;
                m.normal(x, y) = s.normal;
                m.flux(x, y) = flux_at(s, x, y);
            }
        }
    });
}

// Fills `m` with the perspective map `layout` of `l`, each texel's flux from `flux_of`.
void cast_perspective(const accel& bvh, const scene_view& scene, const packed_light& l, const rsm_map_layout& layout,
                      std::size_t r, texel_flux flux_of, reflective_shadow_map& m) {
    const camera cam = layout.perspective_camera();
    allocate(m, r);
    m.light_view_projection = layout.light_view_projection;
    m.orthographic = false;
    m.texel_size = layout.texel_size;
    const double t = std::tan(glm::radians(double(layout.fov_deg)) * 0.5);
    cast_texels(
        bvh, scene, r, -layout.forward,
        [&](std::size_t x, std::size_t y) {
            return ray{.origin = cam.position, .direction = cam.direction(float(x) + 0.5f, float(y) + 0.5f, r, r)};
        },
        [&](const surface& s, std::size_t x, std::size_t y) {
            return flux_of(l, s, rsm_texel_solid_angle(t, r, x, y));
        },
        m);
}

// Fills `m` with the orthographic map `layout` across the beam of the directional light `l`.
void cast_orthographic(const accel& bvh, const scene_view& scene, const packed_light& l,
                       const rsm_map_layout& layout, std::size_t r, reflective_shadow_map& m) {
    const glm::vec3 d = layout.forward;
    const glm::vec3 eye = layout.position;
    const float radius = layout.radius;
    // glm::lookAt's frame: s = normalize(cross(f, up)), u = cross(s, f).
    const glm::vec3 right = glm::normalize(glm::cross(d, layout.up));
    const glm::vec3 true_up = glm::cross(right, d);
    allocate(m, r);
    m.light_view_projection = layout.light_view_projection;
    m.orthographic = true;
    const double side = 2.0 * double(radius) / double(r);
    m.texel_size = layout.texel_size;
    const float area = float(side * side);
    cast_texels(
        bvh, scene, r, -d,
        [&](std::size_t x, std::size_t y) {
            const float u = float(-double(radius) + (double(x) + 0.5) * side);
            const float v = float(double(radius) - (double(y) + 0.5) * side);
            return ray{.origin = eye + u * right + v * true_up, .direction = d};
        },
        [&](const surface& s, std::size_t, std::size_t) {
            return directional_light_texel_flux<float, glm::vec3>(s.albedo, s.normal, d, l.intensity(), area);
        },
        m);
}

bool any_flux(const reflective_shadow_map& m) {
    for (std::size_t y = 0; y < m.flux.height(); ++y)
        for (const glm::vec3& f : m.flux.view().row(y))
            if (f.x > 0.f || f.y > 0.f || f.z > 0.f) return true;
    return false;
}

}  // namespace

void rsm_ray_caster::render(std::span<const light> lights) {
    const std::size_t r = settings_.resolution;
    const auto [lo, hi] = scene_.bounds();
    const std::vector<rsm_map_layout> layouts = rsm_layout(lights, lo, hi, settings_);
    std::size_t used = 0;
    for (const rsm_map_layout& layout : layouts) {
        if (used == maps_.size()) maps_.emplace_back();
        reflective_shadow_map& m = maps_[used++];
        m.light = layout.light;
        const packed_light l = pack(lights[layout.light]);
        if (layout.orthographic) {
            cast_orthographic(bvh_, scene_, l, layout, r, m);
            continue;
        }
        const bool spot = l.kind() == light_kind::spot;
        cast_perspective(bvh_, scene_, l, layout, r, spot ? spot_flux : point_flux, m);
        // A cube face that sees nothing lit (or that a spot's cone does not reach) adds
        // nothing but work; a single spot map is kept whatever it sees.
        if (layout.cube_face >= 0 && !any_flux(m)) --used;
    }
    maps_.resize(used);
    views_.clear();
    for (const auto& m : maps_) views_.push_back(m.view());
}

}  // namespace bounce::embree
