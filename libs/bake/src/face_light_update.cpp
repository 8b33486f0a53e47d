// Keeping a face light in step with an edited world (docs/spec.md section 3.2, "Edits").
#include <algorithm>
#include <set>

#include "rdm/bake/face_light.h"
#include "rdm/base/check.h"

namespace rdm {
namespace {

bool sameVoxels(const VoxelWorld& a, const VoxelWorld& b, const glm::ivec3& s) {
  const int32_t ba = a.blockAt(s), bb = b.blockAt(s);
  if (ba < 0 || bb < 0) return ba == bb;
  return a.blocks[size_t(ba)].voxels == b.blocks[size_t(bb)].voxels;
}

// The slots of `after` to re-bake: those whose voxels changed, and their 6-neighbours whose
// exposed faces no longer match the stored ones; (i, j, k) lexicographic.
std::vector<glm::ivec3> staleSlots(const VoxelWorld& before, const VoxelWorld& after,
                                   const FaceLight& light) {
  auto less = [](const glm::ivec3& a, const glm::ivec3& b) { return slotOrderLess(a, b); };
  std::set<glm::ivec3, decltype(less)> changed(less), stale(less);
  for (int k = 0; k < after.size.z; ++k)
    for (int j = 0; j < after.size.y; ++j)
      for (int i = 0; i < after.size.x; ++i)
        if (!sameVoxels(before, after, {i, j, k})) changed.insert({i, j, k});
  for (const glm::ivec3& s : changed) {
    if (after.blockAt(s) >= 0) stale.insert(s);
    for (int f = 0; f < shared::kFaceCount; ++f) {
      const glm::ivec3 n = s + shared::faceNormal(f);
      if (after.blockAt(n) < 0 || changed.count(n)) continue;
      auto it = std::find_if(light.slots.begin(), light.slots.end(),
                             [&](const FaceLightSlot& l) { return l.slot == n; });
      if (it == light.slots.end() || it->faces != exposedFaces(after, n)) stale.insert(n);
    }
  }
  return {stale.begin(), stale.end()};
}

}  // namespace

Expected<std::vector<glm::ivec3>> updateFaceLightOn(FaceLightTracer& tracer,
                                                    const VoxelWorld& before,
                                                    const VoxelWorld& after,
                                                    const BakeSettings& settings, FaceLight& light,
                                                    const std::atomic<bool>* stop) {
  if (light.slots.empty() || light.spp == 0) return std::vector<glm::ivec3>();
  const std::vector<glm::ivec3> stale = staleSlots(before, after, light);
  std::vector<FaceLightSlot> baked(stale.size());
  for (size_t i = 0; i < stale.size(); ++i) {
    baked[i].slot = stale[i];
    baked[i].faces = exposedFaces(after, stale[i]);
  }
  FaceLightTraceHooks hooks;
  hooks.stop = stop;
  if (Status s = tracer.trace(after, settings, int(light.spp), baked, hooks); !s) return s;
  if (stop && stop->load(std::memory_order_relaxed)) return stale;  // incomplete
  std::vector<FaceLightSlot> kept;
  for (FaceLightSlot& s : light.slots) {
    const bool replaced = std::binary_search(stale.begin(), stale.end(), s.slot, slotOrderLess);
    if (!replaced && after.blockAt(s.slot) >= 0) kept.push_back(std::move(s));
  }
  for (FaceLightSlot& s : baked) kept.push_back(std::move(s));
  std::sort(kept.begin(), kept.end(), [](const FaceLightSlot& a, const FaceLightSlot& b) {
    return slotOrderLess(a.slot, b.slot);
  });
  light.slots = std::move(kept);
  return stale;
}

std::vector<glm::ivec3> updateFaceLight(const VoxelWorld& before, const VoxelWorld& after,
                                        const BakeSettings& settings, FaceLight& light, int threads,
                                        const std::atomic<bool>* stop) {
  CpuFaceLightTracer tracer(threads);
  auto stale = updateFaceLightOn(tracer, before, after, settings, light, stop);
  RDM_CHECK(stale.ok() && "the CPU tracer never fails");
  return std::move(*stale);
}

}  // namespace rdm
