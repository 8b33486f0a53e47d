// Reference renders on Vulkan (rdm render --backend vulkan; docs/vulkan.md "Reference renders"):
// the kernel traces rdm::renderReference's camera paths (keys, pixel jitter, direct sun and
// emitters at full weight), so the two images differ only where the device's float ray
// direction or arithmetic took another branch. Tolerances: per pixel |dL| <= 1e-3 L + 1e-5
// on all but 2 % of the pixels, the image means within 1e-3 relative, and the pixel RMSE
// between the backends below a tenth of the CPU's own seed-to-seed RMSE. Without a Vulkan
// device the tests fail (test_requirements.h).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli_run.h"
#include "rdm/bake/render.h"
#include "rdm/image/exr_io.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "vulkan_bake_support.h"

namespace rdm {
namespace {

Image renderCpu(const Scene& scene, const VoxelWorld& world, const RenderOptions& o,
                RenderReport* report = nullptr) {
  auto image = renderReference(scene, world, o, report);
  if (!image) ADD_FAILURE() << image.error();
  return image ? std::move(*image) : Image(1, 1, 3);
}

double rmse(const Image& a, const Image& b) {
  double sum = 0.0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const double d = double(a.pixels[i]) - double(b.pixels[i]);
    sum += d * d;
  }
  return std::sqrt(sum / double(a.pixels.size()));
}

double mean(const Image& image) {
  double sum = 0.0;
  for (float v : image.pixels) sum += v;
  return sum / double(image.pixels.size());
}

// The hard scene seen from outside, and a narrow camera looking at the sun past the lamp.
Scene hardSceneWithCameras() {
  Scene s = test::hardScene();
  s.cameras = {Camera{{4.5, 2.6, -1.5}, {1.5, 0.5, 1.5}, 60.0},
               Camera{{2.1, 0.2, 2.1}, {2.1 + 0.4, 0.2 + 1.0, 2.1 + 0.3}, 3.0}};
  return s;
}

void expectAgreement(const Scene& scene, const RenderOptions& o, const std::string& what) {
  const VoxelWorld world = buildWorld(scene);
  auto baker = test::makeVulkanBaker();
  ASSERT_TRUE(baker);
  RenderReport cpu_report, vk_report;
  const Image cpu = renderCpu(scene, world, o, &cpu_report);
  auto vk = baker->render(scene, world, o, &vk_report);
  ASSERT_TRUE(vk) << vk.error();
  ASSERT_EQ(vk->pixels.size(), cpu.pixels.size());
  Scene reseeded = scene;
  reseeded.bake.seed += 1;
  const Image other_seed = renderCpu(reseeded, world, o);
  size_t outside = 0;
  for (size_t i = 0; i < cpu.pixels.size(); i += 3) {
    bool bad = false;
    for (size_t c = 0; c < 3; ++c) {
      const double a = cpu.pixels[i + c], b = vk->pixels[i + c];
      if (!(std::abs(a - b) <= 1e-3 * std::abs(a) + 1e-5)) bad = true;
    }
    outside += bad ? 1 : 0;
  }
  const size_t pixels = cpu.pixels.size() / 3;
  const double between = rmse(cpu, *vk), seed_to_seed = rmse(cpu, other_seed);
  std::printf(
      "%s: %zu of %zu pixels outside the per-pixel tolerance, RMSE %.3g (seed to seed "
      "%.3g), means %.6g / %.6g, rays %llu / %llu\n",
      what.c_str(), outside, pixels, between, seed_to_seed, mean(cpu), mean(*vk),
      (unsigned long long)cpu_report.rays, (unsigned long long)vk_report.rays);
  EXPECT_GT(mean(cpu), 0.0) << what;
  EXPECT_LE(double(outside), 0.02 * double(pixels)) << what;
  EXPECT_NEAR(mean(*vk), mean(cpu), 1e-3 * mean(cpu)) << what;
  EXPECT_LT(between, 0.1 * seed_to_seed) << what;
  // The kernel counts every segment and shadow ray as the CPU does.
  EXPECT_NEAR(double(vk_report.rays), double(cpu_report.rays), 0.01 * double(cpu_report.rays))
      << what;
}

TEST(VulkanRender, AgreesWithTheCpuOnEveryLightPath) {
  RDM_REQUIRE_VULKAN();
  const Scene scene = hardSceneWithCameras();
  RenderOptions o;
  o.width = 48, o.height = 32, o.spp = 8, o.threads = 2;
  expectAgreement(scene, o, "hard scene (mirror, glossy, lamp, sun)");
  o.camera = 1;  // the sun's disc fills the middle: seen directly, it counts in full
  expectAgreement(scene, o, "hard scene, looking at the sun");
}

TEST(VulkanRender, AgreesWithTheCpuOnTheBuiltInScenes) {
  RDM_REQUIRE_VULKAN();
  for (const char* name : {"chess", "island"}) {
    auto scene = builtinScene(name);
    ASSERT_TRUE(scene) << scene.error();
    scene->bake.max_bounces = std::min(scene->bake.max_bounces, 2);
    RenderOptions o;
    o.width = 64, o.height = 36, o.spp = 4, o.threads = 2;
    expectAgreement(*scene, o, name);
  }
}

// The hard scene with its cameras, its world and a baker.
struct VulkanRenderHardScene : testing::Test {
  const Scene scene = hardSceneWithCameras();
  const VoxelWorld world = buildWorld(scene);
  std::unique_ptr<VulkanBaker> baker;
  void SetUp() override {
    RDM_REQUIRE_VULKAN();
    baker = test::makeVulkanBaker();
    ASSERT_TRUE(baker);
  }
};

// Every pixel is written and finite, and the same render twice is the same image bit for bit.
TEST_F(VulkanRenderHardScene, TheSameRenderTwiceIsTheSameImageBitForBit) {
  RenderOptions o;
  o.width = 21, o.height = 13, o.spp = 3;
  auto a = baker->render(scene, world, o);
  ASSERT_TRUE(a) << a.error();
  auto b = baker->render(scene, world, o);
  ASSERT_TRUE(b) << b.error();
  EXPECT_TRUE(a->pixels == b->pixels);
  for (float v : a->pixels) EXPECT_TRUE(std::isfinite(v));
}

TEST_F(VulkanRenderHardScene, RefusesWhatTheCpuRefusesAndStopsWhenCancelled) {
  RenderOptions o;
  o.width = 16, o.height = 16, o.spp = 1;
  o.camera = 2;
  auto bad = baker->render(scene, world, o);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().find("camera 2 out of range"), std::string::npos) << bad.error();
  o.camera = 0;
  std::atomic<bool> cancel{true};
  o.cancel = &cancel;
  auto cancelled = baker->render(scene, world, o);
  ASSERT_FALSE(cancelled);
  EXPECT_EQ(cancelled.status().code(), StatusCode::kCancelled);
}

