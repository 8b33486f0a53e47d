// Frame recording, submission and readback of the Renderer.
#include <chrono>
#include <cmath>
#include <cstring>
#include <numbers>

#include "camera.h"
#include "rdm/base/check.h"
#include "renderer.h"
#include "vk_check.h"

namespace rdm::viewer {
namespace {

void setViewport(VkCommandBuffer cmd, uint32_t w, uint32_t h) {
  const VkViewport viewport{0.0f, 0.0f, float(w), float(h), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, {w, h}};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
}

}  // namespace

FrameUniforms Renderer::frameUniforms(const Camera& camera, uint32_t terms,
                                      glm::vec2 jitter) const {
  FrameUniforms u{};
  const CameraBasis basis = cameraBasis(camera).value();  // validated by the caller
  const float aspect = float(width_) / float(height_);    // of the full image, at any divisor
  // Pixel p then shows what the unjittered projection puts at p + jitter (Vulkan's
  // framebuffer x and y grow with NDC x and y).
  glm::mat4 shift(1.0f);
  shift[3] = glm::vec4(-2.0f * jitter.x / float(shadedWidth()),
                       -2.0f * jitter.y / float(shadedHeight()), 0.0f, 1.0f);
  u.view_proj = shift * viewProjection(basis, aspect);
  u.camera_position = glm::vec4(basis.position, basis.tan_half_fov);
  u.camera_forward = glm::vec4(basis.forward, aspect);
  u.camera_right = glm::vec4(basis.right, 0.0f);
  u.camera_up = glm::vec4(basis.up, 0.0f);
  float texel_world = 0.0f;
  const SunLight& sun = world_.sun;
  if (sun.present) {
    u.light_view_proj =
        sunViewProjection(sun.direction, world_.size, options_.shadow_map_size, &texel_world);
    const double theta = scene_.sun->angular_radius_deg * std::numbers::pi / 180.0;
    u.sun_direction = glm::vec4(sun.direction, 1.0f);
    u.sun_irradiance = glm::vec4(sun.irradiance, float(std::sin(theta)));
    u.sun_radiance = glm::vec4(sun.radiance, sun.disc_c2);
  } else {
    u.light_view_proj = glm::mat4(1.0f);
    u.sun_direction = glm::vec4(0.0f, 1.0f, 0.0f, 0.0f);
  }
  u.sky_zenith = glm::vec4(world_.sky.zenith, 0.0f);
  u.sky_horizon = glm::vec4(world_.sky.horizon, 0.0f);
  u.sky_ground = glm::vec4(world_.sky.ground, 0.0f);
  u.ambient = glm::vec4(world_.ambient, float(scene_.emission_scale));
  u.grid_size = glm::ivec4(world_.size, int32_t(terms));
  u.viewport =
      glm::vec4(float(shadedWidth()), float(shadedHeight()), texel_world, float(atlas_->layers()));
  u.atlas_size = glm::vec4(float(atlas_->width()), float(atlas_->height()),
                           1.0f / float(atlas_->width()), 1.0f / float(atlas_->height()));
  u.jitter = glm::vec4(jitter, 0.0f, 0.0f);
  return u;
}

Status Renderer::recordFrame(VkCommandBuffer cmd, const Camera& camera, uint32_t terms) {
  if (auto basis = cameraBasis(camera); !basis) return basis.status();
  const AccumulationStep step = accumulator_.next(camera, terms, divisor_);
  if (step.shade) {
    const FrameUniforms u = frameUniforms(camera, terms, step.jitter);
    uniforms_.write(&u, sizeof(u));
    recordShading(cmd, terms, step);
  }
  // Tone-map pass of the mean, over the whole image.
  VkRenderPassBeginInfo pass{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  pass.renderPass = pipelines_.tonemap_pass;
  pass.framebuffer = tonemap_fb_;
  pass.renderArea = {{0, 0}, {uint32_t(width_), uint32_t(height_)}};
  vkCmdBeginRenderPass(cmd, &pass, VK_SUBPASS_CONTENTS_INLINE);
  setViewport(cmd, uint32_t(width_), uint32_t(height_));
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelines_.tonemap);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelines_.image_layout, 0, 1,
                          &tonemap_set_, 0, nullptr);
  vkCmdDraw(cmd, 3, 1, 0, 0);
  vkCmdEndRenderPass(cmd);
  return Status();
}

