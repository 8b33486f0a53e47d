// Owning wrappers for Vulkan buffers and images, and barrier helpers. Buffers are
// host-visible, coherent and persistently mapped (lavapipe's memory is host memory; on a
// discrete GPU these are the small per-scene buffers, read through the PCIe BAR).
#pragma once

#include <cstddef>
#include <cstdint>

#include <vulkan/vulkan.h>

#include "rdm/base/status.h"
#include "vk_context.h"

namespace rdm::viewer {

class GpuBuffer {
 public:
  GpuBuffer() = default;
  GpuBuffer(GpuBuffer&& other) noexcept { *this = std::move(other); }
  GpuBuffer& operator=(GpuBuffer&& other) noexcept;
  ~GpuBuffer() { reset(); }

  // `size` is rounded up to at least 16 bytes (zero-sized bindings are invalid).
  static Expected<GpuBuffer> create(const VulkanContext& context, VkDeviceSize size,
                                    VkBufferUsageFlags usage);
  void reset();
  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  uint8_t* mapped() const { return static_cast<uint8_t*>(mapped_); }
  // Copies `bytes` bytes to `offset`; the range must lie inside the buffer (RDM_CHECK).
  void write(const void* data, size_t bytes, size_t offset = 0);

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
};

struct ImageSpec {
  uint32_t width = 1, height = 1, layers = 1;
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  VkImageUsageFlags usage = 0;
  VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
  VkImageViewType view_type = VK_IMAGE_VIEW_TYPE_2D;
  bool alpha_view = false;  // also a view whose every component reads the alpha channel
};

class GpuImage {
 public:
  GpuImage() = default;
  GpuImage(GpuImage&& other) noexcept { *this = std::move(other); }
  GpuImage& operator=(GpuImage&& other) noexcept;
  ~GpuImage() { reset(); }

  // Device-local image in VK_IMAGE_LAYOUT_UNDEFINED with one view over all layers.
  static Expected<GpuImage> create(const VulkanContext& context, const ImageSpec& spec);
  void reset();
  VkImage handle() const { return image_; }
  VkImageView view() const { return view_; }
  VkImageView alphaView() const { return alpha_view_; }  // spec().alpha_view
  const ImageSpec& spec() const { return spec_; }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VkImage image_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  VkImageView alpha_view_ = VK_NULL_HANDLE;
  ImageSpec spec_;
};

struct LayoutTransition {
  VkImageLayout from, to;
  VkPipelineStageFlags src_stage, dst_stage;
  VkAccessFlags src_access, dst_access;
};
// Records an image memory barrier over every layer and the whole aspect of `image`.
void transitionImage(VkCommandBuffer cmd, const GpuImage& image, const LayoutTransition& t);

Expected<VkShaderModule> createShaderModule(VkDevice device, const uint32_t* code, size_t bytes);

}  // namespace rdm::viewer
