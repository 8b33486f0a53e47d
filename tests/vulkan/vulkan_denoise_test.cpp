// The Vulkan denoiser (rdm/vulkan/vulkan_denoise.h, docs/denoise.md) against the CPU's: both
// run shaders/shared/rdm_denoise.h, so every texel agrees up to the device's exp() and the
// order of float sums (tolerance: 1e-5 relative, plus 1e-7 absolute). On a baked island at
// 1 spp through the whole stream (neighbours, several batches and bands), and on a grid of
// synthetic blocks with every kind of texel the filter treats apart (dead, no standard error,
// below the floor) and skipped faces. Without a Vulkan device the tests fail
// (test_requirements.h); CI always has lavapipe.
#include "rdm/vulkan/vulkan_denoise.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "rdm/bake/bake.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "vulkan_bake_support.h"

namespace rdm {
namespace {

std::string spillDir() {
  const std::string dir = testing::TempDir() + "/vulkan_denoise_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  return dir;
}

// The RDMs of `rdms` denoised on the CPU (device null) or on `device`.
std::vector<RdmData> denoised(const std::vector<RdmData>& rdms, DenoiseDevice* device,
                              DenoiseStats& stats) {
  auto spill = RdmSpill::create(spillDir());
  EXPECT_TRUE(spill.ok());
  EXPECT_TRUE(
      denoiseRdms(MemoryRdmSource(rdms), nullptr, **spill, DenoiseSettings{}, 2, stats, device));
  std::vector<RdmData> out;
  for (size_t i = 0; i < rdms.size(); ++i)
    EXPECT_TRUE((*spill)->visit(i, [&](const RdmData& d) { out.push_back(d); }));
  return out;
}

void expectClose(const std::vector<float>& cpu, const std::vector<float>& gpu, const char* what) {
  ASSERT_EQ(cpu.size(), gpu.size());
  size_t worst = 0;
  double worst_excess = -1.0;
  for (size_t i = 0; i < cpu.size(); ++i) {
    const double excess =
        std::abs(double(cpu[i]) - double(gpu[i])) - (1e-5 * std::abs(double(cpu[i])) + 1e-7);
    if (excess > worst_excess) worst_excess = excess, worst = i;
  }
  EXPECT_LE(worst_excess, 0.0) << what << " " << worst << ": cpu " << cpu[worst] << ", vulkan "
                               << gpu[worst];
}

void expectSameResults(const std::vector<RdmData>& rdms) {
  auto device = VulkanDenoiser::create("");
  ASSERT_TRUE(device.ok()) << device.error();
  DenoiseStats cpu_stats, gpu_stats;
  const std::vector<RdmData> cpu = denoised(rdms, nullptr, cpu_stats);
  const std::vector<RdmData> gpu = denoised(rdms, device->get(), gpu_stats);
  ASSERT_EQ(cpu.size(), gpu.size());
  for (size_t r = 0; r < cpu.size(); ++r) {
    EXPECT_EQ(cpu[r].id, gpu[r].id);
    expectClose(cpu[r].image.pixels, gpu[r].image.pixels, "texel float");
    expectClose(cpu[r].stderr_rgb, gpu[r].stderr_rgb, "standard error float");
  }
  EXPECT_EQ(cpu_stats.rdms, gpu_stats.rdms);
  EXPECT_EQ(cpu_stats.texels, gpu_stats.texels);
  EXPECT_EQ(cpu_stats.filtered, gpu_stats.filtered);
  EXPECT_GT(gpu_stats.filtered, 0u);
  EXPECT_NEAR(cpu_stats.relativeErrorAfter(), gpu_stats.relativeErrorAfter(), 1e-6);
  EXPECT_GT((*device)->info().dispatches, 0u);
}

TEST(VulkanDenoise, IslandAtOneSppFiltersAsTheCpuDoes) {
  RDM_REQUIRE_VULKAN();
  Scene scene = *builtinScene("island");
  scene.bake.spp = 1, scene.bake.max_hemisphere = 16;
  BakeOptions options;
  options.threads = 2;
  const BakeResult result = bakeScene(buildWorld(scene), scene.bake, options);
  ASSERT_GT(result.rdms.size(), 64u) << "several device batches";
  expectSameResults(result.rdms);
}

TEST(VulkanDenoise, SyntheticBlocksWithDeadTexelsAndSkippedFaces) {
  RDM_REQUIRE_VULKAN();
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<RdmData> rdms;
  for (int x = 0; x < 3; ++x) {
    for (int level : {0, 3}) {
      RdmData r;
      r.id = RdmId{{x, 0, 0}, level, 8};
      r.image = Image(16, 24, 4);
      r.stderr_rgb.resize(16 * 24 * 3);
      for (size_t p = 0; p < 16 * 24; ++p) {
        const float depth = unit(rng) < 0.1f ? 0.0f : 0.5f + 20.0f * unit(rng);  // some dead
        for (int c = 0; c < 3; ++c) {
          r.image.pixels[p * 4 + size_t(c)] = 2.0f * unit(rng);
          r.stderr_rgb[p * 3 + size_t(c)] = unit(rng) < 0.2f ? 0.0f : 0.3f * unit(rng);
        }
        r.image.pixels[p * 4 + 3] = depth;
      }
      r.skipped[size_t(x)] = true;  // a different face skipped in each block
      rdms.push_back(std::move(r));
    }
  }
  expectSameResults(rdms);
}

}  // namespace
}  // namespace rdm
