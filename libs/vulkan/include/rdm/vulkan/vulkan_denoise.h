// The cross-block denoiser on Vulkan compute (shaders/denoise.comp, docs/denoise.md): the
// filter of shaders/shared/rdm_denoise.h, which the CPU runs too, one invocation per texel of
// a batch's faces. The source faces are built on the host (rdm::denoiseFaceTexels, each face
// of the batch once) and uploaded; the results come back into the RDMs. They agree with the
// CPU's up to the device's exp() (tests/vulkan/vulkan_denoise_test.cpp). Without the Vulkan
// backend (RDM_VULKAN=OFF) creation fails with a Status.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "rdm/bake/denoise.h"
#include "rdm/base/status.h"
#include "rdm/vulkan/vulkan_bake.h"

namespace rdm {

struct VulkanDenoiseInfo {
  uint64_t texels = 0;      // filtered (or passed through) since creation
  uint64_t dispatches = 0;  // one per band of faces
  double seconds = 0.0;     // in denoise(): building, upload, dispatches, read-back
};

// A Vulkan device with the denoiser's pipeline, kept across batches. One thread at a time.
class VulkanDenoiser final : public DenoiseDevice {
 public:
  // `device`: by index or name substring, as VulkanBakeOptions::device.
  [[nodiscard]] static Expected<std::unique_ptr<VulkanDenoiser>> create(const std::string& device);
  ~VulkanDenoiser() override;
  VulkanDenoiser(const VulkanDenoiser&) = delete;
  VulkanDenoiser& operator=(const VulkanDenoiser&) = delete;

  const VulkanDeviceInfo& device() const;
  const VulkanDenoiseInfo& info() const;

  [[nodiscard]] Status denoise(const std::vector<DenoiseInput>& batch,
                               const DenoiseSettings& settings, std::vector<RdmData>& out,
                               DenoiseStats& stats) override;
  size_t batchRdms() const override { return 64; }

 private:
  struct Impl;
  explicit VulkanDenoiser(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace rdm
