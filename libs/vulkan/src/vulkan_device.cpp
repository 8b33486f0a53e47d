#if RDM_HAVE_VULKAN  // a compile definition of rdm_core (shaders/CMakeLists.txt)
#include "rdm/vulkan/vulkan_device.h"

#include <algorithm>
#include <cctype>

namespace rdm {
namespace {

std::string deviceTypeName(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "cpu";
    default:
      return "other";
  }
}

int typeRank(const std::string& type) {
  for (int r = 0; const char* t : {"discrete-gpu", "integrated-gpu", "virtual-gpu", "cpu"}) {
    if (type == t) return r;
    ++r;
  }
  return 4;
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool hasQueue(const VulkanDeviceInfo& d, QueueNeed need) {
  return need == QueueNeed::kCompute ? d.has_compute : d.has_graphics;
}

const char* queueName(QueueNeed need) {
  return need == QueueNeed::kCompute ? "compute" : "graphics";
}

Expected<int> deviceByName(const std::vector<VulkanDeviceInfo>& infos, const std::string& wanted) {
  const bool numeric = std::all_of(wanted.begin(), wanted.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c));
  });
  if (numeric) {
    const long long v = wanted.size() > 9 ? -1 : std::stoll(wanted);
    if (v < 0 || v >= (long long)infos.size()) {
      return Status::invalid("device",
                             "Vulkan: device index " + wanted +
                                 " out of range; devices: " + describeVulkanDevices(infos));
    }
    return int(v);
  }
  for (const VulkanDeviceInfo& d : infos) {
    if (lower(d.name).find(lower(wanted)) != std::string::npos) return d.index;
  }
  return Status::invalid("device", "Vulkan: no device named '" + wanted +
                                       "'; devices: " + describeVulkanDevices(infos));
}

}  // namespace

const char* vkResultName(VkResult r) {
  switch (r) {
#define RDM_VK_CASE(x) \
  case x:              \
    return #x;
    RDM_VK_CASE(VK_SUCCESS)
    RDM_VK_CASE(VK_NOT_READY)
    RDM_VK_CASE(VK_TIMEOUT)
    RDM_VK_CASE(VK_INCOMPLETE)
    RDM_VK_CASE(VK_SUBOPTIMAL_KHR)
    RDM_VK_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    RDM_VK_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    RDM_VK_CASE(VK_ERROR_INITIALIZATION_FAILED)
    RDM_VK_CASE(VK_ERROR_DEVICE_LOST)
    RDM_VK_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    RDM_VK_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    RDM_VK_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    RDM_VK_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    RDM_VK_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    RDM_VK_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    RDM_VK_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    RDM_VK_CASE(VK_ERROR_FRAGMENTED_POOL)
    RDM_VK_CASE(VK_ERROR_UNKNOWN)
    RDM_VK_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    RDM_VK_CASE(VK_ERROR_SURFACE_LOST_KHR)
    RDM_VK_CASE(VK_ERROR_OUT_OF_DATE_KHR)
    RDM_VK_CASE(VK_ERROR_INVALID_SHADER_NV)
#undef RDM_VK_CASE
    default:
      return "VkResult (unlisted)";
  }
}

Status vkStatus(const char* call, VkResult r) {
  if (r == VK_SUCCESS) return Status();
  std::string msg = std::string("Vulkan: ") + call + " failed: " + vkResultName(r) + " (" +
                    std::to_string(int(r)) + ")";
  if (r == VK_ERROR_DEVICE_LOST)
    msg += ": the device was lost (driver reset or hang); retry, or use the CPU";
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
    msg += ": out of memory; try a smaller max_batch_paths or the CPU backend";
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER) msg += ": no Vulkan driver (ICD) is installed";
  return Status::error(StatusCode::kDevice, msg);
}

Status enumerateVulkanDevices(VkInstance instance, std::vector<VkPhysicalDevice>& devices,
                              std::vector<VulkanDeviceInfo>& infos) {
  uint32_t count = 0;
  RDM_VK_TRY(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  devices.resize(count);
  if (count) RDM_VK_TRY(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
  devices.resize(count);
  infos.clear();
  for (uint32_t i = 0; i < count; ++i) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(devices[i], &p);
    VulkanDeviceInfo d;
    d.index = int(i);
    d.name = p.deviceName;
    d.type = deviceTypeName(p.deviceType);
    d.api_version = p.apiVersion;
    if (p.apiVersion >= VK_API_VERSION_1_2) {
      VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
      VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
      p2.pNext = &driver;
      vkGetPhysicalDeviceProperties2(devices[i], &p2);
      d.driver = std::string(driver.driverName) + " " + driver.driverInfo;
    }
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(devices[i], &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    vkGetPhysicalDeviceQueueFamilyProperties(devices[i], &families, props.data());
    for (const auto& f : props) {
      d.has_compute = d.has_compute || (f.queueFlags & VK_QUEUE_COMPUTE_BIT);
      d.has_graphics = d.has_graphics || (f.queueFlags & VK_QUEUE_GRAPHICS_BIT);
    }
    infos.push_back(d);
  }
  return {};
}

std::string describeVulkanDevices(const std::vector<VulkanDeviceInfo>& infos) {
  std::string s;
  for (const auto& d : infos)
    s += (s.empty() ? "" : ", ") + std::to_string(d.index) + " '" + d.name + "' (" + d.type + ")";
  return s.empty() ? "none" : s;
}

Expected<int> selectVulkanDevice(const std::vector<VulkanDeviceInfo>& infos,
                                 const std::string& wanted, QueueNeed need) {
  if (infos.empty()) {
    return Status::error(
        StatusCode::kDevice,
        "Vulkan: no Vulkan device found (vkEnumeratePhysicalDevices returned none)");
  }
  if (wanted.empty()) {
    int best = -1;
    for (const auto& d : infos) {
      if (!hasQueue(d, need)) continue;
      if (best < 0 || typeRank(d.type) < typeRank(infos[size_t(best)].type)) best = d.index;
    }
    if (best < 0) {
      return Status::error(StatusCode::kDevice, std::string("Vulkan: no device with a ") +
                                                    queueName(need) + " queue among " +
                                                    describeVulkanDevices(infos));
    }
    return best;
  }
  auto index = deviceByName(infos, wanted);
  if (!index) return index;
  if (!hasQueue(infos[size_t(*index)], need)) {
    return Status::error(StatusCode::kDevice, "Vulkan: device '" + infos[size_t(*index)].name +
                                                  "' has no " + queueName(need) + " queue");
  }
  return index;
}

}  // namespace rdm
#endif
