#include "atlas_texture.h"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>

#include <algorithm>
#include <cmath>
#include <exception>

#include "atlas_transfers.h"
#include "rdm/base/file_util.h"
#include "vk_check.h"

namespace rdm::viewer {
namespace {

bool rectInPage(const AtlasPage& page, int x, int y, int w, int h) {
  return x >= 0 && y >= 0 && w >= 0 && h >= 0 && x + w <= page.width && y + h <= page.height;
}

}  // namespace

uint16_t atlasHalf(float value) {
  return Imath::half(std::clamp(value, -kAtlasHalfMax, kAtlasHalfMax)).bits();
}

const char* atlasPrecisionName(AtlasPrecision precision) {
  switch (precision) {
    case AtlasPrecision::kFloat:
      return "float";
    case AtlasPrecision::kBc6h:
      return "bc6h";
    case AtlasPrecision::kHalf:
      break;
  }
  return "half";
}

float atlasFloat(uint16_t bits) {
  Imath::half h;
  h.setBits(bits);
  return float(h);
}

Expected<std::unique_ptr<AtlasTexture>> AtlasTexture::create(VulkanContext& context,
                                                             std::vector<AtlasPage> sizes,
                                                             AtlasPrecision precision) {
  std::unique_ptr<AtlasTexture> atlas(new AtlasTexture(context, precision));
  if (sizes.empty()) sizes.push_back({1, 1});
  ImageSpec spec;
  spec.format = precision == AtlasPrecision::kHalf ? VK_FORMAT_R16G16B16A16_SFLOAT
                                                   : VK_FORMAT_R32G32B32A32_SFLOAT;
  spec.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
               VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  spec.view_type = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
  spec.alpha_view = true;
  spec.layers = uint32_t(sizes.size());
  spec.width = spec.height = 1;
  for (const AtlasPage& p : sizes) {
    if (p.width < 1 || p.height < 1) return Status::error("atlas page of no texels");
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
  if (precision == AtlasPrecision::kBc6h) {
    RDM_TRY(atlas->createBc6hImages(spec));
  } else {
    auto image = GpuImage::create(context, spec);
    if (!image) return image.status();
    atlas->image_ = std::move(*image);
    // The image starts in the layout every later upload expects (its texels undefined).
    const GpuImage& img = atlas->image_;
    RDM_TRY(context.submitAndWait([&](VkCommandBuffer cmd) {
      transitionImage(cmd, img,
                      {VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                       VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0,
                       VK_ACCESS_SHADER_READ_BIT});
    }));
  }
  atlas->depth_.reset(int(atlas->layers()), atlas->width(), atlas->height());
  std::vector<Rect> pages;
  for (size_t p = 0; p < sizes.size(); ++p)
    pages.push_back({int(p), 0, 0, sizes[p].width + 1, sizes[p].height + 1});
  atlas->sizes_ = std::move(sizes);
  RDM_TRY(atlas->zeroRects(pages));
  return atlas;
}

Expected<std::unique_ptr<AtlasTexture>> AtlasTexture::create(VulkanContext& context,
                                                             std::vector<Image> pages,
                                                             AtlasPrecision precision) {
  std::vector<AtlasPage> sizes;
  for (const Image& p : pages) {
    if (p.channels != 4) return Status::error("atlas pages need 4 channels (R, G, B, Z)");
    sizes.push_back({p.width, p.height});
  }
  auto atlas = create(context, std::move(sizes), precision);
  if (!atlas) return atlas.status();
  for (size_t p = 0; p < pages.size(); ++p) {
    std::vector<AtlasRectUpdate> whole;
    whole.push_back({int(p), 0, 0, std::move(pages[p])});
    RDM_TRY((*atlas)->applyDelta(whole));  // the page's floats are released here
  }
  return atlas;
}

bool AtlasTexture::growInPlace(const std::vector<AtlasPage>& sizes) {
  if (sizes.size() != sizes_.size()) return false;
  for (size_t p = 0; p < sizes.size(); ++p) {
    if (sizes[p].width < sizes_[p].width || sizes[p].height < sizes_[p].height ||
        uint32_t(sizes[p].width) > image_.spec().width ||
        uint32_t(sizes[p].height) > image_.spec().height)
      return false;
  }
  // The grown texels and the new border: a band right of the old page, the rows below it.
  std::vector<Rect> grown;
  for (size_t p = 0; p < sizes.size(); ++p) {
    const AtlasPage& old = sizes_[p];
    const AtlasPage& now = sizes[p];
    if (now.width > old.width)
      grown.push_back({int(p), old.width, 0, now.width - old.width + 1, old.height});
    if (now.height > old.height)
      grown.push_back({int(p), 0, old.height, now.width + 1, now.height - old.height + 1});
  }
  if (!zeroRects(grown).ok()) return false;
  sizes_ = sizes;
  return true;
}

Status AtlasTexture::applyDelta(const std::vector<AtlasRectUpdate>& updates) {
  for (const auto& u : updates) {
    if (u.page < 0 || u.page >= int(sizes_.size()) || u.texels.channels != 4 ||
        !rectInPage(sizes_[size_t(u.page)], u.x, u.y, u.texels.width, u.texels.height)) {
      return Status::error("atlas delta rect outside its page (page " + std::to_string(u.page) +
                           ")");
    }
  }
  RDM_TRY(uploadRects(updates));
  for (const auto& u : updates) depth_.write(u.page, u.x, u.y, u.texels);
  return Status();
}

// Converts the rects to half in staging buffers of at most kStagingBytes (a larger rect is
// split into bands of rows) and copies them in, one submission per buffer.
Status AtlasTexture::uploadRects(const std::vector<AtlasRectUpdate>& updates) {
  if (precision_ == AtlasPrecision::kBc6h) return uploadRectsBc6h(updates);
  struct Band {
    const AtlasRectUpdate* update;
    int row, rows;
  };
  std::vector<Band> bands;
  for (const auto& u : updates) {
    const size_t row_bytes = size_t(u.texels.width) * texelBytes();
    const int rows_per_band =
        int(std::max<size_t>(1, kStagingBytes / std::max<size_t>(1, row_bytes)));
    for (int r = 0; r < u.texels.height; r += rows_per_band)
      bands.push_back({&u, r, std::min(rows_per_band, u.texels.height - r)});
  }
  const GpuImage& img = image_;
  for (size_t first = 0; first < bands.size();) {
    size_t bytes = 0, last = first;
    while (last < bands.size()) {
      const size_t n =
          size_t(bands[last].update->texels.width) * size_t(bands[last].rows) * texelBytes();
      if (last > first && bytes + n > kStagingBytes) break;
      bytes += n, ++last;
    }
    auto staging = GpuBuffer::create(context_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    if (!staging) return staging.status();
    std::vector<VkBufferImageCopy> regions;
    size_t offset = 0;
    for (size_t b = first; b < last; ++b) {
      const AtlasRectUpdate& u = *bands[b].update;
      const size_t count = size_t(u.texels.width) * size_t(bands[b].rows) * 4;
      const float* src = &u.texels.pixels[size_t(bands[b].row) * size_t(u.texels.width) * 4];
      if (precision_ == AtlasPrecision::kHalf) {
        uint16_t* dst = reinterpret_cast<uint16_t*>(staging->mapped() + offset);
        for (size_t i = 0; i < count; ++i) dst[i] = atlasHalf(src[i]);
      } else {
        std::copy_n(src, count, reinterpret_cast<float*>(staging->mapped() + offset));
      }
      VkBufferImageCopy region{};
      region.bufferOffset = offset;
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, uint32_t(u.page), 1};
      region.imageOffset = {u.x, u.y + bands[b].row, 0};
      region.imageExtent = {uint32_t(u.texels.width), uint32_t(bands[b].rows), 1};
      if (region.imageExtent.width > 0 && region.imageExtent.height > 0) regions.push_back(region);
      offset += count * (texelBytes() / 4);
    }
    RDM_TRY(context_.submitAndWait([&](VkCommandBuffer cmd) {
      transitionImage(cmd, img, kReadToDst);
      if (!regions.empty()) {
        vkCmdCopyBufferToImage(cmd, staging->handle(), img.handle(),
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, uint32_t(regions.size()),
                               regions.data());
      }
      transitionImage(cmd, img, kDstToRead);
    }));
    first = last;
  }
  return Status();
}

// Pages are zeroed with a border of one texel right and below: the bilinear fetch at a
// tile's last texel centre weighs the next texel by 0, and 0 times an unwritten texel (NaN,
// infinity) is not 0.
Status AtlasTexture::zeroRects(const std::vector<Rect>& rects) {
  if (precision_ == AtlasPrecision::kBc6h) return zeroRectsBc6h(rects);
  std::vector<TexelRect> todo;
  for (const Rect& r : rects) {
    todo.push_back({r.page, r.x, r.y, std::min(r.w, width() - r.x), std::min(r.h, height() - r.y)});
    if (todo.back().w > 0 && todo.back().h > 0)
      depth_.clear(r.page, r.x, r.y, todo.back().w, todo.back().h);
  }
  return zeroImageRects(context_, image_, texelBytes(), todo);
}

Status AtlasTexture::copyPagesFrom(const AtlasTexture& old) {
  if (old.precision_ != precision_) return Status::error("atlas copy between texture formats");
  const bool blocks = precision_ == AtlasPrecision::kBc6h;
  const auto whole_blocks = [blocks](int v) { return uint32_t(blocks ? (v + 3) / 4 * 4 : v); };
  std::vector<VkImageCopy> regions, depths;
  for (size_t p = 0; p < old.sizes_.size() && p < sizes_.size(); ++p) {
    const AtlasPage& from = old.sizes_[p];
    if (from.width > sizes_[p].width || from.height > sizes_[p].height)
      return Status::error("atlas page " + std::to_string(p) + " shrinks");
    VkImageCopy region{};
    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, uint32_t(p), 1};
    region.dstSubresource = region.srcSubresource;
    region.extent = {uint32_t(from.width), uint32_t(from.height), 1};
    depths.push_back(region);
    region.extent = {whole_blocks(from.width), whole_blocks(from.height), 1};
    regions.push_back(region);
  }
  if (regions.empty()) return Status();
  RDM_TRY(copyImageRegions(context_, old.image_, image_, regions));
  if (blocks) RDM_TRY(copyImageRegions(context_, old.depth_image_, depth_image_, depths));
  for (size_t p = 0; p < regions.size(); ++p)
    depth_.copyFrom(old.depth_, int(p), old.sizes_[p].width, old.sizes_[p].height);
  return Status();
}

Expected<Image> AtlasTexture::readLayer(int layer) {
  if (layer < 0 || layer >= layers()) return Status::error("atlas layer out of range");
  if (precision_ == AtlasPrecision::kBc6h) return readLayerBc6h(layer);
  const int w = width(), h = height();
  auto staging =
      GpuBuffer::create(context_, size_t(w) * h * texelBytes(), VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (!staging) return staging.status();
  const GpuImage& img = image_;
  RDM_TRY(context_.submitAndWait([&](VkCommandBuffer cmd) {
    transitionImage(cmd, img, kReadToSrc);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, uint32_t(layer), 1};
    region.imageExtent = {uint32_t(w), uint32_t(h), 1};
    vkCmdCopyImageToBuffer(cmd, img.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           staging->handle(), 1, &region);
    transitionImage(cmd, img, kSrcToRead);
  }));
  Image out(w, h, 4);
  if (precision_ == AtlasPrecision::kHalf) {
    const uint16_t* half = reinterpret_cast<const uint16_t*>(staging->mapped());
    for (size_t i = 0; i < out.pixels.size(); ++i) out.pixels[i] = atlasFloat(half[i]);
  } else {
    std::copy_n(reinterpret_cast<const float*>(staging->mapped()), out.pixels.size(),
                out.pixels.data());
  }
  return out;
}

namespace {

// One page of `dir` read in strips into `texture`; throws on OpenEXR failures.
Status loadPage(const std::string& dir, const AtlasLayout& layout, int page,
                AtlasTexture& texture) {
  const std::string path = dir + "/" + atlasPageFileName(page);
  Imf::InputFile file(path.c_str());
  const Imath::Box2i window = file.header().dataWindow();
  const AtlasPage& size = layout.pages[size_t(page)];
  if (window.min.x != 0 || window.min.y != 0 || window.max.x + 1 != size.width ||
      window.max.y + 1 != size.height) {
    return Status::invalid("index.json", path + ": size differs from index.json");
  }
  const char* names[4] = {"R", "G", "B", "Z"};
  for (const char* name : names) {
    const Imf::Channel* channel = file.header().channels().findChannel(name);
    if (channel == nullptr || channel->xSampling != 1 || channel->ySampling != 1)
      return Status::error(path + ": no channel '" + std::string(name) + "' at full resolution");
  }
  // The tiles of this page whose radiance the file stores scaled (half atlases).
  struct Scaled {
    int x, y, size, exponent;
  };
  std::vector<Scaled> scaled;
  for (const AtlasEntry& e : layout.entries)
    for (const FaceTile& t : e.faces)
      if (t.page == page && t.exponent != 0) scaled.push_back({t.x, t.y, e.id.size, t.exponent});
  const size_t row_floats = size_t(size.width) * 4;
  const int strip = std::max(16, int(kStagingBytes / (row_floats * sizeof(float))) / 16 * 16);
  for (int y0 = 0; y0 < size.height; y0 += strip) {
    const int rows = std::min(strip, size.height - y0);
    AtlasRectUpdate u{page, 0, y0, Image(size.width, rows, 4)};
    Imf::FrameBuffer fb;
    const Imath::Box2i band(Imath::V2i(0, y0), Imath::V2i(size.width - 1, y0 + rows - 1));
    for (int c = 0; c < 4; ++c) {
      fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, &u.texels.pixels[size_t(c)], band,
                                           4 * sizeof(float), row_floats * sizeof(float)));
    }
    file.setFrameBuffer(fb);
    file.readPixels(y0, y0 + rows - 1);
    for (const Scaled& s : scaled) {  // restoreRadiance, for the rows of this strip
      for (int y = std::max(s.y, y0); y < std::min(s.y + s.size, y0 + rows); ++y)
        for (int x = s.x; x < s.x + s.size; ++x)
          for (int c = 0; c < 3; ++c) {
            float& v = u.texels.at(x, y - y0, c);
            v = std::ldexp(v, s.exponent);
          }
    }
    std::vector<AtlasRectUpdate> updates;
    updates.push_back(std::move(u));
    RDM_TRY(texture.applyDelta(updates));
  }
  return Status();
}

