// The walk of shaders/shared/rdm_walk.h driven over a VoxelWorld on the CPU, as bake.comp and
// the viewer's in-block reflections drive it: one walkLeave per cell. It exists to check and
// time that walk (tests/trace/traversal_test.cpp holds it to referenceWalk bit for bit;
// bench/traversal_vs_embree.cpp times it); the bake takes traceVoxels, which is faster
// (docs/performance.md). Header only, so no product binary carries it.
#pragma once

#include "rdm/base/check.h"
#include "rdm/scene/world.h"
#include "rdm/trace/traversal.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {

inline TraceHit traceSharedWalk(const VoxelWorld& world, const FloatRay& ray, float& t_hit) {
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