// `rdm render --backend vulkan` writes the CPU's image within the tolerances above; a
// --device without a Vulkan backend is refused.
TEST(VulkanRender, TheCliRendersOnTheDevice) {
  RDM_REQUIRE_VULKAN();
  const std::string dir = tempDir("vulkan_render");
  std::filesystem::create_directories(dir);
  const std::string args = "render --scene island --spp 2 --width 40 --height 24 -o " + dir;
  CliResult cpu = runRdm(args + "/cpu.exr --backend cpu -q");
  ASSERT_EQ(cpu.code, 0) << cpu.err;
  CliResult vk = runRdm(args + "/vk.exr --backend vulkan --device 0 -q");
  ASSERT_EQ(vk.code, 0) << vk.err;
  EXPECT_NE(vk.out.find("rendered 40x24 at 2 spp"), std::string::npos) << vk.out;
  auto a = readExr(dir + "/cpu.exr", kRgbChannels), b = readExr(dir + "/vk.exr", kRgbChannels);
  ASSERT_TRUE(a.ok() && b.ok());
  size_t outside = 0;
  for (size_t i = 0; i < a->pixels.size(); ++i)
    outside +=
        std::abs(a->pixels[i] - b->pixels[i]) <= 1e-3f * std::abs(a->pixels[i]) + 1e-5f ? 0 : 1;
  EXPECT_LE(double(outside), 0.02 * double(a->pixels.size()));
  CliResult refused = runRdm(args + "/x.exr --backend cpu --device 0 -q");
  EXPECT_EQ(refused.code, 2);
  EXPECT_NE(refused.err.find("--device names a Vulkan device"), std::string::npos) << refused.err;
}

// Glass is path traced on the CPU only (docs/status.md): the device refuses a scene with a
// glass voxel naming what to do, and `auto` takes the CPU for it.
TEST(VulkanRender, AGlassSceneIsRefusedOnTheDeviceAndAutoTakesTheCpu) {
  RDM_REQUIRE_VULKAN();
  Scene s = test::uniformSkyScene(1, 1, 1, 1.0);
  s.palette = {{{255, 255, 255}, 0, 0, 0, 1.0, 1.5}};
  s.blocks["pane"] = test::blockFrom([](int, int y, int) { return y == 4 ? 1 : 0; });
  s.placements = {{{0, 0, 0}, "pane", 0}};
  s.cameras = {Camera{{0.5, 0.9, 0.5}, {0.5, 0.0, 0.6}, 60.0}};
  const VoxelWorld world = buildWorld(s);
  auto baker = test::makeVulkanBaker();
  ASSERT_TRUE(baker);
  RenderOptions o;
  o.width = 8, o.height = 8, o.spp = 1;
  auto image = baker->render(s, world, o);
  ASSERT_FALSE(image.ok());
  EXPECT_NE(image.error().find("glass is path traced on the CPU backend only"), std::string::npos)
      << image.error();
  EXPECT_EQ(resolveBakeBackend(BakeBackend::kAuto, "", s).backend, BakeBackend::kCpu);
  s.palette[0].transmission = 0.0;  // opaque: auto decides as for any scene
  EXPECT_EQ(resolveBakeBackend(BakeBackend::kAuto, "", s).reason,
            resolveBakeBackend(BakeBackend::kAuto, "").reason);
}

}  // namespace
}  // namespace rdm
