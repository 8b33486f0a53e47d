#include "vk_context.h"

#include <utility>
#include <vector>

namespace rdm::viewer {

Expected<std::unique_ptr<VulkanContext>> VulkanContext::create(const ContextOptions& options) {
  std::unique_ptr<VulkanContext> context(new VulkanContext());
  Status status = context->init(options);
  if (!status.ok()) return status;
  return context;
}

Status VulkanContext::init(const ContextOptions& options) {
  VulkanInstanceOptions instance_options;
  instance_options.application = "rdm-viewer";
  instance_options.extensions = options.instance_extensions;
  if (options.validation && vulkanLayerAvailable("VK_LAYER_KHRONOS_validation"))
    instance_options.layers.push_back("VK_LAYER_KHRONOS_validation");
  auto instance = VulkanInstance::create(instance_options);
  if (!instance) return instance.status();
  instance_ = std::move(*instance);
  if (options.make_surface) {
    auto surface = options.make_surface(instance_.handle());
    if (!surface) return surface.status();
    surface_ = *surface;
  }
  return pickDevice(options.device);
}

// The core's device policy (rdm/vulkan/vulkan_device.h) for a graphics queue; with a window,
// only graphics families that present to it count, and the device gets VK_KHR_swapchain.
Status VulkanContext::pickDevice(const std::string& wanted) {
  const bool need_present = surface_ != VK_NULL_HANDLE;
  QueueFamilyFilter presents;
  if (need_present) {
    presents = [surface = surface_](VkPhysicalDevice device, uint32_t family) {
      VkBool32 present = VK_FALSE;
      return vkGetPhysicalDeviceSurfaceSupportKHR(device, family, surface, &present) ==
                 VK_SUCCESS &&
             present;
    };
  }
  auto choice = chooseVulkanDevice(instance_.handle(), wanted, QueueNeed::kGraphics, presents);
  if (!choice) {
    if (!need_present) return choice.status();
    return Status::error(choice.status().code(),
                         choice.error() + " (that can present to the window)",
                         choice.status().field());
  }
  std::vector<const char*> extensions;
  if (need_present) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  auto device = VulkanDevice::create(choice->physical, choice->queue_family, extensions);
  if (!device) return device.status();
  device_ = std::move(*device);
  return Status();
}

VulkanContext::~VulkanContext() {
  device_ = VulkanDevice();
  if (surface_ != VK_NULL_HANDLE) vkDestroySurfaceKHR(instance_.handle(), surface_, nullptr);
}

std::string VulkanContext::deviceDescription() const {
  const VkPhysicalDeviceProperties& p = device_.properties();
  const uint32_t v = p.driverVersion;
  return std::string(p.deviceName) + " (Vulkan " + std::to_string(VK_VERSION_MAJOR(p.apiVersion)) +
         "." + std::to_string(VK_VERSION_MINOR(p.apiVersion)) + ", driver " +
         std::to_string(VK_VERSION_MAJOR(v)) + "." + std::to_string(VK_VERSION_MINOR(v)) + "." +
         std::to_string(VK_VERSION_PATCH(v)) + ")";
}

}  // namespace rdm::viewer
