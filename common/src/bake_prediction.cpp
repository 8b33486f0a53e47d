#include "rdm/bake_prediction.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <tuple>

#include "rdm/check.h"
#include "rdm/parallel.h"
#include "rdm/prefilter.h"
#include "rdm/rdm_shared_cpp.h"

namespace rdm {
namespace {

// Sample counts per preset; the prefiltered estimator's seed-to-seed RMSE on chess at these
// counts is docs/results.md section 2b's.
const QualityPreset kPresets[] = {{"draft", 4, 2}, {"preview", 16, 4}, {"final", 128, 6}};

// A pilot run shorter than this is repeated until its runs add up to it (at least 3, at
// most kMaxPilotRepeats runs), and its times are their medians: a bake of a few
// milliseconds (the furnace's) is otherwise scheduler and timer noise, which the prediction
// extrapolates many-fold.
constexpr double kMinPilotSeconds = kPredictionResolutionSeconds;
constexpr int kMaxPilotRepeats = 64;
// A bake predicted to take at least this long gets each pilot run shorter than
// kRepeatRunsBelowSeconds three times (the medians): one slow run of a 0.2 s pilot otherwise
// moves the prediction by half. Longer runs are measured once: three runs of a 2.7 s pilot
// cost 75 % of mirror_floor's final bake.
constexpr double kRepeatPilotAboveSeconds = 1.0;
constexpr double kRepeatRunsBelowSeconds = 0.25;
// The sample's spp: enough above 1 to split each slot's cost into fixed and per-sample work,
// and to measure the noise (which reads low at few samples, docs/results.md section 2b).
int secondPilotSpp(int spp) {
  return std::clamp(spp / 4, 4, 16);
}

using SlotGroups = std::vector<std::vector<RdmId>>;

// The bake's RDMs grouped by slot.
SlotGroups groupBySlot(const std::vector<RdmId>& rdms) {
  std::map<std::tuple<int, int, int>, std::vector<RdmId>> by_slot;
  for (const RdmId& id : rdms)
    by_slot[std::make_tuple(id.slot.x, id.slot.y, id.slot.z)].push_back(id);
  SlotGroups groups;
  for (auto& [key, ids] : by_slot) groups.push_back(std::move(ids));
  return groups;
}

// The prefilter kernels the bake will apply (bake.cpp's bakeFromMap: rough levels of a slot
// baked from a map), built once per process: the bake then reuses them, so the pilot must
// not time their construction as if the bake paid it.
void buildKernels(const VoxelWorld& world, const BakeSettings& settings, const SlotGroups& slots) {
  for (const std::vector<RdmId>& ids : slots) {
    const int map_level = radianceMapLevel(world, settings, ids.front().slot);
    if (map_level < 0) continue;
    const int map_size = shared::hemisphereSize(map_level, settings.max_hemisphere);
    for (const RdmId& id : ids) {
      if (id.level != 0 && id.level != shared::kDiffuseLevel)
        (void)prefilterKernel(id.level, id.size, map_size);
    }
  }
}

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + long(values.size() / 2), values.end());
  return values[values.size() / 2];
}

// The repeated runs of one pilot bake (the same slots at the same spp).
struct PilotRun {
  std::vector<size_t> slots;                 // indices into the bake's slot groups
  std::vector<double> slot_cpu_sum;          // per entry of `slots`: CPU seconds summed over runs
  std::vector<double> wall, cpu, units_cpu;  // per run
  double relative_error = 0.0;               // the same bake each time

  double cpuSeconds() const { return median(cpu); }
  // Each slot's mean over the runs, scaled so that they add up to the median run's units.
  std::vector<double> slotCpu() const {
    const double total = std::accumulate(units_cpu.begin(), units_cpu.end(), 0.0);
    const double scale = total > 0.0 ? median(units_cpu) / total : 0.0;
    std::vector<double> out;
    for (double sum : slot_cpu_sum) out.push_back(sum * scale);
    return out;
  }
};

// Runs the pilot bake of `run.slots` at `spp` until it holds at least `min_runs` runs and
// the kMinPilotSeconds rule is met.
void runPilot(const VoxelWorld& world, BakeSettings settings, int spp, const SlotGroups& groups,
              int threads, size_t min_runs, PilotRun& run) {
  settings.spp = spp;
  std::vector<RdmId> ids;
  std::map<std::tuple<int, int, int>, size_t> entry_of_slot;
  for (size_t k = 0; k < run.slots.size(); ++k) {
    const std::vector<RdmId>& group = groups[run.slots[k]];
    ids.insert(ids.end(), group.begin(), group.end());
    const glm::ivec3 s = group.front().slot;
    entry_of_slot[std::make_tuple(s.x, s.y, s.z)] = k;
  }
  std::sort(ids.begin(), ids.end(), canonicalLess);
  run.slot_cpu_sum.resize(run.slots.size(), 0.0);
  std::vector<double> rdm_cpu;
  BakeOptions o;
  o.threads = threads;
  o.rdm_cpu_seconds = &rdm_cpu;
  auto more = [&] {
    if (run.wall.size() < min_runs) return true;
    if (run.wall.front() >= kMinPilotSeconds || int(run.wall.size()) >= kMaxPilotRepeats)
      return false;
    return run.wall.size() < 3 ||
           std::accumulate(run.wall.begin(), run.wall.end(), 0.0) < kMinPilotSeconds;
  };
  while (more()) {
    const auto start = std::chrono::steady_clock::now();
    BakeResult r = bakeRdms(world, settings, ids, o);
    run.wall.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    run.cpu.push_back(r.report.cpu_seconds);
    run.units_cpu.push_back(std::accumulate(rdm_cpu.begin(), rdm_cpu.end(), 0.0));
    for (size_t i = 0; i < r.rdms.size(); ++i) {
      const glm::ivec3 s = r.rdms[i].id.slot;
      run.slot_cpu_sum[entry_of_slot.at(std::make_tuple(s.x, s.y, s.z))] += rdm_cpu[i];
    }
    run.relative_error = r.report.mean_relative_error;
  }
}

