// The Vulkan instance, device and queue the viewer renders with. Creation never crashes on
// a machine without Vulkan: every failure (no loader, no device, no graphics queue) comes
// back as a Status with a message a user can act on.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "rdm/base/status.h"

namespace rdm::viewer {

struct ContextOptions {
  std::vector<std::string> instance_extensions;  // e.g. from glfwGetRequiredInstanceExtensions
  // When set, called once the instance exists; the device's queue must present to the
  // returned surface and the device gets VK_KHR_swapchain. The context owns the surface.
  std::function<Expected<VkSurfaceKHR>(VkInstance)> make_surface;
  bool validation = false;  // enable VK_LAYER_KHRONOS_validation when installed
  std::string device;       // --device: an index or a name substring; empty: the best GPU
};

class VulkanContext {
 public:
  static Expected<std::unique_ptr<VulkanContext>> create(const ContextOptions& options);
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return queue_family_; }
  VkCommandPool commandPool() const { return pool_; }
  VkSurfaceKHR surface() const { return surface_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  std::string deviceDescription() const;

  // A memory type index allowed by `type_bits` with all of `flags`, or an error.
  Expected<uint32_t> memoryType(uint32_t type_bits, VkMemoryPropertyFlags flags) const;
  // Records `record` into a one-time command buffer, submits it and waits for it.
  Status submitAndWait(const std::function<void(VkCommandBuffer)>& record);

 private:
  VulkanContext() = default;
  Status init(const ContextOptions& options);
  Status pickDevice(const std::string& wanted, bool need_present);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_{};
};

}  // namespace rdm::viewer
