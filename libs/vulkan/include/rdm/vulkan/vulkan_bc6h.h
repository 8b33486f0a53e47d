// BC6H_UFLOAT encoding on Vulkan compute (shaders/bc6h_encode.comp, docs/bc6h.md): one
// invocation per 4 x 4 block, running shaders/shared/rdm_bc6h_encode.h, the encoder the CPU
// runs (rdm::encodeBc6h), in 32-bit integer arithmetic, so both give the same blocks on every
// device. Without the Vulkan backend (RDM_VULKAN=OFF) creation fails with a Status.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "rdm/base/status.h"
#include "rdm/image/bc6h.h"
#include "rdm/image/image.h"
#include "rdm/vulkan/vulkan_bake.h"

namespace rdm {

struct VulkanBc6hInfo {
  uint64_t blocks = 0;      // encoded since creation
  uint64_t dispatches = 0;  // one per band of block rows
  double seconds = 0.0;     // in encode(): upload, dispatches, read-back
};

// A Vulkan device with the BC6H encoder's pipeline, kept across images. One thread at a time.
class VulkanBc6hEncoder {
 public:
  // `device`: by index or name substring, as VulkanBakeOptions::device; empty picks the first
  // discrete GPU, else integrated, virtual, then CPU device.
  [[nodiscard]] static Expected<std::unique_ptr<VulkanBc6hEncoder>> create(
      const std::string& device);
  ~VulkanBc6hEncoder();
  VulkanBc6hEncoder(const VulkanBc6hEncoder&) = delete;
  VulkanBc6hEncoder& operator=(const VulkanBc6hEncoder&) = delete;

  const VulkanDeviceInfo& device() const;
  // Whether the device samples VK_FORMAT_BC6H_UFLOAT_BLOCK images with optimal tiling (and
  // filters them linearly): encoded pages could then be uploaded as they are.
  bool samplesBc6h() const;
  const VulkanBc6hInfo& info() const;

  // As encodeBc6h(image, {modes}): the same blocks, the same refusals (bc6hCheckEncodable);
  // device failures are kDevice errors.
  [[nodiscard]] Expected<Bc6hImage> encode(const Image& image,
                                           Bc6hModeSet modes = Bc6hModeSet::kAll);

 private:
  struct Impl;
  explicit VulkanBc6hEncoder(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// VulkanBc6hEncoder::create(device), then encode(image, modes).
[[nodiscard]] Expected<Bc6hImage> encodeBc6hVulkan(const Image& image,
                                                   const std::string& device = "",
                                                   Bc6hModeSet modes = Bc6hModeSet::kAll);

}  // namespace rdm
