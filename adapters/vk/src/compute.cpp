// Vulkan plumbing: errors, compute pipelines over storage buffers, run-and-wait submission.
#include <bounce/vk/compute.hpp>

#include <vector>

namespace bounce::vk {

std::string result_name(VkResult r) {
    switch (r) {
#define BOUNCE_VK_RESULT(name) \
    case name: return #name;
        BOUNCE_VK_RESULT(VK_SUCCESS)
        BOUNCE_VK_RESULT(VK_NOT_READY)
        BOUNCE_VK_RESULT(VK_TIMEOUT)
        BOUNCE_VK_RESULT(VK_INCOMPLETE)
        BOUNCE_VK_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
        BOUNCE_VK_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        BOUNCE_VK_RESULT(VK_ERROR_INITIALIZATION_FAILED)
        BOUNCE_VK_RESULT(VK_ERROR_DEVICE_LOST)
        BOUNCE_VK_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
        BOUNCE_VK_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
        BOUNCE_VK_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
        BOUNCE_VK_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
        BOUNCE_VK_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
        BOUNCE_VK_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
        BOUNCE_VK_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
        BOUNCE_VK_RESULT(VK_ERROR_FRAGMENTED_POOL)
        BOUNCE_VK_RESULT(VK_ERROR_UNKNOWN)
        BOUNCE_VK_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
        BOUNCE_VK_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
        BOUNCE_VK_RESULT(VK_ERROR_FRAGMENTATION)
        BOUNCE_VK_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
        BOUNCE_VK_RESULT(VK_ERROR_INVALID_SHADER_NV)
#undef BOUNCE_VK_RESULT
        default: return "VkResult " + std::to_string(int(r));
    }
}

vulkan_error::vulkan_error(const std::string& call, VkResult result)
    : error(call + " failed: " + result_name(result) + " (" + std::to_string(int(result)) + ")"), call_(call), result_(result) {}

void device_ref::validate() const {
    require(device != VK_NULL_HANDLE && queue != VK_NULL_HANDLE, "device", "needs the caller's VkDevice and VkQueue");
}

compute_pipeline::compute_pipeline(VkDevice device, std::span<const std::uint32_t> spirv, std::uint32_t buffers,
                                   std::uint32_t push_bytes)
    : device_(device), buffers_(buffers), push_bytes_(push_bytes) {
    require(device != VK_NULL_HANDLE, "device", "needs the caller's VkDevice");
    std::vector<VkDescriptorSetLayoutBinding> bindings(buffers);
    for (std::uint32_t b = 0; b < buffers; ++b)
        bindings[b] = {b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    // Each object is owned as soon as it exists: a later failure destroys the earlier ones.
    struct cleanup {
        compute_pipeline* self;
        VkShaderModule module = VK_NULL_HANDLE;
        bool done = false;
        ~cleanup() {
            if (module) vkDestroyShaderModule(self->device_, module, nullptr);
            if (!done) self->destroy();
        }
    } guard{this};
    const VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, nullptr, 0, buffers,
                                                   bindings.data()};
    check(vkCreateDescriptorSetLayout(device_, &set_info, nullptr, &set_layout_), "vkCreateDescriptorSetLayout");
    const VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes};
    const VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, nullptr, 0, 1, &set_layout_,
                                                 push_bytes ? 1u : 0u, push_bytes ? &range : nullptr};
    check(vkCreatePipelineLayout(device_, &layout_info, nullptr, &layout_), "vkCreatePipelineLayout");
    const VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO, nullptr, 0,
                                               spirv.size() * sizeof(std::uint32_t), spirv.data()};
    check(vkCreateShaderModule(device_, &module_info, nullptr, &guard.module), "vkCreateShaderModule");
    const VkComputePipelineCreateInfo pipeline_info{
        VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO, nullptr, 0,
        {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_COMPUTE_BIT, guard.module, "main", nullptr},
        layout_, VK_NULL_HANDLE, -1};
    check(vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &pipeline_info, nullptr, &pipeline_), "vkCreateComputePipelines");
    const VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, buffers};
    const VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, nullptr, 0, 1, 1, &pool_size};
    check(vkCreateDescriptorPool(device_, &pool_info, nullptr, &pool_), "vkCreateDescriptorPool");
    const VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, nullptr, pool_, 1, &set_layout_};
    check(vkAllocateDescriptorSets(device_, &alloc, &set_), "vkAllocateDescriptorSets");
    guard.done = true;
}

