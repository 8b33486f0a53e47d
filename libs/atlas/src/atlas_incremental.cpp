#include "rdm/atlas/atlas_incremental.h"

#include <algorithm>

namespace rdm {
namespace {

// Every tile has x and y multiples of its size S >= 2 (a power of two), so occupancy is
// tracked on a grid of 2 x 2 pixel cells; a bc6h layout's of kBc6hTileAlign cells (a tile
// below that size takes a whole cell).
int cellOf(RadianceFormat format) {
  return format == RadianceFormat::kBc6h ? kBc6hTileAlign : 2;
}

class PageGrid {
 public:
  PageGrid(int width, int cell) : cell_(cell), columns_(width / cell) {}

  bool isFree(int cx, int cy, int n) const {
    if (cx + n > columns_) return false;
    for (int y = cy; y < cy + n; ++y) {
      if (y >= rows()) return true;  // rows past the end are free
      for (int x = cx; x < cx + n; ++x) {
        if (cells_[size_t(y) * columns_ + x]) return false;
      }
    }
    return true;
  }
  void mark(int cx, int cy, int n) {
    if (cy + n > rows()) cells_.resize(size_t(cy + n) * columns_, 0);
    for (int y = cy; y < cy + n; ++y)
      for (int x = cx; x < cx + n; ++x) cells_[size_t(y) * columns_ + x] = 1;
  }
  int columns() const { return columns_; }
  int cell() const { return cell_; }
  // A tile of an RDM of size S spans this many cells each way.
  int cellsOf(const RdmId& id) const { return std::max(1, id.size / cell_); }

 private:
  int rows() const { return columns_ ? int(cells_.size() / size_t(columns_)) : 0; }
  int cell_;
  int columns_;
  std::vector<uint8_t> cells_;
};

bool placeOnPage(PageGrid& grid, AtlasPage& page, int page_index, const RdmId& id, FaceTile& out) {
  const int n = grid.cellsOf(id), cell = grid.cell();
  const int max_rows = kPackedPageSize / cell;
  for (int cy = 0; cy + n <= max_rows; cy += n) {
    for (int cx = 0; cx + n <= grid.columns(); cx += n) {
      if (!grid.isFree(cx, cy, n)) continue;
      grid.mark(cx, cy, n);
      out = {page_index, cx * cell, cy * cell};
      page.height = std::max(page.height, out.y + std::max(id.size, cell));
      return true;
    }
  }
  return false;
}

struct Placer {
  AtlasLayout& out;
  int cell;
  std::vector<PageGrid> grids;

  void keep(const RdmId& id, const FaceTile& t) {
    PageGrid& grid = grids[size_t(t.page)];
    grid.mark(t.x / cell, t.y / cell, grid.cellsOf(id));
  }
  FaceTile place(const RdmId& id) {
    FaceTile tile;
    for (size_t p = 0; p < out.pages.size(); ++p) {
      if (placeOnPage(grids[p], out.pages[p], int(p), id, tile)) return tile;
    }
    out.pages.push_back({std::max(out.pages[0].width, std::max(id.size, cell)), 0});
    grids.emplace_back(out.pages.back().width, cell);
    const bool placed =
        placeOnPage(grids.back(), out.pages.back(), int(out.pages.size() - 1), id, tile);
    RDM_CHECK(placed);
    return tile;
  }
};

}  // namespace

AtlasLayout packIncremental(const AtlasLayout& base, const std::vector<RdmId>& rdms,
                            const StoredFaces& stored, RadianceFormat format) {
  // A bc6h layout keeps only tiles already block-aligned: a float32 or half base's may share
  // a block.
  const bool keep_tiles = format != RadianceFormat::kBc6h || base.radiance == format;
  if (base.entries.empty() || base.pages.empty() || !keep_tiles) {
    AtlasLayout fresh = packCanonical(rdms, stored, format);
    fresh.scene_version = base.scene_version;
    fresh.lighting = base.lighting;
    return fresh;
  }
  AtlasLayout out;
  out.scene_version = base.scene_version;
  out.lighting = base.lighting;
  out.pages = base.pages;
  out.radiance = format;
  Placer placer{out, cellOf(format), {}};
  for (const AtlasPage& p : out.pages) placer.grids.emplace_back(p.width, placer.cell);
  struct Fresh {
    size_t entry;
    int face;
  };
  std::vector<Fresh> fresh;
  for (const RdmId& id : rdms) {
    const AtlasEntry* old = base.find(id.slot, id.level);
    const bool same_size = old && old->id.size == id.size;
    const FaceMask mask = stored(id.slot);
    AtlasEntry entry{id, {}};
    for (int f = 0; f < 6; ++f) {
      if (!(mask >> f & 1u)) continue;
      if (same_size && old->faces[size_t(f)].stored()) {
        entry.faces[size_t(f)] = old->faces[size_t(f)];
        placer.keep(id, entry.faces[size_t(f)]);
      } else {
        fresh.push_back({out.entries.size(), f});
      }
    }
    out.entries.push_back(entry);
  }
  std::stable_sort(fresh.begin(), fresh.end(), [&](const Fresh& a, const Fresh& b) {
    const RdmId &ia = out.entries[a.entry].id, &ib = out.entries[b.entry].id;
    if (canonicalLess(ia, ib) || canonicalLess(ib, ia)) return canonicalLess(ia, ib);
    return a.face < b.face;
  });
  for (const Fresh& t : fresh)
    out.entries[t.entry].faces[size_t(t.face)] = placer.place(out.entries[t.entry].id);
  std::sort(out.entries.begin(), out.entries.end(),
            [](const AtlasEntry& a, const AtlasEntry& b) { return canonicalLess(a.id, b.id); });
  return out;
}

}  // namespace rdm
