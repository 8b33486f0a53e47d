#include "rdm/bake/rebake_selection.h"

#include <algorithm>
#include <map>
#include <tuple>

#include "rdm/scene/world.h"

namespace rdm {
namespace {

using Key = std::tuple<int, int, int, int>;  // slot, level
Key keyOf(const RdmId& id) {
  return {id.slot.x, id.slot.y, id.slot.z, id.level};
}

// Linear indices of changed slots and of their 6-neighbours in the grid.
void changedAndNeighbours(const VoxelWorld& w, const SceneDiff& diff,
                          std::vector<uint32_t>& changed, std::vector<uint8_t>& near) {
  near.assign(w.slots.size(), 0);
  static const glm::ivec3 kSteps[] = {{0, 0, 0},  {1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                      {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const glm::ivec3& s : diff.changed_slots) {
    changed.push_back(uint32_t(w.slotLinear(s)));
    for (const glm::ivec3& d : kSteps) {
      if (w.slotInGrid(s + d)) near[size_t(w.slotLinear(s + d))] = 1;
    }
  }
  std::sort(changed.begin(), changed.end());
}

}  // namespace

const char* modeName(BakeMode m) {
  return m == BakeMode::kFull ? "full" : (m == BakeMode::kExact ? "exact" : "fast");
}

bool parseMode(const std::string& text, BakeMode& mode) {
  for (BakeMode m : {BakeMode::kFull, BakeMode::kExact, BakeMode::kFast}) {
    if (text == modeName(m)) return mode = m, true;
  }
  return false;
}

RebakeSelection selectRebake(BakeMode mode, const SceneDiff& diff, bool emitters_changed,
                             const VoxelWorld& target, const std::vector<RdmId>& target_rdms,
                             const std::vector<RdmRecord>& base_rdms) {
  RebakeSelection sel;
  std::map<Key, const RdmRecord*> base;
  for (const RdmRecord& r : base_rdms) base[keyOf(r.id)] = &r;
  std::vector<uint32_t> changed;
  std::vector<uint8_t> near;
  changedAndNeighbours(target, diff, changed, near);
  for (const RdmId& id : target_rdms) {
    auto it = base.find(keyOf(id));
    const RdmRecord* b = it == base.end() || it->second->id.size != id.size ? nullptr : it->second;
    bool bake = true;
    if (diff.dirty_all) {
      sel.by_slot++;
    } else if (!b) {
      sel.new_rdms++;
    } else if (near[size_t(target.slotLinear(id.slot))]) {
      sel.by_slot++;
    } else if ((mode == BakeMode::kFast ? b->first_set : b->full_set).meets(changed)) {
      sel.by_set++;
    } else if (mode == BakeMode::kExact && emitters_changed && b->smooth) {
      sel.by_emitters++;
    } else {
      bake = false;
    }
    (bake ? sel.rebake : sel.copy).push_back(id);
  }
  return sel;
}

void orderByVisibility(std::vector<RdmId>& plan, const SceneDiff& diff, const VoxelWorld& target,
                       const std::vector<RdmRecord>& base_rdms) {
  std::map<Key, const RdmRecord*> base;
  for (const RdmRecord& r : base_rdms) base[keyOf(r.id)] = &r;
  std::vector<uint32_t> changed;
  std::vector<uint8_t> near;
  changedAndNeighbours(target, diff, changed, near);
  auto distance = [&](const RdmId& id) {
    int best = 1 << 30;
    for (const glm::ivec3& c : diff.changed_slots) {
      const glm::ivec3 d = glm::abs(c - id.slot);
      best = std::min(best, std::max(d.x, std::max(d.y, d.z)));
    }
    return best;
  };
  auto rank = [&](const RdmId& id) {
    if (near[size_t(target.slotLinear(id.slot))]) return 0;
    auto it = base.find(keyOf(id));
    return it != base.end() && it->second->first_set.meets(changed) ? 1 : 2;
  };
  std::vector<std::tuple<int, int, size_t>> order;
  for (size_t i = 0; i < plan.size(); ++i) order.emplace_back(rank(plan[i]), distance(plan[i]), i);
  std::sort(order.begin(), order.end());
  std::vector<RdmId> out;
  out.reserve(plan.size());
  for (const auto& [r, d, i] : order) out.push_back(plan[i]);
  plan.swap(out);
}

}  // namespace rdm
