// The BC6H encoder on Vulkan compute (rdm/vulkan/vulkan_bc6h.h, shaders/bc6h_encode.comp): its
// own device, descriptor set (binding 0 texels, 1 blocks) and pipeline, on the bake's Context
// and Buffers. An image is encoded in bands of whole block rows, one dispatch each, so the
// buffers stay small and a dispatch short whatever the image's size.
#include "rdm/vulkan/vulkan_bc6h.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "shared/rdm_bc6h_encode.h"

#if RDM_HAVE_VULKAN
#include "vulkan_context.h"
#endif

namespace rdm {

static_assert(int(Bc6hModeSet::kMode11) == shared::kBc6hModesMode11 &&
              int(Bc6hModeSet::kOneRegion) == shared::kBc6hModesOneRegion &&
              int(Bc6hModeSet::kAll) == shared::kBc6hModesAll);

#if !RDM_HAVE_VULKAN

struct VulkanBc6hEncoder::Impl {
  VulkanDeviceInfo device;
  VulkanBc6hInfo info;
};
Expected<std::unique_ptr<VulkanBc6hEncoder>> VulkanBc6hEncoder::create(const std::string&) {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}
bool VulkanBc6hEncoder::samplesBc6h() const {
  return false;
}
Expected<Bc6hImage> VulkanBc6hEncoder::encode(const Image&, Bc6hModeSet) {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}

#else

using namespace vkbake;

namespace {

// Blocks per dispatch: 256 workgroups; about 0.1-0.3 s on lavapipe with 2 cores.
constexpr uint32_t kBandBlocks = 1u << 14;

}  // namespace

struct VulkanBc6hEncoder::Impl {
  Context ctx;
  Buffers buffers{ctx};
  VkShaderModule shader = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  Buffer *texels = nullptr, *blocks = nullptr;
  VulkanDeviceInfo device;
  bool samples_bc6h = false;
  VulkanBc6hInfo info;

  ~Impl() {
    if (!ctx.device) return;
    vkDeviceWaitIdle(ctx.device);
    if (pipeline) vkDestroyPipeline(ctx.device, pipeline, nullptr);
    if (shader) vkDestroyShaderModule(ctx.device, shader, nullptr);
  }

