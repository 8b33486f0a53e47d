#if RDM_HAVE_VULKAN  // a compile definition of rdm_core (shaders/CMakeLists.txt)
#include "rdm/vulkan/vulkan_bootstrap.h"

#include <cstdio>
#include <cstring>
#include <optional>
#include <utility>

namespace rdm {
namespace {

// "HOST_VISIBLE|HOST_COHERENT", or "no flags".
std::string memoryFlagsName(VkMemoryPropertyFlags flags) {
  static constexpr std::pair<VkMemoryPropertyFlagBits, const char*> kNames[] = {
      {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, "DEVICE_LOCAL"},
      {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, "HOST_VISIBLE"},
      {VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, "HOST_COHERENT"},
      {VK_MEMORY_PROPERTY_HOST_CACHED_BIT, "HOST_CACHED"},
      {VK_MEMORY_PROPERTY_LAZILY_ALLOCATED_BIT, "LAZILY_ALLOCATED"},
      {VK_MEMORY_PROPERTY_PROTECTED_BIT, "PROTECTED"}};
  std::string s;
  for (const auto& [bit, name] : kNames) {
    if (!(flags & bit)) continue;
    if (!s.empty()) s += '|';
    s += name;
    flags &= ~VkMemoryPropertyFlags(bit);
  }
  if (flags) {
    char rest[16];
    std::snprintf(rest, sizeof(rest), "0x%x", unsigned(flags));
    if (!s.empty()) s += '|';
    s += rest;
  }
  return s.empty() ? "no flags" : s;
}

// The first queue family of `device` with the need's bit that `family_fits` accepts.
std::optional<uint32_t> servingFamily(VkPhysicalDevice device, QueueNeed need,
                                      const QueueFamilyFilter& family_fits) {
  const VkQueueFlags bit =
      need == QueueNeed::kCompute ? VK_QUEUE_COMPUTE_BIT : VK_QUEUE_GRAPHICS_BIT;
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  for (uint32_t f = 0; f < count; ++f) {
    if (!(families[f].queueFlags & bit)) continue;
    if (!family_fits || family_fits(device, f)) return f;
  }
  return std::nullopt;
}

}  // namespace

bool vulkanLayerAvailable(const char* name) {
  uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  for (const auto& l : layers) {
    if (std::strcmp(l.layerName, name) == 0) return true;
  }
  return false;
}

Expected<VulkanInstance> VulkanInstance::create(const VulkanInstanceOptions& options) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = options.application.c_str();
  app.applicationVersion = 1;
  app.pEngineName = "rdm";
  app.apiVersion = VK_API_VERSION_1_1;
  std::vector<const char*> extensions;
  for (const auto& e : options.extensions) extensions.push_back(e.c_str());
  std::vector<const char*> layers;
  for (const auto& l : options.layers) layers.push_back(l.c_str());
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  info.enabledLayerCount = uint32_t(layers.size());
  info.ppEnabledLayerNames = layers.data();
  VulkanInstance instance;
  const VkResult r = vkCreateInstance(&info, nullptr, &instance.handle_);
  if (r != VK_SUCCESS) {
    instance.handle_ = VK_NULL_HANDLE;
    return vkStatus("vkCreateInstance", r);
  }
  return instance;
}

VulkanInstance::~VulkanInstance() {
  if (handle_ != VK_NULL_HANDLE) vkDestroyInstance(handle_, nullptr);
}

VulkanInstance::VulkanInstance(VulkanInstance&& other) noexcept
    : handle_(std::exchange(other.handle_, VK_NULL_HANDLE)) {}

VulkanInstance& VulkanInstance::operator=(VulkanInstance&& other) noexcept {
  if (this != &other) {
    if (handle_ != VK_NULL_HANDLE) vkDestroyInstance(handle_, nullptr);
    handle_ = std::exchange(other.handle_, VK_NULL_HANDLE);
  }
  return *this;
}

Expected<VulkanDeviceChoice> chooseVulkanDevice(VkInstance instance, const std::string& wanted,
                                                QueueNeed need,
                                                const QueueFamilyFilter& family_fits) {
  std::vector<VkPhysicalDevice> devices;
  std::vector<VulkanDeviceInfo> infos;
  if (Status s = enumerateVulkanDevices(instance, devices, infos); !s) return s;
  std::vector<std::optional<uint32_t>> families(devices.size());
  for (size_t i = 0; i < devices.size(); ++i) {
    families[i] = servingFamily(devices[i], need, family_fits);
    bool& has = need == QueueNeed::kCompute ? infos[i].has_compute : infos[i].has_graphics;
    has = families[i].has_value();
  }
  auto index = selectVulkanDevice(infos, wanted, need);
  if (!index) return index.status();
  const size_t chosen = size_t(*index);
  return VulkanDeviceChoice{devices[chosen], infos[chosen], *families[chosen]};
}

