// Embree 3 device and BVH behind RAII, and the shading attributes of a hit.
#include <bounce/embree/accel.hpp>

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <mutex>
#include <vector>

#include <glm/geometric.hpp>

namespace bounce::embree {

namespace {

const char* error_name(int code) {
    switch (code) {
    case RTC_ERROR_NONE: return "RTC_ERROR_NONE";
    case RTC_ERROR_UNKNOWN: return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT: return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION: return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY: return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU: return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED: return "RTC_ERROR_CANCELLED";
    default: return "RTC_ERROR (unknown code)";
    }
}

std::string describe(int code, const std::string& message, std::string_view during) {
    std::string s = "bounce::embree: ";
    s += during;
    s += ": ";
    s += error_name(code);
    if (!message.empty()) s += ": " + message;
    return s;
}

}  // namespace

embree_error::embree_error(int code, std::string message, std::string_view during)
    : bounce::error(describe(code, message, during)), code_(code), message_(std::move(message)) {}

namespace detail {

// The device and the last message its error callback received. Embree calls the callback
// on the thread whose call failed, before that call returns; check() then reads the code
// (per thread in Embree) and this message.
struct device_state {
    RTCDevice handle = nullptr;
    std::string config;  // rtcNewDevice's configuration string; empty for the default
    std::mutex mutex;
    std::string last_message;

    ~device_state() {
        if (handle) rtcReleaseDevice(handle);
    }
    static void on_error(void* user, RTCError, const char* message) {
        auto* self = static_cast<device_state*>(user);
        const std::lock_guard lock(self->mutex);
        self->last_message = message ? message : "";
    }
};

struct scene_state {
    std::shared_ptr<device_state> device;  // keeps the device alive as long as the scene
    RTCScene handle = nullptr;
    std::size_t triangles = 0;
    float diagonal = 0.f, max_coordinate = 0.f;