  Status createDevice(const std::string& wanted);
  Status createPipeline();
  Status ensure(Buffer*& buffer, uint64_t bytes, const char* what);
};

Status VulkanBc6hEncoder::Impl::createDevice(const std::string& wanted) {
  VulkanInstanceOptions options;
  options.application = "rdm-bc6h";
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
  samples_bc6h = ctx.vulkan_device.samplesBc6h();
  return {};
}

// The set layout, pipeline layout and descriptor set live in the Context, which destroys them.
Status VulkanBc6hEncoder::Impl::createPipeline() {
  const VkDevice dev = ctx.device;
  VkDescriptorSetLayoutBinding bindings[2];
  for (uint32_t i = 0; i < 2; ++i)
    bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.bindingCount = 2;
  set_info.pBindings = bindings;
  RDM_VK_TRY(vkCreateDescriptorSetLayout(dev, &set_info, nullptr, &ctx.set_layout));
  VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(gpu::GpuPush)};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &ctx.set_layout;
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &push;
  RDM_VK_TRY(vkCreatePipelineLayout(dev, &layout_info, nullptr, &ctx.pipeline_layout));
  VkShaderModuleCreateInfo module{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  module.codeSize = spirv::kBc6hEncodeCompWords * sizeof(uint32_t);
  module.pCode = spirv::kBc6hEncodeComp;
  RDM_VK_TRY(vkCreateShaderModule(dev, &module, nullptr, &shader));
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = shader;
  info.stage.pName = "main";
  info.layout = ctx.pipeline_layout;
  RDM_VK_TRY(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2};
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

Status VulkanBc6hEncoder::Impl::ensure(Buffer*& buffer, uint64_t bytes, const char* what) {
  if (buffer && buffer->size >= bytes) return {};
  // A grown buffer's predecessor stays allocated until the encoder is destroyed; sizes double.
  auto made = buffers.create(std::max<uint64_t>(bytes, buffer ? 2 * buffer->size : 0), what);
  if (!made) return made.status();
  buffer = *made;
  return {};
}

Expected<std::unique_ptr<VulkanBc6hEncoder>> VulkanBc6hEncoder::create(const std::string& device) {
  auto impl = std::make_unique<Impl>();
  if (Status s = impl->createDevice(device); !s) return s;
  if (Status s = impl->createPipeline(); !s) return s;
  return std::unique_ptr<VulkanBc6hEncoder>(new VulkanBc6hEncoder(std::move(impl)));
}

bool VulkanBc6hEncoder::samplesBc6h() const {
  return impl_->samples_bc6h;
}

Expected<Bc6hImage> VulkanBc6hEncoder::encode(const Image& image, Bc6hModeSet modes) {
  if (Status s = bc6hCheckEncodable(image); !s) return s;
  const auto start = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  Bc6hImage out;
  out.width = image.width;
  out.height = image.height;
  const uint32_t wide = uint32_t(out.blocksWide()), high = uint32_t(out.blocksHigh());
  out.blocks.resize(size_t(wide) * high * kBc6hBlockBytes);
  // One block row: 4 texel rows of `channels` floats, and `wide` blocks.
  const uint64_t row_bytes = uint64_t(image.width) * 4 * uint64_t(image.channels) * sizeof(float);
  const uint64_t row_limit = m.ctx.props.limits.maxStorageBufferRange / row_bytes;
  if (row_limit == 0)
    return Status::invalidField("width", "a block row of " + std::to_string(row_bytes) +
                                             " bytes exceeds the device's storage buffer range");
  const uint32_t rows =
      uint32_t(std::min<uint64_t>({std::max(1u, kBandBlocks / wide), high, row_limit}));
  if (Status s = m.ensure(m.texels, rows * row_bytes, "BC6H texel"); !s) return s;
  if (Status s = m.ensure(m.blocks, uint64_t(rows) * wide * kBc6hBlockBytes, "BC6H block"); !s)
    return s;
  m.ctx.bind({m.texels, m.blocks}, m.ctx.descriptor_set);
  for (uint32_t by = 0; by < high; by += rows) {
    const uint32_t band = std::min(rows, high - by), count = band * wide;
    RDM_CHECK((count + gpu::kWorkgroupSize - 1) / gpu::kWorkgroupSize <=
              m.ctx.props.limits.maxComputeWorkGroupCount[0]);
    std::memcpy(m.texels->mapped, &image.pixels[size_t(by) * (row_bytes / sizeof(float))],
                band * row_bytes);
    // Texels per block ride in z's bits 8..15 (bc6h_encode.comp): not a compile-time constant.
    const uint32_t modes_texels = uint32_t(int(modes)) | (16u << 8);
    const gpu::GpuPush push{
        glm::uvec4(uint32_t(image.width), uint32_t(image.channels), modes_texels, count)};
    if (Status s = m.ctx.dispatch(m.pipeline, push, count, nullptr, m.ctx.descriptor_set); !s)
      return s;
    std::memcpy(&out.blocks[size_t(by) * wide * kBc6hBlockBytes], m.blocks->mapped,
                size_t(count) * kBc6hBlockBytes);
    ++m.info.dispatches;
  }
  m.info.blocks += uint64_t(wide) * high;
  m.info.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

#endif  // RDM_HAVE_VULKAN

VulkanBc6hEncoder::VulkanBc6hEncoder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
VulkanBc6hEncoder::~VulkanBc6hEncoder() = default;

const VulkanDeviceInfo& VulkanBc6hEncoder::device() const {
  return impl_->device;
}
const VulkanBc6hInfo& VulkanBc6hEncoder::info() const {
  return impl_->info;
}

Expected<Bc6hImage> encodeBc6hVulkan(const Image& image, const std::string& device,
                                     Bc6hModeSet modes) {
  if (Status s = bc6hCheckEncodable(image); !s) return s;
  auto encoder = VulkanBc6hEncoder::create(device);
  if (!encoder) return encoder.status();
  return (*encoder)->encode(image, modes);
}

}  // namespace rdm
