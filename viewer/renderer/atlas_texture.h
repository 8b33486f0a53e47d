// The RDM atlas on the device: a 2D array image, one layer per atlas page, every layer as
// large as the largest page. kHalf / kFloat: RGBA16F / RGBA32F (R, G, B, Z). kBc6h: the
// pages' BC6H blocks as the atlas stores them, and Z in an R16F image beside them. No CPU
// copy of the texels is kept: pages are converted and uploaded in strips (loadAtlasPages
// reads them from the files strip by strip), and the slot table's depth checks read a
// one-bit-per-texel mask.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gpu_resources.h"
#include "rdm/atlas/atlas.h"
#include "rdm/base/status.h"
#include "rdm/image/bc6h.h"
#include "rdm/image/image.h"
#include "scene_gpu.h"

namespace rdm::viewer {

using rdm::LoadedAtlas;  // rdm/atlas/atlas.h
// New texels for one rectangle of one page (an RDM re-baked by an incremental job).
struct AtlasRectUpdate {
  int page = 0;
  int x = 0, y = 0;
  Image texels;  // w x h, channels R, G, B, Z
};

// Half's largest finite value. Radiance above it (a sun-lit mirror's reflection of the sun
// disc) is clamped: after tone mapping it is white either way; depths stay far below it.
constexpr float kAtlasHalfMax = 65504.0f;
// Round to nearest even (Imath::half), clamped to +-kAtlasHalfMax; NaN stays NaN.
uint16_t atlasHalf(float value);
float atlasFloat(uint16_t half);

// kHalf: RGBA16F, what the viewer shows. kFloat: RGBA32F (twice the memory), the reference
// the half atlas is measured against (rdm-viewer --float-atlas, tests). kBc6h: a bc6h atlas's
// blocks uploaded as they are (1 byte a texel) and Z as half (2 bytes); needs a device that
// samples BC6H (VulkanContext::samplesBc6h). Rects written into it are encoded on the CPU,
// with the blocks they share with other texels read back and re-encoded (docs/bc6h.md).
enum class AtlasPrecision { kHalf, kFloat, kBc6h };
const char* atlasPrecisionName(AtlasPrecision precision);

class AtlasTexture {
 public:
  // An image for pages of `sizes`, their texels 0 (`sizes` empty: one 1 x 1 page). Texels
  // outside the pages and their one-texel border (the padding of smaller pages, the
  // headroom) are never written, so they cost no memory on lavapipe until a page grows over
  // them; shaders read only inside tiles.
  static Expected<std::unique_ptr<AtlasTexture>> create(
      VulkanContext& context, std::vector<AtlasPage> sizes,
      AtlasPrecision precision = AtlasPrecision::kHalf);
  // create(sizes of `pages`), then each page uploaded and released in turn.
  static Expected<std::unique_ptr<AtlasTexture>> create(
      VulkanContext& context, std::vector<Image> pages,
      AtlasPrecision precision = AtlasPrecision::kHalf);

  VkImageView view() const { return image_.view(); }
  // Z in the r component (kBindingAtlasDepth).
  VkImageView depthView() const {
    return precision_ == AtlasPrecision::kBc6h ? depth_image_.view() : image_.alphaView();
  }
  AtlasPrecision precision() const { return precision_; }
  int width() const { return int(image_.spec().width); }
  int height() const { return int(image_.spec().height); }
  int layers() const { return int(image_.spec().layers); }
  const std::vector<AtlasPage>& pageSizes() const { return sizes_; }
  const AtlasDepthMask& depthMask() const { return depth_; }
  VkFormat format() const { return image_.spec().format; }
  // Device bytes per texel: radiance and depth together.
  size_t texelBytes() const {
    return precision_ == AtlasPrecision::kBc6h ? 3 : precision_ == AtlasPrecision::kHalf ? 8 : 16;
  }
  // The device images' bytes (every layer at width() x height(), headroom included).
  size_t deviceBytes() const { return size_t(width()) * height() * layers() * texelBytes(); }

  // kBc6h: page `page`'s blocks (blocks.width x blocks.height texels from (0, 0)) and its Z
  // (one channel, the same size) as they are. Fails (changing nothing) when they leave it.
  Status uploadPageBlocks(int page, const Bc6hImage& blocks, const Image& depth);

  // Converts each update to half and copies it into its rect of the device image (and the
  // depth mask), touching no other texel. Fails (changing nothing) when a rect leaves its
  // page.
  Status applyDelta(const std::vector<AtlasRectUpdate>& updates);
  // Grows the pages to `sizes` in place when they fit the device image, which is made
  // kHeadroom taller than its largest page so that an incremental job's new RDMs rarely
  // need a new image: the grown texels are zeroed. False (changing nothing) when a page
  // shrinks, a page is added or a page does not fit.
  bool growInPlace(const std::vector<AtlasPage>& sizes);
  static constexpr double kHeadroom = 0.25;
  // Copies every page of `old` (on the device) and its depth bits into the same place here;
  // each of this atlas's pages must hold the old page of the same index, if any.
  Status copyPagesFrom(const AtlasTexture& old);
  // Reads one layer back from the device (R, G, B, Z as float), for tests and screenshots.
  Expected<Image> readLayer(int layer);

 private:
  AtlasTexture(VulkanContext& context, AtlasPrecision precision)
      : context_(context), precision_(precision) {}
  Status uploadRects(const std::vector<AtlasRectUpdate>& updates);
  struct Rect {
    int page, x, y, w, h;
  };
  Status zeroRects(const std::vector<Rect>& rects);
  // kBc6h (atlas_texture_bc6h.cpp).
  Status createBc6hImages(ImageSpec spec);
  Status uploadRectsBc6h(const std::vector<AtlasRectUpdate>& updates);
  Status zeroRectsBc6h(const std::vector<Rect>& rects);
  Expected<Image> readLayerBc6h(int layer);
  // Replaces the texels of the 4 x 4-aligned rect (x, y, w, h) of `page` by `fill`'s: the
  // blocks are read back and decoded first unless `fill` writes every texel (`whole`).
  Status rewriteBlocks(int page, int x, int y, int w, int h, bool whole,
                       const std::function<void(Image&)>& fill);
  Status uploadDepthRects(const std::vector<AtlasRectUpdate>& updates);

  VulkanContext& context_;
  AtlasPrecision precision_;
  GpuImage image_;
  GpuImage depth_image_;  // kBc6h: R16F Z
  std::vector<AtlasPage> sizes_;
  AtlasDepthMask depth_;
};

// Reads pages of the atlas in `dir` (as writeAtlasOutputs wrote them, sizes as in `layout`)
// into `texture` in strips of rows: converted to half, the tile exponents undone, never more
// than one strip of floats in memory. `texture` must have been made for `layout.pages`.
// A bc6h atlas goes to a kBc6h texture as its blocks are (tiles the file stores scaled are
// restored, clamped to half's range and re-encoded); to any other, it is decoded on the CPU a
// page at a time (one page of floats in memory).
Status loadAtlasPages(const std::string& dir, const AtlasLayout& layout, AtlasTexture& texture);
// Page `page` of the bc6h atlas in `dir` into a kBc6h `texture`, its blocks as stored.
Status loadBc6hPageAsStored(const std::string& dir, const AtlasLayout& layout, int page,
                            AtlasTexture& texture);

}  // namespace rdm::viewer
