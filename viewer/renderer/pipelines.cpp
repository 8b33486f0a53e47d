#include "pipelines.h"

#include <array>
#include <vector>

#include "gpu_resources.h"
#include "mesher.h"
#include "shader_code.h"
#include "vk_check.h"

namespace rdm::viewer {
namespace {

VkSubpassDependency dependency(uint32_t src, uint32_t dst) {
  // Conservative: any earlier attachment write or transfer before any later read or write.
  constexpr VkPipelineStageFlags kStages =
      VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
      VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT |
      VK_PIPELINE_STAGE_TRANSFER_BIT;
  constexpr VkAccessFlags kAccess =
      VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT |
      VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  return {src, dst, kStages, kStages, kAccess, kAccess, 0};
}

Status makeRenderPass(VkDevice device, const std::vector<VkAttachmentDescription>& attachments,
                      bool has_color, bool has_depth, VkRenderPass& out) {
  VkAttachmentReference color{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkAttachmentReference depth{has_color ? 1u : 0u,
                              VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = has_color ? 1 : 0;
  subpass.pColorAttachments = has_color ? &color : nullptr;
  subpass.pDepthStencilAttachment = has_depth ? &depth : nullptr;
  const std::array<VkSubpassDependency, 2> deps = {dependency(VK_SUBPASS_EXTERNAL, 0),
                                                   dependency(0, VK_SUBPASS_EXTERNAL)};
  VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  info.attachmentCount = uint32_t(attachments.size());
  info.pAttachments = attachments.data();
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  info.dependencyCount = uint32_t(deps.size());
  info.pDependencies = deps.data();
  RDM_VK_TRY(vkCreateRenderPass(device, &info, nullptr, &out));
  return Status();
}

VkAttachmentDescription attachment(VkFormat format, VkAttachmentLoadOp load,
                                   VkAttachmentStoreOp store, VkImageLayout final_layout,
                                   VkImageLayout initial_layout = VK_IMAGE_LAYOUT_UNDEFINED) {
  VkAttachmentDescription a{};
  a.format = format;
  a.samples = VK_SAMPLE_COUNT_1_BIT;
  a.loadOp = load;
  a.storeOp = store;
  a.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  a.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  a.initialLayout = initial_layout;
  a.finalLayout = final_layout;
  return a;
}

Status makeRenderPasses(VkDevice device, PipelineSet& p) {
  RDM_TRY(makeRenderPass(
      device,
      {attachment(kDepthFormat, VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_STORE,
                  VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL)},
      false, true, p.shadow_pass));
  RDM_TRY(makeRenderPass(
      device,
      {attachment(kHdrFormat, VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_STORE,
                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL),
       attachment(kDepthFormat, VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_DONT_CARE,
                  VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL)},
      true, true, p.main_pass));
  // The running mean is loaded and kept between frames in its sampled layout.
  RDM_TRY(makeRenderPass(
      device,
      {attachment(kHdrFormat, VK_ATTACHMENT_LOAD_OP_LOAD, VK_ATTACHMENT_STORE_OP_STORE,
                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)},
      true, false, p.accumulate_pass));
  return makeRenderPass(
      device,
      {attachment(kLdrFormat, VK_ATTACHMENT_LOAD_OP_DONT_CARE, VK_ATTACHMENT_STORE_OP_STORE,
                  VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL)},
      true, false, p.tonemap_pass);
}

Status makeSetLayouts(VkDevice device, PipelineSet& p) {
  constexpr VkShaderStageFlags kVertFrag =
      VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  const std::array<VkDescriptorSetLayoutBinding, 8> scene = {{
      {kBindingFrame, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, kVertFrag, nullptr},
      {kBindingVoxels, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 1, VK_SHADER_STAGE_FRAGMENT_BIT,
       nullptr},
      {kBindingSlots, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
      {kBindingTables, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
      {kBindingAtlas, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT,
       nullptr},
      {kBindingShadowMap, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1,
       VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
      {kBindingFaceLight, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 1, VK_SHADER_STAGE_FRAGMENT_BIT,
       nullptr},
      {kBindingAtlasDepth, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1,
       VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
  }};
  VkDescriptorSetLayoutCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  info.bindingCount = uint32_t(scene.size());
  info.pBindings = scene.data();
  RDM_VK_TRY(vkCreateDescriptorSetLayout(device, &info, nullptr, &p.scene_set_layout));
  const VkDescriptorSetLayoutBinding hdr = {0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1,
                                            VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
  info.bindingCount = 1;
  info.pBindings = &hdr;
  RDM_VK_TRY(vkCreateDescriptorSetLayout(device, &info, nullptr, &p.image_set_layout));
  VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout.setLayoutCount = 1;
  layout.pSetLayouts = &p.scene_set_layout;
  RDM_VK_TRY(vkCreatePipelineLayout(device, &layout, nullptr, &p.scene_layout));
  layout.pSetLayouts = &p.image_set_layout;
  const VkPushConstantRange divisor{VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(int32_t)};
  layout.pushConstantRangeCount = 1;
  layout.pPushConstantRanges = &divisor;  // the resolution divisor (accumulate.frag)
  RDM_VK_TRY(vkCreatePipelineLayout(device, &layout, nullptr, &p.image_layout));
  return Status();
}

struct PipelineDesc {
  ShaderId vert;
  const ShaderId* frag;  // null: depth only
  bool block_vertices;   // mesh vertex input (scene_gpu.h), else no vertex input
  bool depth_test;
  bool depth_bias;
  VkCompareOp depth_compare;
  bool depth_write;
  bool color_attachment;  // the pass has one colour attachment (written only with a fragment stage)
  bool blend_constant;    // out = src * c + dst * (1 - c), c the dynamic blend constant's alpha
  VkPipelineLayout layout;
  VkRenderPass pass;
  // Back faces culled: a mesh quad faces out of its solid voxel, so its back is only seen from
  // inside a solid voxel; culled before triangle setup, which on lavapipe costs per triangle.
  bool cull_back = false;
};

Status makePipeline(VkDevice device, const PipelineDesc& d, VkPipeline& out) {
  std::vector<VkPipelineShaderStageCreateInfo> stages;
  std::vector<VkShaderModule> modules;
  auto add_stage = [&](ShaderId id, VkShaderStageFlagBits stage) -> Status {
    const ShaderCode code = shaderCode(id);
    auto module = createShaderModule(device, code.words, code.bytes);
    if (!module) return module.status();
    modules.push_back(*module);
    VkPipelineShaderStageCreateInfo s{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    s.stage = stage;
    s.module = *module;
    s.pName = "main";
    stages.push_back(s);
    return Status();
  };
  Status status = add_stage(d.vert, VK_SHADER_STAGE_VERTEX_BIT);
  if (status.ok() && d.frag) status = add_stage(*d.frag, VK_SHADER_STAGE_FRAGMENT_BIT);
  if (status.ok()) {
    const std::array<VkVertexInputBindingDescription, 2> bindings = {{
        {0, sizeof(MeshVertex), VK_VERTEX_INPUT_RATE_VERTEX},
        {1, 4 * sizeof(int32_t), VK_VERTEX_INPUT_RATE_VERTEX},  // slot, block per vertex
    }};
    const std::array<VkVertexInputAttributeDescription, 2> attributes = {{
        {0, 0, VK_FORMAT_R32G32_UINT, 0},
        {1, 1, VK_FORMAT_R32G32B32A32_SINT, 0},
    }};
    VkPipelineVertexInputStateCreateInfo input{
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    if (d.block_vertices) {
      input.vertexBindingDescriptionCount = uint32_t(bindings.size());
      input.pVertexBindingDescriptions = bindings.data();
      input.vertexAttributeDescriptionCount = uint32_t(attributes.size());
      input.pVertexAttributeDescriptions = attributes.data();
    }
    VkPipelineInputAssemblyStateCreateInfo assembly{
        VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo viewport{
        VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = d.cull_back ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1.0f;
    raster.depthBiasEnable = d.depth_bias ? VK_TRUE : VK_FALSE;
    raster.depthBiasConstantFactor = 1.5f;
    raster.depthBiasSlopeFactor = 2.0f;
    VkPipelineMultisampleStateCreateInfo multisample{
        VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo depth{
        VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    depth.depthTestEnable = d.depth_test ? VK_TRUE : VK_FALSE;
    depth.depthWriteEnable = d.depth_test && d.depth_write ? VK_TRUE : VK_FALSE;
    depth.depthCompareOp = d.depth_compare;
    VkPipelineColorBlendAttachmentState blend_attachment{};
    blend_attachment.colorWriteMask = d.frag ? 0xfu : 0u;
    if (d.blend_constant) {
      blend_attachment.blendEnable = VK_TRUE;
      blend_attachment.srcColorBlendFactor = blend_attachment.srcAlphaBlendFactor =
          VK_BLEND_FACTOR_CONSTANT_ALPHA;
      blend_attachment.dstColorBlendFactor = blend_attachment.dstAlphaBlendFactor =
          VK_BLEND_FACTOR_ONE_MINUS_CONSTANT_ALPHA;
      blend_attachment.colorBlendOp = blend_attachment.alphaBlendOp = VK_BLEND_OP_ADD;
    }
    VkPipelineColorBlendStateCreateInfo blend{
        VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    blend.attachmentCount = d.color_attachment ? 1 : 0;
    blend.pAttachments = &blend_attachment;
    const std::array<VkDynamicState, 3> dynamic_states = {
        VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR, VK_DYNAMIC_STATE_BLEND_CONSTANTS};
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = d.blend_constant ? 3u : 2u;
    dynamic.pDynamicStates = dynamic_states.data();
    VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.stageCount = uint32_t(stages.size());
    info.pStages = stages.data();
    info.pVertexInputState = &input;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth;
    info.pColorBlendState = &blend;
    info.pDynamicState = &dynamic;
    info.layout = d.layout;
    info.renderPass = d.pass;
    status = vkStatus("vkCreateGraphicsPipelines",
                      vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &out));
  }
  for (VkShaderModule m : modules) vkDestroyShaderModule(device, m, nullptr);
  return status;
}

}  // namespace

Status createPipelines(VkDevice device, PipelineSet& p) {
  RDM_TRY(makeRenderPasses(device, p));
  RDM_TRY(makeSetLayouts(device, p));
  const ShaderId block_frag = ShaderId::kBlockFrag, sky_frag = ShaderId::kSkyFrag;
  const ShaderId accumulate_frag = ShaderId::kAccumulateFrag, tonemap_frag = ShaderId::kTonemapFrag;
  constexpr VkCompareOp kLess = VK_COMPARE_OP_LESS, kLessEqual = VK_COMPARE_OP_LESS_OR_EQUAL;
  RDM_TRY(makePipeline(device,
                       {ShaderId::kShadowVert, nullptr, true, true, true, kLess, true, false, false,
                        p.scene_layout, p.shadow_pass},
                       p.shadow));
  // Depth pre-pass, then shading of the nearest fragment only: on a CPU rasteriser each
  // shaded fragment costs the whole RDM lookup, and blocks are drawn in no depth order.
  RDM_TRY(makePipeline(device,
                       {ShaderId::kBlockVert, nullptr, true, true, false, kLess, true, true, false,
                        p.scene_layout, p.main_pass, true},
                       p.block_depth));
  RDM_TRY(makePipeline(device,
                       {ShaderId::kBlockVert, &block_frag, true, true, false, kLessEqual, false,
                        true, false, p.scene_layout, p.main_pass, true},
                       p.blocks));
  RDM_TRY(makePipeline(device,
                       {ShaderId::kFullscreenVert, &sky_frag, false, false, false, kLess, false,
                        true, false, p.scene_layout, p.main_pass},
                       p.sky));
  RDM_TRY(makePipeline(device,
                       {ShaderId::kFullscreenVert, &accumulate_frag, false, false, false, kLess,
                        false, true, true, p.image_layout, p.accumulate_pass},
                       p.accumulate));
  return makePipeline(device,
                      {ShaderId::kFullscreenVert, &tonemap_frag, false, false, false, kLess, false,
                       true, false, p.image_layout, p.tonemap_pass},
                      p.tonemap);
}

void PipelineSet::destroy(VkDevice device) {
  for (VkPipeline* pipeline : {&shadow, &block_depth, &blocks, &sky, &accumulate, &tonemap}) {
    if (*pipeline != VK_NULL_HANDLE) vkDestroyPipeline(device, *pipeline, nullptr);
    *pipeline = VK_NULL_HANDLE;
  }
  for (VkPipelineLayout* layout : {&scene_layout, &image_layout}) {
    if (*layout != VK_NULL_HANDLE) vkDestroyPipelineLayout(device, *layout, nullptr);
    *layout = VK_NULL_HANDLE;
  }
  for (VkDescriptorSetLayout* layout : {&scene_set_layout, &image_set_layout}) {
    if (*layout != VK_NULL_HANDLE) vkDestroyDescriptorSetLayout(device, *layout, nullptr);
    *layout = VK_NULL_HANDLE;
  }
  for (VkRenderPass* pass : {&shadow_pass, &main_pass, &accumulate_pass, &tonemap_pass}) {
    if (*pass != VK_NULL_HANDLE) vkDestroyRenderPass(device, *pass, nullptr);
    *pass = VK_NULL_HANDLE;
  }
}

}  // namespace rdm::viewer
