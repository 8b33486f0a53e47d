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
#include "rdm/vulkan/vulkan_bootstrap.h"

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

  VkInstance instance() const { return instance_.handle(); }
  VkPhysicalDevice physicalDevice() const { return device_.physical(); }
  VkDevice device() const { return device_.handle(); }
  VkQueue queue() const { return device_.queue(); }
  uint32_t queueFamily() const { return device_.queueFamily(); }
  VkCommandPool commandPool() const { return device_.commandPool(); }
  VkSurfaceKHR surface() const { return surface_; }
  const VkPhysicalDeviceProperties& properties() const { return device_.properties(); }
  bool samplesBc6h() const { return device_.samplesBc6h(); }
  std::string deviceDescription() const;

  // A memory type index allowed by `type_bits` with all of `flags`, or an error.
  Expected<uint32_t> memoryType(uint32_t type_bits, VkMemoryPropertyFlags flags) const {
    return device_.memoryType(type_bits, flags);
  }
  // Records `record` into a one-time command buffer, submits it and waits for it.
  Status submitAndWait(const std::function<void(VkCommandBuffer)>& record) {
    return device_.submitAndWait(record);
  }

 private:
  VulkanContext() = default;
  Status init(const ContextOptions& options);
  Status pickDevice(const std::string& wanted);

  VulkanInstance instance_;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;  // destroyed after device_, before instance_
  VulkanDevice device_;
};

}  // namespace rdm::viewer
