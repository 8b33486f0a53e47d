// The prefiltered estimator on Vulkan (docs/spec.md section 3.1, docs/vulkan.md): the kernel
// traces each face's radiance map (Owen-scrambled Sobol footprint points, the CPU's path keys)
// and the host derives every level with the CPU's FaceMapBuilder and FaceMapDerivation. Agrees
// with the CPU bake within docs/spec.md section 5's tolerances on the built-in scenes and a
// scene with every light path; bit-identical across batch and dispatch splits; slot sets
// recorded for the map's paths. Without a Vulkan device the tests fail (test_requirements.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <string>
#include <vector>

#include "bake_agreement.h"
#include "bake_identity.h"
#include "rdm/bake/bake.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "test_scenes.h"
#include "vulkan_bake_support.h"

namespace rdm {
namespace {

using test::bitIdentical;
using test::expectAgreement;

BakeSettings prefiltered(BakeSettings s) {
  s.estimator = Estimator::kPrefiltered;
  return s;
}

BakeResult bakeCpu(const VoxelWorld& world, const BakeSettings& settings,
                   const std::vector<RdmId>& ids, bool record = false) {
  BakeOptions o;
  o.threads = 2;
  o.record_slot_sets = record;
  return bakeRdms(world, prefiltered(settings), ids, o);
}

BakeResult bakeVk(const VoxelWorld& world, const BakeSettings& settings,
                  const std::vector<RdmId>& ids, const VulkanBakeOptions& o = {}) {
  auto r = bakeRdmsVulkan(world, prefiltered(settings), ids, o);
  if (!r) ADD_FAILURE() << r.error();
  return r ? std::move(*r) : BakeResult{};
}

// Prefiltered bakes of `scene` on both backends agree (same RDMs, face counts, rays within 1 %).
void expectBackendsAgree(const Scene& scene, const std::string& what) {
  const VoxelWorld world = buildWorld(scene);
  const BakeSettings settings = prefiltered(scene.bake);
  const std::vector<RdmId> ids = listRdms(world, settings);
  const BakeResult cpu = bakeCpu(world, settings, ids);
  VulkanBakeInfo info;
  VulkanBakeOptions o;
  o.info = &info;
  const BakeResult vk = bakeVk(world, settings, ids, o);
  uint64_t rough = 0;  // texels of rough levels, which the device's prefilter pass derives
  for (const RdmData& d : vk.rdms) {
    if (d.id.level == 0 || d.id.level == shared::kDiffuseLevel) continue;
    for (int f = 0; f < 6; ++f) rough += d.skipped[size_t(f)] ? 0 : uint64_t(d.id.size) * d.id.size;
  }
  EXPECT_GT(rough, 0u) << what;
  EXPECT_EQ(info.texels_prefiltered, rough) << what;
  ASSERT_EQ(vk.rdms.size(), cpu.rdms.size()) << what;
  EXPECT_EQ(vk.report.faces_baked, cpu.report.faces_baked) << what;
  EXPECT_EQ(vk.report.faces_skipped, cpu.report.faces_skipped) << what;
  EXPECT_NEAR(double(vk.report.rays), double(cpu.report.rays), 0.01 * double(cpu.report.rays))
      << what;
  expectAgreement(cpu, vk, what.c_str());
  // Same path keys and footprint points, so the same paths: texels differ by float rounding
  // (GLSL sin/cos, contraction), far below the statistical tolerance that would also pass
  // other random numbers.
  EXPECT_LE(test::compareBakes(cpu, vk).max_abs_diff, 1e-3) << what;
}

// Built-in scenes at reduced sampling: a few lavapipe seconds each.
Scene reduced(const std::string& name, int spp, int max_hemisphere) {
  Scene s = *builtinScene(name);
  s.bake.spp = spp;
  s.bake.max_hemisphere = max_hemisphere;
  s.bake.max_bounces = std::min(s.bake.max_bounces, 3);
  return s;
}

TEST(VulkanPrefiltered, AgreesWithCpuOnMirrorGlossyEmitterSunScene) {
  RDM_REQUIRE_VULKAN();
  Scene s = test::hardScene();
  s.bake = {8, 4, 5, 8};
  expectBackendsAgree(s, "prefiltered: mirror + glossy + emitter + sun");
}

TEST(VulkanPrefiltered, AgreesWithCpuOnChessAndMirrorFloor) {
  RDM_REQUIRE_VULKAN();
  expectBackendsAgree(reduced("chess", 4, 8), "prefiltered chess (spp 4, S <= 8)");
  expectBackendsAgree(reduced("mirror_floor", 4, 8), "prefiltered mirror_floor (spp 4, S <= 8)");
}

TEST(VulkanPrefiltered, AgreesWithCpuOnIslandAndTerrain) {
  RDM_REQUIRE_VULKAN();
  expectBackendsAgree(reduced("island", 2, 8), "prefiltered island (spp 2, S <= 8)");
  expectBackendsAgree(reduced("terrain", 1, 4), "prefiltered terrain (spp 1, S <= 4)");
}

// Maps split across batches and paths suspended mid-walk: the same bits, and the same slot
// sets with recording on; recording changes no bit.
TEST(VulkanPrefiltered, BitIdenticalAcrossSplitsWithTheSameSlotSets) {
  RDM_REQUIRE_VULKAN();
  Scene s = test::hardScene();
  s.bake = {4, 4, 2, 8};
  const VoxelWorld world = buildWorld(s);
  const std::vector<RdmId> ids = listRdms(world, prefiltered(s.bake));
  VulkanBakeOptions rec;
  rec.record_slot_sets = true;
  const BakeResult plain = bakeVk(world, s.bake, ids);
  const BakeResult recorded = bakeVk(world, s.bake, ids, rec);
  EXPECT_TRUE(bitIdentical(plain, recorded)) << "recording changed the image or its errors";
  VulkanBakeOptions split = rec;
  split.max_batch_paths = 96;
  split.loop_budget = 400;
  split.max_prefilter_texels = 64;  // the prefilter pass runs between batches too
  VulkanBakeInfo info;
  split.info = &info;
  const BakeResult cut = bakeVk(world, s.bake, ids, split);
  EXPECT_GT(info.batches, 10u);
  EXPECT_GT(info.prefilter_dispatches, 2u);
  EXPECT_GT(info.max_dispatches_per_batch, 1u);
  EXPECT_TRUE(bitIdentical(plain, cut));
  ASSERT_EQ(cut.rdms.size(), recorded.rdms.size());
  for (size_t r = 0; r < cut.rdms.size(); ++r) {
    EXPECT_EQ(cut.rdms[r].full_set, recorded.rdms[r].full_set) << "rdm " << r;
    EXPECT_EQ(cut.rdms[r].first_set, recorded.rdms[r].first_set) << "rdm " << r;
    EXPECT_EQ(cut.rdms[r].smooth_vertex, recorded.rdms[r].smooth_vertex) << "rdm " << r;
  }
}

// Each RDM's sets hold its map's paths: the CPU's sets, up to the float-rounding splits the
// naive estimator's test allows (vulkan_slot_sets_test.cpp), 1 % of the entries either way.
TEST(VulkanPrefiltered, SlotSetsMatchTheCpuClosely) {
  RDM_REQUIRE_VULKAN();
  Scene s = reduced("chess", 4, 8);
  const VoxelWorld world = buildWorld(s);
  const std::vector<RdmId> ids = listRdms(world, prefiltered(s.bake));
  VulkanBakeOptions rec;
  rec.record_slot_sets = true;
  const BakeResult vk = bakeVk(world, s.bake, ids, rec);
  const BakeResult cpu = bakeCpu(world, s.bake, ids, true);
  ASSERT_EQ(vk.rdms.size(), cpu.rdms.size());
  size_t entries = 0, differ = 0, smooth_differ = 0;
  for (size_t r = 0; r < vk.rdms.size(); ++r) {
    const auto& v = vk.rdms[r].full_set;
    const auto& c = cpu.rdms[r].full_set;
    std::vector<uint32_t> diff;
    std::set_symmetric_difference(c.begin(), c.end(), v.begin(), v.end(), std::back_inserter(diff));
    entries += c.size(), differ += diff.size();
    smooth_differ += vk.rdms[r].smooth_vertex != cpu.rdms[r].smooth_vertex ? 1 : 0;
  }
  std::printf("[ sets ] %zu CPU full-set entries, %zu differ\n", entries, differ);
  EXPECT_GT(entries, 0u);
  EXPECT_LE(double(differ), 0.02 * double(entries));
  EXPECT_EQ(smooth_differ, 0u);
}

}  // namespace
}  // namespace rdm
