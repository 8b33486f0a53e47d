#include "atlas_transfers.h"

#include <algorithm>

namespace rdm::viewer {

Status zeroImageRects(VulkanContext& context, const GpuImage& image, size_t texel_bytes,
                      const std::vector<TexelRect>& rects) {
  std::vector<TexelRect> todo;
  for (const TexelRect& r : rects)
    if (r.w > 0 && r.h > 0) todo.push_back(r);
  if (todo.empty()) return Status();
  const int width = int(image.spec().width), height = int(image.spec().height);
  const int align = texel_bytes == 1 ? 4 : 1;
  const size_t row_bytes = size_t(width) * texel_bytes;
  const int fit = int(std::min<size_t>(size_t(height), kStagingBytes / 4 / row_bytes));
  const int band = std::max(align, fit / align * align);
  auto zeros =
      GpuBuffer::create(context, row_bytes * size_t(band), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  if (!zeros) return zeros.status();
  std::fill_n(zeros->mapped(), zeros->size(), uint8_t(0));
  std::vector<VkBufferImageCopy> regions;
  for (const TexelRect& r : todo) {
    for (int y = r.y; y < r.y + r.h; y += band) {
      VkBufferImageCopy region{};
      region.bufferRowLength = uint32_t(width);
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, uint32_t(r.layer), 1};
      region.imageOffset = {r.x, y, 0};
      region.imageExtent = {uint32_t(r.w), uint32_t(std::min(band, r.y + r.h - y)), 1};
      regions.push_back(region);
    }
  }
  return context.submitAndWait([&](VkCommandBuffer cmd) {
    transitionImage(cmd, image, kReadToDst);
    vkCmdCopyBufferToImage(cmd, zeros->handle(), image.handle(),
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, uint32_t(regions.size()),
                           regions.data());
    transitionImage(cmd, image, kDstToRead);
  });
}

Status copyImageRegions(VulkanContext& context, const GpuImage& src, const GpuImage& dst,
                        const std::vector<VkImageCopy>& regions) {
  return context.submitAndWait([&](VkCommandBuffer cmd) {
    transitionImage(cmd, src, kReadToSrc);
    transitionImage(cmd, dst, kReadToDst);
    vkCmdCopyImage(cmd, src.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst.handle(),
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, uint32_t(regions.size()), regions.data());
    transitionImage(cmd, dst, kDstToRead);
    transitionImage(cmd, src, kSrcToRead);
  });
}

}  // namespace rdm::viewer
