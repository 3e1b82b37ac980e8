#pragma once
/// \file accel.hpp
/// Embree 3 behind RAII: a `device`, an `accel` (the BVH of a `scene_view`'s triangles),
/// closest-hit and occlusion queries for single rays and streams of rays, and the surface
/// attributes at a hit. Embree's own headers stay private to the adapter; the native
/// handles are exposed as Embree's opaque pointer types for renderers that add their own
/// calls (the Debian build of Embree 3 declares them in the global namespace).

#include <bounce/errors.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

struct RTCDeviceTy;  // Embree's RTCDevice is RTCDeviceTy*
struct RTCSceneTy;   // Embree's RTCScene is RTCSceneTy*

namespace bounce::embree {

/// An error Embree reported. `code()` is Embree's RTCError value and `message()` the text
/// Embree passed to the device's error callback (empty when it gave none).
struct embree_error : bounce::error {
    embree_error(int code, std::string message, std::string_view during);
    int code() const noexcept { return code_; }
    const std::string& message() const noexcept { return message_; }

private:
    int code_;
    std::string message_;
};

namespace detail {
struct device_state;
struct scene_state;
}  // namespace detail

/// An Embree device (RTCDevice) with an error callback that records Embree's message.
/// Cheap to copy: copies share the device, which lives while any copy or any `accel` built
/// on it does. Embree uses the process's TBB scheduler, so tbb::global_control limits it.
///
/// Embree picks its SIMD kernels (SSE2 ... AVX-512) by CPU, and the kernels round hit
/// distances differently in the last bits. bounce's records and references are bitwise
/// reproducible on one machine, not across CPUs: the Cornell box at a = 0.4 makes 3663
/// records with AVX2 kernels and 3675 with SSE4.2 ones, at the same error. Pin the kernels
/// ("max_isa=sse4.2") to compare runs bit for bit across machines.
class device {
public:
    /// The configuration in the environment variable BOUNCE_EMBREE_CONFIG when it is set and
    /// not empty (checked as below), else Embree's default. Throws embree_error or
    /// parameter_error.
    device();
    /// A device with rtcNewDevice's configuration string `config`: comma-separated
    /// `key=value` options from Embree's documented set (threads, user_threads,
    /// set_affinity, start_threads, isa, max_isa, hugepages, enable_selockmemoryprivilege,
    /// verbose, frequency_level), e.g. "max_isa=sse4.2,threads=2"; empty for the default.
    /// Embree ignores options it does not know, so bounce checks keys and values and throws
    /// parameter_error naming the option. Throws embree_error when Embree refuses (an `isa`
    /// this CPU lacks).
    explicit device(std::string_view config);

    /// The configuration the device was created with ("" for Embree's default).
    const std::string& config() const noexcept;

    /// Throws embree_error if Embree recorded an error on this thread since the last check;
    /// `during` names the operation for the message (e.g. "rtcCommitScene").
    void check(std::string_view during) const;

    /// The native RTCDevice, for calls bounce does not wrap. Do not release it.
    RTCDeviceTy* native() const noexcept;

private:
    friend class accel;
    // `source` names the configuration's origin in a refusal.
    device(std::string_view config, std::string_view source);
    std::shared_ptr<detail::device_state> state_;
};

/// No triangle: the `triangle` of a hit that found nothing.
inline constexpr std::uint32_t no_triangle = std::numeric_limits<std::uint32_t>::max();

/// A ray segment origin + t direction, t in [tnear, tfar]. The direction need not be unit
/// length; t is measured in multiples of it.
struct ray {
    glm::vec3 origin{0.f};
    glm::vec3 direction{0.f, 0.f, -1.f};
    float tnear = 0.f;
    float tfar = std::numeric_limits<float>::infinity();
};

/// The closest intersection along a ray. Barycentrics (u, v) weigh the triangle's second
/// and third vertex: p = (1 - u - v) v0 + u v1 + v v2.
struct hit {
    float t = std::numeric_limits<float>::infinity();  ///< ray parameter of the hit
    std::uint32_t triangle = no_triangle;              ///< index into scene_view::triangles
    float u = 0.f, v = 0.f;                            ///< barycentrics of v1 and v2
    bool found() const noexcept { return triangle != no_triangle; }
};

/// A bounding volume hierarchy over the triangles of a scene_view (one Embree triangle
/// mesh, robust traversal, high build quality). Immutable once built, so queries from any
/// number of threads are safe. Cheap to copy (copies share the BVH). The scene data is
/// copied into Embree's buffers: the viewed arrays need not outlive the accel. The scene is
/// committed with RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION, so a native query with a filter in
/// its intersect context may skip triangles on this same BVH (radiosity_visibility does);
/// queries without one run as fast as on a scene without the flag (measured).
class accel {
public:
    /// Builds on a fresh device. Throws parameter_error naming the field of an invalid
    /// scene (index out of range, non-finite vertex, material index out of range, normals
    /// or material_of of the wrong length) and embree_error if Embree fails.
    explicit accel(const scene_view& scene);
    /// Builds on `dev`.
    accel(const device& dev, const scene_view& scene);

