#pragma once
/// \file radiosity_visibility.hpp
/// Ray-cast visibility for progressive radiosity (Cohen et al. 1988; the exact answer the
/// item buffers of Coombe and Harris 2005 approximate): one Embree occlusion ray per asked
/// element, from the shooter to the element's point, or from the point against a
/// directional light. It models cpu::shot_visibility (begin_shot(frame), then
/// visible(point, chart), const and safe from many threads) without including the CPU
/// adapter: begin_shot takes any frame with the fields of cpu::shot_frame.
///
/// Which surfaces may end a ray is told by charts (radiosity/lightmap_atlas.hpp): a ray is blocked by
/// a triangle of any chart but the receiver's own and the shooter's own. Both are planar,
/// so they can only be met at the ray's ends, where a float hit test would decide by
/// rounding; an Embree occlusion filter rejects their hits (the per-ray chart travels in
/// the ray's id). This is the definition the tests' brute-force ray caster uses.
///
/// The rays go through an `accel`'s BVH, the caller's when it has one: the charts are
/// passed in each query's intersect context to a context filter (accel's scenes allow one),
/// which also lets rays pass triangles without a chart. So a renderer that has an accel
/// builds no second BVH and makes no second Embree device. Copies share the accel and the
/// charts; the object is immutable after construction apart from the shot, which begin_shot
/// sets and visible only reads.

#include <bounce/embree/accel.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::embree {

/// The shot a visibility query belongs to (the fields of cpu::shot_frame).
struct radiosity_shot {
    static constexpr std::uint32_t none = 0xffffffffu;  ///< no chart (a light)
    glm::vec3 position{0.f};        ///< the shooter's centre (world); unused for parallel shots
    glm::vec3 axis{0.f, 0.f, 1.f};  ///< the shooter's normal; for parallel shots the direction light travels
    bool parallel = false;          ///< a directional light: rays along -axis from each point
    std::uint32_t chart = none;     ///< the shooter's chart, which never blocks its own rays
};

/// Exact visibility by occlusion rays (see the file comment).
class radiosity_visibility {
public:
    struct options {
        /// Hits within this fraction of the shooter-to-point distance short of the point do
        /// not block (float rounding of coincident surfaces of other charts; typical: 1e-5),
        /// nor hits within the accel's ray_epsilon of the point (the reference integrator's
        /// rays leave a point that far off its surface, so a layer closer than that never
        /// shadows it there).
        float end_tolerance = 1e-5f;
        /// The offset of a ray's end (above); 0: the accel's ray_epsilon(). A visibility of
        /// part of a scene (a moved object alone: radiosity_object_visibility.hpp) casts the
        /// whole scene's rays, so it takes the whole scene's offset.
        float ray_epsilon = 0.f;
    };

    /// Visibility through `bvh` (its device, triangles and BVH), with the chart of each of
    /// its triangles (lightmap_atlas::chart_of_triangle of the scene `bvh` was built from;
    /// radiosity_shot::none for triangles that never block). Throws parameter_error when
    /// the sizes differ or the options are out of range.
    radiosity_visibility(const accel& bvh, std::span<const std::uint32_t> chart_of_triangle, options opt);
    radiosity_visibility(const accel& bvh, std::span<const std::uint32_t> chart_of_triangle)
        : radiosity_visibility(bvh, chart_of_triangle, options{}) {}
    /// Builds an accel of `scene` on `dev` for itself, then as above. Throws parameter_error
    /// as above and as accel does, and embree_error when Embree fails.
    radiosity_visibility(const device& dev, const scene_view& scene, std::span<const std::uint32_t> chart_of_triangle,
                         options opt);
    radiosity_visibility(const device& dev, const scene_view& scene, std::span<const std::uint32_t> chart_of_triangle)
        : radiosity_visibility(dev, scene, chart_of_triangle, options{}) {}

    /// The accel the rays go through (the caller's, or the one built for the scene).
    const accel& bvh() const noexcept { return bvh_; }
    /// The offset of a ray's end: options.ray_epsilon, or the accel's.
    float ray_epsilon() const noexcept { return options_.ray_epsilon > 0.f ? options_.ray_epsilon : bvh_.ray_epsilon(); }
    const options& settings() const noexcept { return options_; }

    /// Prepares for a shot. `Frame` has position, axis, parallel and chart (cpu::shot_frame).
    template <class Frame>
    void begin_shot(const Frame& frame) {
        set_shot(radiosity_shot{frame.position, frame.axis, frame.parallel, frame.chart});
    }
    void set_shot(const radiosity_shot& shot);
    const radiosity_shot& shot() const noexcept { return shot_; }

    /// 1 when the segment from the shooter to `point` (or, for a parallel shot, the ray from
    /// `point` against the light) meets no triangle of a chart other than `chart` and the
    /// shooter's, else 0. Thread-safe.
    float visible(const glm::vec3& point, std::uint32_t chart) const;

    /// 1 when the segment from `origin` (a point of chart `origin_chart`) to `point` meets no
    /// triangle of a chart other than those two, else 0: visibility from any point, without
    /// begin_shot (grouped shooters, radiosity/shooter_groups.hpp, sample one member per
    /// receiver). Thread-safe.
    float visible_from(const glm::vec3& origin, std::uint32_t origin_chart, const glm::vec3& point,
                       std::uint32_t chart) const;

    /// visible() for many points at once, in packets of eight rays (rtcOccluded8): the
    /// same answers. Sizes must match (parameter_error otherwise). Thread-safe.
    void visible(std::span<const glm::vec3> points, std::span<const std::uint32_t> charts, std::span<float> out) const;

private:
    accel bvh_;
    std::shared_ptr<const std::vector<std::uint32_t>> chart_;  // per triangle of bvh_
    radiosity_shot shot_{};
    options options_{};
};

}  // namespace bounce::embree
