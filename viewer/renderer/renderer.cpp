#include "renderer.h"

#include <algorithm>

#include <array>
#include <cstring>
#include <tuple>

#include "vk_check.h"

namespace rdm::viewer {
namespace {

constexpr size_t kTablesDfgBytes = sizeof(glm::vec4) * kDfgRows * kDfgColumns;
constexpr size_t kTablesBytes = kTablesDfgBytes + 256 * sizeof(float);

Expected<VkSampler> makeSampler(VkDevice device, VkFilter filter, bool compare) {
  VkSamplerCreateInfo info{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  info.magFilter = info.minFilter = filter;
  info.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  info.addressModeU = info.addressModeV = info.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  info.compareEnable = compare ? VK_TRUE : VK_FALSE;
  info.compareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
  info.maxLod = 0.0f;
  VkSampler sampler = VK_NULL_HANDLE;
  RDM_VK_TRY(vkCreateSampler(device, &info, nullptr, &sampler));
  return sampler;
}

// Replaces `buffer` with a new one holding `bytes` of `data`.
Status uploadBuffer(const VulkanContext& context, GpuBuffer& buffer, const void* data, size_t bytes,
                    VkBufferUsageFlags usage) {
  auto created = GpuBuffer::create(context, bytes, usage);
  if (!created) return created.status();
  created->write(data, bytes);
  buffer = std::move(*created);
  return Status();
}

}  // namespace

Renderer::Renderer(VulkanContext& context, const RendererOptions& options)
    : context_(context), options_(options), width_(options.width), height_(options.height) {}

Expected<std::unique_ptr<Renderer>> Renderer::create(VulkanContext& context,
                                                     const RendererOptions& options) {
  if (options.width < 1 || options.height < 1 || options.width > 16384 || options.height > 16384) {
    return Status::error("image size must be 1..16384 per axis");
  }
  std::unique_ptr<Renderer> renderer(new Renderer(context, options));
  RDM_TRY(renderer->init());
  return renderer;
}

Status Renderer::init() {
  const VkDevice device = context_.device();
  RDM_TRY(createPipelines(device, pipelines_));
  const std::array<VkDescriptorPoolSize, 4> sizes = {{
      {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
      {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2},
      {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 2},
      {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 5},
  }};
  VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool.maxSets = 3;
  pool.poolSizeCount = uint32_t(sizes.size());
  pool.pPoolSizes = sizes.data();
  RDM_VK_TRY(vkCreateDescriptorPool(device, &pool, nullptr, &descriptor_pool_));
  const std::array<VkDescriptorSetLayout, 3> layouts = {
      pipelines_.scene_set_layout, pipelines_.image_set_layout, pipelines_.image_set_layout};
  std::array<VkDescriptorSet, 3> sets{};
  VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc.descriptorPool = descriptor_pool_;
  alloc.descriptorSetCount = uint32_t(sets.size());
  alloc.pSetLayouts = layouts.data();
  RDM_VK_TRY(vkAllocateDescriptorSets(device, &alloc, sets.data()));
  scene_set_ = sets[0], accumulate_set_ = sets[1], tonemap_set_ = sets[2];
  for (auto [sampler, filter, compare] : {std::tuple{&atlas_sampler_, VK_FILTER_LINEAR, false},
                                          {&shadow_sampler_, VK_FILTER_LINEAR, true},
                                          {&hdr_sampler_, VK_FILTER_NEAREST, false}}) {
    auto s = makeSampler(device, filter, compare);
    if (!s) return s.status();
    *sampler = *s;
  }
  VkCommandBufferAllocateInfo cmd{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cmd.commandPool = context_.commandPool();
  cmd.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cmd.commandBufferCount = 1;
  RDM_VK_TRY(vkAllocateCommandBuffers(device, &cmd, &frame_cmd_));
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  RDM_VK_TRY(vkCreateFence(device, &fence, nullptr, &frame_fence_));
  RDM_TRY(createStaticResources());
  RDM_TRY(createTargets());
  RDM_TRY(setScene(Scene()));
  return setAtlas(LoadedAtlas());
}

Status Renderer::createStaticResources() {
  tables_ = computeShadingTables();
  std::vector<uint8_t> bytes(kTablesBytes);
  std::memcpy(bytes.data(), tables_.dfg.data(), kTablesDfgBytes);
  for (int v = 0; v < 256; ++v) {
    const float linear = srgbToLinear(v);
    std::memcpy(bytes.data() + kTablesDfgBytes + v * sizeof(float), &linear, sizeof(float));
  }
  RDM_TRY(uploadBuffer(context_, tables_buffer_, bytes.data(), bytes.size(),
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT));
  auto uniforms =
      GpuBuffer::create(context_, sizeof(FrameUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  if (!uniforms) return uniforms.status();
  uniforms_ = std::move(*uniforms);
  ImageSpec shadow;
  shadow.width = shadow.height = uint32_t(options_.shadow_map_size);
  shadow.format = kDepthFormat;
  shadow.aspect = VK_IMAGE_ASPECT_DEPTH_BIT;
  shadow.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
  auto map = GpuImage::create(context_, shadow);
  if (!map) return map.status();
  shadow_map_ = std::move(*map);
  VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  fb.renderPass = pipelines_.shadow_pass;
  fb.attachmentCount = 1;
  const VkImageView view = shadow_map_.view();
  fb.pAttachments = &view;
  fb.width = fb.height = shadow.width;
  fb.layers = 1;
  RDM_VK_TRY(vkCreateFramebuffer(context_.device(), &fb, nullptr, &shadow_fb_));
  return Status();
}

Status Renderer::createTargets() {
  const VkDevice device = context_.device();
  accumulator_.invalidate();
  for (VkFramebuffer* fb : {&main_fb_, &accumulate_fb_, &tonemap_fb_}) {
    if (*fb != VK_NULL_HANDLE) vkDestroyFramebuffer(device, *fb, nullptr);
    *fb = VK_NULL_HANDLE;
  }
  ImageSpec spec;
  spec.width = uint32_t(width_), spec.height = uint32_t(height_);
  struct Target {
    GpuImage* image;
    VkFormat format;
    VkImageUsageFlags usage;
    VkImageAspectFlags aspect;
  };
  for (const Target& t :
       {Target{&hdr_, kHdrFormat,
               VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                   VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
               VK_IMAGE_ASPECT_COLOR_BIT},
        Target{&depth_, kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
               VK_IMAGE_ASPECT_DEPTH_BIT},
        Target{&mean_, kHdrFormat,
               VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                   VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
               VK_IMAGE_ASPECT_COLOR_BIT},
        Target{&ldr_, kLdrFormat,
               VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
               VK_IMAGE_ASPECT_COLOR_BIT}}) {
    spec.format = t.format, spec.usage = t.usage, spec.aspect = t.aspect;
    auto image = GpuImage::create(context_, spec);
    if (!image) return image.status();
    *t.image = std::move(*image);
  }
  VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  fb.width = spec.width, fb.height = spec.height, fb.layers = 1;
  const std::array<VkImageView, 2> main_views = {hdr_.view(), depth_.view()};
  fb.renderPass = pipelines_.main_pass;
  fb.attachmentCount = 2;
  fb.pAttachments = main_views.data();
  RDM_VK_TRY(vkCreateFramebuffer(device, &fb, nullptr, &main_fb_));
  const VkImageView mean_view = mean_.view(), ldr_view = ldr_.view();
  fb.renderPass = pipelines_.accumulate_pass;
  fb.attachmentCount = 1;
  fb.pAttachments = &mean_view;
  RDM_VK_TRY(vkCreateFramebuffer(device, &fb, nullptr, &accumulate_fb_));
  fb.renderPass = pipelines_.tonemap_pass;
  fb.pAttachments = &ldr_view;
  RDM_VK_TRY(vkCreateFramebuffer(device, &fb, nullptr, &tonemap_fb_));
  RDM_TRY(clearMean());
  if (voxels_.handle() != VK_NULL_HANDLE && atlas_) writeDescriptors();
  return Status();
}

// The mean starts at zero (its first frame has weight 1, and 0 * NaN garbage would stay NaN)
// in the layout the accumulate pass expects.
Status Renderer::clearMean() {
  return context_.submitAndWait([&](VkCommandBuffer cmd) {
    transitionImage(cmd, mean_,
                    {VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                     VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                     VK_ACCESS_TRANSFER_WRITE_BIT});
    const VkClearColorValue zero{};
    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cmd, mean_.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1,
                         &range);
    transitionImage(cmd, mean_,
                    {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                     VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                     VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_MEMORY_READ_BIT});
  });
}

Status Renderer::resize(int width, int height) {
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    return Status::error("bad image size");
  RDM_VK_TRY(vkDeviceWaitIdle(context_.device()));
  width_ = width, height_ = height;
  return createTargets();
}

Status Renderer::setScene(const Scene& scene) {
  RDM_VK_TRY(vkDeviceWaitIdle(context_.device()));
  scene_ = scene;
  VoxelWorld before = std::move(world_);
  world_ = buildWorld(scene_);
  if (before.size == world_.size) updateFaceLight(before, world_, scene_.bake, face_light_);
  shadow_valid_ = false;
  accumulator_.invalidate();
  scene_data_ = buildSceneGpuData(scene_, world_);
  const auto& d = scene_data_;
  RDM_TRY(uploadBuffer(context_, vertices_, d.vertices.data(),
                       d.vertices.size() * sizeof(MeshVertex), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT));
  RDM_TRY(uploadBuffer(context_, indices_, d.indices.data(), d.indices.size() * sizeof(uint32_t),
                       VK_BUFFER_USAGE_INDEX_BUFFER_BIT));
  RDM_TRY(uploadBuffer(context_, instances_, d.instances.data(),
                       d.instances.size() * sizeof(glm::ivec4), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT));
  RDM_TRY(uploadTexelWords(d.voxels, "voxel words", voxels_, voxel_view_));
  RDM_TRY(uploadFaceLight());
  return atlas_ ? uploadSlots() : Status();
}

Status Renderer::setFaceLight(FaceLight light) {
  RDM_VK_TRY(vkDeviceWaitIdle(context_.device()));
  face_light_ = std::move(light);
  RDM_TRY(uploadFaceLight());
  if (atlas_) writeDescriptors();
  return Status();
}

Status Renderer::uploadFaceLight() {
  accumulator_.invalidate();
  return uploadTexelWords(buildFaceLightWords(world_, face_light_), "face light words",
                          face_light_words_, face_light_view_);
}

Status Renderer::setAtlas(LoadedAtlas atlas) {
  RDM_VK_TRY(vkDeviceWaitIdle(context_.device()));
  std::vector<AtlasPage> sizes;
  for (const Image& p : atlas.pages) sizes.push_back({p.width, p.height});
  atlas_.reset();  // the old image goes before the new one is made
  layout_ = AtlasLayout();
  auto texture = AtlasTexture::create(context_, sizes, options_.atlas_precision);
  if (!texture) return dropAtlas(texture.status());
  atlas_ = std::move(*texture);
  for (size_t p = 0; p < atlas.pages.size(); ++p) {
    std::vector<AtlasRectUpdate> whole;
    whole.push_back({int(p), 0, 0, std::move(atlas.pages[p])});
    if (Status s = atlas_->applyDelta(whole); !s) return dropAtlas(s);  // releases the floats
  }
  layout_ = std::move(atlas.layout);
  return uploadSlots();
}

Status Renderer::loadAtlas(const std::string& dir, AtlasLayout layout) {
  RDM_VK_TRY(vkDeviceWaitIdle(context_.device()));
  atlas_.reset();
  layout_ = AtlasLayout();
  const bool on_cpu = context_.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  const Bc6hTexture wanted = options_.bc6h_texture;
  const bool as_stored =
      layout.radiance == RadianceFormat::kBc6h &&
      options_.atlas_precision == AtlasPrecision::kHalf && context_.samplesBc6h() &&
      (wanted == Bc6hTexture::kStored || (wanted == Bc6hTexture::kAuto && !on_cpu));
  auto texture = AtlasTexture::create(context_, layout.pages,
                                      as_stored ? AtlasPrecision::kBc6h : options_.atlas_precision);
  if (!texture) return dropAtlas(texture.status());
  atlas_ = std::move(*texture);
  if (Status s = loadAtlasPages(dir, layout, *atlas_); !s) return dropAtlas(s);
  layout_ = std::move(layout);
  return uploadSlots();
}

// After a failed setAtlas or loadAtlas: no RDMs (a 1 x 1 zero page), and `why`.
Status Renderer::dropAtlas(const Status& why) {
  atlas_.reset();
  layout_ = AtlasLayout();
  auto empty = AtlasTexture::create(context_, std::vector<AtlasPage>{}, options_.atlas_precision);
  if (empty) atlas_ = std::move(*empty);
  if (atlas_) (void)uploadSlots();
  return why;
}

Status Renderer::applyAtlasDelta(const AtlasLayout& layout,
                                 const std::vector<AtlasRectUpdate>& updates) {
  RDM_VK_TRY(vkDeviceWaitIdle(context_.device()));
  const std::vector<AtlasPage>& held = atlas_->pageSizes();
  bool same = layout.pages.size() == held.size();
  for (size_t p = 0; same && p < layout.pages.size(); ++p)
    same = layout.pages[p].width == held[p].width && layout.pages[p].height == held[p].height;
  if (same || atlas_->growInPlace(layout.pages)) {
    RDM_TRY(atlas_->applyDelta(updates));
    layout_ = layout;
    return uploadSlots();
  }
  // Pages were added or grew past the image (docs/spec.md section 8.9): a texture of the new
  // size holding the old texels where they were (copied on the device), then the rects.
  for (size_t p = 0; p < held.size() && p < layout.pages.size(); ++p) {
    if (held[p].width > layout.pages[p].width || held[p].height > layout.pages[p].height)
      return Status::error("atlas delta shrinks page " + std::to_string(p));
  }
  auto grown = AtlasTexture::create(context_, layout.pages, atlas_->precision());
  if (!grown) return grown.status();
  RDM_TRY((*grown)->copyPagesFrom(*atlas_));
  if (Status s = (*grown)->applyDelta(updates); !s)
    return Status::error("atlas delta: a rect leaves its page");
  atlas_ = std::move(*grown);
  layout_ = layout;
  return uploadSlots();
}

Status Renderer::uploadSlots() {
  accumulator_.invalidate();
  const std::vector<SlotInfo> slots =
      buildSlotInfos(world_, layout_, atlas_->pageSizes(), atlas_->depthMask());
  RDM_TRY(uploadBuffer(context_, slots_, slots.data(), slots.size() * sizeof(SlotInfo),
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT));
  writeDescriptors();
  return Status();
}

void Renderer::writeDescriptors() {
  const VkDescriptorBufferInfo frame{uniforms_.handle(), 0, VK_WHOLE_SIZE};
  const VkDescriptorBufferInfo slots{slots_.handle(), 0, VK_WHOLE_SIZE};
  const VkDescriptorBufferInfo tables{tables_buffer_.handle(), 0, VK_WHOLE_SIZE};
  const VkDescriptorImageInfo atlas{atlas_sampler_, atlas_->view(),
                                    VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  const VkDescriptorImageInfo atlas_depth{atlas_sampler_, atlas_->depthView(),
                                          VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  const VkDescriptorImageInfo shadow{shadow_sampler_, shadow_map_.view(),
                                     VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL};
  const VkDescriptorImageInfo hdr{hdr_sampler_, hdr_.view(),
                                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  const VkDescriptorImageInfo mean{hdr_sampler_, mean_.view(),
                                   VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  VkWriteDescriptorSet texel_write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  texel_write.dstSet = scene_set_, texel_write.dstBinding = kBindingVoxels;
  texel_write.descriptorCount = 1;
  texel_write.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  texel_write.pTexelBufferView = &voxel_view_;
  auto write = [](VkDescriptorSet set, uint32_t binding, VkDescriptorType type,
                  const VkDescriptorBufferInfo* b, const VkDescriptorImageInfo* i) {
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set, w.dstBinding = binding, w.descriptorCount = 1, w.descriptorType = type;
    w.pBufferInfo = b, w.pImageInfo = i;
    return w;
  };
  VkWriteDescriptorSet face_light_write = texel_write;
  face_light_write.dstBinding = kBindingFaceLight;
  face_light_write.pTexelBufferView = &face_light_view_;
  const std::array<VkWriteDescriptorSet, 10> writes = {
      write(scene_set_, kBindingFrame, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, &frame, nullptr),
      texel_write,
      face_light_write,
      write(scene_set_, kBindingSlots, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &slots, nullptr),
      write(scene_set_, kBindingTables, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &tables, nullptr),
      write(scene_set_, kBindingAtlas, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, nullptr, &atlas),
      write(scene_set_, kBindingAtlasDepth, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, nullptr,
            &atlas_depth),
      write(scene_set_, kBindingShadowMap, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, nullptr,
            &shadow),
      write(accumulate_set_, 0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, nullptr, &hdr),
      write(tonemap_set_, 0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, nullptr, &mean),
  };
  vkUpdateDescriptorSets(context_.device(), uint32_t(writes.size()), writes.data(), 0, nullptr);
}

// The voxel and face light words go to the fragment shader as R32_UINT texel buffers:
// llvmpipe gathers texel fetches in SIMD, where a storage-buffer load with a per-pixel index
// runs lane by lane (docs/performance.md, "Frame time").
Status Renderer::uploadTexelWords(const std::vector<uint32_t>& words, const char* what,
                                  GpuBuffer& buffer, VkBufferView& buffer_view) {
  const uint32_t limit = context_.properties().limits.maxTexelBufferElements;
  if (words.size() > limit) {
    return Status::error(StatusCode::kDevice,
                         std::string("scene: ") + std::to_string(words.size()) + " " + what +
                             " exceed the device's texel buffer limit of " + std::to_string(limit));
  }
  if (buffer_view != VK_NULL_HANDLE) vkDestroyBufferView(context_.device(), buffer_view, nullptr);
  buffer_view = VK_NULL_HANDLE;
  RDM_TRY(uploadBuffer(context_, buffer, words.data(), words.size() * sizeof(uint32_t),
                       VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT));
  VkBufferViewCreateInfo view{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
  view.buffer = buffer.handle();
  view.format = VK_FORMAT_R32_UINT;
  view.range = VK_WHOLE_SIZE;
  RDM_VK_TRY(vkCreateBufferView(context_.device(), &view, nullptr, &buffer_view));
  return Status();
}

Renderer::~Renderer() {
  const VkDevice device = context_.device();
  vkDeviceWaitIdle(device);
  for (VkBufferView v : {voxel_view_, face_light_view_}) {
    if (v != VK_NULL_HANDLE) vkDestroyBufferView(device, v, nullptr);
  }
  for (VkFramebuffer fb : {shadow_fb_, main_fb_, accumulate_fb_, tonemap_fb_}) {
    if (fb != VK_NULL_HANDLE) vkDestroyFramebuffer(device, fb, nullptr);
  }
  for (VkSampler s : {atlas_sampler_, shadow_sampler_, hdr_sampler_}) {
    if (s != VK_NULL_HANDLE) vkDestroySampler(device, s, nullptr);
  }
  if (frame_fence_ != VK_NULL_HANDLE) vkDestroyFence(device, frame_fence_, nullptr);
  if (frame_cmd_ != VK_NULL_HANDLE)
    vkFreeCommandBuffers(device, context_.commandPool(), 1, &frame_cmd_);
  if (descriptor_pool_ != VK_NULL_HANDLE)
    vkDestroyDescriptorPool(device, descriptor_pool_, nullptr);
  pipelines_.destroy(device);
}

}  // namespace rdm::viewer
