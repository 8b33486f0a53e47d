// What the Vulkan bake tests share: the device requirement, the naive estimator the kernel
// implements (docs/spec.md section 3.1) on both sides of every comparison, and a small scene
// with every light path the kernel has.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "rdm/bake/bake.h"
#include "rdm/scene/world.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "test_requirements.h"
#include "test_scenes.h"

namespace rdm::test {

// Why no Vulkan device is usable; empty when one is. Asked once per process.
inline const std::string& vulkanMissing() {
  static const std::string reason = [] {
    auto devices = listVulkanDevices();
    if (!devices) return devices.error();
    return devices->empty() ? std::string("vkEnumeratePhysicalDevices returned none")
                            : std::string();
  }();
  return reason;
}

// A VulkanBaker on the default device; a failure is the test's, with the Status message.
inline std::unique_ptr<VulkanBaker> makeVulkanBaker() {
  auto baker = VulkanBaker::create("");
  if (!baker) ADD_FAILURE() << baker.error();
  return baker ? std::move(*baker) : nullptr;
}

inline BakeSettings naive(BakeSettings s) {
  s.estimator = Estimator::kNaive;
  return s;
}

// A naive-estimator Vulkan bake; a failure is the test's, with the Status message.
inline BakeResult bakeVulkan(const VoxelWorld& world, const BakeSettings& settings,
                             const std::vector<RdmId>& ids, VulkanBakeOptions o = {}) {
  auto r = bakeRdmsVulkan(world, naive(settings), ids, o);
  if (!r) ADD_FAILURE() << r.error();
  return r ? std::move(*r) : BakeResult{};
}

// A wall, a mirror, a glossy metal, a lamp and the sun: every origin distribution, the
// delta lobe, MIS between BSDF, sun and emitter sampling.
inline Scene hardScene() {
  Scene s = uniformSkyScene(3, 2, 3);
  s.sky = Sky{{0.3, 0.5, 0.9}, {0.8, 0.85, 0.9}, {0.2, 0.18, 0.15}};
  s.palette = {{{255, 255, 255}, 7, 0, 0},
               {{200, 200, 210}, 0, 3, 0},
               {{180, 90, 60}, 3, 1, 0},
               {{255, 200, 120}, 7, 0, 3},
               {{90, 160, 90}, 5, 0, 0}};
  s.blocks["wall"] = blockFrom([](int x, int y, int) { return x < 4 || y < 3 ? 1 : 0; });
  s.blocks["mirror"] = blockFrom([](int x, int, int z) { return (x + z) % 3 ? 2 : 3; });
  s.blocks["lamp"] = blockFrom([](int x, int y, int z) {
    if (y < 2) return 5;
    return (x >= 6 && x < 10 && z >= 6 && z < 10 && y < 6) ? 4 : 0;
  });
  s.placements = {{{1, 0, 1}, "wall", 0},
                  {{0, 0, 1}, "mirror", 0},
                  {{1, 1, 1}, "wall", 5},
                  {{2, 0, 0}, "mirror", 7},
                  {{2, 0, 2}, "lamp", 0}};
  s.sun = Sun{{0.4, 1.0, 0.3}, {3.0, 2.9, 2.7}, 0.5};
  s.emission_scale = 4.0;
  s.bake = {16, 4, 3, 8};
  return s;
}

// hardScene() at small settings (4-16 spp would cost seconds per lavapipe bake), its world
// and all its RDMs.
struct HardCase {
  Scene scene = hardScene();
  VoxelWorld world;
  std::vector<RdmId> ids;
  HardCase() {
    scene.bake = {8, 6, 5, 4};
    world = buildWorld(scene);
    ids = listRdms(world, scene.bake);
  }
  BakeResult bake(const VulkanBakeOptions& o = {}) const {
    return bakeVulkan(world, scene.bake, ids, o);
  }
};

}  // namespace rdm::test

// Ends the calling test when no Vulkan device is usable (test_requirements.h).
#define RDM_REQUIRE_VULKAN()                             \
  RDM_TEST_REQUIRE(::rdm::test::vulkanMissing().empty(), \
                   "no Vulkan device: " << ::rdm::test::vulkanMissing())
