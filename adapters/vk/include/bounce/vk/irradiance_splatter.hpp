#pragma once
/// \file irradiance_splatter.hpp
/// `vk::irradiance_splatter`: irradiance splatting and its normalization (Gautron 2008,
/// Algorithms 1 and 5) as Vulkan 1.2 compute on the caller's device, queue and buffers:
/// the same kernels as cpu::splat_records and gl::splat_pass (cache/record.hpp's
/// splat_contribution and normalized_splat / hole_filled_splat, the weighting's
/// influence_radius), emitted as GLSL, compiled to SPIR-V at build time.
///
/// Buffers (std430, row 0 of the picture first, pixel (x, y) at y * width + x):
/// - records: `std430_record` (cache/record_std430.hpp; `pack_std430` writes one), 144 bytes each;
/// - position_depth, normal, albedo: one vec4 per pixel, the G-buffer of gl::gbuffer_pass as
///   rows top first: xyz = world position and w = depth along the view axis (+infinity where
///   no geometry is seen), xyz = unit normal facing the camera, rgb = diffuse albedo;
/// - splat: one vec4 per pixel, rgb = sum of w rho/pi E_k(p), a = sum of w (the layout of
///   bounce's splat buffer, image<glm::vec4>); the splat adds to what it holds;
/// - indirect: one vec4 per pixel, rgb = the normalized result, a = 1.
/// docs/vulkan.md lists the bindings, push constants and workgroup sizes.
///
/// Each pass exists twice: `record_*` records into the caller's command buffer (with no
/// barrier: put one between the splat and the normalization that reads it, e.g.
/// vk::compute_barrier), and the plain call runs it on the queue and waits. One splatter
/// rewrites its descriptor sets on every record: what it recorded before must have run.

#include <bounce/cache/record.hpp>
#include <bounce/cache/weighting.hpp>
#include <bounce/output.hpp>
#include <bounce/vk/compute.hpp>
#include <bounce/vk/device.hpp>

#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <tuple>

namespace bounce::vk {

/// The caller's buffers a splat reads and adds to (layouts in the file comment).
struct splat_buffers {
    buffer_range records;
    buffer_range position_depth, normal, albedo;
    buffer_range splat;
};

/// Which records a splat adds, over what picture, and how.
struct splat_job {
    std::size_t width = 0, height = 0;
    std::size_t first = 0, count = 0;  ///< records [first, first + count) of the record buffer
    splat_params params{};             ///< a, gradients, extrapolation clamp, in-front test
    weighting_kind weighting = weighting_kind::ward_smooth;
    /// irradiance: the albedo buffer is not read and rho = pi (so the normalized result is E);
    /// radiance: rho/pi E with the albedo buffer's rho (output.hpp).
    output_quantity quantity = output_quantity::irradiance;
    /// Throws parameter_error naming the first bad field.
    void validate() const;
};

class irradiance_splatter {
public:
    /// Keeps `device` (borrowed) and makes its command pool; pipelines are made on first use
    /// (one per weighting and kernel flags). Throws vulkan_error on a failed call.
    explicit irradiance_splatter(const device_ref& device);
    ~irradiance_splatter();

    /// Adds job.count records' splats to `b.splat`, each pixel's in record order.
    void record_splat(VkCommandBuffer cmd, const splat_buffers& b, const splat_job& job);
    void splat(const splat_buffers& b, const splat_job& job);

    /// indirect = normalized_splat(splat) for `pixels` pixels.
    void record_normalize(VkCommandBuffer cmd, buffer_range splat, buffer_range indirect, std::size_t pixels);
    void normalize(buffer_range splat, buffer_range indirect, std::size_t pixels);
    /// Hole filling: indirect = hole_filled_splat(splat, wide, lambda), `wide` holding the
    /// same records splatted with a wider a (cpu::normalize_splats). Throws parameter_error
    /// naming "lambda" unless it is positive and finite.
    void record_normalize(VkCommandBuffer cmd, buffer_range splat, buffer_range wide, float lambda, buffer_range indirect,
                          std::size_t pixels);
    void normalize(buffer_range splat, buffer_range wide, float lambda, buffer_range indirect, std::size_t pixels);

private:
    const compute_pipeline& splat_pipeline(const splat_job& job);

    submitter submit_;
    std::map<std::tuple<int, bool, bool>, std::unique_ptr<compute_pipeline>> splats_;
    std::unique_ptr<compute_pipeline> normalize_, normalize_wide_;
};

}  // namespace bounce::vk
