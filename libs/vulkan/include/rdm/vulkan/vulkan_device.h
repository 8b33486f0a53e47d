// One Vulkan layer for the compute bake and the viewer: the VkResult -> Status mapping, the
// device list and one device-selection policy (--device of `rdm bake` and `rdm-viewer`).
// Only with RDM_HAVE_VULKAN (the RDM_VULKAN build option).
#pragma once

#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "rdm/base/status.h"
#include "rdm/vulkan/vulkan_bake.h"

namespace rdm {

const char* vkResultName(VkResult result);
// Ok for VK_SUCCESS; else a kDevice error naming the call and the result, with what a user
// can do about lost devices, exhausted memory and a missing driver.
Status vkStatus(const char* call, VkResult result);

// Every physical device of `instance`, its handle and its description in the same order.
Status enumerateVulkanDevices(VkInstance instance, std::vector<VkPhysicalDevice>& devices,
                              std::vector<VulkanDeviceInfo>& infos);
// "0 'llvmpipe (...)' (cpu), ..." or "none".
std::string describeVulkanDevices(const std::vector<VulkanDeviceInfo>& infos);

enum class QueueNeed { kCompute, kGraphics };
// The device policy. `wanted` is an index into `infos` or a case-insensitive substring of a
// device name; empty picks the first device of the best type (discrete, integrated, virtual
// GPU, then CPU) that has the queue. A device that lacks the queue is refused by name.
Expected<int> selectVulkanDevice(const std::vector<VulkanDeviceInfo>& infos,
                                 const std::string& wanted, QueueNeed need);

}  // namespace rdm

// Returns the kDevice Status of a failed Vulkan call from the enclosing function.
#define RDM_VK_TRY(call)                                                             \
  do {                                                                               \
    const VkResult rdm_vk_result_ = (call);                                          \
    if (rdm_vk_result_ != VK_SUCCESS) return ::rdm::vkStatus(#call, rdm_vk_result_); \
  } while (0)
