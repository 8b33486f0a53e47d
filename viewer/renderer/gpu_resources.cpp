#include "gpu_resources.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "vk_check.h"

namespace rdm::viewer {

GpuBuffer& GpuBuffer::operator=(GpuBuffer&& other) noexcept {
  if (this != &other) {
    reset();
    std::swap(device_, other.device_);
    std::swap(buffer_, other.buffer_);
    std::swap(memory_, other.memory_);
    std::swap(size_, other.size_);
    std::swap(mapped_, other.mapped_);
  }
  return *this;
}

void GpuBuffer::reset() {
  if (device_ == VK_NULL_HANDLE) return;
  if (buffer_ != VK_NULL_HANDLE) vkDestroyBuffer(device_, buffer_, nullptr);
  if (memory_ != VK_NULL_HANDLE) vkFreeMemory(device_, memory_, nullptr);  // unmaps implicitly
  device_ = VK_NULL_HANDLE, buffer_ = VK_NULL_HANDLE, memory_ = VK_NULL_HANDLE, mapped_ = nullptr,
  size_ = 0;
}

Expected<GpuBuffer> GpuBuffer::create(const VulkanContext& context, VkDeviceSize size,
                                      VkBufferUsageFlags usage) {
  GpuBuffer b;
  b.device_ = context.device();
  b.size_ = std::max<VkDeviceSize>(size, 16);
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = b.size_;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  RDM_VK_TRY(vkCreateBuffer(b.device_, &info, nullptr, &b.buffer_));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(b.device_, b.buffer_, &req);
  auto type = context.memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                         VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  if (!type) return type.status();
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = *type;
  RDM_VK_TRY(vkAllocateMemory(b.device_, &alloc, nullptr, &b.memory_));
  RDM_VK_TRY(vkBindBufferMemory(b.device_, b.buffer_, b.memory_, 0));
  RDM_VK_TRY(vkMapMemory(b.device_, b.memory_, 0, VK_WHOLE_SIZE, 0, &b.mapped_));
  std::memset(b.mapped_, 0, size_t(b.size_));
  return b;
}

void GpuBuffer::write(const void* data, size_t bytes, size_t offset) {
  RDM_CHECK(offset + bytes <= size_);
  if (bytes > 0) std::memcpy(mapped() + offset, data, bytes);
}

GpuImage& GpuImage::operator=(GpuImage&& other) noexcept {
  if (this != &other) {
    reset();
    std::swap(device_, other.device_);
    std::swap(image_, other.image_);
    std::swap(memory_, other.memory_);
    std::swap(view_, other.view_);
    std::swap(alpha_view_, other.alpha_view_);
    std::swap(spec_, other.spec_);
  }
  return *this;
}

void GpuImage::reset() {
  if (device_ == VK_NULL_HANDLE) return;
  if (view_ != VK_NULL_HANDLE) vkDestroyImageView(device_, view_, nullptr);
  if (alpha_view_ != VK_NULL_HANDLE) vkDestroyImageView(device_, alpha_view_, nullptr);
  if (image_ != VK_NULL_HANDLE) vkDestroyImage(device_, image_, nullptr);
  if (memory_ != VK_NULL_HANDLE) vkFreeMemory(device_, memory_, nullptr);
  device_ = VK_NULL_HANDLE, image_ = VK_NULL_HANDLE, memory_ = VK_NULL_HANDLE,
  view_ = VK_NULL_HANDLE, alpha_view_ = VK_NULL_HANDLE;
}

Expected<GpuImage> GpuImage::create(const VulkanContext& context, const ImageSpec& spec) {
  GpuImage img;
  img.device_ = context.device();
  img.spec_ = spec;
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = spec.format;
  info.extent = {spec.width, spec.height, 1};
  info.mipLevels = 1;
  info.arrayLayers = spec.layers;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = spec.usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  RDM_VK_TRY(vkCreateImage(img.device_, &info, nullptr, &img.image_));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(img.device_, img.image_, &req);
  auto type = context.memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  if (!type) type = context.memoryType(req.memoryTypeBits, 0);
  if (!type) return type.status();
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = *type;
  RDM_VK_TRY(vkAllocateMemory(img.device_, &alloc, nullptr, &img.memory_));
  RDM_VK_TRY(vkBindImageMemory(img.device_, img.image_, img.memory_, 0));
  VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view.image = img.image_;
  view.viewType = spec.view_type;
  view.format = spec.format;
  view.subresourceRange = {spec.aspect, 0, 1, 0, spec.layers};
  RDM_VK_TRY(vkCreateImageView(img.device_, &view, nullptr, &img.view_));
  if (spec.alpha_view) {
    view.components = {VK_COMPONENT_SWIZZLE_A, VK_COMPONENT_SWIZZLE_A, VK_COMPONENT_SWIZZLE_A,
                       VK_COMPONENT_SWIZZLE_A};
    RDM_VK_TRY(vkCreateImageView(img.device_, &view, nullptr, &img.alpha_view_));
  }
  return img;
}

void transitionImage(VkCommandBuffer cmd, const GpuImage& image, const LayoutTransition& t) {
  VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  barrier.oldLayout = t.from;
  barrier.newLayout = t.to;
  barrier.srcAccessMask = t.src_access;
  barrier.dstAccessMask = t.dst_access;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image.handle();
  barrier.subresourceRange = {image.spec().aspect, 0, 1, 0, image.spec().layers};
  vkCmdPipelineBarrier(cmd, t.src_stage, t.dst_stage, 0, 0, nullptr, 0, nullptr, 1, &barrier);
}

Expected<VkShaderModule> createShaderModule(VkDevice device, const uint32_t* code, size_t bytes) {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = bytes;
  info.pCode = code;
  VkShaderModule module = VK_NULL_HANDLE;
  RDM_VK_TRY(vkCreateShaderModule(device, &info, nullptr, &module));
  return module;
}

}  // namespace rdm::viewer
