// Quality presets and a bake's predicted cost (docs/spec.md section 3.2): what a bake will take
// and how noisy it will be, stated before it starts.
#pragma once

#include <string>
#include <vector>

#include "rdm/bake.h"
#include "rdm/status.h"

namespace rdm {

struct QualityPreset {
  std::string name;
  int spp = 16;
  int max_bounces = 4;
};

// draft, preview or final; anything else is refused, naming the presets.
Expected<QualityPreset> qualityPreset(const std::string& name);
// "draft, preview, final"
std::string qualityPresetList();
// The preset applied to a scene's bake settings (estimator prefiltered).
BakeSettings withPreset(BakeSettings settings, const QualityPreset& preset);

struct BakePrediction {
  double seconds = 0.0;         // predicted wall time of the bake on `threads` threads
  double cpu_seconds = 0.0;     // predicted BakeReport::cpu_seconds
  double relative_error = 0.0;  // predicted mean relative standard error (the summary's)
  double pilot_seconds = 0.0;   // what the prediction itself took
  int pilot_slots = 0, slots = 0;
};

// Bakes a pilot on `threads` threads: the RDMs of every k-th slot ordered by traced texels,
// heaviest first (an eighth of the slots, at least 16, or all), once at 1 spp to build the
// kernels they need, then at 1 and at max(4, spp / 4); for a bake of spp >= 16 it costs about
// 4 % of the bake. The bake's wall time is the pilot's straight line in spp at the bake's spp,
// scaled by the traced texels of the bake over the pilot's; its CPU time likewise from the
// pilots' CPU times. The noise is the larger run's, scaled by 1/sqrt(spp).
BakePrediction predictBake(const VoxelWorld& world, const BakeSettings& settings,
                           const std::vector<RdmId>& rdms, int threads);

}  // namespace rdm
