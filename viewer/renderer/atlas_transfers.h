// Transfers into and out of the atlas texture's images (atlas_texture.cpp and its kBc6h half,
// atlas_texture_bc6h.cpp): the layout transitions around a copy, and zeroing rects.
#pragma once

#include <cstddef>
#include <vector>

#include "gpu_resources.h"
#include "rdm/base/status.h"

namespace rdm::viewer {

// Staging for one upload: at most this many bytes per submission, so an upload never holds
// more than one strip of a page on the host besides the device image.
constexpr size_t kStagingBytes = size_t(4) << 20;

inline constexpr LayoutTransition kReadToDst{VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                             VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                                             VK_PIPELINE_STAGE_TRANSFER_BIT,
                                             VK_ACCESS_SHADER_READ_BIT,
                                             VK_ACCESS_TRANSFER_WRITE_BIT};
inline constexpr LayoutTransition kDstToRead{
    VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
    VK_PIPELINE_STAGE_TRANSFER_BIT,       VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
    VK_ACCESS_TRANSFER_WRITE_BIT,         VK_ACCESS_SHADER_READ_BIT};
inline constexpr LayoutTransition kReadToSrc{VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                             VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                             VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                                             VK_PIPELINE_STAGE_TRANSFER_BIT,
                                             VK_ACCESS_SHADER_READ_BIT,
                                             VK_ACCESS_TRANSFER_READ_BIT};
inline constexpr LayoutTransition kSrcToRead{
    VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
    VK_PIPELINE_STAGE_TRANSFER_BIT,       VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
    VK_ACCESS_TRANSFER_READ_BIT,          VK_ACCESS_SHADER_READ_BIT};

// A rect of one layer, in texels. Rects of a block-compressed image are multiples of the
// block or reach the image's edge.
struct TexelRect {
  int layer, x, y, w, h;
};

// Copies from one zeroed buffer of a few rows into every rect of `image` (empty ones
// skipped), band by band, so that only the rects' texels are touched (vkCmdClearColorImage
// would write the whole image, headroom included). `texel_bytes`: bytes per texel, 1 for
// BC6H (16 bytes per 4 x 4 block), whose bands are then whole block rows.
Status zeroImageRects(VulkanContext& context, const GpuImage& image, size_t texel_bytes,
                      const std::vector<TexelRect>& rects);

// Copies `regions` from `src` to `dst` on the device (both in the shader-read layout before
// and after).
Status copyImageRegions(VulkanContext& context, const GpuImage& src, const GpuImage& dst,
                        const std::vector<VkImageCopy>& regions);

}  // namespace rdm::viewer
