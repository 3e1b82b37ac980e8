#pragma once
/// \file volume_surface.hpp
/// An irradiance volume at the surface points of a view (issue 31, "points on surfaces"):
/// the camera's ray-cast G-buffer lit by the volume (cpu::light_gbuffer), against the
/// one-bounce indirect irradiance the probes hold (reference_integrator::
/// indirect_irradiance at each covered pixel, in two independent halves so that the
/// reference's own noise can be taken out), over every covered pixel and over those
/// "near a wall": pixels with another surface within a given distance (one cell of the
/// volume) along one of a set of hemisphere rays, where walls meet floors and a volume
/// leaks.

#include <bounce/camera.hpp>
#include <bounce/cpu/irradiance_volume.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/probe_visibility_baker.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/scene_view.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/volume/probe_visibility.hpp>

#include <cstdint>
#include <span>
#include <string>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace bounce::study {

/// Parameters of the surface measurement (unit and typical value with each).
struct volume_surface_settings {
    std::size_t width = 128, height = 128;  ///< the G-buffer's size
    /// Reference samples per pixel, both halves together (even). Typical: 1024.
    std::uint32_t reference_samples = 1024;
    /// Hemisphere rays per pixel for the near-wall test. Typical: 64.
    std::uint32_t wall_rays = 64;
    std::uint64_t seed = 7;  ///< seed of the reference's halves
};

/// One lookup's error at the surface points.
struct volume_surface_figures {
    noisy_reference_error all, near_wall;  ///< every covered pixel; the near-wall pixels
    double lookup_ns = 0;                  ///< per pixel (light_gbuffer, all threads; loaded machine)
    /// {"all": {...}, "near_wall": {...}, "lookup_ns"}, each {"rel_rms", "rel_rms_debiased",
    /// "rel_rms_debiased_se", "reference_noise_rel_rms", "pixels"}.
    nlohmann::ordered_json to_json() const;
};

class volume_surface_study {
public:
    /// Ray casts the G-buffer of `cam`, marks the pixels near a wall (another surface
    /// within `wall_distance` along one of settings.wall_rays rays of the hemisphere
    /// around the normal) and computes the reference at every covered pixel. Throws
    /// parameter_error naming the setting for a zero size or reference_samples < 2, and
    /// "wall_distance" when not positive and finite.
    volume_surface_study(const embree::reference_integrator& light, const embree::accel& bvh, const scene_view& scene,
                         const camera& cam, float wall_distance, const volume_surface_settings& settings = {});

    /// The volume (with `vis`'s moments when not null) looked up by `how` at every covered
    /// pixel, against the reference.
    volume_surface_figures measure(const irradiance_volume& volume, const probe_visibility* vis,
                                   const cpu::volume_lookup& how) const;
    /// The volume's irradiance image by `how` (uncovered pixels 0), for pictures.
    image<glm::vec3> light(const irradiance_volume& volume, const probe_visibility* vis, const cpu::volume_lookup& how) const;

    const image<glm::vec3>& reference() const noexcept { return mean_; }  ///< the halves' mean
    const image<float>& near_wall_mask() const noexcept { return near_; }
    std::size_t covered_pixels() const noexcept { return covered_; }
    std::size_t near_wall_pixels() const noexcept { return near_wall_; }
    double reference_ms() const noexcept { return reference_ms_; }

private:
    gbuffer<float> g_;
    glm::vec3 eye_{0.f};
    image<glm::vec3> a_, b_, mean_;
    image<float> covered_mask_, near_;
    std::size_t covered_ = 0, near_wall_ = 0;
    double reference_ms_ = 0;
};

/// The volume at a surface study's points by trilinear lookups without and with the probes'
/// visibility (`vis`, DDGI's Chebyshev test with `self_shadow_bias`), what `irradiance_volume
/// --surface` reports.
struct probe_visibility_comparison {
    /// {"trilinear_none": figures, "trilinear_chebyshev": figures} (volume_surface_figures::to_json)
    nlohmann::ordered_json lookups = nlohmann::ordered_json::object();
    image<glm::vec3> strip;  ///< reference | no visibility | Chebyshev side by side (empty unless asked)
};

/// Measures both lookups, prints a line each ("surface <name> rel_rms ..."), and with
/// `pictures` lays out their irradiance beside the reference.
probe_visibility_comparison compare_probe_visibility(const volume_surface_study& study, const irradiance_volume& volume,
                                                     const probe_visibility& vis, float self_shadow_bias, bool pictures);

/// What `irradiance_volume --surface` measures for a built volume.
struct probe_visibility_report_settings {
    embree::probe_visibility_settings visibility;  ///< the distance moments' bake
    volume_surface_settings surface;               ///< the G-buffer and its reference
    /// Pixels with another surface within this distance are near a wall (world units;
    /// typical: the finest cell's shortest edge). Must be positive and finite.
    float wall_distance = 0;
    float self_shadow_bias = 0.3f;  ///< the Chebyshev test's, fraction of 0.75 cell
    /// Reference | no visibility | Chebyshev side by side is written here (.exr: linear;
    /// else 8-bit sRGB exposed for the reference); empty: no picture.
    std::string picture;
};

/// Bakes `volume`'s visibility from `baked_at` (embree::bake_probe_visibility; empty: the
/// lattice points), builds the surface study of the scene's camera, compares the lookups
/// without and with visibility (compare_probe_visibility, a line each), prints the
/// study's line (pixels, reference noise, moments), writes the picture, and returns the
/// run report's "surface" object: the settings, the pixel counts, the reference's and the
/// moments' times, and "lookups".
nlohmann::ordered_json report_probe_visibility(const embree::reference_integrator& light, const embree::accel& bvh,
                                               const io::scene& scene, const irradiance_volume& volume,
                                               std::span<const glm::vec3> baked_at,
                                               const probe_visibility_report_settings& settings);

}  // namespace bounce::study
