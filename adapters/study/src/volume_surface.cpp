#include <bounce/study/volume_surface.hpp>

#include <bounce/embree/probe_visibility_baker.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/errors.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/study/stage_timer.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

namespace bounce::study {

namespace {

constexpr std::uint64_t stage_surface_reference = 0x73757266ull;  // "surf"

nlohmann::ordered_json error_json(const noisy_reference_error& e) {
    return {{"rel_rms", e.rel_rms},
            {"rel_rms_debiased", e.rel_rms_debiased},
            {"rel_rms_debiased_se", e.rel_rms_debiased_se},
            {"reference_noise_rel_rms", e.reference_noise_rel_rms},
            {"pixels", e.pixels}};
}

}  // namespace

nlohmann::ordered_json volume_surface_figures::to_json() const {
    return {{"all", error_json(all)}, {"near_wall", error_json(near_wall)}, {"lookup_ns", lookup_ns}};
}

volume_surface_study::volume_surface_study(const embree::reference_integrator& light, const embree::accel& bvh,
                                           const scene_view& scene, const camera& cam, float wall_distance,
                                           const volume_surface_settings& s)
    : eye_(cam.position) {
    require(s.width > 0 && s.height > 0, "width", "the G-buffer needs pixels");
    require(s.reference_samples >= 2, "reference_samples", "two halves need at least 2 samples");
    require(s.wall_rays > 0, "wall_rays", "at least one ray");
    require(std::isfinite(wall_distance) && wall_distance > 0, "wall_distance", "must be finite and > 0");
    g_ = embree::ray_cast_gbuffer(bvh, scene, cam, s.width, s.height);
    a_ = image<glm::vec3>(s.width, s.height, glm::vec3(0.f));
    b_ = a_;
    mean_ = a_;
    covered_mask_ = image<float>(s.width, s.height, 0.f);
    near_ = covered_mask_;
    std::vector<glm::vec3> dirs;
    for (const glm::dvec3& d : embree::spherical_fibonacci_directions(2 * s.wall_rays)) dirs.push_back(glm::vec3(d));
    const float eps = bvh.ray_epsilon();
    const auto start = std::chrono::steady_clock::now();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.height), [&](const tbb::blocked_range<std::size_t>& rows) {
        for (std::size_t y = rows.begin(); y != rows.end(); ++y)
            for (std::size_t x = 0; x < s.width; ++x) {
                if (!g_.view().covered(x, y)) continue;
                const glm::vec3 p = g_.position(x, y), n = g_.normal(x, y);
                covered_mask_(x, y) = 1.f;
                bool near = false;
                for (const glm::vec3& d : dirs) {  // the half of the Fibonacci set above the surface
                    if (glm::dot(d, n) <= 0.f) continue;
                    if (bvh.occluded(embree::ray{p + eps * n, d, 0.f, wall_distance})) {
                        near = true;
                        break;
                    }
                }
                near_(x, y) = near ? 1.f : 0.f;
                const std::uint64_t pixel = y * s.width + x;
                const std::uint32_t half = s.reference_samples / 2;
                a_(x, y) = light.indirect_irradiance(p, n, half, embree::derive_seed(s.seed, stage_surface_reference, 2 * pixel));
                b_(x, y) = light.indirect_irradiance(p, n, half, embree::derive_seed(s.seed, stage_surface_reference, 2 * pixel + 1));
                mean_(x, y) = 0.5f * (a_(x, y) + b_(x, y));
            }
    });
    reference_ms_ = ms_since(start);
    for (std::size_t y = 0; y < s.height; ++y)
        for (std::size_t x = 0; x < s.width; ++x) covered_ += covered_mask_(x, y) > 0, near_wall_ += near_(x, y) > 0;
    require(covered_ > 0, "cam", "the camera sees no geometry");
}

image<glm::vec3> volume_surface_study::light(const irradiance_volume& volume, const probe_visibility* vis,
                                             const cpu::volume_lookup& how) const {
    auto g = g_;  // gbuffer::view() is not const
    return cpu::light_gbuffer(volume, vis, g.view(), eye_, how);
}

