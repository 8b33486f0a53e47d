// The RDM atlas on the device: a 2D array image (RGBA32F = R, G, B, Z), one layer per atlas
// page, every layer as large as the largest page (smaller pages are zero-padded). A CPU copy
// of the pages is kept for the slot table's depth checks and for incremental updates.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "gpu_resources.h"
#include "rdm/atlas.h"
#include "rdm/image.h"
#include "rdm/status.h"

namespace rdm::viewer {

using rdm::LoadedAtlas;  // rdm/atlas.h
// New texels for one rectangle of one page (an RDM re-baked by an incremental job).
struct AtlasRectUpdate {
  int page = 0;
  int x = 0, y = 0;
  Image texels;  // w x h, channels R, G, B, Z
};

class AtlasTexture {
 public:
  // `pages` may be empty: a 1 x 1 zero page is made (no RDMs).
  static Expected<std::unique_ptr<AtlasTexture>> create(VulkanContext& context,
                                                        std::vector<Image> pages);

  VkImageView view() const { return image_.view(); }
  int width() const { return int(image_.spec().width); }
  int height() const { return int(image_.spec().height); }
  int layers() const { return int(image_.spec().layers); }
  const std::vector<Image>& pages() const { return pages_; }

  // Copies each update into its rect of the device image and of the CPU copy, touching no
  // other texel. Fails (changing nothing) when a rect leaves its page.
  Status applyDelta(const std::vector<AtlasRectUpdate>& updates);
  // Grows the pages to `sizes` in place when they fit the device image, which is made
  // kHeadroom taller than its largest page so that an incremental job's new RDMs rarely
  // need a new image: the grown texels are already zero. False (changing nothing) when a
  // page shrinks, a page is added or a page does not fit.
  bool growInPlace(const std::vector<AtlasPage>& sizes);
  static constexpr double kHeadroom = 0.25;
  // Reads one layer back from the device (R, G, B, Z), for tests and screenshots.
  Expected<Image> readLayer(int layer);

 private:
  explicit AtlasTexture(VulkanContext& context) : context_(context) {}
  Status uploadRects(const std::vector<AtlasRectUpdate>& updates, bool first_upload);

  VulkanContext& context_;
  GpuImage image_;
  std::vector<Image> pages_;
};

}  // namespace rdm::viewer
