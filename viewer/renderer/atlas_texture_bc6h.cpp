// AtlasTexture's kBc6h images (atlas_texture.h): R, G, B as the BC6H_UFLOAT blocks a bc6h atlas
// stores, Z in an R16F image beside them. A rect written into the blocks is encoded on the CPU
// (encodeBc6h); the blocks it shares with texels outside it are read back and decoded first.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "atlas_texture.h"
#include "atlas_transfers.h"
#include "vk_check.h"

namespace rdm::viewer {
namespace {

constexpr int kBlock = 4;

int roundDown(int v) {
  return v / kBlock * kBlock;
}
int roundUp(int v) {
  return (v + kBlock - 1) / kBlock * kBlock;
}
bool aligned(int v) {
  return v % kBlock == 0;
}

size_t blockOffset(const Bc6hImage& image, int bx, int by) {
  return (size_t(by) * size_t(image.blocksWide()) + size_t(bx)) * kBc6hBlockBytes;
}

// The blocks of the 4 x 4-aligned rect (x, y, w, h) of `image`.
Bc6hImage cropBlocks(const Bc6hImage& image, int x, int y, int w, int h) {
  Bc6hImage out{w, h, std::vector<uint8_t>(size_t(w / kBlock) * (h / kBlock) * kBc6hBlockBytes)};
  for (int j = 0; j < h / kBlock; ++j)
    std::memcpy(&out.blocks[blockOffset(out, 0, j)],
                &image.blocks[blockOffset(image, x / kBlock, y / kBlock + j)],
                size_t(w / kBlock) * kBc6hBlockBytes);
  return out;
}

void pasteBlocks(Bc6hImage& image, int x, int y, const Bc6hImage& part) {
  for (int j = 0; j < part.blocksHigh(); ++j)
    std::memcpy(&image.blocks[blockOffset(image, x / kBlock, y / kBlock + j)],
                &part.blocks[blockOffset(part, 0, j)], size_t(part.blocksWide()) * kBc6hBlockBytes);
}

Expected<Bc6hImage> encodeAllCores(const Image& texels) {
  Bc6hOptions options;
  options.threads = 0;  // the blocks do not depend on the thread count
  return encodeBc6h(texels, options);
}

// Splits a rect into its 4 x 4-aligned interior and the strips around it.
void splitAligned(const TexelRect& r, std::vector<TexelRect>& interior,
                  std::vector<TexelRect>& strips) {
  const int x0 = roundUp(r.x), y0 = roundUp(r.y);
  const int x1 = std::max(x0, roundDown(r.x + r.w)), y1 = std::max(y0, roundDown(r.y + r.h));
  if (x1 <= r.x + r.w && y1 <= r.y + r.h && x0 < x1 && y0 < y1)
    interior.push_back({r.layer, x0, y0, x1 - x0, y1 - y0});
  const int top = std::min(y0, r.y + r.h), bottom = std::max(top, std::min(y1, r.y + r.h));
  const TexelRect parts[4] = {{r.layer, r.x, r.y, r.w, top - r.y},
                              {r.layer, r.x, bottom, r.w, r.y + r.h - bottom},
                              {r.layer, r.x, top, std::min(x0, r.x + r.w) - r.x, bottom - top},
                              {r.layer, x1, top, r.x + r.w - x1, bottom - top}};
  for (const TexelRect& p : parts)
    if (p.w > 0 && p.h > 0) strips.push_back(p);
}

Status uploadStaged(VulkanContext& context, const GpuImage& image, const uint8_t* bytes,
                    size_t size, int layer, int x, int y, int w, int h) {
  auto staging = GpuBuffer::create(context, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  if (!staging) return staging.status();
  std::memcpy(staging->mapped(), bytes, size);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, uint32_t(layer), 1};
  region.imageOffset = {x, y, 0};
  region.imageExtent = {uint32_t(w), uint32_t(h), 1};
  return context.submitAndWait([&](VkCommandBuffer cmd) {
    transitionImage(cmd, image, kReadToDst);
    vkCmdCopyBufferToImage(cmd, staging->handle(), image.handle(),
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    transitionImage(cmd, image, kDstToRead);
  });
}

Expected<std::vector<uint8_t>> readBack(VulkanContext& context, const GpuImage& image, size_t size,
                                        int layer, int x, int y, int w, int h) {
  auto staging = GpuBuffer::create(context, size, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!staging) return staging.status();
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, uint32_t(layer), 1};
  region.imageOffset = {x, y, 0};
  region.imageExtent = {uint32_t(w), uint32_t(h), 1};
  RDM_TRY(context.submitAndWait([&](VkCommandBuffer cmd) {
    transitionImage(cmd, image, kReadToSrc);
    vkCmdCopyImageToBuffer(cmd, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           staging->handle(), 1, &region);
    transitionImage(cmd, image, kSrcToRead);
  }));
  return std::vector<uint8_t>(staging->mapped(), staging->mapped() + size);
}

// Z (channel `channel` of `texels`) at (x, y) of `layer` of the R16F image.
Status uploadDepth(VulkanContext& context, const GpuImage& depth, int layer, int x, int y,
                   const Image& texels, int channel) {
  std::vector<uint16_t> half(size_t(texels.width) * size_t(texels.height));
  for (size_t i = 0; i < half.size(); ++i)
    half[i] = atlasHalf(texels.pixels[i * size_t(texels.channels) + size_t(channel)]);
  if (half.empty()) return Status();
  return uploadStaged(context, depth, reinterpret_cast<const uint8_t*>(half.data()),
                      half.size() * 2, layer, x, y, texels.width, texels.height);
}

}  // namespace

Status AtlasTexture::createBc6hImages(ImageSpec spec) {
  spec.width = uint32_t(roundUp(int(spec.width)));
  spec.height = uint32_t(roundUp(int(spec.height)));
  spec.format = VK_FORMAT_BC6H_UFLOAT_BLOCK;
  spec.alpha_view = false;
  auto image = GpuImage::create(context_, spec);
  if (!image) return image.status();
  spec.format = VK_FORMAT_R16_SFLOAT;
  auto depth = GpuImage::create(context_, spec);
  if (!depth) return depth.status();
  image_ = std::move(*image);
  depth_image_ = std::move(*depth);
  const LayoutTransition start{VK_IMAGE_LAYOUT_UNDEFINED,
                               VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                               VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                               VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                               0,
                               VK_ACCESS_SHADER_READ_BIT};
  RDM_TRY(context_.submitAndWait([&](VkCommandBuffer cmd) {
    transitionImage(cmd, image_, start);
    transitionImage(cmd, depth_image_, start);
  }));
  // Every block starts as zero blocks (all 0 texels), so a later rect's read-back never
  // decodes undefined bytes.
  std::vector<TexelRect> layers;
  for (int l = 0; l < int(spec.layers); ++l) layers.push_back({l, 0, 0, width(), height()});
  return zeroImageRects(context_, image_, 1, layers);
}

Status AtlasTexture::rewriteBlocks(int page, int x, int y, int w, int h, bool whole,
                                   const std::function<void(Image&)>& fill) {
  Image texels(w, h, 3);
  if (!whole) {
    const size_t bytes = size_t(w / kBlock) * size_t(h / kBlock) * kBc6hBlockBytes;
    auto old = readBack(context_, image_, bytes, page, x, y, w, h);
    if (!old) return old.status();
    auto decoded = decodeBc6h(Bc6hImage{w, h, std::move(*old)});
    if (!decoded) return decoded.status();
    texels = std::move(*decoded);
  }
  fill(texels);
  auto blocks = encodeAllCores(texels);
  if (!blocks) return blocks.status();
  return uploadStaged(context_, image_, blocks->blocks.data(), blocks->blocks.size(), page, x, y, w,
                      h);
}

Status AtlasTexture::uploadRectsBc6h(const std::vector<AtlasRectUpdate>& updates) {
  for (const AtlasRectUpdate& u : updates) {
    const int w = u.texels.width, h = u.texels.height;
    if (w == 0 || h == 0) continue;
    RDM_TRY(uploadDepth(context_, depth_image_, u.page, u.x, u.y, u.texels, 3));
    const int x0 = roundDown(u.x), y0 = roundDown(u.y);
    const int x1 = roundUp(u.x + w), y1 = roundUp(u.y + h);
    const bool whole = x0 == u.x && y0 == u.y && x1 == u.x + w && y1 == u.y + h;
    RDM_TRY(rewriteBlocks(u.page, x0, y0, x1 - x0, y1 - y0, whole, [&](Image& texels) {
      for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
          for (int c = 0; c < 3; ++c)
            texels.at(u.x - x0 + i, u.y - y0 + j, c) = u.texels.at(i, j, c);
    }));
  }
  return Status();
}

Status AtlasTexture::zeroRectsBc6h(const std::vector<Rect>& rects) {
  std::vector<TexelRect> clipped, interior, strips;
  for (const Rect& r : rects) {
    const TexelRect c{r.page, r.x, r.y, std::min(r.w, width() - r.x),
                      std::min(r.h, height() - r.y)};
    if (c.w <= 0 || c.h <= 0) continue;
    clipped.push_back(c);
    depth_.clear(c.layer, c.x, c.y, c.w, c.h);
    splitAligned(c, interior, strips);
  }
  RDM_TRY(zeroImageRects(context_, depth_image_, 2, clipped));
  RDM_TRY(zeroImageRects(context_, image_, 1, interior));
  for (const TexelRect& s : strips) {
    const int x0 = roundDown(s.x), y0 = roundDown(s.y);
    RDM_TRY(rewriteBlocks(s.layer, x0, y0, roundUp(s.x + s.w) - x0, roundUp(s.y + s.h) - y0, false,
                          [&](Image& texels) {
                            for (int j = 0; j < s.h; ++j)
                              for (int i = 0; i < s.w; ++i)
                                for (int c = 0; c < 3; ++c)
                                  texels.at(s.x - x0 + i, s.y - y0 + j, c) = 0.0f;
                          }));
  }
  return Status();
}

Expected<Image> AtlasTexture::readLayerBc6h(int layer) {
  const int w = width(), h = height();
  auto blocks = readBack(context_, image_, size_t(w) * size_t(h), layer, 0, 0, w, h);
  if (!blocks) return blocks.status();
  auto depth = readBack(context_, depth_image_, size_t(w) * size_t(h) * 2, layer, 0, 0, w, h);
  if (!depth) return depth.status();
  auto rgb = decodeBc6h(Bc6hImage{w, h, std::move(*blocks)});
  if (!rgb) return rgb.status();
  Image out(w, h, 4);
  const uint16_t* z = reinterpret_cast<const uint16_t*>(depth->data());
  for (size_t p = 0; p < size_t(w) * size_t(h); ++p) {
    for (size_t c = 0; c < 3; ++c) out.pixels[p * 4 + c] = rgb->pixels[p * 3 + c];
    out.pixels[p * 4 + 3] = atlasFloat(z[p]);
  }
  return out;
}

Status AtlasTexture::uploadPageBlocks(int page, const Bc6hImage& blocks, const Image& depth) {
  if (precision_ != AtlasPrecision::kBc6h) return Status::error("atlas texture holds no blocks");
  if (page < 0 || page >= int(sizes_.size()) || !aligned(blocks.width) || !aligned(blocks.height) ||
      blocks.width > width() || blocks.height > height() || depth.width != blocks.width ||
      depth.height != blocks.height || depth.channels != 1 ||
      blocks.blocks.size() != size_t(blocks.width) * size_t(blocks.height)) {
    return Status::error("bc6h page " + std::to_string(page) + " does not fit the atlas texture");
  }
  RDM_TRY(uploadStaged(context_, image_, blocks.blocks.data(), blocks.blocks.size(), page, 0, 0,
                       blocks.width, blocks.height));
  RDM_TRY(uploadDepth(context_, depth_image_, page, 0, 0, depth, 0));
  depth_.write(page, 0, 0, depth);
  return Status();
}

namespace {

// Tiles the file stores scaled by 2^-e (docs/spec.md section 4) are decoded, restored,
// clamped to half's range as the RGBA16F texture clamps them, and encoded again.
Status restoreScaledTiles(const AtlasLayout& layout, int page, Bc6hImage& blocks) {
  for (const AtlasEntry& e : layout.entries) {
    const int size = std::max(e.id.size, kBc6hTileAlign);
    for (const FaceTile& t : e.faces) {
      if (t.page != page || t.exponent == 0) continue;
      auto texels = decodeBc6h(cropBlocks(blocks, t.x, t.y, size, size));
      if (!texels) return texels.status();
      for (float& v : texels->pixels) v = std::min(std::ldexp(v, t.exponent), kAtlasHalfMax);
      auto encoded = encodeAllCores(*texels);
      if (!encoded) return encoded.status();
      pasteBlocks(blocks, t.x, t.y, *encoded);
    }
  }
  return Status();
}

}  // namespace

Status loadBc6hPageAsStored(const std::string& dir, const AtlasLayout& layout, int page,
                            AtlasTexture& texture) {
  auto blocks = readBc6hAtlasBlocks(dir, layout, page);
  if (!blocks) return blocks.status();
  auto depth = readBc6hAtlasDepth(dir, layout, page);
  if (!depth) return depth.status();
  RDM_TRY(restoreScaledTiles(layout, page, *blocks));
  return texture.uploadPageBlocks(page, *blocks, *depth);
}

}  // namespace rdm::viewer
