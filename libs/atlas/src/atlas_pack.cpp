#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "rdm/atlas/atlas.h"

namespace rdm {
namespace {

// One face tile to place: entry `entry`, face `face`, in a size x size cell (S, or
// kBc6hTileAlign for smaller tiles of a bc6h layout).
struct TileRef {
  size_t entry;
  int face;
  int size;
};

int cellSize(int tile_size, RadianceFormat format) {
  return format == RadianceFormat::kBc6h ? std::max(tile_size, kBc6hTileAlign) : tile_size;
}

struct Cell {
  int x, y, size;  // a size x size square
};

// A packing's figures; the layout itself is kept only for the winner, since each layout holds
// every entry (a world of 20k RDMs would keep 200 layouts of them: 480 MB).
struct Candidate {
  AtlasLayout layout;
  size_t pages = 0;
  double occupancy = 0.0;
  int extent = 0;  // largest page side
};

// Packs in rows whose cell size is the first remaining tile's size; smaller tiles split a
// cell into four quadrants (TL, TR, BL, BR). Tiles come in size-descending order, so every
// row and cell is aligned to the sizes placed in it.
Candidate packWithWidth(const AtlasLayout& entries, const std::vector<TileRef>& tiles, int width) {
  Candidate c;
  c.layout.entries = entries.entries;
  c.layout.radiance = entries.radiance;
  std::vector<Cell> free_cells;  // back = next to use
  int page = 0, row_y = 0;
  c.layout.pages.push_back({0, 0});
  for (const TileRef& t : tiles) {
    if (free_cells.empty()) {
      if (row_y + t.size > kPackedPageSize) {
        ++page, row_y = 0;
        c.layout.pages.push_back({0, 0});
      }
      for (int x = width - t.size; x >= 0; x -= t.size) free_cells.push_back({x, row_y, t.size});
      row_y += t.size;
    }
    while (free_cells.back().size > t.size) {
      Cell big = free_cells.back();
      free_cells.pop_back();
      const int s = big.size / 2;
      free_cells.push_back({big.x + s, big.y + s, s});
      free_cells.push_back({big.x, big.y + s, s});
      free_cells.push_back({big.x + s, big.y, s});
      free_cells.push_back({big.x, big.y, s});
    }
    const Cell cell = free_cells.back();
    free_cells.pop_back();
    c.layout.entries[t.entry].faces[size_t(t.face)] = {page, cell.x, cell.y};
    AtlasPage& p = c.layout.pages[size_t(page)];
    p.width = std::max(p.width, cell.x + t.size);
    p.height = std::max(p.height, cell.y + t.size);
  }
  c.occupancy = c.layout.occupancy();
  c.pages = c.layout.pages.size();
  for (const AtlasPage& p : c.layout.pages) c.extent = std::max({c.extent, p.width, p.height});
  return c;
}

constexpr double kOccupancySlack = 0.01;

bool better(const Candidate& a, const Candidate& b) {
  if (a.pages != b.pages) return a.pages < b.pages;
  if (a.extent != b.extent) return a.extent < b.extent;
  return a.occupancy > b.occupancy;
}

}  // namespace

StoredFaces storedFacesOf(const VoxelWorld& world) {
  return [&world](const glm::ivec3& slot) {
    FaceMask mask = 0;
    for (int f = 0; f < 6; ++f) mask |= faceSkipped(world, slot, f) ? 0 : FaceMask(1u << f);
    return mask;
  };
}

StoredFaces storedFacesOf(const std::vector<RdmData>& rdms) {
  std::map<std::tuple<int, int, int>, FaceMask> masks;
  for (const RdmData& d : rdms) {
    FaceMask mask = 0;
    for (int f = 0; f < 6; ++f) mask |= d.skipped[size_t(f)] ? 0 : FaceMask(1u << f);
    masks[{d.id.slot.x, d.id.slot.y, d.id.slot.z}] = mask;
  }
  return [masks = std::move(masks)](const glm::ivec3& slot) {
    auto it = masks.find({slot.x, slot.y, slot.z});
    return it == masks.end() ? kAllFaces : it->second;
  };
}

FaceMask allFaces(const glm::ivec3&) {
  return kAllFaces;
}

FaceMask AtlasEntry::storedMask() const {
  FaceMask mask = 0;
  for (int f = 0; f < 6; ++f) mask |= faces[size_t(f)].stored() ? FaceMask(1u << f) : 0;
  return mask;
}

double AtlasLayout::occupancy() const {
  double used = 0.0, total = 0.0;
  for (const AtlasEntry& e : entries) {
    for (const FaceTile& t : e.faces) used += t.stored() ? double(e.id.size) * e.id.size : 0.0;
  }
  for (const AtlasPage& p : pages) total += double(p.width) * p.height;
  return total > 0.0 ? used / total : 0.0;
}

size_t AtlasLayout::storedTiles() const {
  size_t tiles = 0;
  for (const AtlasEntry& e : entries) tiles += size_t(__builtin_popcount(e.storedMask()));
  return tiles;
}

const AtlasEntry* AtlasLayout::find(const glm::ivec3& slot, int level) const {
  for (const AtlasEntry& e : entries) {
    if (e.id.slot == slot && e.id.level == level) return &e;
  }
  return nullptr;
}

bool tilesFit(const AtlasEntry& e, const std::vector<AtlasPage>& pages) {
  if (e.id.size < 1 || e.id.size > kMaxPageSize) return false;
  for (const FaceTile& t : e.faces) {
    if (!t.stored()) continue;
    if (t.page >= int(pages.size()) || t.x < 0 || t.y < 0) return false;
    const AtlasPage& p = pages[size_t(t.page)];
    if (t.x + e.id.size > p.width || t.y + e.id.size > p.height) return false;
  }
  return true;
}

AtlasLayout packCanonical(std::vector<RdmId> rdms, const StoredFaces& stored,
                          RadianceFormat format) {
  std::sort(rdms.begin(), rdms.end(), canonicalLess);
  AtlasLayout base;
  base.radiance = format;
  std::vector<TileRef> tiles;
  double area = 0.0;
  for (const RdmId& id : rdms) {
    const FaceMask mask = stored(id.slot);
    for (int f = 0; f < 6; ++f) {
      if (!(mask >> f & 1u)) continue;
      const int cell = cellSize(id.size, format);
      tiles.push_back({base.entries.size(), f, cell});
      area += double(cell) * cell;
    }
    base.entries.push_back({id, {}});
  }
  if (tiles.empty()) return base;
  const int cell = tiles.front().size;
  const int max_columns =
      std::min(kPackedPageSize / cell, std::max(1, int(std::ceil(std::sqrt(area) / cell)) + 1));
  std::vector<Candidate> candidates;
  double best_occupancy = 0.0;
  for (int columns = 1; columns <= max_columns; ++columns) {
    Candidate c = packWithWidth(base, tiles, columns * cell);
    c.layout = AtlasLayout();
    best_occupancy = std::max(best_occupancy, c.occupancy);
    candidates.push_back(std::move(c));
  }
  // Within kOccupancySlack of the best occupancy, the squarest layout wins.
  int best = -1;
  for (int i = 0; i < int(candidates.size()); ++i) {
    if (candidates[size_t(i)].occupancy < best_occupancy - kOccupancySlack) continue;
    if (best < 0 || better(candidates[size_t(i)], candidates[size_t(best)])) best = i;
  }
  return packWithWidth(base, tiles, (best + 1) * cell).layout;
}

bool blockAligned(const AtlasLayout& layout) {
  std::map<std::tuple<int, int, int>, int> blocks;  // (page, block x, block y) -> tiles
  for (const AtlasPage& p : layout.pages)
    if (p.width % kBc6hTileAlign != 0 || p.height % kBc6hTileAlign != 0) return false;
  for (const AtlasEntry& e : layout.entries) {
    for (const FaceTile& t : e.faces) {
      if (!t.stored()) continue;
      if (t.x % kBc6hTileAlign != 0 || t.y % kBc6hTileAlign != 0) return false;
      if (e.id.size < kBc6hTileAlign &&
          ++blocks[{t.page, t.x / kBc6hTileAlign, t.y / kBc6hTileAlign}] > 1)
        return false;
    }
  }
  return true;
}

}  // namespace rdm
