// The Vulkan bootstrap the compute bake (src/vulkan_context.h) and the viewer
// (viewer/renderer/vk_context.h) share: the instance, the device choice by the one device
// policy (vulkan_device.h), a logical device with one queue, memory-type lookup and a one-shot
// submit-and-wait. What differs between them (surface and swapchain, subgroup needs,
// pipelines) stays with each and comes in as parameters. Every failure is a Status.
// Only with RDM_HAVE_VULKAN (the RDM_VULKAN build option).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "rdm/base/status.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "rdm/vulkan/vulkan_device.h"

namespace rdm {

struct VulkanInstanceOptions {
  std::string application = "rdm";
  std::vector<std::string> extensions;  // e.g. from glfwGetRequiredInstanceExtensions
  std::vector<std::string> layers;      // each must be installed (vulkanLayerAvailable)
};

// Whether the loader lists the instance layer `name`.
bool vulkanLayerAvailable(const char* name);

// A Vulkan 1.1 VkInstance, destroyed with the object. Move-only.
class VulkanInstance {
 public:
  VulkanInstance() = default;
  [[nodiscard]] static Expected<VulkanInstance> create(const VulkanInstanceOptions& options);
  ~VulkanInstance();
  VulkanInstance(VulkanInstance&& other) noexcept;
  VulkanInstance& operator=(VulkanInstance&& other) noexcept;

  VkInstance handle() const { return handle_; }

 private:
  VkInstance handle_ = VK_NULL_HANDLE;
};

// Which of a device's queue families with the need's bit may serve; the viewer narrows them to
// those that present to its window. Unset: every family with the bit.
using QueueFamilyFilter = std::function<bool(VkPhysicalDevice device, uint32_t family)>;

// A device of an instance and the first of its queue families that serves the need.
struct VulkanDeviceChoice {
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VulkanDeviceInfo info;
  uint32_t queue_family = 0;
};

// selectVulkanDevice over the devices of `instance`, where a device has the queue only when
// one of its families has the need's bit and passes `family_fits`.
[[nodiscard]] Expected<VulkanDeviceChoice> chooseVulkanDevice(
    VkInstance instance, const std::string& wanted, QueueNeed need,
    const QueueFamilyFilter& family_fits = {});

// The first memory type allowed by `type_bits` (VkMemoryRequirements::memoryTypeBits) with all
// of `flags`; else a kDevice error naming the flags and the allowed types.
[[nodiscard]] Expected<uint32_t> findMemoryType(const VkPhysicalDeviceMemoryProperties& memory,
                                                uint32_t type_bits, VkMemoryPropertyFlags flags);

// A logical device with one queue of one family, a command pool on that family (its buffers
// resettable) and the command buffer and fence of submitAndWait. Move-only; destruction
// waits for the device to be idle, so everything made on it must be destroyed first.
// Whether `physical` samples VK_FORMAT_BC6H_UFLOAT_BLOCK images (optimal tiling) with linear
// filtering and takes transfers into them.
bool deviceSamplesBc6h(VkPhysicalDevice physical);

class VulkanDevice {
 public:
  VulkanDevice() = default;
  // `extensions`: device extensions to enable (the viewer's VK_KHR_swapchain).
  [[nodiscard]] static Expected<VulkanDevice> create(VkPhysicalDevice physical,
                                                     uint32_t queue_family,
                                                     const std::vector<const char*>& extensions);
  ~VulkanDevice();
  VulkanDevice(VulkanDevice&& other) noexcept;
  VulkanDevice& operator=(VulkanDevice&& other) noexcept;

  VkPhysicalDevice physical() const { return h_.physical; }
  VkDevice handle() const { return h_.device; }
  VkQueue queue() const { return h_.queue; }
  uint32_t queueFamily() const { return h_.queue_family; }
  VkCommandPool commandPool() const { return h_.pool; }
  const VkPhysicalDeviceProperties& properties() const { return h_.properties; }
  const VkPhysicalDeviceMemoryProperties& memoryProperties() const { return h_.memory; }
  // The device was created with textureCompressionBC and samples BC6H_UFLOAT images with
  // linear filtering (deviceSamplesBc6h).
  bool samplesBc6h() const { return h_.samples_bc6h; }

  // findMemoryType on this device.
  [[nodiscard]] Expected<uint32_t> memoryType(uint32_t type_bits,
                                              VkMemoryPropertyFlags flags) const;
  // Records `record` into the one-shot command buffer, submits it to the queue and waits on
  // the fence: the commands have finished on return. Not reentrant (one command buffer).
  [[nodiscard]] Status submitAndWait(const std::function<void(VkCommandBuffer)>& record);

 private:
  struct Handles {
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    uint32_t queue_family = 0;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkCommandBuffer command_buffer = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties properties{};
    VkPhysicalDeviceMemoryProperties memory{};
    bool samples_bc6h = false;
  };
  void destroy();
  Status init(VkPhysicalDevice physical, uint32_t queue_family,
              const std::vector<const char*>& extensions);

  Handles h_;
};

}  // namespace rdm
