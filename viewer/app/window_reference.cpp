// The window's "path-trace this view" (docs/viewer.md, "Reference of the view"): the reference
// render on a worker (reference_view.h), its LDR-FLIP against the real-time frame, and the
// right half of the window replaced by the reference or the FLIP map while the view is the one
// it was rendered for.
#include <cstdio>

#include <imgui.h>

#include "vk_check.h"
#include "window_app.h"

namespace rdm::viewer {
namespace {

std::string percentText(double fraction) {
  char text[64];
  std::snprintf(text, sizeof text, "path tracing this view: %.0f %%", 100.0 * fraction);
  return text;
}

}  // namespace

void WindowApp::startReference() {
  const VkExtent2D e = swapchain_->extent();
  reference_.start(editor_->scene(), camera_.camera(), int(e.width), int(e.height),
                   panel_.reference_spp);
  reference_image_.reset();
  reference_uploaded_ = -1;
  panel_.reference_text = percentText(0.0);
  redraw_ = true;
}

// The LDR-FLIP of the reference against the frame on screen, when that frame shows the same
// view at the same size; else why not.
std::string WindowApp::compareReference() {
  const ReferenceImage& ref = *reference_image_;
  if (!(camera_.camera() == ref.camera) || renderer_->width() != ref.ldr.width ||
      renderer_->height() != ref.ldr.height)
    return "no LDR-FLIP: the view or the resolution changed while it rendered";
  if (vkWaitForFences(context_->device(), 1, &fence_, VK_TRUE, UINT64_MAX) != VK_SUCCESS)
    return "no LDR-FLIP: the last frame did not finish";
  auto shown = renderer_->readLdr();
  if (!shown) return "no LDR-FLIP: " + shown.error();
  auto comparison = compareWithReference(ref.ldr, *shown);
  if (!comparison) return "no LDR-FLIP: " + comparison.error();
  reference_flip_map_ = std::move(comparison->flip_map);
  char text[96];
  std::snprintf(text, sizeof text, "LDR-FLIP %.4f against the real-time image",
                comparison->ldr_flip);
  return text;
}

Status WindowApp::pollReference() {
  if (reference_.busy()) {
    panel_.reference_text = percentText(reference_.fraction());
    return Status();
  }
  auto done = reference_.take();
  if (!done) return prepareReferenceUpload();
  redraw_ = true;
  if (!done->ok()) {
    panel_.reference_text = "reference: " + done->error();
  } else {
    reference_image_ = std::move(**done);
    reference_flip_map_ = Image8();
    reference_uploaded_ = -1;
    char head[64];
    std::snprintf(head, sizeof head, "reference: %d spp in %.1f s, ", reference_image_->spp,
                  reference_image_->seconds);
    panel_.reference_text = head + compareReference();
  }
  std::printf("%s\n", panel_.reference_text.c_str());
  std::fflush(stdout);
  return prepareReferenceUpload();
}

bool WindowApp::referenceShown() const {
  if (!reference_image_ || panel_.reference_display == 0) return false;
  if (panel_.reference_display == 2 && reference_flip_map_.pixels.empty()) return false;
  const VkExtent2D e = swapchain_->extent();
  return camera_.camera() == reference_image_->camera &&
         int(e.width) == reference_image_->ldr.width &&
         int(e.height) == reference_image_->ldr.height;
}

// Fills the upload buffer with the right half of the reference (or its FLIP map) in the
// swapchain's byte order, when what is shown changed.
Status WindowApp::prepareReferenceUpload() {
  if (!referenceShown() || reference_uploaded_ == panel_.reference_display) return Status();
  const Image8& source =
      panel_.reference_display == 2 ? reference_flip_map_ : reference_image_->ldr;
  const int x0 = source.width / 2, w = source.width - x0, h = source.height;
  RDM_VK_TRY(vkWaitForFences(context_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
  if (!reference_upload_.handle() || reference_upload_.size() < VkDeviceSize(w) * h * 4) {
    auto buffer =
        GpuBuffer::create(*context_, VkDeviceSize(w) * h * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    if (!buffer) return buffer.status();
    reference_upload_ = std::move(*buffer);
  }
  const bool bgra = swapchain_->format() == VK_FORMAT_B8G8R8A8_UNORM;
  uint8_t* out = reference_upload_.mapped();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint8_t* p = &source.pixels[(size_t(y) * source.width + x0 + x) * source.channels];
      uint8_t* q = out + (size_t(y) * w + x) * 4;
      q[0] = bgra ? p[2] : p[0], q[1] = p[1], q[2] = bgra ? p[0] : p[2], q[3] = 255;
    }
  reference_uploaded_ = panel_.reference_display;
  return Status();
}

void WindowApp::recordReferenceCopy(VkCommandBuffer cmd, VkImage target) const {
  if (!referenceShown() || reference_uploaded_ != panel_.reference_display) return;
  VkMemoryBarrier after_blit{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  after_blit.srcAccessMask = after_blit.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1,
                       &after_blit, 0, nullptr, 0, nullptr);
  const int width = reference_image_->ldr.width, x0 = width / 2;
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageOffset = {x0, 0, 0};
  region.imageExtent = {uint32_t(width - x0), uint32_t(reference_image_->ldr.height), 1};
  vkCmdCopyBufferToImage(cmd, reference_upload_.handle(), target,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
}

void WindowApp::drawReferenceDivider() const {
  if (!referenceShown()) return;
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  ImDrawList* list = ImGui::GetBackgroundDrawList();
  const float x = size.x * 0.5f;
  list->AddLine(ImVec2(x, 0.0f), ImVec2(x, size.y), 0xffffffff, 2.0f);
  list->AddText(ImVec2(x - 90.0f, 8.0f), 0xffffffff, "real-time");
  list->AddText(ImVec2(x + 10.0f, 8.0f), 0xffffffff,
                panel_.reference_display == 2 ? "LDR-FLIP map" : "path-traced reference");
}

}  // namespace rdm::viewer
