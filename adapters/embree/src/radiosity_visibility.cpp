// Ray-cast visibility for progressive radiosity: an Embree scene of its own with an
// occlusion filter that lets rays pass the receiver's and the shooter's charts.
#include <bounce/embree/radiosity_visibility.hpp>

#include <bounce/errors.hpp>

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace bounce::embree {

namespace detail {

struct radiosity_scene {
    device owner;
    RTCScene handle = nullptr;
    std::vector<std::uint32_t> chart;  // chart of each Embree primitive

    explicit radiosity_scene(const device& d) : owner(d) {}
    ~radiosity_scene() {
        if (handle) rtcReleaseScene(handle);
    }
    radiosity_scene(const radiosity_scene&) = delete;
    radiosity_scene& operator=(const radiosity_scene&) = delete;
};

}  // namespace detail

namespace {

// The intersect context of one query, extended by the shooter's chart (Embree passes the
// context through to filters unchanged; its documented way to hand them per-call data).
struct chart_context {
    RTCIntersectContext base;
    std::uint32_t shooter;
};

// Rejects hits on the ray's own chart (its id) and on the shooter's chart.
void pass_own_charts(const RTCFilterFunctionNArguments* args) {
    const auto* scene = static_cast<const detail::radiosity_scene*>(args->geometryUserPtr);
    const auto* ctx = reinterpret_cast<const chart_context*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const std::uint32_t c = scene->chart[RTCHitN_primID(args->hit, args->N, i)];
        if (c == ctx->shooter || c == RTCRayN_id(args->ray, args->N, i)) args->valid[i] = 0;
    }
}

}  // namespace

radiosity_visibility::radiosity_visibility(const device& dev, const scene_view& scene,
                                           std::span<const std::uint32_t> chart_of_triangle, options opt)
    : options_(opt) {
    scene.validate_mesh();
    if (chart_of_triangle.size() != scene.triangles.size())
        throw parameter_error("chart_of_triangle", "needs one chart per triangle of the scene (" +
                                                       std::to_string(scene.triangles.size()) + "), has " +
                                                       std::to_string(chart_of_triangle.size()));
    require(opt.end_tolerance >= 0.f && opt.end_tolerance < 0.5f, "options.end_tolerance", "must lie in [0, 0.5)");
    auto s = std::make_shared<detail::radiosity_scene>(dev);
    RTCDevice d = dev.native();
    std::vector<std::uint32_t> kept;
    for (std::size_t t = 0; t < scene.triangles.size(); ++t)
        if (chart_of_triangle[t] != radiosity_shot::none) kept.push_back(std::uint32_t(t));
    s->handle = rtcNewScene(d);
    dev.check("rtcNewScene");
    rtcSetSceneFlags(s->handle, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(s->handle, RTC_BUILD_QUALITY_HIGH);
    if (!kept.empty()) {
        RTCGeometry g = rtcNewGeometry(d, RTC_GEOMETRY_TYPE_TRIANGLE);
        dev.check("rtcNewGeometry");
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), 3 * kept.size()));
        auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                    3 * sizeof(unsigned), kept.size()));
        if (!v || !idx) {
            rtcReleaseGeometry(g);
            dev.check("rtcSetNewGeometryBuffer");
            throw embree_error(RTC_ERROR_OUT_OF_MEMORY, "", "rtcSetNewGeometryBuffer");
        }
        s->chart.resize(kept.size());
        for (std::size_t k = 0; k < kept.size(); ++k) {
            const auto& tri = scene.triangles[kept[k]];
            for (int c = 0; c < 3; ++c) {
                const glm::vec3 p = scene.positions[tri[c]];
                for (int a = 0; a < 3; ++a) v[9 * k + 3 * std::size_t(c) + std::size_t(a)] = p[a];
                idx[3 * k + std::size_t(c)] = unsigned(3 * k + std::size_t(c));
            }
            s->chart[k] = chart_of_triangle[kept[k]];
        }
        rtcSetGeometryUserData(g, s.get());
        rtcSetGeometryOccludedFilterFunction(g, &pass_own_charts);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(s->handle, g, 0);
        rtcReleaseGeometry(g);
        dev.check("rtcCommitGeometry");
    }
    rtcCommitScene(s->handle);
    dev.check("rtcCommitScene");
    scene_ = std::move(s);
}

