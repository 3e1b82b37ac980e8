// The Vulkan splat and normalization passes (irradiance_splatter.hpp).
#include <bounce/vk/irradiance_splatter.hpp>

#include "shader_interface.hpp"
#include "spirv.hpp"

#include <array>
#include <cmath>
#include <limits>

namespace bounce::vk {

namespace {

std::uint32_t groups(std::size_t n, std::uint32_t per_group) { return std::uint32_t((n + per_group - 1) / per_group); }

std::uint32_t checked_u32(std::size_t v, const char* name) {
    require(v <= std::numeric_limits<std::uint32_t>::max(), name, "does not fit the shaders' 32-bit indices");
    return std::uint32_t(v);
}

}  // namespace

void splat_job::validate() const {
    params.validate();
    require(width > 0 && height > 0, "width/height", "the picture must have pixels");
    checked_u32(width * height, "width/height");
    checked_u32(first + count, "count");
}

irradiance_splatter::irradiance_splatter(const device_ref& device) : submit_(device) {}

irradiance_splatter::~irradiance_splatter() = default;

const compute_pipeline& irradiance_splatter::splat_pipeline(const splat_job& job) {
    const bool front = job.params.front_test();
    auto& p = splats_[{int(job.weighting), job.params.gradients, front}];
    if (!p)
        p = std::make_unique<compute_pipeline>(
            submit_.device().device, detail::spirv(detail::splat_shader_name(job.weighting, job.params.gradients, front)), 5,
            std::uint32_t(sizeof(detail::splat_constants)));
    return *p;
}

void irradiance_splatter::record_splat(VkCommandBuffer cmd, const splat_buffers& b, const splat_job& job) {
    job.validate();
    const detail::splat_constants c{std::uint32_t(job.width),
                                    std::uint32_t(job.height),
                                    std::uint32_t(job.first),
                                    std::uint32_t(job.count),
                                    job.params.a,
                                    job.params.max_extrapolation,
                                    job.params.front_tolerance,
                                    job.quantity == output_quantity::irradiance ? 1u : 0u};
    // Every binding needs a buffer, even one the shader skips: irradiance may leave the
    // albedo out, and the normals stand in for it.
    std::array<buffer_range, 5> bound{b.records, b.position_depth, b.normal, b.albedo, b.splat};
    if (job.quantity == output_quantity::irradiance && bound[3].buffer == VK_NULL_HANDLE) bound[3] = b.normal;
    splat_pipeline(job).record(cmd, bound, &c, groups(job.width, detail::splat_group), groups(job.height, detail::splat_group));
}

void irradiance_splatter::splat(const splat_buffers& b, const splat_job& job) {
    job.validate();
    submit_.run([&](VkCommandBuffer cmd) { record_splat(cmd, b, job); });
}

void irradiance_splatter::record_normalize(VkCommandBuffer cmd, buffer_range splat, buffer_range indirect, std::size_t pixels) {
    if (!normalize_)
        normalize_ = std::make_unique<compute_pipeline>(submit_.device().device, detail::spirv("normalize"), 2,
                                                        std::uint32_t(sizeof(detail::normalize_constants)));
    const detail::normalize_constants c{checked_u32(pixels, "pixels"), 0.f};
    const std::array<buffer_range, 2> buffers{splat, indirect};
    normalize_->record(cmd, buffers, &c, groups(pixels, detail::normalize_group));
}

void irradiance_splatter::normalize(buffer_range splat, buffer_range indirect, std::size_t pixels) {
    checked_u32(pixels, "pixels");
    submit_.run([&](VkCommandBuffer cmd) { record_normalize(cmd, splat, indirect, pixels); });
}

void irradiance_splatter::record_normalize(VkCommandBuffer cmd, buffer_range splat, buffer_range wide, float lambda,
                                           buffer_range indirect, std::size_t pixels) {
    require(std::isfinite(lambda) && lambda > 0.f, "lambda", "must be a positive number");
    if (!normalize_wide_)
        normalize_wide_ = std::make_unique<compute_pipeline>(submit_.device().device, detail::spirv("normalize_wide"), 3,
                                                             std::uint32_t(sizeof(detail::normalize_constants)));
    const detail::normalize_constants c{checked_u32(pixels, "pixels"), lambda};
    const std::array<buffer_range, 3> buffers{splat, wide, indirect};
    normalize_wide_->record(cmd, buffers, &c, groups(pixels, detail::normalize_group));
}

void irradiance_splatter::normalize(buffer_range splat, buffer_range wide, float lambda, buffer_range indirect,
                                    std::size_t pixels) {
    require(std::isfinite(lambda) && lambda > 0.f, "lambda", "must be a positive number");
    checked_u32(pixels, "pixels");
    submit_.run([&](VkCommandBuffer cmd) { record_normalize(cmd, splat, wide, lambda, indirect, pixels); });
}

}  // namespace bounce::vk
