// Quality presets and a bake's predicted cost (docs/spec.md section 3.2): what a bake will take
// and how noisy it will be, stated before it starts.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "rdm/bake/bake.h"
#include "rdm/base/status.h"

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
  double seconds = 0.0;            // predicted wall time of the bake on `free_cores` cores
  double cpu_seconds = 0.0;        // predicted BakeReport::cpu_seconds
  double relative_error = 0.0;     // predicted mean relative standard error (the summary's)
  double pilot_seconds = 0.0;      // wall time the prediction itself took
  double pilot_cpu_seconds = 0.0;  // the pilot bakes' CPU seconds (kernels excluded): the
                                   // kPilotCpuShare rule holds when this is at most
                                   // kPilotCpuShare * cpu_seconds
  int sampled_slots = 0;           // slots in the 1-spp pilot run
  int pilot_slots = 0, slots = 0;  // slots in the spp2 pilot run, and in the bake
  int spp2 = 0;                    // the second run's samples per texel
  bool cheap = false;              // cpu_seconds < kCheapBakeCpuSeconds: the pilot ran each
                                   // run once and the numbers are rough
  double free_cores = 1.0;         // the parallelism `seconds` assumed (freeCores)
  double load_average = 0.0;       // /proc/loadavg's 1-minute load before the pilot; -1: unread
};

// What the pilot measured, per sampled slot (CPU seconds of the slot's units).
struct PilotCosts {
  std::vector<double> at1;      // each slot of the 1-spp run
  std::vector<size_t> sampled;  // indices into at1 of the slots also baked at spp2 ...
  std::vector<double> at2;      // ... and their costs there, in the same order
  int spp2 = 4;
  double fixed_cpu = 0.0;  // CPU seconds outside the units (session setup, summary) at 1 spp
  double scale = 1.0;      // bake slots per slot of the 1-spp run (slots / at1.size())
};

// The bake's CPU seconds at `spp`: each slot costs fixed + spp * per_sample, and the share
// r = per_sample / (fixed + per_sample) is estimated over the sampled slots, weighted by
// their 1-spp cost: fixed_cpu + scale * sum(at1) * (1 + r (spp - 1)), with r clamped to
// [0, 1]. Exact when every slot has the same r and the 1-spp run's slots cost on average
// what the bake's do; the 1-spp costs carry each slot's own weight.
double predictCpuSeconds(const PilotCosts& costs, int spp);

// The pilot's CPU budget as a share of the bake it predicts.
constexpr double kPilotCpuShare = 0.10;
// The share of the 1-spp run's slots that the spp2 run bakes again.
constexpr double kSecondRunShare = 0.5;
// Fewest slots in the 1-spp run and in the spp2 run (all, in a scene with fewer): below
// that, which slots the stride hits moves the prediction more than the budget saves.
constexpr int kMinPilotSlots = 16;
constexpr int kMinSecondRunSlots = 8;
// A bake predicted below this many CPU seconds is cheap: its pilot is not repeated, and
// its minimum sample may cost more than kPilotCpuShare of it.
constexpr double kCheapBakeCpuSeconds = 1.0;

// The implicit pilot of --quality is skipped when it would cost more than kMaxPilotShare of
// the bake. A pilot costs at least kMinPilotCpuSeconds (kMinPilotSlots slots at 1 spp and
// kMinSecondRunSlots at spp2, two bake sessions: 0.30-0.39 CPU-s measured on chess draft and
// preview), and estimateBake's CPU seconds overstate a prefiltered bake about
// kEstimateOverstatement-fold (chess draft 2.6 estimated / 1.2 measured, preview 16.2 / 3.9),
// so a bake estimated below kSkipPilotBelowEstimatedCpuSeconds (4.8) runs without one.
// --predict runs it whatever it costs.
constexpr double kMaxPilotShare = 0.25;
constexpr double kMinPilotCpuSeconds = 0.4;
constexpr double kEstimateOverstatement = 3.0;
constexpr double kSkipPilotBelowEstimatedCpuSeconds =
    kMinPilotCpuSeconds / kMaxPilotShare * kEstimateOverstatement;
// True when a bake of `estimated_cpu_seconds` (estimateBake) is worth its pilot.
bool pilotWorthRunning(double estimated_cpu_seconds);

// The share of the bake's slots the 1-spp run bakes: with q = kSecondRunShare, the pilot
// costs (f + q f (1 + r (spp2 - 1))) / (1 + r (spp - 1)) of the bake for a per-sample share
// r, largest at r = 0 or r = 1 (measured: chess draft r ~ 0.1, a 5,000-RDM world ~ 1), so
// f = kPilotCpuShare / max(1 + q, (1 + q spp2) / spp) keeps it within kPilotCpuShare for
// any r. Session setup and rounding up to whole slots come on top.
double pilotSlotFraction(int spp, int spp2);

// The cores a bake on `threads` threads gets on a machine with `hardware_threads` whose
// 1-minute load average (runnable threads, /proc/loadavg) is `load` without the bake:
// min(threads, hardware_threads, max(1, hardware_threads - load)). Fractional: 0.5 cores
// are half a core's time.
double freeCores(int threads, int hardware_threads, double load);
// /proc/loadavg's 1-minute load average; -1 where it cannot be read.
double loadAverage1();

// The pilot's progress: fraction of its expected work done, in [0, 1], non-decreasing.
using PilotProgress = std::function<void(double fraction)>;

// Bakes a pilot on `threads` threads (0: all cores), after building the prefilter kernels
// the bake needs (the bake then reuses them): of the slots sorted by texels (most first,
// ties in slot order), a pilotSlotFraction share evenly spaced (at least kMinPilotSlots) at
// 1 spp, timing each slot's units, then every k-th of those ordered by that time, heaviest first
// (kSecondRunShare of them, at least kMinSecondRunSlots), at spp2 = clamp(spp / 4, 4, 16).
// The CPU time is predictCpuSeconds, extrapolated by slots / sampled slots. Unless the bake
// is cheap, runs under 0.25 s are repeated (three runs, the medians) while the pilot stays
// within kPilotCpuShare. The wall time is the serial part (session setup, summary) plus the
// units' CPU time over freeCores(threads, hardware threads, load before the pilot): the load
// is read before the pilot so that the pilot's own threads are not counted. The noise is the
// second run's, scaled by sqrt(spp2 / spp). `progress` (optional) is called from the calling
// thread as the pilot advances, ending at 1. docs/results.md section 2b has what the pilot
// costs beside the bake.
BakePrediction predictBake(const VoxelWorld& world, const BakeSettings& settings,
                           const std::vector<RdmId>& rdms, int threads,
                           const PilotProgress& progress = {});

// The shortest bake time a prediction states as a number: a shorter bake is scheduler and
// timer noise on a shared machine (the furnace's 0.2-0.6 ms bakes vary 2-fold run to run).
constexpr double kPredictionResolutionSeconds = 0.05;
// "1.23 s", or "under 0.05 s" below kPredictionResolutionSeconds.
std::string predictedTimeText(double seconds);

}  // namespace rdm
