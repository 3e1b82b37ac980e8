#pragma once
/// \file indirect/visibility.hpp
/// Visibility between the receivers of one-bounce indirect light and its senders (the texels
/// of a reflective shadow map, the VPLs of SII). DS05 and DS06 leave it out (every sender
/// reaches every receiver in front of it), and that leak is the family's largest error
/// indoors: light passes through walls and partitions (docs/rsm-sii-interleaved.md, "The
/// leak"). A renderer chooses the policy in indirect_options::visibility; the exact one asks
/// an occlusion_query (embree::occlusion_query on the CPU) about each receiver-sender pair
/// the frame sums.
///
/// Units: positions in scene units, offsets in scene units.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::inline indirect {

/// Which receiver-sender pairs of a frame an indirect renderer tests for occluders.
enum class indirect_visibility {
    none,  ///< none, as published (DS05, DS06): light leaks through walls and partitions
    rays,  ///< every pair the frame sums, by an occlusion ray (exact; needs an occlusion_query)
    /// imperfect shadow maps (Ritschel et al. 2008, indirect/imperfect_shadow_maps.hpp): each
    /// VPL's paraboloid depth map splatted from a point sampling of the scene (approximate;
    /// SII only; needs an ism_point_sampler)
    ism,
};

inline constexpr std::array<indirect_visibility, 3> indirect_visibilities = {
    indirect_visibility::none, indirect_visibility::rays, indirect_visibility::ism};

/// "none", "rays", "ism": the spelling of programs' --visibility and of results files.
constexpr std::string_view visibility_name(indirect_visibility v) {
    return v == indirect_visibility::rays ? "rays" : v == indirect_visibility::ism ? "ism" : "none";
}

/// The policy spelled `name` (visibility_name's inverse); nullopt for a name none has.
constexpr std::optional<indirect_visibility> parse_visibility(std::string_view name) {
    for (const indirect_visibility v : indirect_visibilities)
        if (visibility_name(v) == name) return v;
    return std::nullopt;
}

/// One receiver-sender pair: two surface points and their unit normals (either side; the
/// query offsets each end towards the other end's side).
struct visibility_segment {
    glm::vec3 receiver{0.f};
    glm::vec3 receiver_normal{0.f, 0.f, 1.f};
    glm::vec3 sender{0.f};
    glm::vec3 sender_normal{0.f, 0.f, 1.f};
};

/// The end point of a visibility segment on the surface through `p` (unit normal `n`),
/// moved `offset` off the surface on the side of `towards`, so that a ray between two ends
/// does not find the surfaces it joins (float positions carry ~1e-7 relative error; the
/// offset must exceed it, embree::accel::ray_epsilon does). The side is n's where towards
/// lies on or in front of the plane, -n's behind it.
template <class V, class T>
V segment_end(const V& p, const V& n, const V& towards, T offset) {
    const T side = glm::dot(n, towards - p) >= T(0) ? T(1) : T(-1);
    return p + n * (side * offset);
}

/// What an indirect renderer asks about visibility: which segments cross a surface. An
/// implementation must be safe to call from several threads at once (the renderers query
/// per tile or per pixel in parallel).
class occlusion_query {
public:
    virtual ~occlusion_query() = default;
    /// blocked[i] = 1 where a surface lies between segments[i]'s two ends (each moved off
    /// its own surface by segment_end), 0 where the receiver sees the sender. Sizes match.
    virtual void occluded(std::span<const visibility_segment> segments, std::span<std::uint8_t> blocked) const = 0;

protected:
    occlusion_query() = default;
    occlusion_query(const occlusion_query&) = default;
    occlusion_query& operator=(const occlusion_query&) = default;
};

}  // namespace bounce::indirect