compute_pipeline::~compute_pipeline() { destroy(); }

void compute_pipeline::destroy() noexcept {
    if (pool_) vkDestroyDescriptorPool(device_, pool_, nullptr);
    if (pipeline_) vkDestroyPipeline(device_, pipeline_, nullptr);
    if (layout_) vkDestroyPipelineLayout(device_, layout_, nullptr);
    if (set_layout_) vkDestroyDescriptorSetLayout(device_, set_layout_, nullptr);
    pool_ = VK_NULL_HANDLE;
    pipeline_ = VK_NULL_HANDLE;
    layout_ = VK_NULL_HANDLE;
    set_layout_ = VK_NULL_HANDLE;
}

void compute_pipeline::record(VkCommandBuffer cmd, std::span<const buffer_range> buffers, const void* push,
                              std::uint32_t groups_x, std::uint32_t groups_y) const {
    require(buffers.size() == buffers_, "buffers", "one buffer per binding of the pass");
    std::vector<VkDescriptorBufferInfo> infos(buffers_);
    std::vector<VkWriteDescriptorSet> writes(buffers_);
    for (std::uint32_t b = 0; b < buffers_; ++b) {
        require(buffers[b].buffer != VK_NULL_HANDLE, "buffers", "a buffer is null");
        infos[b] = {buffers[b].buffer, buffers[b].offset, buffers[b].size};
        writes[b] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, nullptr, set_, b, 0, 1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, nullptr,
                     &infos[b], nullptr};
    }
    vkUpdateDescriptorSets(device_, buffers_, writes.data(), 0, nullptr);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 0, nullptr);
    if (push_bytes_) vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes_, push);
    if (groups_x > 0 && groups_y > 0) vkCmdDispatch(cmd, groups_x, groups_y, 1);
}

void compute_barrier(VkCommandBuffer cmd) {
    const VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr, VK_ACCESS_SHADER_WRITE_BIT,
                                  VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr, 0,
                         nullptr);
}

submitter::submitter(const device_ref& device) : device_(device) {
    device.validate();
    const VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO, nullptr,
                                            VK_COMMAND_POOL_CREATE_TRANSIENT_BIT, device.queue_family};
    check(vkCreateCommandPool(device_.device, &pool_info, nullptr, &pool_), "vkCreateCommandPool");
    const VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO, nullptr, 0};
    const VkResult r = vkCreateFence(device_.device, &fence_info, nullptr, &fence_);
    if (r != VK_SUCCESS) {
        vkDestroyCommandPool(device_.device, pool_, nullptr);
        throw vulkan_error("vkCreateFence", r);
    }
}

submitter::~submitter() {
    vkDestroyFence(device_.device, fence_, nullptr);
    vkDestroyCommandPool(device_.device, pool_, nullptr);
}

void submitter::run(const std::function<void(VkCommandBuffer)>& record) {
    const VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, pool_,
                                            VK_COMMAND_BUFFER_LEVEL_PRIMARY, 1};
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    check(vkAllocateCommandBuffers(device_.device, &alloc, &cmd), "vkAllocateCommandBuffers");
    struct release {
        VkDevice device;
        VkCommandPool pool;
        VkCommandBuffer cmd;
        ~release() { vkFreeCommandBuffers(device, pool, 1, &cmd); }
    } guard{device_.device, pool_, cmd};
    const VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, nullptr,
                                         VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT, nullptr};
    check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    record(cmd);
    compute_barrier(cmd);
    check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
    const VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO, nullptr, 0, nullptr, nullptr, 1, &cmd, 0, nullptr};
    check(vkResetFences(device_.device, 1, &fence_), "vkResetFences");
    check(vkQueueSubmit(device_.queue, 1, &submit, fence_), "vkQueueSubmit");
    check(vkWaitForFences(device_.device, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
}

}  // namespace bounce::vk
