#include "rdm/bake_prediction.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <tuple>

#include "rdm/rdm_shared_cpp.h"

namespace rdm {
namespace {

// Sample counts per preset; the prefiltered estimator's seed-to-seed RMSE on chess at these
// counts is docs/results.md section 2b's.
const QualityPreset kPresets[] = {{"draft", 4, 2}, {"preview", 16, 4}, {"final", 128, 6}};

// Texels a slot's RDMs trace per sample over their baked faces: one map per face for a
// prefiltered block with a rough level, else every RDM's own S^2.
double tracedTexels(const VoxelWorld& world, const BakeSettings& settings,
                    const std::vector<RdmId>& ids) {
  const glm::ivec3 slot = ids.front().slot;
  int faces = 0;
  for (int f = 0; f < 6; ++f) faces += faceSkipped(world, slot, f) ? 0 : 1;
  const int map_level = radianceMapLevel(world, settings, slot);
  if (map_level >= 0) {
    const double s = shared::hemisphereSize(map_level, settings.max_hemisphere);
    return double(faces) * s * s;
  }
  double texels = 0.0;
  for (const RdmId& id : ids) texels += double(faces) * double(id.size) * double(id.size);
  return texels;
}

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + long(values.size() / 2), values.end());
  return values[values.size() / 2];
}

struct Pilot {
  std::vector<double> runs, cpu_runs;  // wall and CPU seconds of each run of the same bake
  double relative_error = 0.0;
  double seconds() const { return median(runs); }
  double cpuSeconds() const { return median(cpu_runs); }
};

// A pilot run shorter than this is repeated until its runs add up to it (at least 3, at
// most kMaxPilotRepeats runs), and its time is their median: a bake of a few milliseconds
// (the furnace's) is otherwise scheduler and timer noise, which the straight line in spp
// extrapolates 30-fold, and one stalled run of island's 20 ms pilot made the mean 3-4x too
// large.
constexpr double kMinPilotSeconds = 0.05;
constexpr int kMaxPilotRepeats = 64;
// A bake predicted to take at least this long gets both pilot runs three times (the
// median): their noise is extrapolated 4-fold or more, and one slow run of island's final
// pilot (0.2 s) predicted 1.6x. The extra runs cost under 25 % of such a bake.
constexpr double kRepeatPilotAboveSeconds = 1.0;

// Runs the pilot bake of `ids` at `spp` until `pilot` holds at least `min_runs` runs and
// the kMinPilotSeconds rule is met.
void runPilot(const VoxelWorld& world, BakeSettings settings, int spp,
              const std::vector<RdmId>& ids, int threads, size_t min_runs, Pilot& pilot) {
  settings.spp = spp;
  BakeOptions o;
  o.threads = threads;
  auto more = [&] {
    const std::vector<double>& runs = pilot.runs;
    if (runs.size() < min_runs) return true;
    if (runs.front() >= kMinPilotSeconds || int(runs.size()) >= kMaxPilotRepeats) return false;
    double total = 0.0;
    for (double r : runs) total += r;
    return runs.size() < 3 || total < kMinPilotSeconds;
  };
  while (more()) {
    const auto start = std::chrono::steady_clock::now();
    BakeResult r = bakeRdms(world, settings, ids, o);
    pilot.runs.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    pilot.cpu_runs.push_back(r.report.cpu_seconds);
    pilot.relative_error = r.report.mean_relative_error;  // the same bake each time
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

BakePrediction predictBake(const VoxelWorld& world, const BakeSettings& settings,
                           const std::vector<RdmId>& rdms, int threads) {
  const auto start = std::chrono::steady_clock::now();
  std::map<std::tuple<int, int, int>, std::vector<RdmId>> by_slot;
  for (const RdmId& id : rdms)
    by_slot[std::make_tuple(id.slot.x, id.slot.y, id.slot.z)].push_back(id);
  BakePrediction p;
  p.slots = int(by_slot.size());
  if (by_slot.empty()) return p;
  // Slots by traced texels, heaviest first; every k-th one is in the pilot, so it holds the
  // heavy and the light slots in their proportions.
  std::vector<std::pair<double, const std::vector<RdmId>*>> slots;
  for (const auto& [key, ids] : by_slot)
    slots.push_back({tracedTexels(world, settings, ids), &ids});
  std::stable_sort(slots.begin(), slots.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  const size_t step = std::max<size_t>(1, slots.size() / std::max<size_t>(16, slots.size() / 8));
  std::vector<RdmId> pilot;
  double all_texels = 0.0, pilot_texels = 0.0;
  for (size_t i = 0; i < slots.size(); ++i) {
    all_texels += slots[i].first;
    if (i % step != 0) continue;
    pilot.insert(pilot.end(), slots[i].second->begin(), slots[i].second->end());
    pilot_texels += slots[i].first;
    ++p.pilot_slots;
  }
  std::sort(pilot.begin(), pilot.end(), canonicalLess);
  const int spp1 = 1, spp2 = std::max(4, settings.spp / 4);
  Pilot warm, a, b;
  runPilot(world, settings, 1, pilot, threads, 1, warm);  // builds the kernels the pilot needs
  runPilot(world, settings, spp1, pilot, threads, 1, a);
  runPilot(world, settings, spp2, pilot, threads, 1, b);
  const double scale = pilot_texels > 0.0 ? all_texels / pilot_texels : 1.0;
  // The straight line through the two pilots' times, at the bake's spp, scaled up.
  auto predict = [&](double at1, double at2) {
    const double per_spp = std::max(0.0, (at2 - at1) / double(spp2 - spp1));
    const double fixed = std::max(0.0, at1 - per_spp * double(spp1));
    return (fixed + per_spp * double(settings.spp)) * scale;
  };
  p.seconds = predict(a.seconds(), b.seconds());
  if (p.seconds >= kRepeatPilotAboveSeconds) {
    runPilot(world, settings, spp1, pilot, threads, 3, a);
    runPilot(world, settings, spp2, pilot, threads, 3, b);
    p.seconds = predict(a.seconds(), b.seconds());
  }
  p.cpu_seconds = predict(a.cpuSeconds(), b.cpuSeconds());
  p.relative_error = b.relative_error * std::sqrt(double(spp2) / double(settings.spp));
  p.pilot_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return p;
}

}  // namespace rdm
