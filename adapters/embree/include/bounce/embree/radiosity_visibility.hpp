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
/// The scene is copied into its own Embree scene (robust traversal, the filter attached);
/// degenerate triangles (no chart) are left out. Copies share it; it is immutable after
/// construction apart from the shot, which begin_shot sets and visible only reads.

#include <bounce/embree/accel.hpp>
#include <bounce/scene_view.hpp>

#include <cstdint>
#include <memory>
#include <span>

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

namespace detail {
struct radiosity_scene;
}

/// Exact visibility by occlusion rays (see the file comment).
class radiosity_visibility {
public:
    struct options {
        /// Hits within this fraction of the shooter-to-point distance short of the point do
        /// not block (float rounding of coincident surfaces of other charts; typical: 1e-5).
        float end_tolerance = 1e-5f;
    };

    /// Builds on `dev` from `scene` and the chart of each of its triangles
    /// (lightmap_atlas::chart_of_triangle, radiosity_shot::none for triangles to leave out).
    /// Throws parameter_error when the sizes differ or the options are out of range, and
    /// embree_error when Embree fails.
    radiosity_visibility(const device& dev, const scene_view& scene, std::span<const std::uint32_t> chart_of_triangle,
                         options opt);
    radiosity_visibility(const device& dev, const scene_view& scene, std::span<const std::uint32_t> chart_of_triangle)
        : radiosity_visibility(dev, scene, chart_of_triangle, options{}) {}

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

    /// visible() for many points at once, in packets of eight rays (rtcOccluded8): the
    /// same answers. Sizes must match (parameter_error otherwise). Thread-safe.
    void visible(std::span<const glm::vec3> points, std::span<const std::uint32_t> charts, std::span<float> out) const;

private:
    std::shared_ptr<const detail::radiosity_scene> scene_;
    radiosity_shot shot_{};
    options options_{};
};

}  // namespace bounce::embree
