// The face light on Vulkan (docs/spec.md section 3.2, docs/vulkan.md "Face light"): the kernel
// traces the CPU's face-light paths (keys, Sobol directions, face points), one job per exposed
// face, and the host sums them in the CPU's order. The two agree per face within the
// cross-backend tolerance below; an update on the device equals a full device bake bit for
// bit; a stop returns early. Without a Vulkan device the tests fail (test_requirements.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "rdm/bake/face_light.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "test_scenes.h"
#include "vulkan_bake_support.h"

namespace rdm {
namespace {

FaceLight bakeOnDevice(VulkanBaker& baker, const VoxelWorld& world, const Scene& scene, int spp,
                       PathStats* stats = nullptr) {
  VulkanFaceLightTracer tracer(baker);
  FaceLightOptions o;
  o.spp = spp;
  auto light = bakeFaceLightOn(tracer, world, scene, o, stats);
  if (!light) ADD_FAILURE() << light.error();
  return light ? std::move(*light) : FaceLight{};
}

struct FaceAgreement {
  size_t faces = 0, failures = 0;
  double max_abs_diff = 0.0, mean_cpu = 0.0, mean_vk = 0.0;
};

// Same paths on both sides, so a face differs only where the kernel's float arithmetic took
// another branch than the CPU's (a walk tie, an FMA): per face |dL| <= 1e-4 L + 1e-6 on all
// but 0.1 % of the faces, and the mean over every face within 1e-5 relative.
FaceAgreement compareLights(const FaceLight& cpu, const FaceLight& vk) {
  FaceAgreement g;
  EXPECT_EQ(cpu.slots.size(), vk.slots.size());
  EXPECT_EQ(cpu.scene_digest, vk.scene_digest);
  EXPECT_EQ(cpu.spp, vk.spp);
  for (size_t s = 0; s < std::min(cpu.slots.size(), vk.slots.size()); ++s) {
    const FaceLightSlot &a = cpu.slots[s], &b = vk.slots[s];
    EXPECT_EQ(a.slot, b.slot);
    EXPECT_EQ(a.faces, b.faces);
    if (a.light.size() != b.light.size()) {
      ADD_FAILURE() << "slot " << s << ": " << a.light.size() << " vs " << b.light.size();
      continue;
    }
    for (size_t f = 0; f < a.light.size(); ++f) {
      ++g.faces;
      bool bad = false;
      for (int c = 0; c < 3; ++c) {
        const double la = a.light[f][c], lb = b.light[f][c];
        g.max_abs_diff = std::max(g.max_abs_diff, std::abs(la - lb));
        g.mean_cpu += la, g.mean_vk += lb;
        if (!(std::abs(la - lb) <= 1e-4 * std::abs(la) + 1e-6)) bad = true;
      }
      g.failures += bad ? 1 : 0;
    }
  }
  return g;
}

void expectAgreement(const Scene& scene, int spp, const std::string& what) {
  const VoxelWorld world = buildWorld(scene);
  FaceLightOptions o;
  o.spp = spp;
  o.threads = 2;
  PathStats cpu_stats, vk_stats;
  const FaceLight cpu = bakeFaceLight(world, scene, o, &cpu_stats);
  auto baker = test::makeVulkanBaker();
  ASSERT_TRUE(baker);
  const FaceLight vk = bakeOnDevice(*baker, world, scene, spp, &vk_stats);
  const FaceAgreement g = compareLights(cpu, vk);
  std::printf(
      "%s: %zu faces, %zu outside the per-face tolerance, max |dL| %.3g, means %.6g / %.6g\n",
      what.c_str(), g.faces, g.failures, g.max_abs_diff, g.mean_cpu, g.mean_vk);
  EXPECT_GT(g.faces, 0u);
  EXPECT_LE(double(g.failures), 0.001 * double(g.faces)) << what;
  EXPECT_NEAR(g.mean_vk, g.mean_cpu, 1e-5 * std::abs(g.mean_cpu) + 1e-6) << what;
  // The kernel counts every segment and shadow ray as the CPU does.
  EXPECT_NEAR(double(vk_stats.rays), double(cpu_stats.rays), 0.01 * double(cpu_stats.rays)) << what;
}

TEST(VulkanFaceLight, AgreesWithTheCpuOnEveryLightPath) {
  RDM_REQUIRE_VULKAN();
  expectAgreement(test::hardScene(), 16, "hard scene (mirror, glossy, lamp, sun)");
}

TEST(VulkanFaceLight, AgreesWithTheCpuOnTheBuiltInScenes) {
  RDM_REQUIRE_VULKAN();
  for (const char* name : {"chess", "island"}) {
    auto scene = builtinScene(name);
    ASSERT_TRUE(scene) << scene.error();
    scene->bake.max_bounces = std::min(scene->bake.max_bounces, 2);
    expectAgreement(*scene, 2, name);
  }
}

TEST(VulkanFaceLight, AnUpdateOnTheDeviceEqualsAFullDeviceBakeBitForBit) {
  RDM_REQUIRE_VULKAN();
  const Scene before_scene = test::hardScene();
  const Scene after_scene = test::withoutPlacementAt(before_scene, {1, 1, 1});
  const VoxelWorld before = buildWorld(before_scene), after = buildWorld(after_scene);
  auto baker = test::makeVulkanBaker();
  ASSERT_TRUE(baker);
  FaceLight light = bakeOnDevice(*baker, before, before_scene, 8);
  VulkanFaceLightTracer tracer(*baker);
  auto stale = updateFaceLightOn(tracer, before, after, before_scene.bake, light);
  ASSERT_TRUE(stale) << stale.error();
  EXPECT_FALSE(stale->empty());
  const FaceLight full = bakeOnDevice(*baker, after, after_scene, 8);
  ASSERT_EQ(light.slots.size(), full.slots.size());
  size_t rebaked = 0;  // the other slots keep the light of `before` (docs/spec.md section 3.2)
  for (size_t s = 0; s < full.slots.size(); ++s) {
    EXPECT_EQ(light.slots[s].slot, full.slots[s].slot);
    if (std::find(stale->begin(), stale->end(), full.slots[s].slot) == stale->end()) continue;
    ++rebaked;
    EXPECT_EQ(light.slots[s].faces, full.slots[s].faces) << "slot " << s;
    EXPECT_TRUE(light.slots[s].light == full.slots[s].light) << "slot " << s;
  }
  EXPECT_EQ(rebaked, stale->size());
}

TEST(VulkanFaceLight, AStopReturnsEarlyWithoutAnError) {
  RDM_REQUIRE_VULKAN();
  const Scene scene = test::hardScene();
  const VoxelWorld world = buildWorld(scene);
  auto baker = test::makeVulkanBaker();
  ASSERT_TRUE(baker);
  std::atomic<bool> stop{true};
  VulkanFaceLightTracer tracer(*baker);
  FaceLightOptions o;
  o.spp = 8;
  o.stop = &stop;
  size_t reported = 0;
  o.on_progress = [&](const FaceLightProgress& p) { reported = std::max(reported, p.slots_done); };
  auto light = bakeFaceLightOn(tracer, world, scene, o);
  ASSERT_TRUE(light) << light.error();
  size_t lit = 0;
  for (const FaceLightSlot& s : light->slots) lit += s.light.size() == s.faces.size() ? 1 : 0;
  EXPECT_EQ(reported, 0u);
  EXPECT_LT(lit, light->slots.size());
}

}  // namespace
}  // namespace rdm
