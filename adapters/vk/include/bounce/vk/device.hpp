#pragma once
/// \file device.hpp
/// What the Vulkan adapter works on, all the caller's: a VkDevice (Vulkan 1.2), a queue of a
/// family that supports compute, and VkBuffers (storage buffers, std430). The adapter never
/// creates an instance or a device and allocates no memory: it creates only its pipelines,
/// descriptor set layouts and pools, a command pool and a fence, and destroys them.
///
/// Every failing Vulkan call becomes a `vulkan_error` naming the call and its VkResult.

#include <bounce/errors.hpp>

#include <cstdint>
#include <string>

#include <vulkan/vulkan.h>

namespace bounce::vk {

/// A failed Vulkan call: what() is "<call> failed: <VkResult name> (<code>)".
class vulkan_error : public error {
public:
    vulkan_error(const std::string& call, VkResult result);
    /// The call that failed, e.g. "vkCreateComputePipelines".
    const std::string& call() const noexcept { return call_; }
    VkResult result() const noexcept { return result_; }

private:
    std::string call_;
    VkResult result_;
};

/// The name of `r` ("VK_ERROR_OUT_OF_DEVICE_MEMORY"), or "VkResult <code>" for others.
std::string result_name(VkResult r);

/// Throws vulkan_error naming `call` unless `r` is VK_SUCCESS.
inline void check(VkResult r, const char* call) {
    if (r != VK_SUCCESS) throw vulkan_error(call, r);
}

/// The caller's device and the queue the adapter submits to (its family must support
/// compute). Borrowed: they must outlive the adapter's objects.
struct device_ref {
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    std::uint32_t queue_family = 0;
    /// Throws parameter_error naming "device" when device or queue is null.
    void validate() const;
};

/// A range of a caller's buffer (created with VK_BUFFER_USAGE_STORAGE_BUFFER_BIT), bound as
/// a storage buffer. `offset` must be a multiple of the device's
/// minStorageBufferOffsetAlignment.
struct buffer_range {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;
    VkDeviceSize size = VK_WHOLE_SIZE;
};

}  // namespace bounce::vk
