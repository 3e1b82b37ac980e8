// The Vulkan SH projection pass (sh_projection.hpp).
#include <bounce/vk/sh_projection.hpp>

#include "shader_interface.hpp"
#include "spirv.hpp"

#include <algorithm>
#include <array>
#include <limits>

namespace bounce::vk {

namespace {
int checked_bands(int bands) {
    require(std::find(std::begin(detail::sh_bands), std::end(detail::sh_bands), bands) != std::end(detail::sh_bands), "bands",
            "the SH projection is built for 2, 3 or 4 bands");
    return bands;
}
}  // namespace

sh_projector::sh_projector(const device_ref& device, int bands)
    : bands_(checked_bands(bands)),
      submit_(device),
      pipeline_(std::make_unique<compute_pipeline>(device.device, detail::spirv(detail::sh_shader_name(bands)), 2,
                                                   std::uint32_t(sizeof(detail::sh_constants)))) {}

sh_projector::~sh_projector() = default;

void sh_projector::record_project(VkCommandBuffer cmd, buffer_range texels, buffer_range coefficients, std::size_t size,
                                  std::size_t first_map, std::size_t maps) const {
    constexpr std::size_t limit = std::numeric_limits<std::uint32_t>::max();
    require(size > 0 && size <= 4096, "size", "cube-map size must be 1 to 4096 texels");
    require(maps > 0, "maps", "no maps to project");
    // The shader indexes floats with 32-bit integers: 3 * 6 size^2 * (first_map + maps).
    require(first_map + maps <= limit / (18 * size * size), "maps", "too many texels for the shaders' 32-bit indices");
    const detail::sh_constants c{std::uint32_t(size), std::uint32_t(first_map)};
    const std::array<buffer_range, 2> buffers{texels, coefficients};
    pipeline_->record(cmd, buffers, &c, std::uint32_t(maps));
}

void sh_projector::project(buffer_range texels, buffer_range coefficients, std::size_t size, std::size_t first_map,
                           std::size_t maps) {
    submit_.run([&](VkCommandBuffer cmd) { record_project(cmd, texels, coefficients, size, first_map, maps); });
}

}  // namespace bounce::vk