    ~scene_state() {
        if (handle) rtcReleaseScene(handle);
    }
};

}  // namespace detail

namespace {

// Throws parameter_error unless `config` is a list of options rtcNewDevice documents, each
// with a value of its documented form (Embree itself skips what it does not know).
void check_device_config(std::string_view config, std::string_view source) {
    auto is_count = [](std::string_view v) {
        return !v.empty() && v.size() <= 6 &&
               std::all_of(v.begin(), v.end(), [](char c) { return c >= '0' && c <= '9'; });
    };
    auto one_of = [](std::string_view v, std::initializer_list<std::string_view> allowed) {
        return std::find(allowed.begin(), allowed.end(), v) != allowed.end();
    };
    std::size_t start = 0;
    while (start <= config.size()) {
        const std::size_t end = std::min(config.find(',', start), config.size());
        const std::string_view option = config.substr(start, end - start);
        const std::size_t eq = option.find('=');
        const std::string_view key = option.substr(0, eq);
        const std::string_view value = eq == std::string_view::npos ? std::string_view() : option.substr(eq + 1);
        const std::string name(source), quoted = "option '" + std::string(option) + "' ";
        if (eq == std::string_view::npos || key.empty() || value.empty())
            throw parameter_error(name, quoted + "is not key=value (options are separated by commas)");
        const char* expected = nullptr;  // the documented values of `key`, when `value` is not one
        if (one_of(key, {"threads", "user_threads"})) {
            if (!is_count(value)) expected = "a count";
        } else if (one_of(key, {"set_affinity", "start_threads", "hugepages", "enable_selockmemoryprivilege"})) {
            if (!one_of(value, {"0", "1"})) expected = "0 or 1";
        } else if (one_of(key, {"isa", "max_isa"})) {
            if (!one_of(value, {"sse2", "sse4.2", "avx", "avx2", "avx512"}))
                expected = "sse2, sse4.2, avx, avx2 or avx512";
        } else if (key == "verbose") {
            if (!one_of(value, {"0", "1", "2", "3"})) expected = "0 to 3";
        } else if (key == "frequency_level") {
            if (!one_of(value, {"simd128", "simd256", "simd512"})) expected = "simd128, simd256 or simd512";
        } else {
            throw parameter_error(name, quoted + "is not one rtcNewDevice documents");
        }
        if (expected) throw parameter_error(name, quoted + "needs " + expected);
        start = end + 1;
    }
}

const char* environment_config() {
    const char* env = std::getenv("BOUNCE_EMBREE_CONFIG");
    return env ? env : "";
}

}  // namespace

// A bad $BOUNCE_EMBREE_CONFIG is refused under its own name, so the message says where it
// came from.
device::device() : device(environment_config(), "BOUNCE_EMBREE_CONFIG") {}

device::device(std::string_view config) : device(config, "embree::device config") {}

device::device(std::string_view config, std::string_view source)
    : state_(std::make_shared<detail::device_state>()) {
    if (!config.empty()) check_device_config(config, source);
    state_->config = std::string(config);
    state_->handle = rtcNewDevice(config.empty() ? nullptr : state_->config.c_str());
    if (!state_->handle) {
        // Creation errors are reported through rtcGetDeviceError(NULL) only; there is no
        // device yet to carry a callback.
        throw embree_error(int(rtcGetDeviceError(nullptr)), "", "rtcNewDevice(\"" + state_->config + "\")");
    }
    rtcSetDeviceErrorFunction(state_->handle, &detail::device_state::on_error, state_.get());
}

void device::check(std::string_view during) const {
    const RTCError code = rtcGetDeviceError(state_->handle);
    if (code == RTC_ERROR_NONE) return;
    std::string message;
    {
        const std::lock_guard lock(state_->mutex);
        message.swap(state_->last_message);
    }
    throw embree_error(int(code), std::move(message), during);
}

RTCDeviceTy* device::native() const noexcept { return state_->handle; }

const std::string& device::config() const noexcept { return state_->config; }

void require_match(const accel& bvh, const scene_view& scene) {
    if (bvh.triangle_count() != scene.triangles.size() || scene.material_of.size() != scene.triangles.size())
        throw parameter_error("scene", "does not match the accel: it was built from " +
                                           std::to_string(bvh.triangle_count()) + " triangles, the scene has " +
                                           std::to_string(scene.triangles.size()));
}

accel::accel(const scene_view& scene) : accel(device(), scene) {}

accel::accel(const device& dev, const scene_view& scene) : device_(dev), state_(std::make_shared<detail::scene_state>()) {
    scene.validate_mesh();
    RTCDevice d = device_.native();
    state_->device = device_.state_;
    state_->triangles = scene.triangles.size();

    state_->handle = rtcNewScene(d);
    device_.check("rtcNewScene");
    // Robust traversal: no cracks between triangles that share an edge, which the closed
    // sphere of the furnace test and every watertight scene rely on. Context filters: a
    // query may pass a filter in its intersect context (radiosity_visibility does), so the
    // BVH serves queries that skip some triangles; queries without one run as fast (400k
    // rays on 200k triangles: the same time within a run-to-run noise of 3%).
    rtcSetSceneFlags(state_->handle, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION));
    rtcSetSceneBuildQuality(state_->handle, RTC_BUILD_QUALITY_HIGH);
    device_.check("rtcSetSceneFlags");

