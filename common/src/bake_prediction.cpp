#include "rdm/bake_prediction.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <tuple>

namespace rdm {
namespace {

// Sample counts per preset; the prefiltered estimator's seed-to-seed RMSE on chess at these
// counts is docs/results.md section 2b's.
const QualityPreset kPresets[] = {{"draft", 4, 2}, {"preview", 16, 4}, {"final", 128, 6}};

// Output texels an RDM writes: its baked faces' S^2.
double outputTexels(const VoxelWorld& world, const RdmId& id) {
  int faces = 0;
  for (int f = 0; f < 6; ++f) faces += faceSkipped(world, id.slot, f) ? 0 : 1;
  return double(faces) * double(id.size) * double(id.size);
}

struct Pilot {
  double seconds = 0.0;
  double relative_error = 0.0;
};

Pilot runPilot(const VoxelWorld& world, BakeSettings settings, int spp,
               const std::vector<RdmId>& ids, int threads) {
  settings.spp = spp;
  BakeOptions o;
  o.threads = threads;
  const auto start = std::chrono::steady_clock::now();
  BakeResult r = bakeRdms(world, settings, ids, o);
  const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return {t, r.report.mean_relative_error};
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
  // Slots in canonical order of their first RDM; every k-th one is in the pilot.
  std::map<std::tuple<int, int, int>, std::vector<RdmId>> by_slot;
  std::vector<std::tuple<int, int, int>> order;
  for (const RdmId& id : rdms) {
    auto key = std::make_tuple(id.slot.x, id.slot.y, id.slot.z);
    if (!by_slot.count(key)) order.push_back(key);
    by_slot[key].push_back(id);
  }
  BakePrediction p;
  p.slots = int(order.size());
  if (order.empty()) return p;
  const size_t step = std::max<size_t>(1, order.size() / std::max<size_t>(16, order.size() / 8));
  std::vector<RdmId> pilot;
  double all_texels = 0.0, pilot_texels = 0.0;
  for (size_t i = 0; i < order.size(); ++i) {
    for (const RdmId& id : by_slot[order[i]]) {
      const double t = outputTexels(world, id);
      all_texels += t;
      if (i % step == 0) pilot.push_back(id), pilot_texels += t;
    }
    p.pilot_slots += i % step == 0 ? 1 : 0;
  }
  const int spp1 = 1, spp2 = std::max(4, settings.spp / 4);
  (void)runPilot(world, settings, 1, pilot, threads);  // builds the kernels the pilot needs
  const Pilot a = runPilot(world, settings, spp1, pilot, threads);
  const Pilot b = runPilot(world, settings, spp2, pilot, threads);
  const double per_spp = std::max(0.0, (b.seconds - a.seconds) / double(spp2 - spp1));
  const double fixed = std::max(0.0, a.seconds - per_spp * double(spp1));
  const double scale = pilot_texels > 0.0 ? all_texels / pilot_texels : 1.0;
  p.seconds = (fixed + per_spp * double(settings.spp)) * scale;
  p.relative_error = b.relative_error * std::sqrt(double(spp2) / double(settings.spp));
  p.pilot_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return p;
}

}  // namespace rdm
