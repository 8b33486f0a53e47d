#include "rdm/atlas_incremental.h"

#include <algorithm>

namespace rdm {
namespace {

// Every rect has x a multiple of 4 and y a multiple of 6 (S >= 2 and a power of two), so
// occupancy is tracked on a grid of 4 x 6 pixel cells.
constexpr int kCellW = 4, kCellH = 6;

class PageGrid {
 public:
  explicit PageGrid(int width) : columns_(width / kCellW) {}

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

 private:
  int rows() const { return columns_ ? int(cells_.size() / size_t(columns_)) : 0; }
  int columns_;
  std::vector<uint8_t> cells_;
};

// A rect of an RDM of size S spans n = S / 2 cells each way.
int cellsOf(const RdmId& id) {
  return std::max(1, id.size / 2);
}

bool placeOnPage(PageGrid& grid, AtlasPage& page, int page_index, const RdmId& id,
                 AtlasEntry& out) {
  const int n = cellsOf(id);
  const int max_rows = kMaxPageSize / kCellH;
  for (int cy = 0; cy + n <= max_rows; cy += n) {
    for (int cx = 0; cx + n <= grid.columns(); cx += n) {
      if (!grid.isFree(cx, cy, n)) continue;
      grid.mark(cx, cy, n);
      out = {id, page_index, cx * kCellW, cy * kCellH};
      page.height = std::max(page.height, out.y + 3 * id.size);
      return true;
    }
  }
  return false;
}

}  // namespace

AtlasLayout packIncremental(const AtlasLayout& base, const std::vector<RdmId>& rdms) {
  if (base.entries.empty() || base.pages.empty()) {
    AtlasLayout fresh = packCanonical(rdms);
    fresh.scene_version = base.scene_version;
    return fresh;
  }
  AtlasLayout out;
  out.scene_version = base.scene_version;
  out.pages = base.pages;
  std::vector<PageGrid> grids;
  for (const AtlasPage& p : out.pages) grids.emplace_back(p.width);
  std::vector<RdmId> fresh;
  for (const RdmId& id : rdms) {
    const AtlasEntry* old = base.find(id.slot, id.level);
    if (old && old->id.size == id.size) {
      out.entries.push_back({id, old->page, old->x, old->y});
      grids[old->page].mark(old->x / kCellW, old->y / kCellH, cellsOf(id));
    } else {
      fresh.push_back(id);
    }
  }
  std::sort(fresh.begin(), fresh.end(), canonicalLess);
  for (const RdmId& id : fresh) {
    AtlasEntry entry;
    bool placed = false;
    for (size_t p = 0; p < out.pages.size() && !placed; ++p) {
      placed = placeOnPage(grids[p], out.pages[p], int(p), id, entry);
    }
    if (!placed) {
      out.pages.push_back({std::max(out.pages[0].width, 2 * id.size), 0});
      grids.emplace_back(out.pages.back().width);
      placed = placeOnPage(grids.back(), out.pages.back(), int(out.pages.size() - 1), id, entry);
      RDM_CHECK(placed);
    }
    out.entries.push_back(entry);
  }
  std::sort(out.entries.begin(), out.entries.end(),
            [](const AtlasEntry& a, const AtlasEntry& b) { return canonicalLess(a.id, b.id); });
  return out;
}

}  // namespace rdm