// Every k-th slot by 1-spp cost, heaviest first: an eighth of the slots, at least 16, or all,
// so the sample holds the heavy and the light slots in their proportions.
std::vector<size_t> sampleSlots(const std::vector<double>& at1) {
  std::vector<size_t> order(at1.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return at1[a] > at1[b]; });
  const size_t step = std::max<size_t>(1, order.size() / std::max<size_t>(16, order.size() / 8));
  std::vector<size_t> sampled;
  for (size_t i = 0; i < order.size(); i += step) sampled.push_back(order[i]);
  return sampled;
}

}  // namespace

Expected<QualityPreset> qualityPreset(const std::string& name) {
  for (const QualityPreset& p : kPresets) {
    if (p.name == name) return p;
  }
  return Status::invalid("quality",
                         "unknown quality '" + name + "': expected one of " + qualityPresetList());
}

std::string qualityPresetList() {
  std::string out;
  for (const QualityPreset& p : kPresets) out += (out.empty() ? "" : ", ") + p.name;
  return out;
}

BakeSettings withPreset(BakeSettings settings, const QualityPreset& preset) {
  settings.spp = preset.spp;
  settings.max_bounces = preset.max_bounces;
  settings.estimator = Estimator::kPrefiltered;
  return settings;
}

double predictCpuSeconds(const PilotCosts& costs, int spp) {
  RDM_CHECK(costs.sampled.size() == costs.at2.size() && costs.spp2 > 1);
  double sampled_at1 = 0.0, sampled_growth = 0.0;
  for (size_t k = 0; k < costs.sampled.size(); ++k) {
    sampled_at1 += costs.at1[costs.sampled[k]];
    sampled_growth += costs.at2[k] - costs.at1[costs.sampled[k]];
  }
  const double per_sample_share =
      sampled_at1 > 0.0
          ? std::clamp(sampled_growth / (double(costs.spp2 - 1) * sampled_at1), 0.0, 1.0)
          : 1.0;
  const double all_at1 = std::accumulate(costs.at1.begin(), costs.at1.end(), 0.0);
  return costs.fixed_cpu + all_at1 * (1.0 + per_sample_share * double(spp - 1));
}

std::string predictedTimeText(double seconds) {
  char text[48];
  if (seconds < kPredictionResolutionSeconds)
    std::snprintf(text, sizeof text, "under %.2f s", kPredictionResolutionSeconds);
  else
    std::snprintf(text, sizeof text, "%.2f s", seconds);
  return text;
}

BakePrediction predictBake(const VoxelWorld& world, const BakeSettings& settings,
                           const std::vector<RdmId>& rdms, int threads) {
  const auto start = std::chrono::steady_clock::now();
  const SlotGroups groups = groupBySlot(rdms);
  BakePrediction p;
  p.slots = int(groups.size());
  if (groups.empty()) return p;
  buildKernels(world, settings, groups);
  PilotRun whole;
  whole.slots.resize(groups.size());
  std::iota(whole.slots.begin(), whole.slots.end(), size_t(0));
  runPilot(world, settings, 1, groups, threads, 1, whole);
  PilotRun part;
  part.slots = sampleSlots(whole.slotCpu());
  p.pilot_slots = int(part.slots.size());
  const int spp2 = secondPilotSpp(settings.spp);
  runPilot(world, settings, spp2, groups, threads, 1, part);
  // Only CPU times enter, which a shared machine's load changes far less than wall times:
  // the units' CPU time over the bake's threads, plus the serial setup and summary.
  const double parallelism = double(std::min(workerCount(threads), workerCount(0)));
  auto predict = [&] {
    const double serial_cpu = std::max(0.0, whole.cpuSeconds() - median(whole.units_cpu));
    p.cpu_seconds = predictCpuSeconds(
        {whole.slotCpu(), part.slots, part.slotCpu(), spp2, serial_cpu}, settings.spp);
    p.seconds = serial_cpu + (p.cpu_seconds - serial_cpu) / parallelism;
  };
  predict();
  if (p.seconds >= kRepeatPilotAboveSeconds) {
    for (auto [spp, run] : {std::pair{1, &whole}, std::pair{spp2, &part}}) {
      if (run->wall.front() < kRepeatRunsBelowSeconds)
        runPilot(world, settings, spp, groups, threads, 3, *run);
    }
    predict();
  }
  p.relative_error = part.relative_error * std::sqrt(double(spp2) / double(settings.spp));
  p.pilot_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return p;
}

}  // namespace rdm
