// VkResult handling: every Vulkan call's result is checked and turned into an rdm::Status
// naming the call, so that no device failure crashes the viewer.
#pragma once

#include <string>

#include <vulkan/vulkan.h>

#include "rdm/status.h"

namespace rdm::viewer {

const char* vkResultName(VkResult result);

inline Status vkStatus(const char* call, VkResult result) {
  if (result == VK_SUCCESS) return Status();
  return Status::error(std::string(call) + " failed: " + vkResultName(result));
}

}  // namespace rdm::viewer

// Returns an error Status from the enclosing function when `call` does not succeed.
#define RDM_VK_TRY(call)                                     \
  do {                                                       \
    const VkResult rdm_vk_result_ = (call);                  \
    if (rdm_vk_result_ != VK_SUCCESS) {                      \
      return ::rdm::viewer::vkStatus(#call, rdm_vk_result_); \
    }                                                        \
  } while (0)

// Returns from the enclosing function when `expr` (a Status) is an error.
#define RDM_TRY(expr)                          \
  do {                                         \
    ::rdm::Status rdm_status_ = (expr);        \
    if (!rdm_status_.ok()) return rdm_status_; \
  } while (0)
