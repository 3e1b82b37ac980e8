// A Vulkan renderer's link of bounce::vk from an installed bounce: the adapter's errors and
// checks work without a device (the renderer's own instance and device are not needed to link).
#include <bounce/vk/irradiance_splatter.hpp>
#include <bounce/vk/sh_projection.hpp>

#include <cstdio>
#include <string>

int main() {
    if (bounce::vk::result_name(VK_ERROR_DEVICE_LOST) != "VK_ERROR_DEVICE_LOST") return 1;
    try {
        bounce::vk::device_ref{}.validate();
        return 1;
    } catch (const bounce::parameter_error&) {
    }
    std::puts("bounce::vk consumer: linked");
    return 0;
}
