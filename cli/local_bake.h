// The CPU bake as `rdm bake` runs it: a thread pool over one BakeSession (the same work
// units and bit-identical results as bakeRdms), reporting progress in texels so the ETA is
// weighted by each unit's cost, and stopping between units when `options.cancel` is set.
#pragma once

#include <functional>
#include <vector>

#include "rdm/bake.h"

namespace rdm::cli {

struct LocalBakeProgress {
  uint64_t texels_done = 0, texels_total = 0;
  int rdms_done = 0, rdms_total = 0;
  uint64_t rays = 0;
  double seconds = 0.0;
};

// Bakes `rdms` with options.threads, options.target_error, options.max_spp_factor and
// options.cancel; `on_progress` is called from the calling thread about every 20 ms.
BakeResult runLocalBake(const VoxelWorld& world, const BakeSettings& settings,
                        const std::vector<RdmId>& rdms, const BakeOptions& options,
                        const std::function<void(const LocalBakeProgress&)>& on_progress);

// This shard's RDMs in canonical order (index % count == shard index).
std::vector<RdmId> shardRdms(const VoxelWorld& world, const BakeSettings& settings, int shard_index,
                             int shard_count);

}  // namespace rdm::cli
