#include "vk_context.h"

#include <cstring>
#include <optional>
#include <vector>

#include "vk_check.h"

namespace rdm::viewer {
namespace {

bool layerAvailable(const char* name) {
  uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  for (const auto& l : layers) {
    if (std::strcmp(l.layerName, name) == 0) return true;
  }
  return false;
}

}  // namespace

Expected<std::unique_ptr<VulkanContext>> VulkanContext::create(const ContextOptions& options) {
  std::unique_ptr<VulkanContext> context(new VulkanContext());
  Status status = context->init(options);
  if (!status.ok()) return status;
  return context;
}

Status VulkanContext::init(const ContextOptions& options) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "rdm-viewer";
  app.apiVersion = VK_API_VERSION_1_1;
  std::vector<const char*> extensions;
  for (const auto& e : options.instance_extensions) extensions.push_back(e.c_str());
  std::vector<const char*> layers;
  if (options.validation && layerAvailable("VK_LAYER_KHRONOS_validation")) {
    layers.push_back("VK_LAYER_KHRONOS_validation");
  }
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  info.enabledLayerCount = uint32_t(layers.size());
  info.ppEnabledLayerNames = layers.data();
  if (VkResult r = vkCreateInstance(&info, nullptr, &instance_); r != VK_SUCCESS) {
    instance_ = VK_NULL_HANDLE;
    return Status::error(std::string("no Vulkan instance (vkCreateInstance: ") + vkResultName(r) +
                         "); is a Vulkan driver such as mesa-vulkan-drivers installed?");
  }
  if (options.make_surface) {
    auto surface = options.make_surface(instance_);
    if (!surface) return surface.status();
    surface_ = *surface;
  }
  RDM_TRY(pickDevice(options.device, surface_ != VK_NULL_HANDLE));
  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool.queueFamilyIndex = queue_family_;
  RDM_VK_TRY(vkCreateCommandPool(device_, &pool, nullptr, &pool_));
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  RDM_VK_TRY(vkCreateFence(device_, &fence, nullptr, &fence_));
  return Status();
}

namespace {

// A queue family of `device` with graphics (that presents to `surface` when there is one).
std::optional<uint32_t> graphicsFamily(VkPhysicalDevice device, VkSurfaceKHR surface) {
  uint32_t family_count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &family_count, families.data());
  for (uint32_t f = 0; f < family_count; ++f) {
    if (!(families[f].queueFlags & VK_QUEUE_GRAPHICS_BIT)) continue;
    VkBool32 present = VK_TRUE;
    if (surface != VK_NULL_HANDLE &&
        vkGetPhysicalDeviceSurfaceSupportKHR(device, f, surface, &present) != VK_SUCCESS)
      present = VK_FALSE;
    if (present) return f;
  }
  return std::nullopt;
}

}  // namespace

// The core's device policy (rdm/vulkan_device.h), where a device with a window counts as
// graphics-capable only when one of its graphics families presents to the window.
Status VulkanContext::pickDevice(const std::string& wanted, bool need_present) {
  std::vector<VkPhysicalDevice> devices;
  std::vector<VulkanDeviceInfo> infos;
  RDM_TRY(enumerateVulkanDevices(instance_, devices, infos));
  for (size_t i = 0; i < devices.size(); ++i)
    infos[i].has_graphics = graphicsFamily(devices[i], surface_).has_value();
  auto index = selectVulkanDevice(infos, wanted, QueueNeed::kGraphics);
  if (!index) {
    if (!need_present) return index.status();
    return Status::error(index.status().code(), index.error() + " (that can present to the window)",
                         index.status().field());
  }
  physical_ = devices[size_t(*index)];
  queue_family_ = *graphicsFamily(physical_, surface_);
  vkGetPhysicalDeviceProperties(physical_, &properties_);
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueFamilyIndex = queue_family_;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  const char* swapchain = VK_KHR_SWAPCHAIN_EXTENSION_NAME;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue;
  info.enabledExtensionCount = need_present ? 1 : 0;
  info.ppEnabledExtensionNames = need_present ? &swapchain : nullptr;
  RDM_VK_TRY(vkCreateDevice(physical_, &info, nullptr, &device_));
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  return Status();
}

VulkanContext::~VulkanContext() {
  if (device_ != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device_);
    if (fence_ != VK_NULL_HANDLE) vkDestroyFence(device_, fence_, nullptr);
    if (pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (surface_ != VK_NULL_HANDLE) vkDestroySurfaceKHR(instance_, surface_, nullptr);
  if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
}

std::string VulkanContext::deviceDescription() const {
  const uint32_t v = properties_.driverVersion;
  return std::string(properties_.deviceName) + " (Vulkan " +
         std::to_string(VK_VERSION_MAJOR(properties_.apiVersion)) + "." +
         std::to_string(VK_VERSION_MINOR(properties_.apiVersion)) + ", driver " +
         std::to_string(VK_VERSION_MAJOR(v)) + "." + std::to_string(VK_VERSION_MINOR(v)) + "." +
         std::to_string(VK_VERSION_PATCH(v)) + ")";
}

Expected<uint32_t> VulkanContext::memoryType(uint32_t type_bits,
                                             VkMemoryPropertyFlags flags) const {
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
    if ((type_bits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & flags) == flags)
      return i;
  }
  return Status::error("no Vulkan memory type with the required properties");
}

Status VulkanContext::submitAndWait(const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  RDM_VK_TRY(vkAllocateCommandBuffers(device_, &alloc, &cmd));
  struct Free {
    VkDevice device;
    VkCommandPool pool;
    VkCommandBuffer cmd;
    ~Free() { vkFreeCommandBuffers(device, pool, 1, &cmd); }
  } free_cmd{device_, pool_, cmd};
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  RDM_VK_TRY(vkBeginCommandBuffer(cmd, &begin));
  record(cmd);
  RDM_VK_TRY(vkEndCommandBuffer(cmd));
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  RDM_VK_TRY(vkResetFences(device_, 1, &fence_));
  RDM_VK_TRY(vkQueueSubmit(queue_, 1, &submit, fence_));
  RDM_VK_TRY(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
  return Status();
}

}  // namespace rdm::viewer
