// VkResult handling: every Vulkan call's result is checked and turned into an rdm::Status
// naming the call, so that no device failure crashes the viewer.
#pragma once

#include <vulkan/vulkan.h>

#include "rdm/base/status.h"
#include "rdm/vulkan/vulkan_device.h"  // RDM_VK_TRY, vkStatus, vkResultName: one mapping for the core and the viewer

// Returns from the enclosing function when `expr` (a Status) is an error.
#define RDM_TRY(expr)                          \
  do {                                         \
    ::rdm::Status rdm_status_ = (expr);        \
    if (!rdm_status_.ok()) return rdm_status_; \
  } while (0)
