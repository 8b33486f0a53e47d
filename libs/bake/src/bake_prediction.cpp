#include "rdm/bake/bake_prediction.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <tuple>

#include "rdm/bake/prefilter.h"
#include "rdm/base/check.h"
#include "rdm/base/parallel.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

// Sample counts per preset; the prefiltered estimator's seed-to-seed RMSE on chess at these
// counts is docs/results.md section 2b's.
const QualityPreset kPresets[] = {{"draft", 4, 2}, {"preview", 16, 4}, {"final", 128, 6}};

// A bake predicted to take at least kCheapBakeCpuSeconds gets each pilot run shorter than
// kRepeatRunsBelowSeconds three times (the medians) where the budget allows: one slow run of
// a 0.2 s pilot otherwise moves the prediction by half.
constexpr double kRepeatRunsBelowSeconds = 0.25;
// Of the progress reported, the share the two pilot runs' first passes take; the repeats
// fill the rest.
constexpr double kFirstPassesProgress = 0.95;
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

// Runs the pilot bake of `run.slots` at `spp` until it holds `runs` runs; `progress` sees
// each run's fraction done.
void runPilot(const VoxelWorld& world, BakeSettings settings, int spp, const SlotGroups& groups,
              int threads, size_t runs, PilotRun& run,
              const std::function<void(double)>& progress) {
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
  if (progress) {
    o.on_progress = [&progress](const BakeProgress& b) {
      if (b.texels_total > 0) progress(double(b.texels_done) / double(b.texels_total));
    };
  }
  while (run.wall.size() < runs) {
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

// A slot's texels: 6 S^2 per RDM (2S x 3S images), the work a slot holds before any is timed.
double slotTexels(const std::vector<RdmId>& ids) {
  double texels = 0.0;
  for (const RdmId& id : ids) texels += 6.0 * double(id.size) * double(id.size);
  return texels;
}

// `count` of the slot groups, evenly spaced (starting half a stride in) along the slots
// ordered by texels, most first, then by slot order: the sample holds the large and the small
// slots in their proportions, and a stride does not alias with a regular layout as much.
std::vector<size_t> firstRunSlots(const SlotGroups& groups, size_t count) {
  std::vector<double> texels;
  for (const std::vector<RdmId>& ids : groups) texels.push_back(slotTexels(ids));
  std::vector<size_t> order(groups.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return texels[a] > texels[b]; });
  std::vector<size_t> out;
  for (size_t i = 0; i < count; ++i) {
    const auto at = size_t((double(i) + 0.5) * double(order.size()) / double(count));
    out.push_back(order[std::min(order.size() - 1, at)]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Positions in `at1` of `count` entries evenly spaced by 1-spp cost, heaviest first, so the
// sample holds the heavy and the light slots in their proportions.
std::vector<size_t> secondRunEntries(const std::vector<double>& at1, size_t count) {
  std::vector<size_t> order(at1.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return at1[a] > at1[b]; });
  std::vector<size_t> sampled;
  for (size_t i = 0; i < count; ++i) sampled.push_back(order[i * order.size() / count]);
  return sampled;
}

// Slots in the 1-spp run and in the spp2 run for a bake of `slots` slots.
std::pair<size_t, size_t> pilotCounts(size_t slots, int spp, int spp2) {
  const size_t min1 = std::min(slots, size_t(kMinPilotSlots));
  const auto want1 = size_t(std::ceil(pilotSlotFraction(spp, spp2) * double(slots)));
  const size_t first = std::clamp(want1, min1, slots);
  const size_t min2 = std::min(first, size_t(kMinSecondRunSlots));
  const auto want2 = size_t(std::ceil(kSecondRunShare * double(first)));
  return {first, std::clamp(want2, min2, first)};
}

double pilotCpu(const PilotRun& run) {
  return std::accumulate(run.cpu.begin(), run.cpu.end(), 0.0);
}

// Brings each run shorter than kRepeatRunsBelowSeconds to three runs while the pilot's CPU
// seconds, its two extra runs included, stay within `budget_cpu`.
void repeatShortRuns(const VoxelWorld& world, const BakeSettings& settings,
                     const SlotGroups& groups, int threads, double budget_cpu,
                     const std::vector<std::pair<int, PilotRun*>>& runs) {
  double spent = 0.0;
  for (const auto& [spp, run] : runs) spent += pilotCpu(*run);
  for (const auto& [spp, run] : runs) {
    const double extra = 2.0 * run->cpu.front();
    if (run->wall.front() >= kRepeatRunsBelowSeconds || spent + extra > budget_cpu) continue;
    runPilot(world, settings, spp, groups, threads, 3, *run, {});
    spent += pilotCpu(*run) - run->cpu.front();
  }
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
  RDM_CHECK(costs.sampled.size() == costs.at2.size() && costs.spp2 > 1 && costs.scale > 0.0);
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
  return costs.fixed_cpu + costs.scale * all_at1 * (1.0 + per_sample_share * double(spp - 1));
}

std::string predictedTimeText(double seconds) {
  char text[48];
  if (seconds < kPredictionResolutionSeconds)
    std::snprintf(text, sizeof text, "under %.2f s", kPredictionResolutionSeconds);
  else
    std::snprintf(text, sizeof text, "%.2f s", seconds);
  return text;
}

double pilotSlotFraction(int spp, int spp2) {
  RDM_CHECK(spp >= 1 && spp2 >= 1);
  const double q = kSecondRunShare;
  return kPilotCpuShare / std::max(1.0 + q, (1.0 + q * double(spp2)) / double(spp));
}

bool pilotWorthRunning(double estimated_cpu_seconds) {
  return estimated_cpu_seconds >= kSkipPilotBelowEstimatedCpuSeconds;
}

double freeCores(int threads, int hardware_threads, double load) {
  RDM_CHECK(threads >= 1 && hardware_threads >= 1);
  const double idle = std::max(1.0, double(hardware_threads) - std::max(0.0, load));
  return std::min({double(threads), double(hardware_threads), idle});
}

double loadAverage1() {
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  if (!f) return -1.0;
  double load = -1.0;
  if (std::fscanf(f, "%lf", &load) != 1) load = -1.0;
  std::fclose(f);
  return load;
}

BakePrediction predictBake(const VoxelWorld& world, const BakeSettings& settings,
                           const std::vector<RdmId>& rdms, int threads,
                           const PilotProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  BakePrediction p;
  p.load_average = loadAverage1();
  const SlotGroups groups = groupBySlot(rdms);
  p.slots = int(groups.size());
  p.spp2 = secondPilotSpp(settings.spp);
  p.free_cores = freeCores(workerCount(threads), workerCount(0), p.load_average);
  if (groups.empty()) {
    if (progress) progress(1.0);
    return p;
  }
  buildKernels(world, settings, groups);
  const auto [count1, count2] = pilotCounts(groups.size(), settings.spp, p.spp2);
  // Progress weights: slots times spp, the fixed work counted as one sample.
  const double weight1 = double(count1), weight2 = double(count2) * double(p.spp2 + 1) / 2.0;
  const double split = kFirstPassesProgress * weight1 / (weight1 + weight2);
  auto phase = [&progress](double from, double to) -> std::function<void(double)> {
    if (!progress) return {};
    return [&progress, from, to](double f) { progress(from + (to - from) * f); };
  };
  PilotRun whole;
  whole.slots = firstRunSlots(groups, count1);
  runPilot(world, settings, 1, groups, threads, 1, whole, phase(0.0, split));
  const std::vector<size_t> entries = secondRunEntries(whole.slotCpu(), count2);
  PilotRun part;
  for (size_t e : entries) part.slots.push_back(whole.slots[e]);
  runPilot(world, settings, p.spp2, groups, threads, 1, part, phase(split, kFirstPassesProgress));
  p.sampled_slots = int(count1);
  p.pilot_slots = int(count2);
  const double scale = double(groups.size()) / double(count1);
  auto predict = [&] {
    // Only CPU times enter, which a shared machine's load changes far less than wall times:
    // the units' CPU time over the free cores, plus the serial setup and summary.
    const double serial_cpu = std::max(0.0, whole.cpuSeconds() - median(whole.units_cpu));
    p.cpu_seconds = predictCpuSeconds(
        {whole.slotCpu(), entries, part.slotCpu(), p.spp2, serial_cpu, scale}, settings.spp);
    p.seconds = serial_cpu + (p.cpu_seconds - serial_cpu) / p.free_cores;
  };
  predict();
  p.cheap = p.cpu_seconds < kCheapBakeCpuSeconds;
  if (!p.cheap) {
    repeatShortRuns(world, settings, groups, threads, kPilotCpuShare * p.cpu_seconds,
                    {{1, &whole}, {p.spp2, &part}});
    predict();
  }
  p.pilot_cpu_seconds = pilotCpu(whole) + pilotCpu(part);
  p.relative_error = part.relative_error * std::sqrt(double(p.spp2) / double(settings.spp));
  p.pilot_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (progress) progress(1.0);
  return p;
}

}  // namespace rdm
