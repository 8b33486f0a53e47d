#include "rdm/atlas/atlas_compare.h"

#include <cmath>
#include <map>
#include <tuple>

#include "rdm/scene/lights.h"

namespace rdm {

namespace {

float texelLuminance(const Image& page, int x, int y) {
  return luminance(glm::vec3(page.at(x, y, 0), page.at(x, y, 1), page.at(x, y, 2)));
}

// Adds face `f` of `a` against `b`'s (same size): |lum a - lum b| against `reference`'s
// luminance, where b's depth is above 0 (a reference) or always (a pair, against the mean).
void addFace(const LoadedAtlas& atlas_a, const FaceTile& a, const LoadedAtlas& atlas_b,
             const FaceTile& b, int size, bool against_b, LuminanceSums& sums) {
  const Image& page_a = atlas_a.pages[size_t(a.page)];
  const Image& page_b = atlas_b.pages[size_t(b.page)];
  for (int j = 0; j < size; ++j) {
    for (int i = 0; i < size; ++i) {
      if (!(page_b.at(b.x + i, b.y + j, 3) > 0.0f)) continue;
      const float la = texelLuminance(page_a, a.x + i, a.y + j);
      const float lb = texelLuminance(page_b, b.x + i, b.y + j);
      sums.difference += std::abs(double(la) - double(lb));
      sums.value += against_b ? lb : 0.5 * (double(la) + double(lb));
      ++sums.texels;
    }
  }
}

}  // namespace

LevelSums atlasError(const LoadedAtlas& a, const LoadedAtlas& ref) {
  std::map<SlotLevelKey, const AtlasEntry*> in_ref;
  for (const AtlasEntry& e : ref.layout.entries) in_ref[slotLevelKey(e.id.slot, e.id.level)] = &e;
  LevelSums sums{};
  for (const AtlasEntry& e : a.layout.entries) {
    auto it = in_ref.find(slotLevelKey(e.id.slot, e.id.level));
    if (it == in_ref.end() || it->second->id.size != e.id.size) continue;
    for (int f = 0; f < 6; ++f) {
      const FaceTile& ta = e.faces[size_t(f)];
      const FaceTile& tr = it->second->faces[size_t(f)];
      if (ta.stored() && tr.stored())
        addFace(a, ta, ref, tr, e.id.size, true, sums[size_t(e.id.level)]);
    }
  }
  return sums;
}

LevelSums borderDifference(const LoadedAtlas& atlas) {
  std::map<SlotLevelKey, const AtlasEntry*> entries;
  for (const AtlasEntry& e : atlas.layout.entries)
    entries[slotLevelKey(e.id.slot, e.id.level)] = &e;
  LevelSums sums{};
  for (const AtlasEntry& e : atlas.layout.entries) {
    for (int f = 0; f < 6; ++f) {
      const FaceTile& t = e.faces[size_t(f)];
      if (!t.stored()) continue;
      // Each pair once: the neighbour one step up each in-plane axis.
      for (int axis = 0; axis < 3; ++axis) {
        if (axis == f / 2) continue;
        glm::ivec3 slot = e.id.slot;
        slot[axis] += 1;
        auto it = entries.find(slotLevelKey(slot, e.id.level));
        if (it == entries.end() || it->second->id.size != e.id.size) continue;
        const FaceTile& other = it->second->faces[size_t(f)];
        if (other.stored())
          addFace(atlas, t, atlas, other, e.id.size, false, sums[size_t(e.id.level)]);
      }
    }
  }
  return sums;
}

}  // namespace rdm
