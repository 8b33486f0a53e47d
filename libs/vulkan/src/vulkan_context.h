// The Vulkan objects of the compute bake (instance, device, pipelines kept across bakes;
// the buffers of one bake; submission), with every VkResult turned into a Status. Internal
// to vulkan_bake.cpp and vulkan_bake_batches.cpp.
#pragma once

#if RDM_HAVE_VULKAN
#include <vulkan/vulkan.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

#include "rdm/base/status.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "rdm/vulkan/vulkan_bootstrap.h"
#include "rdm/vulkan/vulkan_device.h"
#include "rdm_spirv.h"
#include "shared/rdm_gpu_layout.h"

namespace rdm::vkbake {

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkDeviceSize size = 0;
};

// The device and what bakes share on it: queue, command buffer, descriptor set and the
// compiled pipelines, one per effect and recording variant. Destroyed in reverse order.
struct Context {
  struct Variant {
    bool sun, emitters, record;
    VkPipeline pipeline;
  };
  VulkanInstance instance;
  VulkanDevice vulkan_device;
  VkDevice device = VK_NULL_HANDLE;  // vulkan_device.handle()
  VkPhysicalDeviceProperties props{};
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
  VkShaderModule shader = VK_NULL_HANDLE;
  std::vector<Variant> pipelines;
  VkShaderModule prefilter_shader = VK_NULL_HANDLE;
  VkPipeline prefilter_pipeline = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool = VK_NULL_HANDLE;
  VkDescriptorSet descriptor_set = VK_NULL_HANDLE;  // the bake kernel's buffers
  VkDescriptorSet prefilter_set = VK_NULL_HANDLE;   // the prefilter pass's buffers

  // What the device made; the members then destroy the device (`vulkan_device`) and the instance.
  ~Context() {
    if (device) {
      vkDeviceWaitIdle(device);
      if (descriptor_pool) vkDestroyDescriptorPool(device, descriptor_pool, nullptr);
      for (const Variant& v : pipelines) vkDestroyPipeline(device, v.pipeline, nullptr);
      if (prefilter_pipeline) vkDestroyPipeline(device, prefilter_pipeline, nullptr);
      if (prefilter_shader) vkDestroyShaderModule(device, prefilter_shader, nullptr);
      if (shader) vkDestroyShaderModule(device, shader, nullptr);
      if (pipeline_layout) vkDestroyPipelineLayout(device, pipeline_layout, nullptr);
      if (set_layout) vkDestroyDescriptorSetLayout(device, set_layout, nullptr);
    }
  }