    /// Closest hit along `r` (hit::found() false on a miss).
    hit intersect(const ray& r) const;
    /// Whether anything lies on `r` within [tnear, tfar] (shadow rays).
    bool occluded(const ray& r) const;
    /// Closest hits of a stream of rays (rtcIntersect1M); `coherent` hints that
    /// neighbouring rays travel together (camera rays). Sizes must match.
    void intersect(std::span<const ray> rays, std::span<hit> hits, bool coherent = false) const;
    /// Occlusion of a stream of rays (rtcOccluded1M): 1 where blocked, 0 where free.
    void occluded(std::span<const ray> rays, std::span<std::uint8_t> blocked, bool coherent = false) const;
    /// Closest hits as packets of eight (rtcIntersect8 on rays 8i ... 8i + 7, the last packet
    /// masked where the span ends): Embree traverses a packet's rays together, which pays
    /// when neighbours in the span travel nearly together (one record's hemisphere rays in
    /// stratum order share their origin and are neighbours in direction). The same hits as
    /// the single-ray and stream queries. Sizes must match.
    void intersect_packets(std::span<const ray> rays, std::span<hit> hits) const;
    /// Occlusion as packets of eight (rtcOccluded8): 1 where blocked, 0 where free.
    void occluded_packets(std::span<const ray> rays, std::span<std::uint8_t> blocked) const;

    /// Number of triangles it was built from (to check it matches a scene).
    std::size_t triangle_count() const noexcept;
    /// Length of the diagonal of the scene's bounding box (world units; 0 when empty).
    float diagonal() const noexcept;
    /// Offset for secondary ray origins that clears the surface they leave: 1e-4 of the
    /// larger of the diagonal and the largest coordinate magnitude (float positions carry
    /// a relative error of ~1e-7, so this is ~1000 ulp), at least 1e-6.
    float ray_epsilon() const noexcept;

    const device& owner() const noexcept { return device_; }
    /// The native RTCScene. Do not release or modify it.
    RTCSceneTy* native() const noexcept;

private:
    device device_;
    std::shared_ptr<detail::scene_state> state_;
};

/// Throws parameter_error unless `bvh` was built from a scene with as many triangles as
/// `scene` (a cheap guard against shading hits with the wrong scene).
void require_match(const accel& bvh, const scene_view& scene);

/// The surface a ray found: world position, unit interpolated (barycentric) vertex normal
/// and unit geometric normal, both flipped to face the ray's origin, and the diffuse
/// reflectance Kd of the triangle's material. Where the scene has no vertex normals, or
/// they interpolate to zero, the shading normal is the geometric one.
struct surface {
    glm::vec3 position{0.f};
    glm::vec3 normal{0.f, 0.f, 1.f};
    glm::vec3 geometric_normal{0.f, 0.f, 1.f};
    glm::vec3 albedo{0.f};
    std::uint32_t triangle = no_triangle;
};

/// Surface attributes at `h` (which must have found a triangle of `scene`) along `r`.
surface surface_at(const scene_view& scene, const ray& r, const hit& h);

}  // namespace bounce::embree
