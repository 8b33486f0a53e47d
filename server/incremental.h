// Which RDMs an incremental job re-bakes (SPEC section 8). Mode exact re-bakes (i) RDMs of
// changed slots, (ii) RDMs of occupied 6-neighbours of changed slots, (iii) every RDM whose
// full set meets a changed slot, (iv) after an emitter-list change every RDM with a
// non-delta path vertex. Mode fast re-bakes (i), (ii) and every RDM whose first-segment set
// meets a changed slot. RDMs new in the target are always baked; a dirty-all diff re-bakes
// everything. Everything else is copied from the base job.
#pragma once

#include <vector>

#include "job.h"
#include "rdm/bake.h"
#include "scene_diff.h"
#include "unit_file.h"

namespace rdm::server {

struct RebakeSelection {
  std::vector<RdmId> rebake, copy;  // canonical order each
  int new_rdms = 0, by_slot = 0, by_set = 0, by_emitters = 0;
};

RebakeSelection selectRebake(BakeMode mode, const SceneDiff& diff, bool emitters_changed,
                             const VoxelWorld& target, const std::vector<RdmId>& target_rdms,
                             const std::vector<RdmRecord>& base_rdms);

}  // namespace rdm::server
