// The viewer's real-time RDM renderer (docs/spec.md section 6, thesis 4.3), usable headless: it
// renders into its own HDR (RGBA32F) frame, averages frames into an HDR mean while the view
// is still (frame_accumulator.h), and tone-maps the mean into an LDR (RGBA8) image, which a
// window copies to its swapchain and offscreen runs read back.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "atlas_texture.h"
#include "frame_accumulator.h"
#include "gpu_layout.h"
#include "gpu_resources.h"
#include "pipelines.h"
#include "rdm/atlas/atlas.h"
#include "rdm/bake/face_light.h"
#include "rdm/image/flip.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "scene_gpu.h"
#include "shading_tables.h"
#include "vk_context.h"

namespace rdm::viewer {

// With AtlasPrecision::kHalf, where a bc6h atlas read by loadAtlas goes: kStored, a kBc6h
// texture holding its blocks as they are (when the device samples BC6H); kDecoded, the half
// texture; kAuto, kStored on a GPU and kDecoded on a CPU device (lavapipe decodes BC6H at
// every fetch: 2.5-3x the frame time, docs/bc6h.md).
enum class Bc6hTexture { kAuto, kStored, kDecoded };

struct RendererOptions {
  int width = 1280, height = 720;
  int shadow_map_size = 2048;
  AtlasPrecision atlas_precision = AtlasPrecision::kHalf;  // kFloat: the reference
  Bc6hTexture bc6h_texture = Bc6hTexture::kAuto;
};

class Renderer {
 public:
  static Expected<std::unique_ptr<Renderer>> create(VulkanContext& context,
                                                    const RendererOptions& options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Builds the world and uploads meshes, voxels and the slot table; re-bakes the face light
  // of the slots an edit changed (updateFaceLight, on the CPU, before returning). Keeps the atlas;
  // RDMs of slots that became empty are ignored, slots without RDMs fall back to ambient.
  Status setScene(const Scene& scene);
  // Replaces the atlas and rebuilds the slot table. The pages are converted to half and
  // released one by one.
  Status setAtlas(LoadedAtlas atlas);
  // setAtlas from the atlas files in `dir` (`layout`: its index.json, readAtlasLayout),
  // read strip by strip: the host holds the device image (half) and one strip of floats.
  Status loadAtlas(const std::string& dir, AtlasLayout layout);
  // Per-voxel-face diffuse light (docs/spec.md section 3.2). Slots whose exposed faces do not
  // match the world (a face light of another scene version) fall back to the RDMs.
  Status setFaceLight(FaceLight light);
  // Writes re-baked rects into the atlas texture and switches to `layout` (which must keep
  // the pages' sizes); only the given rects change.
  Status applyAtlasDelta(const AtlasLayout& layout, const std::vector<AtlasRectUpdate>& updates);
  Status resize(int width, int height);
  // Frames shade width / divisor x height / divisor pixels (rounded up) and the tone-map pass
  // scales them up to the full image, nearest: the viewer's interactive resolution while a
  // rebake shares the CPU with a CPU rasteriser (docs/viewer.md). 1 to 4; 1 by default.
  void setResolutionDivisor(int divisor);
  int resolutionDivisor() const { return divisor_; }
  // Anti-aliasing: up to `frames` jittered frames of an unchanged view are averaged, after
  // which frames only re-present the mean. 1 (the default): every frame is shaded afresh at
  // pixel centres.
  void setAccumulationLimit(int frames) { accumulator_.setLimit(frames); }
  const FrameAccumulator& accumulation() const { return accumulator_; }

  // Records the frame (shadow, main, tone-map passes) into `cmd` and writes the frame's
  // uniforms, so no earlier frame may still be executing. Afterwards the LDR image is in
  // TRANSFER_SRC_OPTIMAL layout.
  Status recordFrame(VkCommandBuffer cmd, const Camera& camera, uint32_t terms);
  // One offscreen frame: records, submits and waits; returns the seconds from submission
  // to completion (on lavapipe, the frame's whole rendering time).
  Expected<double> renderFrame(const Camera& camera, uint32_t terms);
  Expected<Image> readHdr();   // RGB linear radiance shown by the last frame (the mean)
  Expected<Image8> readLdr();  // RGB 8-bit, Reinhard + sRGB, of the last frame

  const GpuImage& ldrImage() const { return ldr_; }
  int width() const { return width_; }
  int height() const { return height_; }
  const Scene& scene() const { return scene_; }
  const VoxelWorld& world() const { return world_; }
  const AtlasLayout& layout() const { return layout_; }
  AtlasTexture& atlas() { return *atlas_; }
  const SceneGpuData& sceneData() const { return scene_data_; }
  const ShadingTables& tables() const { return tables_; }

 private:
  Renderer(VulkanContext& context, const RendererOptions& options);
  Status init();
  Status uploadTexelWords(const std::vector<uint32_t>& words, const char* what, GpuBuffer& buffer,
                          VkBufferView& view);
  Status uploadFaceLight();
  int shadedWidth() const { return (width_ + divisor_ - 1) / divisor_; }
  int shadedHeight() const { return (height_ + divisor_ - 1) / divisor_; }
  Status createTargets();
  Status clearMean();
  Status createStaticResources();
  Status uploadSlots();
  Status dropAtlas(const Status& why);
  void writeDescriptors();
  FrameUniforms frameUniforms(const Camera& camera, uint32_t terms, glm::vec2 jitter) const;
  void recordShading(VkCommandBuffer cmd, uint32_t terms, const AccumulationStep& step);
  Expected<std::vector<uint8_t>> readImage(const GpuImage& image, VkImageLayout layout,
                                           size_t bytes);

  VulkanContext& context_;
  RendererOptions options_;
  int width_ = 0, height_ = 0;
  PipelineSet pipelines_;
  VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
  // accumulate_set_ samples the frame (hdr_), tonemap_set_ the mean (mean_).
  VkDescriptorSet scene_set_ = VK_NULL_HANDLE, accumulate_set_ = VK_NULL_HANDLE,
                  tonemap_set_ = VK_NULL_HANDLE;
  VkSampler atlas_sampler_ = VK_NULL_HANDLE, shadow_sampler_ = VK_NULL_HANDLE,
            hdr_sampler_ = VK_NULL_HANDLE;
  VkCommandBuffer frame_cmd_ = VK_NULL_HANDLE;
  VkBufferView voxel_view_ = VK_NULL_HANDLE, face_light_view_ = VK_NULL_HANDLE;
  int divisor_ = 1;
  VkFence frame_fence_ = VK_NULL_HANDLE;
  VkFramebuffer shadow_fb_ = VK_NULL_HANDLE, main_fb_ = VK_NULL_HANDLE,
                accumulate_fb_ = VK_NULL_HANDLE, tonemap_fb_ = VK_NULL_HANDLE;
  GpuImage shadow_map_, hdr_, depth_, mean_, ldr_;
  FrameAccumulator accumulator_;
  GpuBuffer uniforms_, tables_buffer_, vertices_, indices_, instances_, voxels_, slots_,
      face_light_words_;
  ShadingTables tables_;
  Scene scene_;
  VoxelWorld world_;
  SceneGpuData scene_data_;
  AtlasLayout layout_;
  std::unique_ptr<AtlasTexture> atlas_;
  FaceLight face_light_;
  bool shadow_valid_ = false;  // the shadow map holds the current geometry and sun
  uint32_t shadow_terms_ = 0;  // kTermSun | kTermShadows bits it was drawn with
};

}  // namespace rdm::viewer