volume_surface_figures volume_surface_study::measure(const irradiance_volume& volume, const probe_visibility* vis,
                                                     const cpu::volume_lookup& how) const {
    volume_surface_figures f;
    const auto start = std::chrono::steady_clock::now();
    const image<glm::vec3> lit = light(volume, vis, how);
    f.lookup_ns = ms_since(start) * 1e6 / double(covered_);
    f.all = compare_luminance_debiased(lit.view(), a_.view(), b_.view(), covered_mask_.view());
    if (near_wall_ > 0) f.near_wall = compare_luminance_debiased(lit.view(), a_.view(), b_.view(), near_.view());
    return f;
}

probe_visibility_comparison compare_probe_visibility(const volume_surface_study& study, const irradiance_volume& volume,
                                                     const probe_visibility& vis, float self_shadow_bias, bool pictures) {
    probe_visibility_comparison c;
    std::vector<image<glm::vec3>> frames{study.reference()};
    for (const auto& [name, mode] : {std::pair{"none", volume_visibility::none}, std::pair{"chebyshev", volume_visibility::chebyshev}}) {
        cpu::volume_lookup how;
        how.visibility = {mode, self_shadow_bias};
        const volume_surface_figures f = study.measure(volume, &vis, how);
        c.lookups[std::string("trilinear_") + name] = f.to_json();
        std::printf("surface %-10s rel_rms all %.4f (debiased %.4f)  near walls %.4f (debiased %.4f)  lookup %.0f ns\n", name,
                    f.all.rel_rms, f.all.rel_rms_debiased, f.near_wall.rel_rms, f.near_wall.rel_rms_debiased, f.lookup_ns);
        if (pictures) frames.push_back(study.light(volume, &vis, how));
    }
    if (!pictures) return c;
    const std::size_t w = frames.front().width(), h = frames.front().height();
    c.strip = image<glm::vec3>(frames.size() * w, h);
    for (std::size_t k = 0; k < frames.size(); ++k)
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t x = 0; x < w; ++x) c.strip(k * w + x, y) = frames[k](x, y);
    return c;
}

nlohmann::ordered_json report_probe_visibility(const embree::reference_integrator& light, const embree::accel& bvh,
                                               const io::scene& scene, const irradiance_volume& volume,
                                               std::span<const glm::vec3> baked_at,
                                               const probe_visibility_report_settings& s) {
    const auto vis_start = std::chrono::steady_clock::now();
    const probe_visibility vis = embree::bake_probe_visibility(bvh, volume, s.visibility, baked_at);
    const double vis_ms = ms_since(vis_start);
    const volume_surface_study surface(light, bvh, scene, scene.camera, s.wall_distance, s.surface);
    const probe_visibility_comparison c = compare_probe_visibility(surface, volume, vis, s.self_shadow_bias, !s.picture.empty());
    std::printf("%s: %zu covered pixels, %zu within %.4g of a wall; reference noise %.4f; moments %ux%u from %u rays, %.0f ms\n",
                scene.name.c_str(), surface.covered_pixels(), surface.near_wall_pixels(), s.wall_distance,
                c.lookups["trilinear_none"]["near_wall"]["reference_noise_rel_rms"].get<double>(), s.visibility.resolution,
                s.visibility.resolution, s.visibility.rays, vis_ms);
    if (!s.picture.empty()) {  // reference | no visibility | Chebyshev, irradiance
        if (std::filesystem::path(s.picture).extension() == ".exr") io::write_exr(s.picture, c.strip.view());
        else io::write_png(s.picture, c.strip.view(), io::auto_exposure(surface.reference().view()));
    }
    return {{"width", s.surface.width}, {"height", s.surface.height}, {"reference_samples", s.surface.reference_samples},
            {"wall_distance", s.wall_distance}, {"covered_pixels", surface.covered_pixels()},
            {"near_wall_pixels", surface.near_wall_pixels()}, {"reference_ms", surface.reference_ms()},
            {"visibility_resolution", s.visibility.resolution}, {"visibility_rays", s.visibility.rays},
            {"visibility_sharpness", s.visibility.sharpness}, {"max_distance_ratio", s.visibility.max_distance_ratio},
            {"self_shadow_bias", s.self_shadow_bias}, {"visibility_bake_ms", vis_ms}, {"lookups", c.lookups}};
}

}  // namespace bounce::study