  // The device of `choice` (chooseVulkanDevice with QueueNeed::kCompute) with its queue.
  Status createDevice(const VulkanDeviceChoice& choice) {
    // The kernel accounts its loop iterations with subgroupMax (shaders/bake.comp).
    VkPhysicalDeviceSubgroupProperties subgroup{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props2.pNext = &subgroup;
    vkGetPhysicalDeviceProperties2(choice.physical, &props2);
    if (!(subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) ||
        !(subgroup.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT)) {
      return Status::error(
          std::string("Vulkan: device '") + props2.properties.deviceName +
          "' lacks subgroup arithmetic in compute shaders, which the bake kernel needs");
    }
    auto created = VulkanDevice::create(choice.physical, choice.queue_family, {});
    if (!created) return created.status();
    vulkan_device = std::move(*created);
    device = vulkan_device.handle();
    props = vulkan_device.properties();
    return {};
  }

  // The descriptor set layout, pipeline layout, shader modules and the two descriptor sets
  // (bake kernel, prefilter pass) the pipelines share; the prefilter pass uses the first
  // kBindingDerivedTexels + 1 bindings.
  Status createLayout() {
    std::vector<VkDescriptorSetLayoutBinding> bindings(gpu::kBindingCount);
    for (int i = 0; i < gpu::kBindingCount; ++i) {
      bindings[size_t(i)] = {uint32_t(i), VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1,
                             VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    }
    VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    set_info.bindingCount = uint32_t(bindings.size());
    set_info.pBindings = bindings.data();
    RDM_VK_TRY(vkCreateDescriptorSetLayout(device, &set_info, nullptr, &set_layout));
    VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(gpu::GpuPush)};
    VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &set_layout;
    layout_info.pushConstantRangeCount = 1;
    layout_info.pPushConstantRanges = &push;
    RDM_VK_TRY(vkCreatePipelineLayout(device, &layout_info, nullptr, &pipeline_layout));
    VkShaderModuleCreateInfo module{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    module.codeSize = spirv::kBakeCompWords * sizeof(uint32_t);
    module.pCode = spirv::kBakeComp;
    RDM_VK_TRY(vkCreateShaderModule(device, &module, nullptr, &shader));
    module.codeSize = spirv::kPrefilterCompWords * sizeof(uint32_t);
    module.pCode = spirv::kPrefilterComp;
    RDM_VK_TRY(vkCreateShaderModule(device, &module, nullptr, &prefilter_shader));
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2 * uint32_t(gpu::kBindingCount)};
    VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pool.maxSets = 2;
    pool.poolSizeCount = 1;
    pool.pPoolSizes = &size;
    RDM_VK_TRY(vkCreateDescriptorPool(device, &pool, nullptr, &descriptor_pool));
    VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    alloc.descriptorPool = descriptor_pool;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &set_layout;
    RDM_VK_TRY(vkAllocateDescriptorSets(device, &alloc, &descriptor_set));
    RDM_VK_TRY(vkAllocateDescriptorSets(device, &alloc, &prefilter_set));
    return {};
  }

  // The prefilter pass's pipeline, compiled on first use and kept.
  Expected<VkPipeline> prefilterPipeline() {
    if (prefilter_pipeline) return prefilter_pipeline;
    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = prefilter_shader;
    info.stage.pName = "main";
    info.layout = pipeline_layout;
    RDM_VK_TRY(
        vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &prefilter_pipeline));
    return prefilter_pipeline;
  }