    if (!scene.triangles.empty()) {
        RTCGeometry g = rtcNewGeometry(d, RTC_GEOMETRY_TYPE_TRIANGLE);
        device_.check("rtcNewGeometry");
        // Embree allocates the vertex buffer with the padding its SIMD loads need.
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), scene.positions.size()));
        auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                    3 * sizeof(unsigned), scene.triangles.size()));
        if (!v || !idx) {
            rtcReleaseGeometry(g);
            device_.check("rtcSetNewGeometryBuffer");
            throw embree_error(RTC_ERROR_OUT_OF_MEMORY, "", "rtcSetNewGeometryBuffer");
        }
        for (std::size_t i = 0; i < scene.positions.size(); ++i)
            for (int c = 0; c < 3; ++c) v[3 * i + c] = scene.positions[i][c];
        for (std::size_t t = 0; t < scene.triangles.size(); ++t)
            for (int c = 0; c < 3; ++c) idx[3 * t + c] = scene.triangles[t][c];
        rtcCommitGeometry(g);
        // Geometry ID 0: hits report it, and primID is the triangle index.
        rtcAttachGeometryByID(state_->handle, g, 0);
        rtcReleaseGeometry(g);
        device_.check("rtcCommitGeometry");
    }
    rtcCommitScene(state_->handle);
    device_.check("rtcCommitScene");

    if (!scene.positions.empty()) {
        glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
        float m = 0.f;
        for (const auto& p : scene.positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
            m = std::max({m, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        }
        state_->diagonal = glm::length(hi - lo);
        state_->max_coordinate = m;
    }
}

namespace {

RTCRayHit to_rayhit(const ray& r) {
    RTCRayHit rh;
    rh.ray.org_x = r.origin.x;
    rh.ray.org_y = r.origin.y;
    rh.ray.org_z = r.origin.z;
    rh.ray.tnear = r.tnear;
    rh.ray.dir_x = r.direction.x;
    rh.ray.dir_y = r.direction.y;
    rh.ray.dir_z = r.direction.z;
    rh.ray.time = 0.f;
    rh.ray.tfar = r.tfar;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

// rtcOccluded sets tfar to -inf when it finds an occluder.
bool found_occluder(const RTCRay& r) { return r.tfar < 0.f && std::isinf(r.tfar); }

hit from_rayhit(const RTCRayHit& rh) {
    hit h;
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
        h.t = rh.ray.tfar;
        h.triangle = rh.hit.primID;
        h.u = rh.hit.u;
        h.v = rh.hit.v;
    }
    return h;
}

RTCIntersectContext context(bool coherent) {
    RTCIntersectContext c;
    rtcInitIntersectContext(&c);
    c.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    return c;
}

void require_sizes(std::size_t a, std::size_t b) {
    if (a != b) throw parameter_error("rays", "stream and result spans differ in size");
}

}  // namespace

hit accel::intersect(const ray& r) const {
    RTCIntersectContext c = context(false);
    RTCRayHit rh = to_rayhit(r);
    rtcIntersect1(state_->handle, &c, &rh);
    return from_rayhit(rh);
}

bool accel::occluded(const ray& r) const {
    RTCIntersectContext c = context(false);
    RTCRayHit rh = to_rayhit(r);
    rtcOccluded1(state_->handle, &c, &rh.ray);
    return found_occluder(rh.ray);
}

namespace {

// Calls query(base, n) for the consecutive chunks [base, base + n) of `count` rays, n <= size:
// streams go through Embree in chunks that fit the stack (memory stays bounded), packets in
// chunks of their width.
template <class Query>
void in_chunks(std::size_t count, std::size_t size, Query&& query) {
    for (std::size_t base = 0; base < count; base += size) query(base, std::min(size, count - base));
}

constexpr std::size_t stream_chunk = 256;

}  // namespace

void accel::intersect(std::span<const ray> rays, std::span<hit> hits, bool coherent) const {
    require_sizes(rays.size(), hits.size());
    RTCRayHit buffer[stream_chunk];
    RTCIntersectContext c = context(coherent);
    in_chunks(rays.size(), stream_chunk, [&](std::size_t base, std::size_t n) {
        for (std::size_t i = 0; i < n; ++i) buffer[i] = to_rayhit(rays[base + i]);
        rtcIntersect1M(state_->handle, &c, buffer, unsigned(n), sizeof(RTCRayHit));
        for (std::size_t i = 0; i < n; ++i) hits[base + i] = from_rayhit(buffer[i]);
    });
}

void accel::occluded(std::span<const ray> rays, std::span<std::uint8_t> blocked, bool coherent) const {
    require_sizes(rays.size(), blocked.size());
    RTCRay buffer[stream_chunk];
    RTCIntersectContext c = context(coherent);
    in_chunks(rays.size(), stream_chunk, [&](std::size_t base, std::size_t n) {
        for (std::size_t i = 0; i < n; ++i) buffer[i] = to_rayhit(rays[base + i]).ray;
        rtcOccluded1M(state_->handle, &c, buffer, unsigned(n), sizeof(RTCRay));
        for (std::size_t i = 0; i < n; ++i) blocked[base + i] = found_occluder(buffer[i]) ? 1 : 0;
    });
}

namespace {

// Embree's packet width for the packet queries: eight lanes, one AVX register (SSE CPUs
// run them as two halves inside Embree).
constexpr std::size_t packet_width = 8;

// Lane `i` of `ray8` from `r`.
void set_lane(RTCRay8& ray8, std::size_t i, const ray& r) {
    ray8.org_x[i] = r.origin.x;
    ray8.org_y[i] = r.origin.y;
    ray8.org_z[i] = r.origin.z;
    ray8.tnear[i] = r.tnear;
    ray8.dir_x[i] = r.direction.x;
    ray8.dir_y[i] = r.direction.y;
    ray8.dir_z[i] = r.direction.z;
    ray8.time[i] = 0.f;
    ray8.tfar[i] = r.tfar;
    ray8.mask[i] = ~0u;
    ray8.id[i] = 0;
    ray8.flags[i] = 0;
}

// Fills the valid mask (-1: lane in use) and the lanes of rays[base, base + n); lanes past n
// repeat the packet's first ray, so every lane holds finite values even where masked off.
void fill_packet(std::span<const ray> rays, std::size_t base, std::size_t n, int* valid, RTCRay8& ray8) {
    for (std::size_t i = 0; i < packet_width; ++i) {
        valid[i] = i < n ? -1 : 0;
        set_lane(ray8, i, rays[base + (i < n ? i : 0)]);
    }
}

}  // namespace

void accel::intersect_packets(std::span<const ray> rays, std::span<hit> hits) const {
    require_sizes(rays.size(), hits.size());
    RTCIntersectContext c = context(true);
    in_chunks(rays.size(), packet_width, [&](std::size_t base, std::size_t n) {
        alignas(32) int valid[packet_width];
        RTCRayHit8 rh;
        fill_packet(rays, base, n, valid, rh.ray);
        for (std::size_t i = 0; i < packet_width; ++i) {
            rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
            rh.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect8(valid, state_->handle, &c, &rh);
        for (std::size_t i = 0; i < n; ++i) {
            hit h;
            if (rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID) {
                h.t = rh.ray.tfar[i];
                h.triangle = rh.hit.primID[i];
                h.u = rh.hit.u[i];
                h.v = rh.hit.v[i];
            }
            hits[base + i] = h;
        }
    });
}

void accel::occluded_packets(std::span<const ray> rays, std::span<std::uint8_t> blocked) const {
    require_sizes(rays.size(), blocked.size());
    RTCIntersectContext c = context(true);
    in_chunks(rays.size(), packet_width, [&](std::size_t base, std::size_t n) {
        alignas(32) int valid[packet_width];
        RTCRay8 r8;
        fill_packet(rays, base, n, valid, r8);
        rtcOccluded8(valid, state_->handle, &c, &r8);
        // rtcOccluded8 sets a lane's tfar to -inf when it finds an occluder.
        for (std::size_t i = 0; i < n; ++i) blocked[base + i] = r8.tfar[i] < 0.f && std::isinf(r8.tfar[i]) ? 1 : 0;
    });
}

std::size_t accel::triangle_count() const noexcept { return state_->triangles; }
float accel::diagonal() const noexcept { return state_->diagonal; }
float accel::ray_epsilon() const noexcept {
    return std::max(1e-6f, 1e-4f * std::max(state_->diagonal, state_->max_coordinate));
}
RTCSceneTy* accel::native() const noexcept { return state_->handle; }

surface surface_at(const scene_view& scene, const ray& r, const hit& h) {
    surface s;
    s.triangle = h.triangle;
    s.position = r.origin + h.t * r.direction;
    const glm::uvec3 tri = scene.triangles[h.triangle];
    const glm::vec3 p0 = scene.positions[tri.x], p1 = scene.positions[tri.y], p2 = scene.positions[tri.z];
    glm::vec3 ng = glm::cross(p1 - p0, p2 - p0);
    const float ng_len = glm::length(ng);
    // A hit on a degenerate triangle has no plane; fall back to facing the ray.
    ng = ng_len > 0.f ? ng / ng_len : -glm::normalize(r.direction);
    if (glm::dot(ng, r.direction) > 0.f) ng = -ng;
    s.geometric_normal = ng;

    glm::vec3 n = ng;
    if (!scene.normals.empty()) {
        const float w0 = 1.f - h.u - h.v;
        const glm::vec3 blend = w0 * scene.normals[tri.x] + h.u * scene.normals[tri.y] + h.v * scene.normals[tri.z];
        const float len = glm::length(blend);
        if (len > 0.f && std::isfinite(len)) n = blend / len;
    }
    if (glm::dot(n, r.direction) > 0.f) n = -n;
    s.normal = n;
    s.albedo = scene.materials[scene.material_of[h.triangle]].albedo;
    return s;
}

}  // namespace bounce::embree