void radiosity_visibility::set_shot(const radiosity_shot& shot) {
    require(std::isfinite(shot.position.x) && std::isfinite(shot.position.y) && std::isfinite(shot.position.z),
            "shot.position", "must be finite");
    require(!shot.parallel || glm::length(shot.axis) > 0.f, "shot.axis", "must be non-zero for a parallel shot");
    shot_ = shot;
    if (shot_.parallel) shot_.axis = glm::normalize(shot_.axis);
}

namespace {

// The ray for `point`: from the shooter to the point, t in [0, 1 - tolerance], or from the
// point against a parallel light, t in [0, inf).
void set_ray(const radiosity_shot& shot, float tolerance, const glm::vec3& p, glm::vec3& origin, glm::vec3& dir,
             float& tfar) {
    if (shot.parallel) {
        origin = p;
        dir = -shot.axis;
        tfar = std::numeric_limits<float>::infinity();
    } else {
        origin = shot.position;
        dir = p - shot.position;
        tfar = 1.f - tolerance;
    }
}

}  // namespace

float radiosity_visibility::visible(const glm::vec3& point, std::uint32_t chart) const {
    chart_context ctx;
    rtcInitIntersectContext(&ctx.base);
    ctx.shooter = shot_.chart;
    glm::vec3 o, d;
    float tfar;
    set_ray(shot_, options_.end_tolerance, point, o, d, tfar);
    RTCRay r;
    r.org_x = o.x;
    r.org_y = o.y;
    r.org_z = o.z;
    r.tnear = 0.f;
    r.dir_x = d.x;
    r.dir_y = d.y;
    r.dir_z = d.z;
    r.time = 0.f;
    r.tfar = tfar;
    r.mask = ~0u;
    r.id = chart;
    r.flags = 0;
    rtcOccluded1(scene_->handle, &ctx.base, &r);
    // rtcOccluded sets tfar to -inf when it finds an occluder.
    return (r.tfar < 0.f && std::isinf(r.tfar)) ? 0.f : 1.f;
}

void radiosity_visibility::visible(std::span<const glm::vec3> points, std::span<const std::uint32_t> charts,
                                   std::span<float> out) const {
    require(charts.size() == points.size(), "charts", "must have one chart per point");
    require(out.size() == points.size(), "out", "must have one entry per point");
    chart_context ctx;
    rtcInitIntersectContext(&ctx.base);
    ctx.base.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // a shot's rays share their origin
    ctx.shooter = shot_.chart;
    for (std::size_t first = 0; first < points.size(); first += 8) {
        const std::size_t n = std::min<std::size_t>(8, points.size() - first);
        alignas(32) std::array<int, 8> valid{};
        alignas(32) RTCRay8 r;
        for (std::size_t i = 0; i < 8; ++i) {
            const std::size_t k = first + std::min(i, n - 1);
            glm::vec3 o, d;
            float tfar;
            set_ray(shot_, options_.end_tolerance, points[k], o, d, tfar);
            valid[i] = i < n ? -1 : 0;
            r.org_x[i] = o.x;
            r.org_y[i] = o.y;
            r.org_z[i] = o.z;
            r.tnear[i] = 0.f;
            r.dir_x[i] = d.x;
            r.dir_y[i] = d.y;
            r.dir_z[i] = d.z;
            r.time[i] = 0.f;
            r.tfar[i] = tfar;
            r.mask[i] = ~0u;
            r.id[i] = charts[k];
            r.flags[i] = 0;
        }
        rtcOccluded8(valid.data(), scene_->handle, &ctx.base, &r);
        for (std::size_t i = 0; i < n; ++i)
            out[first + i] = (r.tfar[i] < 0.f && std::isinf(r.tfar[i])) ? 0.f : 1.f;
    }
}

}  // namespace bounce::embree
