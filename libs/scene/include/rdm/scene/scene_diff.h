// Which slots changed between two versions of a scene (docs/spec.md section 8): slots whose
// placement changed, slots using a redefined block, slots containing a changed palette
// index. Changes of sun, sky, emission_scale, ambient, bake settings or size dirty all.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace rdm {

struct SceneDiff {
  bool dirty_all = false;
  std::vector<std::string> global_changes;  // names of the global fields that changed
  std::vector<glm::ivec3> changed_slots;    // sorted by linear slot index
};

SceneDiff diffScenes(const Scene& a, const Scene& b);

// The emitter lists (docs/spec.md section 5) of two worlds differ.
bool emittersDiffer(const VoxelWorld& a, const VoxelWorld& b);

}  // namespace rdm
