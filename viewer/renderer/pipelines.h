// Render passes, descriptor layouts and graphics pipelines of the viewer's frame:
//   shadow pass  (depth only, sun's orthographic view)
//   main pass    (sky/sun-disc background, then the instanced blocks) -> HDR RGBA32F
//   accumulate pass (the frame blended into the running mean) -> HDR RGBA32F, full size
//   tonemap pass (Reinhard + sRGB of the mean) -> RGBA8 UNORM
// Viewport and scissor are dynamic, so a resize rebuilds only the framebuffers.
#pragma once

#include <vulkan/vulkan.h>

#include "rdm/base/status.h"

namespace rdm::viewer {

inline constexpr VkFormat kHdrFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
inline constexpr VkFormat kLdrFormat = VK_FORMAT_R8G8B8A8_UNORM;
inline constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

// Scene descriptor set bindings (viewer_common.glsl, shading.glsl, rdm_lookup.glsl).
enum SceneBinding : uint32_t {
  kBindingFrame = 0,
  kBindingVoxels = 1,
  kBindingSlots = 2,
  kBindingTables = 3,
  kBindingAtlas = 4,
  kBindingShadowMap = 5,
  kBindingFaceLight = 6,
  kBindingAtlasDepth = 7,
};

struct PipelineSet {
  VkRenderPass shadow_pass = VK_NULL_HANDLE, main_pass = VK_NULL_HANDLE,
               accumulate_pass = VK_NULL_HANDLE, tonemap_pass = VK_NULL_HANDLE;
  // The accumulate and tonemap passes read one sampled image each (image_set_layout); the
  // push constant is the resolution divisor (accumulate.frag).
  VkDescriptorSetLayout scene_set_layout = VK_NULL_HANDLE, image_set_layout = VK_NULL_HANDLE;
  VkPipelineLayout scene_layout = VK_NULL_HANDLE, image_layout = VK_NULL_HANDLE;
  VkPipeline shadow = VK_NULL_HANDLE, block_depth = VK_NULL_HANDLE, blocks = VK_NULL_HANDLE,
             sky = VK_NULL_HANDLE, accumulate = VK_NULL_HANDLE, tonemap = VK_NULL_HANDLE;

  // Destroys whatever was created; safe on a partially built set.
  void destroy(VkDevice device);
};

// Builds every object of the set into `out` (partially on failure; call destroy).
Status createPipelines(VkDevice device, PipelineSet& out);

}  // namespace rdm::viewer