// One page of a bc6h atlas, decoded on the CPU whole and converted to the texture's format
// (the fallback for devices without BC6H sampling; lavapipe, docs/bc6h.md).
Status loadBc6hPage(const std::string& dir, const AtlasLayout& layout, int page,
                    AtlasTexture& texture) {
  auto texels = readBc6hAtlasPage(dir, layout, page);
  if (!texels) return texels.status();
  restoreRadiance(layout, page, *texels);
  std::vector<AtlasRectUpdate> updates;
  updates.push_back({page, 0, 0, std::move(*texels)});
  return texture.applyDelta(updates);
}

}  // namespace

Status loadAtlasPages(const std::string& dir, const AtlasLayout& layout, AtlasTexture& texture) {
  if (texture.pageSizes().size() != layout.pages.size())
    return Status::error("atlas texture made for another layout");
  if (texture.precision() == AtlasPrecision::kBc6h && layout.radiance != RadianceFormat::kBc6h)
    return Status::error("a bc6h atlas texture takes a bc6h atlas only");
  for (size_t p = 0; p < layout.pages.size(); ++p) {
    if (layout.radiance == RadianceFormat::kBc6h) {
      RDM_TRY(texture.precision() == AtlasPrecision::kBc6h
                  ? loadBc6hPageAsStored(dir, layout, int(p), texture)
                  : loadBc6hPage(dir, layout, int(p), texture));
      continue;
    }
    try {
      RDM_TRY(loadPage(dir, layout, int(p), texture));
    } catch (const std::exception& e) {
      return Status::error(StatusCode::kIo,
                           dir + "/" + atlasPageFileName(int(p)) + ": " + e.what());
    }
  }
  return Status();
}

}  // namespace rdm::viewer
