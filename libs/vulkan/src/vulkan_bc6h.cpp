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
#include "vulkan_compute_program.h"
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
  ComputeProgram program;
  const VulkanDeviceInfo& device{program.device};
  Buffer *texels = nullptr, *blocks = nullptr;
  bool samples_bc6h = false;
  VulkanBc6hInfo info;
};

Expected<std::unique_ptr<VulkanBc6hEncoder>> VulkanBc6hEncoder::create(const std::string& device) {
  auto impl = std::make_unique<Impl>();
  if (Status s = impl->program.create(device, "rdm-bc6h", spirv::kBc6hEncodeComp,
                                      spirv::kBc6hEncodeCompWords, 2);
      !s)
    return s;
  impl->samples_bc6h = impl->program.ctx.vulkan_device.samplesBc6h();
  return std::unique_ptr<VulkanBc6hEncoder>(new VulkanBc6hEncoder(std::move(impl)));
}

bool VulkanBc6hEncoder::samplesBc6h() const {
  return impl_->samples_bc6h;
}

Expected<Bc6hImage> VulkanBc6hEncoder::encode(const Image& image, Bc6hModeSet modes) {
  if (Status s = bc6hCheckEncodable(image); !s) return s;
  const auto start = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  ComputeProgram& p = m.program;
  Bc6hImage out;
  out.width = image.width;
  out.height = image.height;
  const uint32_t wide = uint32_t(out.blocksWide()), high = uint32_t(out.blocksHigh());
  out.blocks.resize(size_t(wide) * high * kBc6hBlockBytes);
  // One block row: 4 texel rows of `channels` floats, and `wide` blocks.
  const uint64_t row_bytes = uint64_t(image.width) * 4 * uint64_t(image.channels) * sizeof(float);
  const uint64_t row_limit = p.ctx.props.limits.maxStorageBufferRange / row_bytes;
  if (row_limit == 0)
    return Status::invalidField("width", "a block row of " + std::to_string(row_bytes) +
                                             " bytes exceeds the device's storage buffer range");
  const uint32_t rows =
      uint32_t(std::min<uint64_t>({std::max(1u, kBandBlocks / wide), high, row_limit}));
  if (Status s = p.ensure(m.texels, rows * row_bytes, "BC6H texel"); !s) return s;
  if (Status s = p.ensure(m.blocks, uint64_t(rows) * wide * kBc6hBlockBytes, "BC6H block"); !s)
    return s;
  p.ctx.bind({m.texels, m.blocks}, p.ctx.descriptor_set);
  for (uint32_t by = 0; by < high; by += rows) {
    const uint32_t band = std::min(rows, high - by), count = band * wide;
    RDM_CHECK((count + gpu::kWorkgroupSize - 1) / gpu::kWorkgroupSize <=
              p.ctx.props.limits.maxComputeWorkGroupCount[0]);
    std::memcpy(m.texels->mapped, &image.pixels[size_t(by) * (row_bytes / sizeof(float))],
                band * row_bytes);
    // Texels per block ride in z's bits 8..15 (bc6h_encode.comp): not a compile-time constant.
    const uint32_t modes_texels = uint32_t(int(modes)) | (16u << 8);
    const gpu::GpuPush push{
        glm::uvec4(uint32_t(image.width), uint32_t(image.channels), modes_texels, count)};
    if (Status s = p.ctx.dispatch(p.pipeline, push, count, nullptr, p.ctx.descriptor_set); !s)
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
