#pragma once
/// \file compute.hpp
/// The plumbing every Vulkan pass shares: a compute pipeline over N storage buffers at set 0,
/// bindings 0 .. N - 1, with push constants, built from SPIR-V words; and a submitter that
/// records a command buffer, submits it to the caller's queue and waits for it.

#include <bounce/vk/device.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>

namespace bounce::vk {

/// One compute pipeline and its one descriptor set. `record` rewrites the descriptor set, so
/// a command buffer that used the pipeline must have completed before `record` is called
/// again (the passes' run-and-wait calls guarantee it; a renderer recording its own command
/// buffers must too).
class compute_pipeline {
public:
    /// `spirv`: the shader (entry point "main"); `buffers`: storage buffers at bindings
    /// 0 .. buffers - 1 of set 0; `push_bytes`: size of the push-constant block (0: none).
    compute_pipeline(VkDevice device, std::span<const std::uint32_t> spirv, std::uint32_t buffers,
                     std::uint32_t push_bytes);
    ~compute_pipeline();
    compute_pipeline(const compute_pipeline&) = delete;
    compute_pipeline& operator=(const compute_pipeline&) = delete;

    /// Binds `buffers` (one per binding), pushes `push` (push_bytes bytes) and dispatches
    /// groups_x x groups_y x 1 workgroups into `cmd`. Throws parameter_error naming "buffers"
    /// when their count is not the pipeline's.
    void record(VkCommandBuffer cmd, std::span<const buffer_range> buffers, const void* push, std::uint32_t groups_x,
                std::uint32_t groups_y = 1) const;

private:
    void destroy() noexcept;

    VkDevice device_;
    std::uint32_t buffers_, push_bytes_;
    VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    VkDescriptorPool pool_ = VK_NULL_HANDLE;
    VkDescriptorSet set_ = VK_NULL_HANDLE;
};

/// Records into `cmd` a barrier making compute shader writes visible to later compute
/// shader reads and to the host.
void compute_barrier(VkCommandBuffer cmd);

/// Runs recorded work on the caller's queue and waits for it: owns a command pool (of the
/// queue's family) and a fence.
class submitter {
public:
    explicit submitter(const device_ref& device);
    ~submitter();
    submitter(const submitter&) = delete;
    submitter& operator=(const submitter&) = delete;

    /// Allocates a primary command buffer, calls `record(cmd)`, adds compute_barrier, submits
    /// it and waits until the queue has run it (so the host may read the results).
    void run(const std::function<void(VkCommandBuffer)>& record);

    const device_ref& device() const noexcept { return device_; }

private:
    device_ref device_;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
};

}  // namespace bounce::vk
