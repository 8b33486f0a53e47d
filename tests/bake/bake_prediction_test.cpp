// The bake's predicted cost (docs/spec.md section 3.1, "Quality presets and prediction"): the
// cost model on pilot costs stated here, and the pilot itself on a small scene. How close the
// predictions come to measured bakes is a benchmark (docs/results.md section 2b), not a test.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <set>
#include <tuple>
#include <vector>

#include "rdm/bake/bake.h"
#include "rdm/bake/bake_prediction.h"
#include "rdm/scene/scene.h"
#include "test_scenes.h"

namespace rdm {
namespace {

// Slot s costs fixed[s] + spp * per_sample[s] CPU seconds.
struct LinearSlots {
  std::vector<double> fixed, per_sample;
  double at(size_t s, int spp) const { return fixed[s] + double(spp) * per_sample[s]; }
  double total(int spp) const {
    double t = 0.0;
    for (size_t s = 0; s < fixed.size(); ++s) t += at(s, spp);
    return t;
  }
  PilotCosts pilot(const std::vector<size_t>& sampled, int spp2) const {
    PilotCosts c;
    for (size_t s = 0; s < fixed.size(); ++s) c.at1.push_back(at(s, 1));
    c.sampled = sampled;
    for (size_t s : sampled) c.at2.push_back(at(s, spp2));
    c.spp2 = spp2;
    return c;
  }
};

// Slots whose costs differ 50-fold but share one fixed/per-sample split (island's mirror
// cube beside its grass): the 1-spp costs carry each slot's weight, so any sample predicts
// exactly. Tolerance: double rounding.
TEST(BakePrediction, ExactForAnySampleWhenSlotsShareTheirSplit) {
  LinearSlots slots;
  for (double weight : {50.0, 1.0, 1.0, 2.0, 0.5, 1.0, 7.0, 1.0}) {
    slots.fixed.push_back(0.2 * weight);
    slots.per_sample.push_back(0.8 * weight);
  }
  for (const std::vector<size_t>& sampled :
       {std::vector<size_t>{0}, std::vector<size_t>{1, 2}, std::vector<size_t>{3, 5, 7}}) {
    for (int spp : {4, 16, 128}) {
      const double predicted = predictCpuSeconds(slots.pilot(sampled, 8), spp);
      EXPECT_NEAR(predicted, slots.total(spp), 1e-9 * slots.total(spp))
          << "spp " << spp << ", first sampled slot " << sampled.front();
    }
  }
}

// A texel-count scaling would take the sample's cost per slot for every slot; weighting by
// the 1-spp costs keeps a heavy slot outside the sample in the prediction. With different
// splits the error is bounded by how far the sample's split is from the whole's.
TEST(BakePrediction, UnsampledHeavySlotStillCounts) {
  LinearSlots slots{{1.0, 0.1, 0.1, 0.1}, {9.0, 0.9, 0.8, 1.0}};
  const double predicted = predictCpuSeconds(slots.pilot({1, 2, 3}, 4), 64);
  EXPECT_NEAR(predicted / slots.total(64), 1.0, 0.02);
}

// Timer noise can make the larger run cheaper, or more than linear; the share is clamped to
// [0, 1], so the prediction stays between the 1-spp cost and spp times it.
TEST(BakePrediction, ShareIsClampedAndFixedCostAdded) {
  PilotCosts cheaper{{1.0, 2.0}, {0, 1}, {0.5, 1.0}, 4, 0.25};
  EXPECT_DOUBLE_EQ(predictCpuSeconds(cheaper, 64), 0.25 + 3.0);
  PilotCosts steeper{{1.0, 2.0}, {0, 1}, {10.0, 20.0}, 4, 0.25};
  EXPECT_DOUBLE_EQ(predictCpuSeconds(steeper, 64), 0.25 + 3.0 * 64.0);
}

// Below the resolution a prediction is a bound, not a number.
TEST(BakePrediction, TimesBelowResolutionAreStatedAsABound) {
  EXPECT_EQ(predictedTimeText(0.0004), "under 0.05 s");
  EXPECT_EQ(predictedTimeText(0.05), "0.05 s");
  EXPECT_EQ(predictedTimeText(12.345), "12.35 s");
}

// The bake reports each RDM's unit CPU time when asked; they add up to the bake's unit time.
TEST(BakePrediction, BakeReportsCpuSecondsPerRdm) {
  const Scene scene = test::randomVoxelScene(3, 2, 2, 0.3, 11);
  const VoxelWorld world = buildWorld(scene);
  const std::vector<RdmId> rdms = listRdms(world, scene.bake);
  std::vector<double> cpu;
  BakeOptions o;
  o.threads = 2;
  o.rdm_cpu_seconds = &cpu;
  const BakeResult r = bakeRdms(world, scene.bake, rdms, o);
  ASSERT_EQ(cpu.size(), rdms.size());
  for (double c : cpu) EXPECT_GE(c, 0.0);
  const double units = std::accumulate(cpu.begin(), cpu.end(), 0.0);
  EXPECT_GT(units, 0.0);
  EXPECT_LE(units, r.report.cpu_seconds * (1.0 + 1e-12));
}

// The pilot on a real bake: the slot counts (below kMinPilotSlots slots the 1-spp run is every
// slot), and the noise. The 1/sqrt(spp) scaling of the spp2 run's noise reads low on this
// sparse scene: at spp2 = 8 more texels have seen only sky of one colour and count as
// noise-free. The bound states that direction and size (0.30 and 0.22 measured, clang + ASan
// on a loaded machine: the pilot's repeat runs follow its timings); docs/results.md section 2b
// has the built-in scenes'.
TEST(BakePrediction, PilotCountsSlotsAndPredictsNoise) {
  Scene scene = test::randomVoxelScene(5, 2, 4, 0.3, 7);
  scene.bake.spp = 32;
  const VoxelWorld world = buildWorld(scene);
  const std::vector<RdmId> rdms = listRdms(world, scene.bake);
  std::vector<double> progress;
  const BakePrediction p =
      predictBake(world, scene.bake, rdms, 2, [&](double f) { progress.push_back(f); });
  std::set<std::tuple<int, int, int>> distinct;
  for (const RdmId& id : rdms) distinct.insert({id.slot.x, id.slot.y, id.slot.z});
  const int slots = int(distinct.size());
  EXPECT_EQ(p.slots, slots);
  EXPECT_EQ(p.sampled_slots, std::min(slots, kMinPilotSlots));
  EXPECT_EQ(p.pilot_slots, std::min(p.sampled_slots, kMinSecondRunSlots));
  EXPECT_EQ(p.spp2, 8);
  EXPECT_GT(p.seconds, 0.0);
  EXPECT_GT(p.cpu_seconds, 0.0);
  EXPECT_GT(p.pilot_cpu_seconds, 0.0);
  ASSERT_FALSE(progress.empty());
  EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
  EXPECT_GE(progress.front(), 0.0);
  EXPECT_EQ(progress.back(), 1.0);
  BakeOptions o;
  o.threads = 2;
  const BakeResult r = bakeRdms(world, scene.bake, rdms, o);
  const double ratio = p.relative_error / r.report.mean_relative_error;
  EXPECT_GT(ratio, 0.15);
  EXPECT_LT(ratio, 1.1);
}

// The 1-spp run's share keeps the pilot within kPilotCpuShare of the bake for every split
// between fixed and per-sample work (r), at the presets' and other sample counts.
// Tolerance: double rounding.
TEST(BakePrediction, SlotFractionBoundsThePilotForAnySplit) {
  for (int spp : {1, 2, 4, 16, 64, 128, 1024}) {
    const int spp2 = std::clamp(spp / 4, 4, 16);
    const double f = pilotSlotFraction(spp, spp2), q = kSecondRunShare;
    double worst = 0.0;
    for (int i = 0; i <= 100; ++i) {
      const double r = i / 100.0;
      const double pilot = f + q * f * (1.0 + r * (spp2 - 1));
      worst = std::max(worst, pilot / (1.0 + r * (spp - 1)));
    }
    EXPECT_LE(worst, kPilotCpuShare * (1.0 + 1e-12)) << "spp " << spp;
    EXPECT_GE(worst, kPilotCpuShare * (1.0 - 1e-12)) << "spp " << spp << ": budget unused";
  }
}

// The cores the wall time assumes: the threads asked for, within the hardware, less the load
// of the rest of the machine, but never under one core. An unread load (-1) counts as none.
TEST(BakePrediction, FreeCoresSubtractTheLoad) {
  EXPECT_DOUBLE_EQ(freeCores(2, 2, 0.0), 2.0);
  EXPECT_DOUBLE_EQ(freeCores(2, 2, 0.5), 1.5);
  EXPECT_DOUBLE_EQ(freeCores(2, 2, 1.3), 1.0);
  EXPECT_DOUBLE_EQ(freeCores(2, 2, 7.0), 1.0);
  EXPECT_DOUBLE_EQ(freeCores(2, 2, -1.0), 2.0);
  EXPECT_DOUBLE_EQ(freeCores(8, 16, 4.0), 8.0);
  EXPECT_DOUBLE_EQ(freeCores(16, 16, 4.0), 12.0);
  EXPECT_DOUBLE_EQ(freeCores(32, 16, 0.0), 16.0);
  EXPECT_DOUBLE_EQ(freeCores(1, 16, 20.0), 1.0);
}

// A sampled 1-spp run is extrapolated by bake slots per sampled slot; the fixed CPU is not.
TEST(BakePrediction, SampledSlotsAreScaledUp) {
  PilotCosts sampled{{1.0, 2.0}, {0, 1}, {2.5, 5.0}, 4, 0.25, 10.0};
  // r = (7.5 - 3) / (3 * 3) = 0.5; 10 * 3 * (1 + 0.5 * 15) = 255.
  EXPECT_DOUBLE_EQ(predictCpuSeconds(sampled, 16), 0.25 + 255.0);
}

// About 300 slots of random voxels at draft settings (4 spp, 2 bounces), every other block
// glossy (two RDMs, level 3 at S <= 16): enough work per slot that the bake's session setup
// is a small part of it, as in the worlds the pilot's budget is for.
Scene glossyWorld() {
  Scene scene = test::randomVoxelScene(12, 3, 12, 0.3, 5);
  scene.palette.push_back({{120, 140, 170}, 3, 1, 0});
  bool glossy = false;
  for (auto& [name, block] : scene.blocks) {
    glossy = !glossy;
    for (auto& v : block.voxels) v = glossy && v == 1 ? 2 : v;
  }
  scene.bake.spp = 4;
  scene.bake.max_bounces = 2;
  scene.bake.max_hemisphere = 16;
  return scene;
}

// A generated world of about 300 slots at draft settings: the pilot's CPU seconds stay within
// kPilotCpuShare of the bake it predicts. Tolerance 30 % of the share: rounding up to whole
// slots (20 of 295 slots where 19.7 were due), the two pilot runs' session setups, and the
// spread of the strided sample's slots around the mean. CPU seconds of one process, so no
// timed assertion: both sides come from the same pilot.
TEST(BakePrediction, PilotCostsAtMostATenthOfTheBake) {
  Scene scene = glossyWorld();
  const VoxelWorld world = buildWorld(scene);
  const std::vector<RdmId> rdms = listRdms(world, scene.bake);
  const BakePrediction p = predictBake(world, scene.bake, rdms, 2);
  ASSERT_GE(p.slots, 250);
  EXPECT_LT(p.sampled_slots, p.slots / 10);
  EXPECT_GT(p.cpu_seconds, 0.0);
  EXPECT_LE(p.pilot_cpu_seconds, 1.3 * kPilotCpuShare * p.cpu_seconds)
      << p.pilot_cpu_seconds << " CPU-s pilot for " << p.cpu_seconds << " CPU-s predicted";
}

// The sampled pilot's CPU prediction against the measured bake on two built-in scenes at
// draft: chess (80 slots, fixed work dominates) and island (157 slots, a mirror and lamps
// among grass). Both get the minimum sample (16 slots at 1 spp, 8 at spp2), whose draw is
// the main error: measured 0.78-0.95x on chess and 1.2-1.5x on island (docs/results.md
// section 2b). Factor 2 either way.
TEST(BakePrediction, PredictsCpuSecondsOfBuiltInScenes) {
  for (const char* name : {"chess", "island"}) {
    Expected<Scene> scene = builtinScene(name);
    ASSERT_TRUE(scene) << name;
    const BakeSettings settings = withPreset(scene->bake, *qualityPreset("draft"));
    const VoxelWorld world = buildWorld(*scene);
    const std::vector<RdmId> rdms = listRdms(world, settings);
    const BakePrediction p = predictBake(world, settings, rdms, 2);
    BakeOptions o;
    o.threads = 2;
    const BakeResult r = bakeRdms(world, settings, rdms, o);
    const double ratio = p.cpu_seconds / r.report.cpu_seconds;
    EXPECT_GT(ratio, 0.5) << name;
    EXPECT_LT(ratio, 2.0) << name;
  }
}

}  // namespace
}  // namespace rdm
