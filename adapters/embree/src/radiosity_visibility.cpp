// Ray-cast visibility for progressive radiosity: occlusion rays through an accel's BVH with a
// context filter that lets rays pass the receiver's and the shooter's charts.
#include <bounce/embree/radiosity_visibility.hpp>

#include <bounce/errors.hpp>

#include <embree3/rtcore.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace bounce::embree {

namespace {

// The intersect context of one query, extended by the charts and the shooter's chart (Embree
// passes the context through to filters unchanged; its documented way to hand them per-call
// data).
struct chart_context {
    RTCIntersectContext base;
    const std::uint32_t* chart;  // chart of each triangle of the accel
    std::uint32_t shooter;
};

// Rejects hits on triangles without a chart, on the ray's own chart (its id) and on the
// shooter's chart: the context filter of every query.
void pass_own_charts(const RTCFilterFunctionNArguments* args) {
    const auto* ctx = reinterpret_cast<const chart_context*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const std::uint32_t c = ctx->chart[RTCHitN_primID(args->hit, args->N, i)];
        if (c == radiosity_shot::none || c == ctx->shooter || c == RTCRayN_id(args->ray, args->N, i))
            args->valid[i] = 0;
    }
}

chart_context context_for(const std::vector<std::uint32_t>& chart, std::uint32_t shooter, bool coherent) {
    chart_context ctx;
    rtcInitIntersectContext(&ctx.base);
    ctx.base.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    ctx.base.filter = &pass_own_charts;
    ctx.chart = chart.data();
    ctx.shooter = shooter;
    return ctx;
}

}  // namespace

radiosity_visibility::radiosity_visibility(const accel& bvh, std::span<const std::uint32_t> chart_of_triangle,
                                           options opt)
    : bvh_(bvh), options_(opt) {
    if (chart_of_triangle.size() != bvh.triangle_count())
        throw parameter_error("chart_of_triangle", "needs one chart per triangle of the scene (" +
                                                       std::to_string(bvh.triangle_count()) + "), has " +
                                                       std::to_string(chart_of_triangle.size()));
    require(opt.end_tolerance >= 0.f && opt.end_tolerance < 0.5f, "options.end_tolerance", "must lie in [0, 0.5)");
    require(opt.ray_epsilon >= 0.f && std::isfinite(opt.ray_epsilon), "options.ray_epsilon", "must be finite and non-negative");
    chart_ = std::make_shared<const std::vector<std::uint32_t>>(chart_of_triangle.begin(), chart_of_triangle.end());
}

radiosity_visibility::radiosity_visibility(const device& dev, const scene_view& scene,
                                           std::span<const std::uint32_t> chart_of_triangle, options opt)
    : radiosity_visibility(accel(dev, scene), chart_of_triangle, opt) {}

void radiosity_visibility::set_shot(const radiosity_shot& shot) {
    require(std::isfinite(shot.position.x) && std::isfinite(shot.position.y) && std::isfinite(shot.position.z),
            "shot.position", "must be finite");
    require(!shot.parallel || glm::length(shot.axis) > 0.f, "shot.axis", "must be non-zero for a parallel shot");
    shot_ = shot;
    if (shot_.parallel) shot_.axis = glm::normalize(shot_.axis);
}

namespace {

// The end of a ray from `origin` to `point` (t = 1 at the point): short of the point by
// `tolerance` of the distance or by `epsilon`, the larger. A surface closer to the point than
// the accel's ray_epsilon does not shadow it: the reference integrator's rays leave a point
// ray_epsilon off its surface, so such a layer (a coplanar face of another chart a fraction of
// a millimetre over the element: the conference room's tables) never shadows it there.
float ray_end(const glm::vec3& origin, const glm::vec3& point, float tolerance, float epsilon) {
    const float d = glm::length(point - origin);
    return 1.f - std::max(tolerance, d > 0.f ? std::min(0.5f, epsilon / d) : 0.f);
}

// The ray for `point`: from the shooter to the point, t in [0, ray_end], or from the point
// against a parallel light, t in [epsilon, inf).
void set_ray(const radiosity_shot& shot, float tolerance, float epsilon, const glm::vec3& p, glm::vec3& origin,
             glm::vec3& dir, float& tnear, float& tfar) {
    if (shot.parallel) {
        origin = p;
        dir = -shot.axis;
        tnear = epsilon;
        tfar = std::numeric_limits<float>::infinity();
    } else {
        origin = shot.position;
        dir = p - shot.position;
        tnear = 0.f;
        tfar = ray_end(shot.position, p, tolerance, epsilon);
    }
}

}  // namespace