Expected<uint32_t> findMemoryType(const VkPhysicalDeviceMemoryProperties& memory,
                                  uint32_t type_bits, VkMemoryPropertyFlags flags) {
  for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
    if ((type_bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & flags) == flags) return i;
  }
  char allowed[16];
  std::snprintf(allowed, sizeof(allowed), "0x%x", type_bits);
  return Status::error(StatusCode::kDevice,
                       "Vulkan: no memory type with " + memoryFlagsName(flags) +
                           " among the allowed types " + allowed + " (of " +
                           std::to_string(memory.memoryTypeCount) + " on the device)");
}

bool deviceSamplesBc6h(VkPhysicalDevice physical) {
  VkFormatProperties format{};
  vkGetPhysicalDeviceFormatProperties(physical, VK_FORMAT_BC6H_UFLOAT_BLOCK, &format);
  const VkFormatFeatureFlags needed = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT |
                                      VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT |
                                      VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
  return (format.optimalTilingFeatures & needed) == needed;
}

Expected<VulkanDevice> VulkanDevice::create(VkPhysicalDevice physical, uint32_t queue_family,
                                            const std::vector<const char*>& extensions) {
  VulkanDevice device;
  if (Status s = device.init(physical, queue_family, extensions); !s) return s;
  return device;
}

Status VulkanDevice::init(VkPhysicalDevice physical, uint32_t queue_family,
                          const std::vector<const char*>& extensions) {
  h_.physical = physical;
  h_.queue_family = queue_family;
  vkGetPhysicalDeviceProperties(physical, &h_.properties);
  vkGetPhysicalDeviceMemoryProperties(physical, &h_.memory);
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueFamilyIndex = queue_family;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue;
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.empty() ? nullptr : extensions.data();
  // BC formats may only be used with the feature enabled; it changes nothing else.
  VkPhysicalDeviceFeatures supported{}, enabled{};
  vkGetPhysicalDeviceFeatures(physical, &supported);
  enabled.textureCompressionBC = supported.textureCompressionBC;
  info.pEnabledFeatures = &enabled;
  h_.samples_bc6h = enabled.textureCompressionBC && deviceSamplesBc6h(physical);
  if (VkResult r = vkCreateDevice(physical, &info, nullptr, &h_.device); r != VK_SUCCESS) {
    h_.device = VK_NULL_HANDLE;
    return vkStatus("vkCreateDevice", r);
  }
  vkGetDeviceQueue(h_.device, queue_family, 0, &h_.queue);
  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool.queueFamilyIndex = queue_family;
  RDM_VK_TRY(vkCreateCommandPool(h_.device, &pool, nullptr, &h_.pool));
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = h_.pool;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  RDM_VK_TRY(vkAllocateCommandBuffers(h_.device, &alloc, &h_.command_buffer));
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  RDM_VK_TRY(vkCreateFence(h_.device, &fence, nullptr, &h_.fence));
  return {};
}

void VulkanDevice::destroy() {
  if (h_.device == VK_NULL_HANDLE) return;
  vkDeviceWaitIdle(h_.device);
  if (h_.fence != VK_NULL_HANDLE) vkDestroyFence(h_.device, h_.fence, nullptr);
  // Frees the command buffers allocated from it too.
  if (h_.pool != VK_NULL_HANDLE) vkDestroyCommandPool(h_.device, h_.pool, nullptr);
  vkDestroyDevice(h_.device, nullptr);
  h_ = Handles{};
}

VulkanDevice::~VulkanDevice() {
  destroy();
}

VulkanDevice::VulkanDevice(VulkanDevice&& other) noexcept
    : h_(std::exchange(other.h_, Handles{})) {}

VulkanDevice& VulkanDevice::operator=(VulkanDevice&& other) noexcept {
  if (this != &other) {
    destroy();
    h_ = std::exchange(other.h_, Handles{});
  }
  return *this;
}

Expected<uint32_t> VulkanDevice::memoryType(uint32_t type_bits, VkMemoryPropertyFlags flags) const {
  return findMemoryType(h_.memory, type_bits, flags);
}

Status VulkanDevice::submitAndWait(const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBuffer cmd = h_.command_buffer;
  RDM_VK_TRY(vkResetCommandBuffer(cmd, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  RDM_VK_TRY(vkBeginCommandBuffer(cmd, &begin));
  record(cmd);
  RDM_VK_TRY(vkEndCommandBuffer(cmd));
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  RDM_VK_TRY(vkResetFences(h_.device, 1, &h_.fence));
  RDM_VK_TRY(vkQueueSubmit(h_.queue, 1, &submit, h_.fence));
  RDM_VK_TRY(vkWaitForFences(h_.device, 1, &h_.fence, VK_TRUE, UINT64_MAX));
  return {};
}

}  // namespace rdm
#endif  // RDM_HAVE_VULKAN
