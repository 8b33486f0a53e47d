#include "atlas_texture.h"

#include <algorithm>

#include "vk_check.h"

namespace rdm::viewer {

Expected<std::unique_ptr<AtlasTexture>> AtlasTexture::create(VulkanContext& context,
                                                             std::vector<Image> pages) {
  std::unique_ptr<AtlasTexture> atlas(new AtlasTexture(context));
  if (pages.empty()) pages.push_back(Image(1, 1, 4));
  ImageSpec spec;
  spec.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  spec.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
               VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  spec.view_type = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
  spec.layers = uint32_t(pages.size());
  spec.width = spec.height = 1;
  for (const Image& p : pages) {
    if (p.channels != 4) return Status::error("atlas pages need 4 channels (R, G, B, Z)");
    spec.width = std::max(spec.width, uint32_t(p.width));
    spec.height = std::max(spec.height, uint32_t(p.height));
  }
  const auto& limits = context.properties().limits;
  if (spec.width > limits.maxImageDimension2D || spec.height > limits.maxImageDimension2D ||
      spec.layers > limits.maxImageArrayLayers) {
    return Status::error("atlas page larger than the device's image limits");
  }
  const uint32_t room = uint32_t(double(spec.height) * (1.0 + kHeadroom) + 63.0) / 64u * 64u;
  spec.height = std::min(std::max(spec.height, room), limits.maxImageDimension2D);
  auto image = GpuImage::create(context, spec);
  if (!image) return image.status();
  atlas->image_ = std::move(*image);
  std::vector<AtlasRectUpdate> whole;
  for (size_t p = 0; p < pages.size(); ++p) whole.push_back({int(p), 0, 0, pages[p]});
  atlas->pages_ = std::move(pages);
  RDM_TRY(atlas->uploadRects(whole, true));
  return atlas;
}

bool AtlasTexture::growInPlace(const std::vector<AtlasPage>& sizes) {
  if (sizes.size() != pages_.size()) return false;
  for (size_t p = 0; p < sizes.size(); ++p) {
    if (sizes[p].width < pages_[p].width || sizes[p].height < pages_[p].height ||
        uint32_t(sizes[p].width) > image_.spec().width ||
        uint32_t(sizes[p].height) > image_.spec().height)
      return false;
  }
  for (size_t p = 0; p < sizes.size(); ++p) {
    const Image& old = pages_[p];
    if (old.width == sizes[p].width && old.height == sizes[p].height) continue;
    Image page(sizes[p].width, sizes[p].height, 4);
    for (int y = 0; y < old.height; ++y)
      std::copy_n(&old.pixels[size_t(y) * old.width * 4], size_t(old.width) * 4,
                  &page.pixels[size_t(y) * page.width * 4]);
    pages_[p] = std::move(page);
  }
  return true;
}

Status AtlasTexture::applyDelta(const std::vector<AtlasRectUpdate>& updates) {
  for (const auto& u : updates) {
    if (u.page < 0 || u.page >= int(pages_.size()) || u.texels.channels != 4 || u.x < 0 ||
        u.y < 0 || u.x + u.texels.width > pages_[u.page].width ||
        u.y + u.texels.height > pages_[u.page].height) {
      return Status::error("atlas delta rect outside its page (page " + std::to_string(u.page) +
                           ")");
    }
  }
  RDM_TRY(uploadRects(updates, false));
  for (const auto& u : updates) {
    Image& page = pages_[u.page];
    for (int r = 0; r < u.texels.height; ++r) {
      std::copy_n(&u.texels.pixels[size_t(r) * u.texels.width * 4], size_t(u.texels.width) * 4,
                  &page.pixels[(size_t(u.y + r) * page.width + u.x) * 4]);
    }
  }
  return Status();
}

Status AtlasTexture::uploadRects(const std::vector<AtlasRectUpdate>& updates, bool first_upload) {
  size_t bytes = 0;
  for (const auto& u : updates) bytes += u.texels.pixels.size() * sizeof(float);
  auto staging = GpuBuffer::create(context_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  if (!staging) return staging.status();
  std::vector<VkBufferImageCopy> regions;
  size_t offset = 0;
  for (const auto& u : updates) {
    const size_t n = u.texels.pixels.size() * sizeof(float);
    staging->write(u.texels.pixels.data(), n, offset);
    VkBufferImageCopy region{};
    region.bufferOffset = offset;
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, uint32_t(u.page), 1};
    region.imageOffset = {u.x, u.y, 0};
    region.imageExtent = {uint32_t(u.texels.width), uint32_t(u.texels.height), 1};
    regions.push_back(region);
    offset += n;
  }
  const GpuImage& img = image_;
  return context_.submitAndWait([&](VkCommandBuffer cmd) {
    if (first_upload) {  // zero the padding of smaller pages, then copy the pages in
      transitionImage(cmd, img,
                      {VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                       VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                       VK_ACCESS_TRANSFER_WRITE_BIT});
      VkClearColorValue zero{};
      VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, img.spec().layers};
      vkCmdClearColorImage(cmd, img.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1,
                           &range);
      transitionImage(cmd, img,
                      {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                       VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_TRANSFER_WRITE_BIT});
    } else {
      transitionImage(
          cmd, img,
          {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
           VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
           VK_ACCESS_SHADER_READ_BIT, VK_ACCESS_TRANSFER_WRITE_BIT});
    }
    if (!regions.empty()) {
      vkCmdCopyBufferToImage(cmd, staging->handle(), img.handle(),
                             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, uint32_t(regions.size()),
                             regions.data());
    }
    transitionImage(cmd, img,
                    {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                     VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                     VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT});
  });
}

Expected<Image> AtlasTexture::readLayer(int layer) {
  if (layer < 0 || layer >= layers()) return Status::error("atlas layer out of range");
  const int w = width(), h = height();
  auto staging = GpuBuffer::create(context_, size_t(w) * h * 16, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!staging) return staging.status();
  const GpuImage& img = image_;
  RDM_TRY(context_.submitAndWait([&](VkCommandBuffer cmd) {
    transitionImage(cmd, img,
                    {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                     VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_SHADER_READ_BIT, VK_ACCESS_TRANSFER_READ_BIT});
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, uint32_t(layer), 1};
    region.imageExtent = {uint32_t(w), uint32_t(h), 1};
    vkCmdCopyImageToBuffer(cmd, img.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           staging->handle(), 1, &region);
    transitionImage(cmd, img,
                    {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                     VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                     VK_ACCESS_TRANSFER_READ_BIT, VK_ACCESS_SHADER_READ_BIT});
  }));
  Image out(w, h, 4);
  std::copy_n(reinterpret_cast<const float*>(staging->mapped()), out.pixels.size(),
              out.pixels.data());
  return out;
}

}  // namespace rdm::viewer
