// A window's swapchain plus the render pass that draws the ImGui overlay on top of the
// renderer's image after it has been blitted in. Frames: acquire -> record -> present.
#pragma once

#include <vector>

#include <vulkan/vulkan.h>

#include "rdm/base/status.h"
#include "vk_context.h"

namespace rdm::viewer {

class Swapchain {
 public:
  explicit Swapchain(VulkanContext& context) : context_(context) {}
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  // (Re)creates the swapchain for a framebuffer of width x height pixels.
  Status create(int width, int height);
  VkExtent2D extent() const { return extent_; }
  VkFormat format() const { return format_; }
  VkRenderPass overlayPass() const { return overlay_pass_; }
  uint32_t imageCount() const { return uint32_t(images_.size()); }
  VkImage image(uint32_t i) const { return images_[i]; }
  VkFramebuffer framebuffer(uint32_t i) const { return framebuffers_[i]; }

  // Acquires the next image; `out_of_date` is set (with an ok Status) when the swapchain must
  // be recreated first.
  Status acquire(VkSemaphore signal, uint32_t& index, bool& out_of_date);
  Status present(VkSemaphore wait, uint32_t index, bool& out_of_date);

 private:
  void destroyImages();

  VulkanContext& context_;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkExtent2D extent_{};
  VkRenderPass overlay_pass_ = VK_NULL_HANDLE;
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
  std::vector<VkFramebuffer> framebuffers_;
};

}  // namespace rdm::viewer
