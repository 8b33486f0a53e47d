#include "rdm/trace/traversal.h"

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {

float exactCentralDepth(const VoxelWorld& world, const glm::ivec3& origin, const glm::ivec3& dir,
                        std::vector<uint32_t>* slots) {
  ExactRay ray(origin, dir);
  ExactRay::Time t;
  int last = -1;
  TraceHit hit = traceVoxels(world, ray, t, [&](int slot) {
    if (slots && slot != last) slots->push_back(uint32_t(slot)), last = slot;
  });
  if (!hit.hit) return shared::kSkyDepth;
  if (hit.started_solid) return 0.0f;
  double length = std::sqrt(double(dir.x) * dir.x + double(dir.y) * dir.y + double(dir.z) * dir.z);
  return float(double(t.num) / double(t.den) * length / 16.0);
}

TraceHit traceSharedWalk(const VoxelWorld& world, const FloatRay& ray, float& t_hit) {
  TraceHit hit;
  shared::ShWalk w;
  const glm::ivec3 extent = world.voxelExtent();
  if (!shared::walkStart(w, ray.o, ray.d, extent)) return hit;
  const bool regular = shared::walkRegular(w);
  const int max_steps = extent.x + extent.y + extent.z + 8;
  for (int step = 0;; ++step) {
    RDM_CHECK(step < max_steps);  // every cell the walk enters is new
    const int32_t block = world.slots[size_t(world.slotLinear(w.cell >> 4))];
    const glm::ivec3 l = w.cell & 15;
    const int brick = shared::walkBrickIndex(l);
    const int bits =
        block < 0
            ? shared::kWalkSlotBits
            : shared::walkBlockStepBits(
                  uint32_t(world.occupancy[size_t(block)].bricks >> (brick & 32)), brick, regular);
    const uint8_t p = bits != shared::kWalkVoxelBits
                          ? 0
                          : world.blocks[size_t(block)].voxels[l.x + 16 * l.y + 256 * l.z];
    if (p != 0) {
      hit.hit = true, hit.voxel = w.cell, hit.palette = p;
      hit.axis = step == 0 && w.mask == 0 ? -1 : shared::entryAxis(w.mask, w.d);
      hit.started_solid = hit.axis < 0;
      t_hit = w.t;
      return hit;
    }
    shared::walkLeave(w, bits);
    if (w.mask == 0 || glm::any(glm::lessThan(w.cell, glm::ivec3(0))) ||
        glm::any(glm::greaterThanEqual(w.cell, extent)))
      return hit;
  }
}

}  // namespace rdm
