#pragma once
// The test's own Vulkan instance and device (the adapter never creates them): the first
// physical device with a compute queue (lavapipe here), and host-visible coherent storage
// buffers the tests fill and read directly.
#include <bounce/vk/device.hpp>

#include <cstddef>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

namespace vk_test {

class host_buffer {
public:
    host_buffer(VkDevice device, VkPhysicalDevice physical, std::size_t bytes);
    ~host_buffer();
    host_buffer(const host_buffer&) = delete;
    host_buffer& operator=(const host_buffer&) = delete;

    bounce::vk::buffer_range range() const { return {buffer_, 0, VK_WHOLE_SIZE}; }
    template <class T>
    void write(std::span<const T> values) {
        std::memcpy(mapped_, values.data(), values.size_bytes());
    }
    template <class T>
    std::vector<T> read(std::size_t count) const {
        std::vector<T> out(count);
        std::memcpy(out.data(), mapped_, count * sizeof(T));
        return out;
    }

private:
    VkDevice device_;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    void* mapped_ = nullptr;
};

class test_device {
public:
    /// The device, or null when this machine has no Vulkan device with a compute queue.
    static std::unique_ptr<test_device> create();
    ~test_device();

    bounce::vk::device_ref ref() const { return {device_, queue_, family_}; }
    /// A buffer of `count` T, filled with `values` when given.
    template <class T>
    std::unique_ptr<host_buffer> buffer(std::size_t count, std::span<const T> values = {}) {
        auto b = std::make_unique<host_buffer>(device_, physical_, std::max<std::size_t>(count * sizeof(T), 16));
        if (!values.empty()) b->write(values);
        return b;
    }
    /// The device's name, for messages.
    std::string name() const;

private:
    test_device() = default;
    VkInstance instance_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    std::uint32_t family_ = 0;
};

}  // namespace vk_test