  // The pipeline of one variant, compiled on first use (lavapipe: 0.1-0.3 s) and kept.
  // Specialization constants 0 (sun), 1 (emitters) and 2 (slot-set recording).
  Expected<VkPipeline> pipeline(bool sun, bool emitters, bool record) {
    for (const Variant& v : pipelines) {
      if (v.sun == sun && v.emitters == emitters && v.record == record) return v.pipeline;
    }
    const VkBool32 constants[3] = {sun ? VK_TRUE : VK_FALSE, emitters ? VK_TRUE : VK_FALSE,
                                   record ? VK_TRUE : VK_FALSE};
    const VkSpecializationMapEntry entries[3] = {{0, 0, sizeof(VkBool32)},
                                                 {1, sizeof(VkBool32), sizeof(VkBool32)},
                                                 {2, 2 * sizeof(VkBool32), sizeof(VkBool32)}};
    VkSpecializationInfo spec{3, entries, sizeof(constants), constants};
    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = shader;
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = &spec;
    info.layout = pipeline_layout;
    VkPipeline made = VK_NULL_HANDLE;
    RDM_VK_TRY(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &made));
    pipelines.push_back({sun, emitters, record, made});
    return made;
  }

  // Points `set`'s bindings 0.. at `by_binding`.
  void bind(const std::vector<Buffer*>& by_binding, VkDescriptorSet set) {
    std::vector<VkDescriptorBufferInfo> infos(by_binding.size());
    std::vector<VkWriteDescriptorSet> writes(by_binding.size());
    for (size_t i = 0; i < by_binding.size(); ++i) {
      infos[i] = {by_binding[i]->buffer, 0, VK_WHOLE_SIZE};
      writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      writes[i].dstSet = set;
      writes[i].dstBinding = uint32_t(i);
      writes[i].descriptorCount = 1;
      writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[i].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(device, uint32_t(writes.size()), writes.data(), 0, nullptr);
  }

  // Records and runs one dispatch of `invocations` on `set` (after clearing `clear` when
  // given) and waits for it.
  Status dispatch(VkPipeline pipeline, const gpu::GpuPush& push, uint32_t invocations,
                  Buffer* clear, VkDescriptorSet set) {
    return vulkan_device.submitAndWait([&](VkCommandBuffer command_buffer) {
      VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      barrier.srcAccessMask = VK_ACCESS_HOST_WRITE_BIT;
      barrier.dstAccessMask =
          VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
      vkCmdPipelineBarrier(command_buffer, VK_PIPELINE_STAGE_HOST_BIT,
                           VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                           1, &barrier, 0, nullptr, 0, nullptr);
      if (clear) {
        vkCmdFillBuffer(command_buffer, clear->buffer, 0, VK_WHOLE_SIZE, 0u);
        barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
        vkCmdPipelineBarrier(command_buffer, VK_PIPELINE_STAGE_TRANSFER_BIT,
                             VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &barrier, 0, nullptr, 0,
                             nullptr);
      }
      vkCmdBindPipeline(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
      vkCmdBindDescriptorSets(command_buffer, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout, 0, 1,
                              &set, 0, nullptr);
      vkCmdPushConstants(command_buffer, pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                         sizeof(push), &push);
      vkCmdDispatch(command_buffer, (invocations + gpu::kWorkgroupSize - 1) / gpu::kWorkgroupSize,
                    1, 1);
      barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
      barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
      vkCmdPipelineBarrier(command_buffer, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                           VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr, 0, nullptr);
    });
  }
};

// The buffers of one bake, freed when it ends (after the device is idle).
struct Buffers {
  Context& ctx;
  std::deque<Buffer> list;  // stable addresses
  explicit Buffers(Context& c) : ctx(c) {}
  Buffers(const Buffers&) = delete;
  Buffers& operator=(const Buffers&) = delete;
  ~Buffers() {
    if (list.empty()) return;
    vkDeviceWaitIdle(ctx.device);
    for (Buffer& b : list) {
      if (b.mapped) vkUnmapMemory(ctx.device, b.memory);
      if (b.buffer) vkDestroyBuffer(ctx.device, b.buffer, nullptr);
      if (b.memory) vkFreeMemory(ctx.device, b.memory, nullptr);
    }
  }

  // A host-visible, coherent storage buffer (device-local too where the device offers it).
  Expected<Buffer*> create(VkDeviceSize size, const char* what) {
    size = std::max<VkDeviceSize>(size, 16);
    if (size > ctx.props.limits.maxStorageBufferRange) {
      return Status::error(std::string("Vulkan: the ") + what + " buffer needs " +
                           std::to_string(size) +
                           " bytes, more than the device's maxStorageBufferRange " +
                           std::to_string(ctx.props.limits.maxStorageBufferRange));
    }
    list.emplace_back();
    Buffer& b = list.back();
    b.size = size;
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    RDM_VK_TRY(vkCreateBuffer(ctx.device, &info, nullptr, &b.buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(ctx.device, b.buffer, &req);
    const VkMemoryPropertyFlags need =
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    auto type = ctx.vulkan_device.memoryType(req.memoryTypeBits,
                                             need | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (!type) type = ctx.vulkan_device.memoryType(req.memoryTypeBits, need);
    if (!type) {
      return Status::error(StatusCode::kDevice,
                           type.error() + " for the " + what + " storage buffer");
    }
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = *type;
    RDM_VK_TRY(vkAllocateMemory(ctx.device, &alloc, nullptr, &b.memory));
    RDM_VK_TRY(vkBindBufferMemory(ctx.device, b.buffer, b.memory, 0));
    RDM_VK_TRY(vkMapMemory(ctx.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
    return &b;
  }
};

// One bake on `ctx` (created, with its layout; vulkan_bake_batches.cpp): bakeRdmsVulkan without
// the device creation and the argument checks.
Expected<BakeResult> bakeOnContext(Context& ctx, const VulkanDeviceInfo& device,
                                   const VoxelWorld& world, const BakeSettings& settings,
                                   const std::vector<RdmId>& rdms,
                                   const VulkanBakeOptions& options);
// VulkanBaker::traceFaceLight on `ctx` (vulkan_face_light.cpp).
Status traceFaceLightOnContext(Context& ctx, const VoxelWorld& world, const BakeSettings& settings,
                               int spp, std::vector<FaceLightSlot>& slots,
                               const FaceLightTraceHooks& hooks);
// VulkanBaker::render on `ctx` (vulkan_render.cpp); `options` already checked.
Expected<Image> renderOnContext(Context& ctx, const Scene& scene, const VoxelWorld& world,
                                const RenderOptions& options, RenderReport* report);

}  // namespace rdm::vkbake
#endif  // RDM_HAVE_VULKAN
