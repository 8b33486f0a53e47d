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
  double seconds = 0.0;            // predicted wall time of the bake on `threads` threads
  double cpu_seconds = 0.0;        // predicted BakeReport::cpu_seconds
  double relative_error = 0.0;     // predicted mean relative standard error (the summary's)
  double pilot_seconds = 0.0;      // what the prediction itself took
  int pilot_slots = 0, slots = 0;  // slots in the second pilot run, and in the bake
};

// What the pilot measured, per slot of the bake (CPU seconds of the slot's units).
struct PilotCosts {
  std::vector<double> at1;      // every slot at 1 spp
  std::vector<size_t> sampled;  // the slots also baked at spp2 ...
  std::vector<double> at2;      // ... and their costs there, in the same order
  int spp2 = 4;
  double fixed_cpu = 0.0;  // CPU seconds outside the units (session setup, summary) at 1 spp
};

// The bake's CPU seconds at `spp`: each slot costs fixed + spp * per_sample, and the share
// r = per_sample / (fixed + per_sample) is estimated over the sampled slots, weighted by
// their 1-spp cost: fixed_cpu + sum(at1) * (1 + r (spp - 1)), with r clamped to [0, 1].
// Exact when every slot has the same r; the 1-spp costs carry each slot's own weight.
double predictCpuSeconds(const PilotCosts& costs, int spp);

// Bakes a pilot on `threads` threads (0: all cores), after building the prefilter kernels
// the bake needs (the bake then reuses them): every slot at 1 spp, timing each slot's units,
// then the RDMs of every k-th slot ordered by that time, heaviest first (an eighth of the
// slots, at least 16, or all), at spp2 = clamp(spp / 4, 4, 16). The CPU time is
// predictCpuSeconds; the wall time is the serial part (session setup, summary) plus the
// units' CPU time over min(threads, hardware threads): it assumes the bake gets its cores,
// which the CPU time does not. The noise is the second run's, scaled by sqrt(spp2 / spp).
// docs/results.md section 2b has what the pilot costs beside the bake.
BakePrediction predictBake(const VoxelWorld& world, const BakeSettings& settings,
                           const std::vector<RdmId>& rdms, int threads);

// The shortest bake time a prediction states as a number: a shorter bake is scheduler and
// timer noise on a shared machine (the furnace's 0.2-0.6 ms bakes vary 2-fold run to run).
constexpr double kPredictionResolutionSeconds = 0.05;
// "1.23 s", or "under 0.05 s" below kPredictionResolutionSeconds.
std::string predictedTimeText(double seconds);

}  // namespace rdm
