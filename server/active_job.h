// A prepared job inside the executor: its world, the RDMs it bakes, their work units and
// how far they got. Fields below `mutex-guarded` are touched only under JobManager's mutex;
// texels of distinct units are written by workers without it (disjoint rects).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "incremental.h"
#include "job.h"
#include "rdm/bake.h"
#include "rdm/scene.h"
#include "rdm/world.h"
#include "unit_file.h"

namespace rdm::server {

struct ActiveJob {
  std::string id;
  BakeMode mode = BakeMode::kFull;
  long long seq = 0;
  BakeSettings settings;
  std::shared_ptr<const Scene> scene;
  std::unique_ptr<VoxelWorld> world;
  std::vector<RdmId> all;                // every RDM of the target version, canonical
  std::vector<RdmId> plan;               // RDMs this job bakes
  std::unique_ptr<BakeSession> storage;  // holds the plan's texels; its units() schedule
  std::vector<BakeUnit> units;
  std::vector<int> local_index;  // unit's index among its RDM's units

  // mutex-guarded
  std::vector<uint8_t> unit_state;  // 0 pending, 1 running, 2 done
  size_t cursor = 0;                // no pending unit before it
  std::vector<int> units_left;      // per plan RDM
  std::vector<RdmRecord> records;   // per plan RDM: accumulated slot sets
  int in_flight = 0;
  bool cancelled = false;

  bool hasPending() const { return !cancelled && cursor < units.size(); }
  bool finishable() const { return in_flight == 0 && (cancelled || cursor >= units.size()); }
};

}  // namespace rdm::server
