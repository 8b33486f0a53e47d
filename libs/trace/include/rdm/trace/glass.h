// Glass in the path tracer (docs/spec.md section 5, "Glass"): a ray that refracts into a glass
// voxel walks the glass voxels behind it in a straight line until the first voxel that is not
// glass, and shadow rays cross glass in a straight line with the transmittance of a slab with
// parallel faces. Only scenes with glass (hasGlass) reach this code.
#pragma once

#include <glm/glm.hpp>

#include "rdm/scene/world.h"
#include "rdm/trace/traversal.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {

// Shadow rays cross at most this many glass regions; past them the light is blocked.
constexpr int kMaxGlassCrossings = 4;
// A path meets glass (enters, leaves or reflects off it) at most this many times, besides its
// bounces; past them it ends (total internal reflection can otherwise go on).
constexpr int kMaxGlassEvents = 32;

inline bool isGlass(const VoxelWorld& world, uint8_t palette) {
  return palette != 0 && world.materials[palette].transmission > 0.0f;
}

// Where a ray that starts in glass at `o` (on the face it entered by) leaves it: the first cell
// along d that is not a glass voxel.
struct GlassExit {
  bool left = false;         // false: the walk found no glass at o (a degenerate ray)
  bool into_opaque = false;  // the next cell is a solid voxel that is not glass
  float t = 0.0f;            // distance along d to the boundary
  int axis = -1;             // the axis crossed into the next cell
  glm::ivec3 cell{0};        // the next cell (it may lie outside the grid)
  uint8_t palette = 0;       // its palette index, 0 when empty or outside
};

// `visit(slot)` as traceVoxels' visitor, for every slot the walk passes through.
template <class Visitor>
GlassExit traceGlass(const VoxelWorld& world, const glm::vec3& o, const glm::vec3& d,
                     Visitor&& visit) {
  GlassExit exit;
  shared::ShWalk w;
  const glm::ivec3 extent = world.voxelExtent();
  if (!shared::walkStart(w, o, d, extent)) return exit;
  const int max_steps = extent.x + extent.y + extent.z + 8;
  for (int step = 0; step < max_steps; ++step) {
    const bool inside = glm::all(glm::greaterThanEqual(w.cell, glm::ivec3(0))) &&
                        glm::all(glm::lessThan(w.cell, extent));
    const uint8_t palette = inside ? world.voxelAt(w.cell) : 0;
    if (inside) visit(world.slotLinear(w.cell >> 4));
    if (!isGlass(world, palette)) {
      if (step == 0) return exit;
      exit.left = true, exit.into_opaque = palette != 0;
      exit.t = w.t, exit.axis = shared::entryAxis(w.mask, w.d);
      exit.cell = w.cell, exit.palette = palette;
      return exit;
    }
    shared::walkLeave(w, shared::kWalkVoxelBits);
    if (w.mask == 0) return exit;
  }
  return exit;
}

// The fraction of light a straight crossing of a glass voxel region keeps, entered at cos_i
// through its face: the transmission choice, both interfaces of a slab with parallel faces
// (1 - F)^2, and the tint.
inline glm::vec3 glassCrossing(const Material& m, float cos_i) {
  const float f = shared::fresnelDielectric(cos_i, 1.0f / m.ior);
  return m.base_color * (m.transmission * (1.0f - f) * (1.0f - f));
}

}  // namespace rdm
