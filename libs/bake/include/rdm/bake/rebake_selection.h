// Which RDMs an incremental job re-bakes (docs/spec.md section 8). Mode exact re-bakes (i) RDMs of
// changed slots, (ii) RDMs of occupied 6-neighbours of changed slots, (iii) every RDM whose
// full set meets a changed slot, (iv) after an emitter-list change every RDM with a
// non-delta path vertex. Mode fast re-bakes (i), (ii) and every RDM whose first-segment set
// meets a changed slot. RDMs new in the target are always baked; a dirty-all diff re-bakes
// everything. Everything else is copied from the base job.
#pragma once

#include <string>
#include <vector>

#include "rdm/bake/bake.h"
#include "rdm/bake/unit_checkpoint.h"
#include "rdm/scene/scene_diff.h"

namespace rdm {

// full: every RDM; exact: bit-identical to a full bake of the new scene; fast: first-segment
// dependents only (an approximation that skips far reflections and emitter changes).
enum class BakeMode { kFull, kExact, kFast };
const char* modeName(BakeMode m);
bool parseMode(const std::string& text, BakeMode& mode);

struct RebakeSelection {
  std::vector<RdmId> rebake, copy;  // canonical order each
  int new_rdms = 0, by_slot = 0, by_set = 0, by_emitters = 0;
};

RebakeSelection selectRebake(BakeMode mode, const SceneDiff& diff, bool emitters_changed,
                             const VoxelWorld& target, const std::vector<RdmId>& target_rdms,
                             const std::vector<RdmRecord>& base_rdms);

// The order an incremental job bakes its plan in (docs/spec.md, "Progressive rebakes"): RDMs
// of changed slots and their 6-neighbours, then RDMs whose first segments met a changed slot
// in the base (what a viewer sees directly in reflections), then the rest; within each
// rank nearer to a change first (Chebyshev slot distance), then canonical order.
void orderByVisibility(std::vector<RdmId>& plan, const SceneDiff& diff, const VoxelWorld& target,
                       const std::vector<RdmRecord>& base_rdms);

}  // namespace rdm
