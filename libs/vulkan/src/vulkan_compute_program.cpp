#if RDM_HAVE_VULKAN

#include "vulkan_compute_program.h"

#include <algorithm>
#include <vector>

namespace rdm::vkbake {

ComputeProgram::~ComputeProgram() {
  if (!ctx.device) return;
  vkDeviceWaitIdle(ctx.device);
  if (pipeline) vkDestroyPipeline(ctx.device, pipeline, nullptr);
  if (shader) vkDestroyShaderModule(ctx.device, shader, nullptr);
}

Status ComputeProgram::create(const std::string& wanted, const char* application,
                              const uint32_t* words, size_t word_count, uint32_t bindings) {
  if (Status s = createDevice(wanted, application); !s) return s;
  return createPipeline(words, word_count, bindings);
}

Status ComputeProgram::createDevice(const std::string& wanted, const char* application) {
  VulkanInstanceOptions options;
  options.application = application;
  auto instance = VulkanInstance::create(options);
  if (!instance) return instance.status();
  ctx.instance = std::move(*instance);
  auto choice = chooseVulkanDevice(ctx.instance.handle(), wanted, QueueNeed::kCompute);
  if (!choice) return choice.status();
  auto created = VulkanDevice::create(choice->physical, choice->queue_family, {});
  if (!created) return created.status();
  ctx.vulkan_device = std::move(*created);
  ctx.device = ctx.vulkan_device.handle();
  ctx.props = ctx.vulkan_device.properties();
  device = choice->info;
  return {};
}

// The set layout, pipeline layout and descriptor set live in the Context, which destroys them.
Status ComputeProgram::createPipeline(const uint32_t* words, size_t word_count, uint32_t bindings) {
  const VkDevice dev = ctx.device;
  std::vector<VkDescriptorSetLayoutBinding> layout(bindings);
  for (uint32_t i = 0; i < bindings; ++i)
    layout[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.bindingCount = bindings;
  set_info.pBindings = layout.data();
  RDM_VK_TRY(vkCreateDescriptorSetLayout(dev, &set_info, nullptr, &ctx.set_layout));
  VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(gpu::GpuPush)};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &ctx.set_layout;
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &push;
  RDM_VK_TRY(vkCreatePipelineLayout(dev, &layout_info, nullptr, &ctx.pipeline_layout));
  VkShaderModuleCreateInfo module{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  module.codeSize = word_count * sizeof(uint32_t);
  module.pCode = words;
  RDM_VK_TRY(vkCreateShaderModule(dev, &module, nullptr, &shader));
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = shader;
  info.stage.pName = "main";
  info.layout = ctx.pipeline_layout;
  RDM_VK_TRY(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, bindings};
  VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool.maxSets = 1;
  pool.poolSizeCount = 1;
  pool.pPoolSizes = &size;
  RDM_VK_TRY(vkCreateDescriptorPool(dev, &pool, nullptr, &ctx.descriptor_pool));
  VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc.descriptorPool = ctx.descriptor_pool;
  alloc.descriptorSetCount = 1;
  alloc.pSetLayouts = &ctx.set_layout;
  RDM_VK_TRY(vkAllocateDescriptorSets(dev, &alloc, &ctx.descriptor_set));
  return {};
}

Status ComputeProgram::ensure(Buffer*& buffer, uint64_t bytes, const char* what) {
  if (buffer && buffer->size >= bytes) return {};
  auto made = buffers.create(std::max<uint64_t>(bytes, buffer ? 2 * buffer->size : 0), what);
  if (!made) return made.status();
  buffer = *made;
  return {};
}

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
