#include <algorithm>
#include <cmath>

#include "rdm/atlas.h"

namespace rdm {
namespace {

struct Cell {
  int x, y, size;  // size S: the cell is 2S x 3S
};

struct Candidate {
  AtlasLayout layout;
  double occupancy = 0.0;
  int extent = 0;  // largest page side
};

// Packs in rows whose cell size is the first remaining RDM's size; smaller RDMs split a
// cell into four quadrants (TL, TR, BL, BR), which tile a 2S x 3S cell exactly.
Candidate packWithWidth(const std::vector<RdmId>& rdms, int width) {
  Candidate c;
  std::vector<Cell> free_cells;  // front = next to use
  int page = 0, row_y = 0;
  c.layout.pages.push_back({0, 0});
  for (const RdmId& id : rdms) {
    if (free_cells.empty()) {
      int cell_height = 3 * id.size;
      if (row_y + cell_height > kMaxPageSize) {
        ++page, row_y = 0;
        c.layout.pages.push_back({0, 0});
      }
      for (int x = width - 2 * id.size; x >= 0; x -= 2 * id.size)
        free_cells.push_back({x, row_y, id.size});
      row_y += cell_height;
    }
    while (free_cells.back().size > id.size) {
      Cell big = free_cells.back();
      free_cells.pop_back();
      int s = big.size / 2;
      free_cells.push_back({big.x + 2 * s, big.y + 3 * s, s});
      free_cells.push_back({big.x, big.y + 3 * s, s});
      free_cells.push_back({big.x + 2 * s, big.y, s});
      free_cells.push_back({big.x, big.y, s});
    }
    Cell cell = free_cells.back();
    free_cells.pop_back();
    c.layout.entries.push_back({id, page, cell.x, cell.y});
    AtlasPage& p = c.layout.pages[page];
    p.width = std::max(p.width, cell.x + 2 * id.size);
    p.height = std::max(p.height, cell.y + 3 * id.size);
  }
  c.occupancy = c.layout.occupancy();
  for (const AtlasPage& p : c.layout.pages) c.extent = std::max({c.extent, p.width, p.height});
  return c;
}

constexpr double kOccupancySlack = 0.01;

bool better(const Candidate& a, const Candidate& b) {
  if (a.layout.pages.size() != b.layout.pages.size())
    return a.layout.pages.size() < b.layout.pages.size();
  if (a.extent != b.extent) return a.extent < b.extent;
  return a.occupancy > b.occupancy;
}

}  // namespace

double AtlasLayout::occupancy() const {
  double used = 0.0, total = 0.0;
  for (const AtlasEntry& e : entries) used += 6.0 * e.id.size * e.id.size;
  for (const AtlasPage& p : pages) total += double(p.width) * p.height;
  return total > 0.0 ? used / total : 0.0;
}

const AtlasEntry* AtlasLayout::find(const glm::ivec3& slot, int level) const {
  for (const AtlasEntry& e : entries) {
    if (e.id.slot == slot && e.id.level == level) return &e;
  }
  return nullptr;
}

AtlasLayout packCanonical(std::vector<RdmId> rdms) {
  std::sort(rdms.begin(), rdms.end(), canonicalLess);
  if (rdms.empty()) return AtlasLayout{};
  const int cell_width = 2 * rdms.front().size;
  double area = 0.0;
  for (const RdmId& id : rdms) area += 6.0 * id.size * id.size;
  const int max_columns =
      std::min(kMaxPageSize / cell_width,
               std::max(1, int(std::ceil(2.0 * std::sqrt(area) / cell_width)) + 1));
  std::vector<Candidate> candidates;
  double best_occupancy = 0.0;
  for (int columns = 1; columns <= max_columns; ++columns) {
    candidates.push_back(packWithWidth(rdms, columns * cell_width));
    best_occupancy = std::max(best_occupancy, candidates.back().occupancy);
  }
  // Within kOccupancySlack of the best occupancy, the squarest layout wins.
  const Candidate* best = nullptr;
  for (const Candidate& c : candidates) {
    if (c.occupancy < best_occupancy - kOccupancySlack) continue;
    if (!best || better(c, *best)) best = &c;
  }
  return best->layout;
}

}  // namespace rdm
