#include "swapchain.h"

#include <algorithm>

#include "vk_check.h"

namespace rdm::viewer {
namespace {

// UNORM formats only: the renderer's image is already sRGB-encoded.
VkSurfaceFormatKHR pickFormat(const std::vector<VkSurfaceFormatKHR>& formats) {
  for (const auto& f : formats) {
    if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) return f;
  }
  return formats.front();
}

Status makeOverlayPass(VkDevice device, VkFormat format, VkRenderPass& out) {
  VkAttachmentDescription color{};
  color.format = format;
  color.samples = VK_SAMPLE_COUNT_1_BIT;
  color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  color.initialLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  color.finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &ref;
  VkSubpassDependency dep{
      VK_SUBPASS_EXTERNAL,
      0,
      VK_PIPELINE_STAGE_TRANSFER_BIT,
      VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
      VK_ACCESS_TRANSFER_WRITE_BIT,
      VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
      0};
  VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  info.attachmentCount = 1;
  info.pAttachments = &color;
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  info.dependencyCount = 1;
  info.pDependencies = &dep;
  RDM_VK_TRY(vkCreateRenderPass(device, &info, nullptr, &out));
  return Status();
}

}  // namespace

Status Swapchain::create(int width, int height) {
  const VkDevice device = context_.device();
  const VkPhysicalDevice physical = context_.physicalDevice();
  const VkSurfaceKHR surface = context_.surface();
  RDM_VK_TRY(vkDeviceWaitIdle(device));
  VkSurfaceCapabilitiesKHR caps;
  RDM_VK_TRY(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, surface, &caps));
  uint32_t count = 0;
  RDM_VK_TRY(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, nullptr));
  if (count == 0) return Status::error("the window surface offers no formats");
  std::vector<VkSurfaceFormatKHR> formats(count);
  RDM_VK_TRY(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, formats.data()));
  const VkSurfaceFormatKHR format = pickFormat(formats);
  if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) {
    return Status::error(
        "the window's swapchain images cannot be blitted to (no TRANSFER_DST usage)");
  }
  extent_ = caps.currentExtent;
  if (extent_.width == UINT32_MAX) {
    extent_.width =
        std::clamp(uint32_t(width), caps.minImageExtent.width, caps.maxImageExtent.width);
    extent_.height =
        std::clamp(uint32_t(height), caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = surface;
  info.minImageCount = std::max(caps.minImageCount, 2u);
  if (caps.maxImageCount > 0) info.minImageCount = std::min(info.minImageCount, caps.maxImageCount);
  info.imageFormat = format.format;
  info.imageColorSpace = format.colorSpace;
  info.imageExtent = extent_;
  info.imageArrayLayers = 1;
  info.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // always supported
  info.clipped = VK_TRUE;
  info.oldSwapchain = swapchain_;
  VkSwapchainKHR created = VK_NULL_HANDLE;
  RDM_VK_TRY(vkCreateSwapchainKHR(device, &info, nullptr, &created));
  destroyImages();
  if (swapchain_ != VK_NULL_HANDLE) vkDestroySwapchainKHR(device, swapchain_, nullptr);
  swapchain_ = created;
  if (format_ != format.format && overlay_pass_ != VK_NULL_HANDLE) {
    vkDestroyRenderPass(device, overlay_pass_, nullptr);
    overlay_pass_ = VK_NULL_HANDLE;
  }
  format_ = format.format;
  if (overlay_pass_ == VK_NULL_HANDLE) RDM_TRY(makeOverlayPass(device, format_, overlay_pass_));
  RDM_VK_TRY(vkGetSwapchainImagesKHR(device, swapchain_, &count, nullptr));
  images_.resize(count);
  RDM_VK_TRY(vkGetSwapchainImagesKHR(device, swapchain_, &count, images_.data()));
  for (VkImage image : images_) {
    VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format_;
    view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    views_.push_back(VK_NULL_HANDLE);
    RDM_VK_TRY(vkCreateImageView(device, &view, nullptr, &views_.back()));
    VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fb.renderPass = overlay_pass_;
    fb.attachmentCount = 1;
    fb.pAttachments = &views_.back();
    fb.width = extent_.width, fb.height = extent_.height, fb.layers = 1;
    framebuffers_.push_back(VK_NULL_HANDLE);
    RDM_VK_TRY(vkCreateFramebuffer(device, &fb, nullptr, &framebuffers_.back()));
  }
  return Status();
}

Status Swapchain::acquire(VkSemaphore signal, uint32_t& index, bool& out_of_date) {
  const VkResult r = vkAcquireNextImageKHR(context_.device(), swapchain_, UINT64_MAX, signal,
                                           VK_NULL_HANDLE, &index);
  out_of_date = r == VK_ERROR_OUT_OF_DATE_KHR;
  if (r == VK_SUCCESS || r == VK_SUBOPTIMAL_KHR || out_of_date) return Status();
  return vkStatus("vkAcquireNextImageKHR", r);
}

Status Swapchain::present(VkSemaphore wait, uint32_t index, bool& out_of_date) {
  VkPresentInfoKHR info{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  info.waitSemaphoreCount = 1;
  info.pWaitSemaphores = &wait;
  info.swapchainCount = 1;
  info.pSwapchains = &swapchain_;
  info.pImageIndices = &index;
  const VkResult r = vkQueuePresentKHR(context_.queue(), &info);
  out_of_date = r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR;
  if (r == VK_SUCCESS || out_of_date) return Status();
  return vkStatus("vkQueuePresentKHR", r);
}

void Swapchain::destroyImages() {
  const VkDevice device = context_.device();
  for (VkFramebuffer fb : framebuffers_) vkDestroyFramebuffer(device, fb, nullptr);
  for (VkImageView v : views_) vkDestroyImageView(device, v, nullptr);
  framebuffers_.clear(), views_.clear(), images_.clear();
}

Swapchain::~Swapchain() {
  vkDeviceWaitIdle(context_.device());
  destroyImages();
  if (swapchain_ != VK_NULL_HANDLE) vkDestroySwapchainKHR(context_.device(), swapchain_, nullptr);
  if (overlay_pass_ != VK_NULL_HANDLE)
    vkDestroyRenderPass(context_.device(), overlay_pass_, nullptr);
}

}  // namespace rdm::viewer
