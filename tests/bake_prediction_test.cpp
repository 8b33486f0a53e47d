// The bake's predicted cost (docs/spec.md section 3.1, "Quality presets and prediction"): the
// cost model on pilot costs stated here, and the pilot itself on a small scene. How close the
// predictions come to measured bakes is a benchmark (docs/results.md section 2b), not a test.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <set>
#include <tuple>
#include <vector>

#include "rdm/bake.h"
#include "rdm/bake_prediction.h"
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

// The pilot on a real bake: the slot counts (under 32 slots the sample is every slot), and the
// noise. The 1/sqrt(spp) scaling of the spp2 run's noise reads low on this sparse scene: at
// spp2 = 8 more texels have seen only sky of one colour and count as noise-free. The bound
// states that direction and size; docs/results.md section 2b has the built-in scenes'.
TEST(BakePrediction, PilotCountsSlotsAndPredictsNoise) {
  Scene scene = test::randomVoxelScene(5, 2, 4, 0.3, 7);
  scene.bake.spp = 32;
  const VoxelWorld world = buildWorld(scene);
  const std::vector<RdmId> rdms = listRdms(world, scene.bake);
  const BakePrediction p = predictBake(world, scene.bake, rdms, 2);
  std::set<std::tuple<int, int, int>> distinct;
  for (const RdmId& id : rdms) distinct.insert({id.slot.x, id.slot.y, id.slot.z});
  const int slots = int(distinct.size());
  EXPECT_EQ(p.slots, slots);
  EXPECT_EQ(p.pilot_slots, slots);
  EXPECT_GT(p.seconds, 0.0);
  EXPECT_GT(p.cpu_seconds, 0.0);
  BakeOptions o;
  o.threads = 2;
  const BakeResult r = bakeRdms(world, scene.bake, rdms, o);
  const double ratio = p.relative_error / r.report.mean_relative_error;
  EXPECT_GT(ratio, 0.3);
  EXPECT_LT(ratio, 1.1);
}

}  // namespace
}  // namespace rdm