// The shadow (when stale), main and accumulate passes of a shaded frame.
void Renderer::recordShading(VkCommandBuffer cmd, uint32_t terms, const AccumulationStep& step) {
  const VkDeviceSize zero = 0;
  auto draw_blocks = [&](VkPipeline pipeline) {
    if (scene_data_.draws.empty()) return;
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    const VkBuffer vb = vertices_.handle(), ib = instances_.handle();
    vkCmdBindVertexBuffers(cmd, 0, 1, &vb, &zero);
    vkCmdBindVertexBuffers(cmd, 1, 1, &ib, &zero);
    vkCmdBindIndexBuffer(cmd, indices_.handle(), 0, VK_INDEX_TYPE_UINT32);
    for (const BlockDraw& d : scene_data_.draws) {
      vkCmdDrawIndexed(cmd, d.index_count, d.instance_count, d.first_index, d.vertex_offset,
                       d.first_instance);
    }
  };
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelines_.scene_layout, 0, 1,
                          &scene_set_, 0, nullptr);
  // Shadow pass: the map depends only on the geometry, the sun and the shadow terms, so it
  // is drawn on the first frame and again only when one of them changed (it then stays in
  // its sampled layout); it draws blocks only with a sun.
  const uint32_t shadow_size = uint32_t(options_.shadow_map_size);
  const uint32_t shadow_terms = terms & (kTermSun | kTermShadows);
  VkClearValue depth_clear{};
  depth_clear.depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo pass{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  if (!shadow_valid_ || shadow_terms != shadow_terms_) {
    pass.renderPass = pipelines_.shadow_pass;
    pass.framebuffer = shadow_fb_;
    pass.renderArea = {{0, 0}, {shadow_size, shadow_size}};
    pass.clearValueCount = 1;
    pass.pClearValues = &depth_clear;
    vkCmdBeginRenderPass(cmd, &pass, VK_SUBPASS_CONTENTS_INLINE);
    setViewport(cmd, shadow_size, shadow_size);
    if (world_.sun.present && (terms & kTermSun) && (terms & kTermShadows))
      draw_blocks(pipelines_.shadow);
    vkCmdEndRenderPass(cmd);
    shadow_valid_ = true, shadow_terms_ = shadow_terms;
  }
  // Main pass: background, then blocks.
  const std::array<VkClearValue, 2> clears = {VkClearValue{}, depth_clear};
  pass.renderPass = pipelines_.main_pass;
  pass.framebuffer = main_fb_;
  const uint32_t shaded_w = uint32_t(shadedWidth()), shaded_h = uint32_t(shadedHeight());
  pass.renderArea = {{0, 0}, {shaded_w, shaded_h}};
  pass.clearValueCount = 2;
  pass.pClearValues = clears.data();
  vkCmdBeginRenderPass(cmd, &pass, VK_SUBPASS_CONTENTS_INLINE);
  setViewport(cmd, shaded_w, shaded_h);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelines_.sky);
  vkCmdDraw(cmd, 3, 1, 0, 0);
  draw_blocks(pipelines_.block_depth);
  draw_blocks(pipelines_.blocks);
  vkCmdEndRenderPass(cmd);
  // Accumulate pass: the frame, scaled up by the divisor, into the mean with its weight.
  pass.renderPass = pipelines_.accumulate_pass;
  pass.framebuffer = accumulate_fb_;
  pass.renderArea = {{0, 0}, {uint32_t(width_), uint32_t(height_)}};
  pass.clearValueCount = 0;
  pass.pClearValues = nullptr;
  vkCmdBeginRenderPass(cmd, &pass, VK_SUBPASS_CONTENTS_INLINE);
  setViewport(cmd, uint32_t(width_), uint32_t(height_));
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelines_.accumulate);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelines_.image_layout, 0, 1,
                          &accumulate_set_, 0, nullptr);
  const int32_t divisor = divisor_;
  vkCmdPushConstants(cmd, pipelines_.image_layout, VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(divisor),
                     &divisor);
  const float blend[4] = {0.0f, 0.0f, 0.0f, step.weight};
  vkCmdSetBlendConstants(cmd, blend);
  vkCmdDraw(cmd, 3, 1, 0, 0);
  vkCmdEndRenderPass(cmd);
}

void Renderer::setResolutionDivisor(int divisor) {
  RDM_CHECK(divisor >= 1 && divisor <= 4);
  divisor_ = divisor;
}

Expected<double> Renderer::renderFrame(const Camera& camera, uint32_t terms) {
  RDM_VK_TRY(vkResetCommandBuffer(frame_cmd_, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  RDM_VK_TRY(vkBeginCommandBuffer(frame_cmd_, &begin));
  RDM_TRY(recordFrame(frame_cmd_, camera, terms));
  RDM_VK_TRY(vkEndCommandBuffer(frame_cmd_));
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &frame_cmd_;
  RDM_VK_TRY(vkResetFences(context_.device(), 1, &frame_fence_));
  const auto start = std::chrono::steady_clock::now();
  RDM_VK_TRY(vkQueueSubmit(context_.queue(), 1, &submit, frame_fence_));
  RDM_VK_TRY(vkWaitForFences(context_.device(), 1, &frame_fence_, VK_TRUE, UINT64_MAX));
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Expected<std::vector<uint8_t>> Renderer::readImage(const GpuImage& image, VkImageLayout layout,
                                                   size_t bytes) {
  auto staging = GpuBuffer::create(context_, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!staging) return staging.status();
  RDM_TRY(context_.submitAndWait([&](VkCommandBuffer cmd) {
    const bool move = layout != VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    if (move) {
      transitionImage(cmd, image,
                      {layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                       VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_ACCESS_MEMORY_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT});
    }
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {image.spec().width, image.spec().height, 1};
    vkCmdCopyImageToBuffer(cmd, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           staging->handle(), 1, &region);
    if (move) {
      transitionImage(cmd, image,
                      {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout, VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_TRANSFER_READ_BIT,
                       VK_ACCESS_MEMORY_READ_BIT});
    }
  }));
  return std::vector<uint8_t>(staging->mapped(), staging->mapped() + bytes);
}

Expected<Image> Renderer::readHdr() {
  auto bytes =
      readImage(mean_, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, size_t(width_) * height_ * 16);
  if (!bytes) return bytes.status();
  Image image(width_, height_, 3);
  const float* src = reinterpret_cast<const float*>(bytes->data());
  for (size_t p = 0; p < size_t(width_) * height_; ++p) {
    for (int c = 0; c < 3; ++c) image.pixels[p * 3 + c] = src[p * 4 + c];
  }
  return image;
}

Expected<Image8> Renderer::readLdr() {
  auto bytes = readImage(ldr_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, size_t(width_) * height_ * 4);
  if (!bytes) return bytes.status();
  Image8 image{width_, height_, 3, std::vector<uint8_t>(size_t(width_) * height_ * 3)};
  for (size_t p = 0; p < size_t(width_) * height_; ++p) {
    for (int c = 0; c < 3; ++c) image.pixels[p * 3 + c] = (*bytes)[p * 4 + c];
  }
  return image;
}

}  // namespace rdm::viewer
