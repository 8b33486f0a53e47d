// encodeBc6hReusing (rdm/atlas/atlas.h): an incremental bc6h page copies the blocks of the tiles
// it keeps from its base and encodes only the others, gathered into one strip of blocks so that
// any encoder (the CPU's or a device's) encodes them in one call.
#include <algorithm>
#include <cstring>

#include "rdm/atlas/atlas.h"

namespace rdm {
namespace {

constexpr int kBlock = 4;
constexpr int kStripBlocks = 1024;  // blocks per row of the strip the encoder is given

struct BlockPos {
  int x, y;  // block coordinates
};

size_t blockOffset(int blocks_wide, int bx, int by) {
  return (size_t(by) * size_t(blocks_wide) + size_t(bx)) * kBc6hBlockBytes;
}

// One flag per block of page `page`: its texels all belong to a tile `reuse` may copy.
std::vector<uint8_t> reusableBlocks(const AtlasLayout& layout, int page, const Bc6hReuse& reuse,
                                    int blocks_wide, int blocks_high, const AtlasPage& base_page) {
  std::vector<uint8_t> reusable(size_t(blocks_wide) * size_t(blocks_high), 0);
  for (const AtlasEntry& e : layout.entries) {
    if (reuse.rebaked(e.id)) continue;
    const AtlasEntry* old = reuse.base.find(e.id.slot, e.id.level);
    if (!old || old->id.size != e.id.size) continue;
    const int span = std::max(e.id.size, kBlock);
    for (int f = 0; f < 6; ++f) {
      const FaceTile& t = e.faces[size_t(f)];
      if (t.page != page || !(t == old->faces[size_t(f)])) continue;
      if (t.x + span > base_page.width || t.y + span > base_page.height) continue;
      for (int by = t.y / kBlock; by < (t.y + span) / kBlock; ++by)
        for (int bx = t.x / kBlock; bx < (t.x + span) / kBlock; ++bx)
          reusable[size_t(by) * size_t(blocks_wide) + size_t(bx)] = 1;
    }
  }
  return reusable;
}

// The texels of `blocks` side by side in rows of kStripBlocks (unused blocks 0).
Image gatherStrip(const Image& texels, const std::vector<BlockPos>& blocks) {
  const int wide = std::min<int>(int(blocks.size()), kStripBlocks);
  const int high = int((blocks.size() + kStripBlocks - 1) / kStripBlocks);
  Image strip(wide * kBlock, high * kBlock, 3);
  for (size_t i = 0; i < blocks.size(); ++i) {
    const int sx = int(i % kStripBlocks) * kBlock, sy = int(i / kStripBlocks) * kBlock;
    for (int y = 0; y < kBlock; ++y)
      for (int x = 0; x < kBlock; ++x)
        for (int c = 0; c < 3; ++c)
          strip.at(sx + x, sy + y, c) =
              texels.at(blocks[i].x * kBlock + x, blocks[i].y * kBlock + y, c);
  }
  return strip;
}

}  // namespace

Expected<Bc6hImage> encodeBc6hReusing(const AtlasLayout& layout, int page, const Image& texels,
                                      const Bc6hEncodeFn& encode, Bc6hReuse& reuse) {
  if (Status s = bc6hCheckEncodable(texels); !s) return s;
  Bc6hImage out{texels.width, texels.height, {}};
  const int wide = out.blocksWide(), high = out.blocksHigh();
  out.blocks.assign(size_t(wide) * size_t(high) * kBc6hBlockBytes, 0);
  std::vector<uint8_t> reusable;
  Bc6hImage base;
  if (page < int(reuse.base.pages.size()) && reuse.base.radiance == RadianceFormat::kBc6h) {
    auto stored = reuse.base_page(page);
    if (!stored) return stored.status();
    base = std::move(*stored);
    reusable = reusableBlocks(layout, page, reuse, wide, high, {base.width, base.height});
  }
  std::vector<BlockPos> fresh;
  for (int by = 0; by < high; ++by)
    for (int bx = 0; bx < wide; ++bx) {
      if (!reusable.empty() && reusable[size_t(by) * size_t(wide) + size_t(bx)]) {
        std::memcpy(&out.blocks[blockOffset(wide, bx, by)],
                    &base.blocks[blockOffset(base.blocksWide(), bx, by)], kBc6hBlockBytes);
        ++reuse.reused_blocks;
      } else {
        fresh.push_back({bx, by});
      }
    }
  if (fresh.empty()) return out;
  const Image strip = gatherStrip(texels, fresh);
  Bc6hOptions options;
  options.threads = 0;  // the blocks do not depend on the thread count
  auto encoded = encode ? encode(strip) : encodeBc6h(strip, options);
  if (!encoded) return encoded.status();
  for (size_t i = 0; i < fresh.size(); ++i)
    std::memcpy(&out.blocks[blockOffset(wide, fresh[i].x, fresh[i].y)],
                &encoded->blocks[blockOffset(encoded->blocksWide(), int(i % kStripBlocks),
                                             int(i / kStripBlocks))],
                kBc6hBlockBytes);
  reuse.encoded_blocks += fresh.size();
  return out;
}

}  // namespace rdm
