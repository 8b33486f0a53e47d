// A standalone compute program (the BC6H encoder, the denoiser): its own device, one pipeline
// over `bindings` storage buffers at bindings 0.. with a GpuPush push constant, and the
// buffers it grows, on the bake's Context and Buffers.
#pragma once

#if RDM_HAVE_VULKAN

#include <cstddef>
#include <cstdint>
#include <string>

#include "vulkan_context.h"

namespace rdm::vkbake {

struct ComputeProgram {
  Context ctx;
  Buffers buffers{ctx};
  VkShaderModule shader = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VulkanDeviceInfo device;

  ComputeProgram() = default;
  ComputeProgram(const ComputeProgram&) = delete;
  ComputeProgram& operator=(const ComputeProgram&) = delete;
  ~ComputeProgram();

  // The device `wanted` (VulkanBakeOptions::device) and the pipeline of `words` (SPIR-V).
  [[nodiscard]] Status create(const std::string& wanted, const char* application,
                              const uint32_t* words, size_t word_count, uint32_t bindings);
  // `buffer` grown to at least `bytes` (a grown buffer's predecessor stays allocated until the
  // program is destroyed; sizes double).
  [[nodiscard]] Status ensure(Buffer*& buffer, uint64_t bytes, const char* what);

 private:
  Status createDevice(const std::string& wanted, const char* application);
  Status createPipeline(const uint32_t* words, size_t word_count, uint32_t bindings);
};

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
