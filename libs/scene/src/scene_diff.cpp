#include "rdm/scene/scene_diff.h"

#include <set>

namespace rdm {
namespace {

std::vector<const Placement*> slotMap(const Scene& s) {
  std::vector<const Placement*> map(size_t(s.size[0]) * s.size[1] * s.size[2], nullptr);
  for (const Placement& p : s.placements) {
    map[size_t(p.at[0]) + size_t(s.size[0]) * (size_t(p.at[1]) + size_t(s.size[1]) * p.at[2])] = &p;
  }
  return map;
}

std::set<int> changedPaletteIndices(const Scene& a, const Scene& b) {
  std::set<int> changed;
  size_t n = std::max(a.palette.size(), b.palette.size());
  for (size_t i = 0; i < n; ++i) {
    bool same = i < a.palette.size() && i < b.palette.size() && a.palette[i] == b.palette[i];
    if (!same) changed.insert(int(i) + 1);
  }
  return changed;
}

bool usesAny(const Block& block, const std::set<int>& indices) {
  if (indices.empty()) return false;
  for (uint8_t v : block.voxels) {
    if (v && indices.count(v)) return true;
  }
  return false;
}

void globalChanges(const Scene& a, const Scene& b, SceneDiff& diff) {
  auto note = [&](bool differs, const char* name) {
    if (differs) diff.global_changes.push_back(name);
  };
  note(a.size != b.size, "size");
  note(a.sun != b.sun, "sun");
  note(a.sky != b.sky, "sky");
  note(a.emission_scale != b.emission_scale, "emission_scale");
  note(a.ambient != b.ambient, "ambient");
  note(a.bake != b.bake, "bake");
  diff.dirty_all = !diff.global_changes.empty();
}

}  // namespace

SceneDiff diffScenes(const Scene& a, const Scene& b) {
  SceneDiff diff;
  globalChanges(a, b, diff);
  if (a.size != b.size) return diff;
  const std::set<int> palette = changedPaletteIndices(a, b);
  std::set<std::string> dirty_blocks;  // redefined, or using a changed palette index
  for (const auto& [name, block] : b.blocks) {
    auto it = a.blocks.find(name);
    if (it == a.blocks.end() || !(it->second == block) || usesAny(block, palette))
      dirty_blocks.insert(name);
  }
  for (const auto& [name, block] : a.blocks) {
    if (!b.blocks.count(name) || usesAny(block, palette)) dirty_blocks.insert(name);
  }
  std::vector<const Placement*> ma = slotMap(a), mb = slotMap(b);
  for (size_t i = 0; i < ma.size(); ++i) {
    const Placement *pa = ma[i], *pb = mb[i];
    if (!pa && !pb) continue;
    bool changed =
        !pa || !pb || pa->block != pb->block || pa->rot != pb->rot || dirty_blocks.count(pb->block);
    if (!changed) continue;
    const int x = b.size[0], y = b.size[1];
    diff.changed_slots.push_back(
        {int(i % size_t(x)), int(i / size_t(x) % size_t(y)), int(i / size_t(x * y))});
  }
  return diff;
}

bool emittersDiffer(const VoxelWorld& a, const VoxelWorld& b) {
  const auto &ea = a.emitters.emitters, &eb = b.emitters.emitters;
  if (ea.size() != eb.size()) return true;
  for (size_t i = 0; i < ea.size(); ++i) {
    if (ea[i].voxel != eb[i].voxel || ea[i].face != eb[i].face || ea[i].radiance != eb[i].radiance)
      return true;
  }
  return false;
}

}  // namespace rdm
