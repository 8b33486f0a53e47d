// The bc6h atlas's files (rdm/atlas/atlas.h, docs/spec.md section 4, docs/bc6h.md): R, G, B
// as BC6H_UFLOAT in KTX2, Z as a one-channel half EXR beside it. Half depth is what the
// viewer samples anyway (its atlas texture is RGBA16F), and spares 2 bytes a texel.
#include <algorithm>
#include <string>

#include "rdm/atlas/atlas.h"
#include "rdm/image/bc6h.h"
#include "rdm/image/exr_io.h"
#include "rdm/image/ktx2.h"

namespace rdm {
namespace {

const std::vector<std::string> kDepthChannel = {"Z"};

// Calls `use(tile, size)` for every tile of `page` smaller than a block.
template <typename Use>
void forEachSmallTile(const AtlasLayout& layout, int page, Use use) {
  for (const AtlasEntry& e : layout.entries) {
    if (e.id.size >= kBc6hTileAlign) continue;
    for (const FaceTile& t : e.faces)
      if (t.page == page) use(t, e.id.size);
  }
}

Image channelsOf(const Image& texels, int first, int count) {
  Image out(texels.width, texels.height, count);
  const size_t pixels = size_t(texels.width) * size_t(texels.height);
  for (size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < count; ++c)
      out.pixels[p * size_t(count) + size_t(c)] =
          texels.pixels[p * size_t(texels.channels) + size_t(first + c)];
  return out;
}

Status checkDepthFitsHalf(const Image& depth, const std::string& path) {
  for (float z : depth.pixels) {
    if (!(z <= kHalfMax))
      return Status::invalid(
          "Z", path + ": depth " + std::to_string(z) + " does not fit half (at most 65504)");
  }
  return {};
}

Expected<Bc6hImage> readBlocks(const std::string& path, const AtlasPage& size) {
  auto ktx2 = readKtx2(path);
  if (!ktx2) return ktx2.status();
  if (ktx2->format != Ktx2Format::kBc6hUfloat)
    return Status::invalid("vkFormat", path + ": not BC6H_UFLOAT (vkFormat " +
                                           std::to_string(uint32_t(ktx2->format)) + ")");
  if (ktx2->width != size.width || ktx2->height != size.height)
    return Status::invalid("index.json", path + ": size differs from index.json");
  return Bc6hImage{ktx2->width, ktx2->height, std::move(ktx2->data)};
}

Expected<Image> readDepth(const std::string& path, const AtlasPage& size) {
  auto depth = readExr(path, kDepthChannel);
  if (!depth) return depth.status();
  if (depth->width != size.width || depth->height != size.height)
    return Status::invalid("index.json", path + ": size differs from index.json");
  return depth;
}

// Zeroes the padding of the small tiles' cells, so texels outside tiles read as 0.
void clearPadding(const AtlasLayout& layout, int page, Image& texels) {
  forEachSmallTile(layout, page, [&texels](const FaceTile& t, int size) {
    for (int y = 0; y < kBc6hTileAlign; ++y)
      for (int x = 0; x < kBc6hTileAlign; ++x)
        if (x >= size || y >= size)
          for (int c = 0; c < texels.channels; ++c) texels.at(t.x + x, t.y + y, c) = 0.0f;
  });
}

}  // namespace

std::string atlasKtx2FileName(int page) {
  return page == 0 ? "atlas.ktx2" : "atlas.page" + std::to_string(page) + ".ktx2";
}

std::string atlasDepthFileName(int page) {
  return page == 0 ? "depth.exr" : "depth.page" + std::to_string(page) + ".exr";
}

void padSmallTiles(const AtlasLayout& layout, int page, Image& texels) {
  forEachSmallTile(layout, page, [&texels](const FaceTile& t, int size) {
    for (int y = 0; y < kBc6hTileAlign; ++y)
      for (int x = 0; x < kBc6hTileAlign; ++x) {
        const int from_x = t.x + std::min(x, size - 1), from_y = t.y + std::min(y, size - 1);
        for (int c = 0; c < 3; ++c) texels.at(t.x + x, t.y + y, c) = texels.at(from_x, from_y, c);
      }
  });
}

Status writeBc6hAtlasPage(const std::string& dir, const AtlasLayout& layout, int page,
                          Image& texels, const Bc6hEncodeFn& encode, Bc6hReuse* reuse) {
  const std::string depth_path = dir + "/" + atlasDepthFileName(page);
  const Image depth = channelsOf(texels, 3, 1);
  if (Status s = checkDepthFitsHalf(depth, depth_path); !s) return s;
  padSmallTiles(layout, page, texels);
  Bc6hOptions options;
  options.threads = 0;  // the blocks do not depend on the thread count
  auto blocks = reuse    ? encodeBc6hReusing(layout, page, texels, encode, *reuse)
                : encode ? encode(texels)
                         : encodeBc6h(texels, options);
  if (!blocks)
    return Status::invalid(blocks.status().field(),
                           dir + "/" + atlasKtx2FileName(page) + ": " + blocks.error());
  const Ktx2Image ktx2{Ktx2Format::kBc6hUfloat, blocks->width, blocks->height,
                       std::move(blocks->blocks)};
  if (Status s = writeKtx2(dir + "/" + atlasKtx2FileName(page), ktx2); !s) return s;
  return writeExr(depth_path, depth, kDepthChannel, kDepthChannel);
}

Expected<Bc6hImage> readBc6hAtlasBlocks(const std::string& dir, const AtlasLayout& layout,
                                        int page) {
  return readBlocks(dir + "/" + atlasKtx2FileName(page), layout.pages.at(size_t(page)));
}

Expected<Image> readBc6hAtlasDepth(const std::string& dir, const AtlasLayout& layout, int page) {
  return readDepth(dir + "/" + atlasDepthFileName(page), layout.pages.at(size_t(page)));
}

Expected<Image> joinBc6hAtlasPage(const AtlasLayout& layout, int page, const Bc6hImage& blocks,
                                  const Image& depth) {
  const AtlasPage& size = layout.pages.at(size_t(page));
  if (blocks.width != size.width || blocks.height != size.height || depth.width != size.width ||
      depth.height != size.height || depth.channels != 1)
    return Status::invalid("index.json",
                           "bc6h page " + std::to_string(page) + ": size differs from index.json");
  auto rgb = decodeBc6h(blocks);
  if (!rgb) return rgb.status();
  Image out(size.width, size.height, 4);
  const size_t pixels = size_t(size.width) * size_t(size.height);
  for (size_t p = 0; p < pixels; ++p) {
    for (size_t c = 0; c < 3; ++c) out.pixels[p * 4 + c] = rgb->pixels[p * 3 + c];
    out.pixels[p * 4 + 3] = depth.pixels[p];
  }
  clearPadding(layout, page, out);
  return out;
}

Expected<Image> readBc6hAtlasPage(const std::string& dir, const AtlasLayout& layout, int page) {
  auto blocks = readBc6hAtlasBlocks(dir, layout, page);
  if (!blocks) return blocks.status();
  auto depth = readBc6hAtlasDepth(dir, layout, page);
  if (!depth) return depth.status();
  auto out = joinBc6hAtlasPage(layout, page, *blocks, *depth);
  if (!out)
    return Status::invalid(out.status().field(),
                           dir + "/" + atlasKtx2FileName(page) + ": " + out.error());
  return out;
}

}  // namespace rdm
