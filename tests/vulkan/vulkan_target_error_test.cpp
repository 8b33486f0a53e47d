// Target-error sampling on Vulkan (rdm bake --target-error; docs/vulkan.md "Target error"): a
// texel group (an RDM texel, a level-7 face, a radiance-map texel) whose relative standard
// error is not below the target doubles its samples, up to spp * max_spp_factor, as the CPU's
// bake does, with the same path keys. So the two backends agree within docs/spec.md section
// 5's tolerances and take the same samples up to the few groups whose error sits at the
// target; and the device's result does not depend on how its rounds were batched. Without a
// Vulkan device the tests fail (test_requirements.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "bake_agreement.h"
#include "bake_identity.h"
#include "cli_run.h"
#include "rdm/bake/bake.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "test_scenes.h"
#include "vulkan_bake_support.h"

namespace rdm {
namespace {

constexpr double kTarget = 0.05;

BakeResult bakeCpu(const VoxelWorld& world, const BakeSettings& settings,
                   const std::vector<RdmId>& ids, double target) {
  BakeOptions o;
  o.threads = 2;
  o.target_error = target;
  o.max_spp_factor = 8;
  return bakeRdms(world, settings, ids, o);
}

BakeResult bakeVk(const VoxelWorld& world, const BakeSettings& settings,
                  const std::vector<RdmId>& ids, double target, VulkanBakeOptions o = {}) {
  o.target_error = target;
  o.max_spp_factor = 8;
  auto r = bakeRdmsVulkan(world, settings, ids, o);
  if (!r) ADD_FAILURE() << r.error();
  return r ? std::move(*r) : BakeResult{};
}

uint32_t mostSamples(const BakeResult& r) {
  uint32_t m = 0;
  for (const RdmData& d : r.rdms) m = std::max(m, d.max_samples);
  return m;
}

void expectTargetErrorAgreement(Scene scene, Estimator estimator, const std::string& what) {
  scene.bake.estimator = estimator;
  const VoxelWorld world = buildWorld(scene);
  const std::vector<RdmId> ids = listRdms(world, scene.bake);
  const BakeResult cpu = bakeCpu(world, scene.bake, ids, kTarget);
  const BakeResult vk = bakeVk(world, scene.bake, ids, kTarget);
  const BakeResult vk_plain = bakeVk(world, scene.bake, ids, 0.0);
  ASSERT_EQ(vk.rdms.size(), cpu.rdms.size()) << what;
  // Refinement ran: more paths than one pass, and some group at the cap of 8 x spp.
  EXPECT_GT(double(vk.report.rays), 1.5 * double(vk_plain.report.rays)) << what;
  EXPECT_EQ(mostSamples(vk), mostSamples(cpu)) << what;
  EXPECT_EQ(mostSamples(vk), uint32_t(8 * scene.bake.spp)) << what;
  EXPECT_NEAR(double(vk.report.rays), double(cpu.report.rays), 0.02 * double(cpu.report.rays))
      << what;
  size_t same_samples = 0;
  for (size_t r = 0; r < vk.rdms.size(); ++r)
    same_samples += vk.rdms[r].max_samples == cpu.rdms[r].max_samples ? 1 : 0;
  EXPECT_GE(double(same_samples), 0.95 * double(vk.rdms.size())) << what;
  test::expectAgreement(cpu, vk, what.c_str());
}

TEST(VulkanTargetError, AgreesWithTheCpuWithTheNaiveEstimator) {
  RDM_REQUIRE_VULKAN();
  Scene s = test::hardScene();
  s.bake = {4, 2, 3, 8};
  expectTargetErrorAgreement(s, Estimator::kNaive, "naive, target 0.05");
}

TEST(VulkanTargetError, AgreesWithTheCpuWithThePrefilteredEstimator) {
  RDM_REQUIRE_VULKAN();
  Scene s = test::hardScene();
  s.bake = {4, 2, 3, 8};
  expectTargetErrorAgreement(s, Estimator::kPrefiltered, "prefiltered, target 0.05");
}

// Rounds cut into small batches, paths suspended, and slot sets recorded: the same bits.
TEST(VulkanTargetError, TheSameBitsWhateverTheBatchesAndWithSlotSets) {
  RDM_REQUIRE_VULKAN();
  for (Estimator estimator : {Estimator::kNaive, Estimator::kPrefiltered}) {
    Scene s = test::hardScene();
    s.bake = {4, 2, 2, 8};
    s.bake.estimator = estimator;
    const VoxelWorld world = buildWorld(s);
    const std::vector<RdmId> ids = listRdms(world, s.bake);
    const BakeResult plain = bakeVk(world, s.bake, ids, kTarget);
    VulkanBakeOptions split;
    split.record_slot_sets = true;
    split.max_batch_paths = 96;
    split.loop_budget = 400;
    const BakeResult cut = bakeVk(world, s.bake, ids, kTarget, split);
    EXPECT_TRUE(test::bitIdentical(plain, cut)) << int(estimator);
    ASSERT_EQ(plain.rdms.size(), cut.rdms.size());
    for (size_t r = 0; r < plain.rdms.size(); ++r)
      EXPECT_EQ(plain.rdms[r].max_samples, cut.rdms[r].max_samples) << "rdm " << r;
  }
}

// `rdm bake --target-error` runs on Vulkan (it was refused) and reports the target.
TEST(VulkanTargetError, TheCliBakesWithATargetOnTheDevice) {
  RDM_REQUIRE_VULKAN();
  const std::string dir = tempDir("vulkan_target");
  CliResult r = runRdm(
      "bake --scene chess --spp 1 --max-hemisphere 4 --target-error 0.5 "
      "--backend vulkan --device 0 -q -o " +
      dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("target 50.00 %"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("vulkan"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace rdm