float radiosity_visibility::visible(const glm::vec3& point, std::uint32_t chart) const {
    chart_context ctx = context_for(*chart_, shot_.chart, false);
    glm::vec3 o, d;
    float tnear, tfar;
    set_ray(shot_, options_.end_tolerance, ray_epsilon(), point, o, d, tnear, tfar);
    RTCRay r;
    r.org_x = o.x;
    r.org_y = o.y;
    r.org_z = o.z;
    r.tnear = tnear;
    r.dir_x = d.x;
    r.dir_y = d.y;
    r.dir_z = d.z;
    r.time = 0.f;
    r.tfar = tfar;
    r.mask = ~0u;
    r.id = chart;
    r.flags = 0;
    rtcOccluded1(bvh_.native(), &ctx.base, &r);
    // rtcOccluded sets tfar to -inf when it finds an occluder.
    return (r.tfar < 0.f && std::isinf(r.tfar)) ? 0.f : 1.f;
}

float radiosity_visibility::visible_from(const glm::vec3& origin, std::uint32_t origin_chart, const glm::vec3& point,
                                         std::uint32_t chart) const {
    chart_context ctx = context_for(*chart_, origin_chart, false);
    RTCRay r;
    r.org_x = origin.x;
    r.org_y = origin.y;
    r.org_z = origin.z;
    r.tnear = 0.f;
    r.dir_x = point.x - origin.x;
    r.dir_y = point.y - origin.y;
    r.dir_z = point.z - origin.z;
    r.time = 0.f;
    r.tfar = ray_end(origin, point, options_.end_tolerance, ray_epsilon());
    r.mask = ~0u;
    r.id = chart;
    r.flags = 0;
    rtcOccluded1(bvh_.native(), &ctx.base, &r);
    return (r.tfar < 0.f && std::isinf(r.tfar)) ? 0.f : 1.f;
}

void radiosity_visibility::visible(std::span<const glm::vec3> points, std::span<const std::uint32_t> charts,
                                   std::span<float> out) const {
    require(charts.size() == points.size(), "charts", "must have one chart per point");
    require(out.size() == points.size(), "out", "must have one entry per point");
    chart_context ctx = context_for(*chart_, shot_.chart, true);  // coherent: a shot's rays share their origin
    const float epsilon = ray_epsilon();
    for (std::size_t first = 0; first < points.size(); first += 8) {
        const std::size_t n = std::min<std::size_t>(8, points.size() - first);
        alignas(32) std::array<int, 8> valid{};
        alignas(32) RTCRay8 r;
        for (std::size_t i = 0; i < 8; ++i) {
            const std::size_t k = first + std::min(i, n - 1);
            glm::vec3 o, d;
            float tnear, tfar;
            set_ray(shot_, options_.end_tolerance, epsilon, points[k], o, d, tnear, tfar);
            valid[i] = i < n ? -1 : 0;
            r.org_x[i] = o.x;
            r.org_y[i] = o.y;
            r.org_z[i] = o.z;
            r.tnear[i] = tnear;
            r.dir_x[i] = d.x;
            r.dir_y[i] = d.y;
            r.dir_z[i] = d.z;
            r.time[i] = 0.f;
            r.tfar[i] = tfar;
            r.mask[i] = ~0u;
            r.id[i] = charts[k];
            r.flags[i] = 0;
        }
        rtcOccluded8(valid.data(), bvh_.native(), &ctx.base, &r);
        for (std::size_t i = 0; i < n; ++i)
            out[first + i] = (r.tfar[i] < 0.f && std::isinf(r.tfar[i])) ? 0.f : 1.f;
    }
}

}  // namespace bounce::embree
