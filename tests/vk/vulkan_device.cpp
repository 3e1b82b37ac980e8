#include "vulkan_device.hpp"

#include <algorithm>
#include <string>

namespace vk_test {

using bounce::vk::check;

host_buffer::host_buffer(VkDevice device, VkPhysicalDevice physical, std::size_t bytes) : device_(device) {
    const VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, nullptr, 0, VkDeviceSize(bytes),
                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, VK_SHARING_MODE_EXCLUSIVE, 0, nullptr};
    check(vkCreateBuffer(device, &info, nullptr, &buffer_), "vkCreateBuffer");
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, buffer_, &req);
    VkPhysicalDeviceMemoryProperties props;
    vkGetPhysicalDeviceMemoryProperties(physical, &props);
    const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    std::uint32_t type = props.memoryTypeCount;
    for (std::uint32_t t = 0; t < props.memoryTypeCount; ++t)
        if ((req.memoryTypeBits & (1u << t)) && (props.memoryTypes[t].propertyFlags & want) == want) {
            type = t;
            break;
        }
    if (type == props.memoryTypeCount) throw bounce::vk::vulkan_error("host-visible memory type", VK_ERROR_FEATURE_NOT_PRESENT);
    const VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, nullptr, req.size, type};
    check(vkAllocateMemory(device, &alloc, nullptr, &memory_), "vkAllocateMemory");
    check(vkBindBufferMemory(device, buffer_, memory_, 0), "vkBindBufferMemory");
    check(vkMapMemory(device, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
    std::memset(mapped_, 0, bytes);
}

host_buffer::~host_buffer() {
    if (memory_) vkFreeMemory(device_, memory_, nullptr);  // unmaps
    if (buffer_) vkDestroyBuffer(device_, buffer_, nullptr);
}

std::unique_ptr<test_device> test_device::create() {
    std::unique_ptr<test_device> d(new test_device);
    const VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO, nullptr, "bounce tests", 1, nullptr, 0, VK_API_VERSION_1_2};
    const VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, nullptr, 0, &app, 0, nullptr, 0, nullptr};
    if (vkCreateInstance(&info, nullptr, &d->instance_) != VK_SUCCESS) return nullptr;
    std::uint32_t count = 0;
    vkEnumeratePhysicalDevices(d->instance_, &count, nullptr);
    std::vector<VkPhysicalDevice> physical(count);
    vkEnumeratePhysicalDevices(d->instance_, &count, physical.data());
    for (VkPhysicalDevice p : physical) {
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(p, &props);
        if (props.apiVersion < VK_API_VERSION_1_2) continue;
        std::uint32_t families = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(p, &families, nullptr);
        std::vector<VkQueueFamilyProperties> fp(families);
        vkGetPhysicalDeviceQueueFamilyProperties(p, &families, fp.data());
        for (std::uint32_t f = 0; f < families; ++f)
            if (fp[f].queueFlags & VK_QUEUE_COMPUTE_BIT) {
                const float priority = 1.f;
                const VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO, nullptr, 0, f, 1, &priority};
                const VkDeviceCreateInfo dev{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, nullptr, 0, 1, &queue, 0, nullptr, 0, nullptr, nullptr};
                if (vkCreateDevice(p, &dev, nullptr, &d->device_) != VK_SUCCESS) continue;
                d->physical_ = p;
                d->family_ = f;
                vkGetDeviceQueue(d->device_, f, 0, &d->queue_);
                return d;
            }
    }
    return nullptr;  // the destructor destroys the instance
}

test_device::~test_device() {
    if (device_) vkDestroyDevice(device_, nullptr);
    if (instance_) vkDestroyInstance(instance_, nullptr);
}

std::string test_device::name() const {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physical_, &props);
    return props.deviceName;
}

}  // namespace vk_test
