// The admission estimate (rdm/atlas/bake_estimate.h) against real `rdm bake` processes of built-in
// scenes: RDMs, texels and atlas bytes exactly, peak memory and CPU time within stated factors.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_run.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/bake_estimate.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/world.h"
#include "test_requirements.h"

namespace rdm {
namespace {

// Runs `rdm bake ARGS...` and returns its peak resident set in bytes (wait4's ru_maxrss), or 0
// when it failed.
uint64_t bakePeakRss(const std::vector<std::string>& args) {
  std::vector<std::string> argv_text = {RDM_BINARY, "bake"};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  const pid_t pid = fork();
  if (pid == 0) {
    std::freopen("/dev/null", "w", stdout);
    std::freopen("/dev/null", "w", stderr);
    std::vector<char*> argv;
    for (std::string& a : argv_text) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  rusage usage{};
  if (pid < 0 || wait4(pid, &status, 0, &usage) != pid) return 0;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return 0;
  return uint64_t(usage.ru_maxrss) * 1024;
}

BakeEstimate estimateOf(const std::string& scene, int spp, int hemisphere, RadianceFormat radiance,
                        int threads) {
  Scene s = *builtinScene(scene);
  BakeSettings settings = s.bake;
  settings.spp = spp, settings.max_hemisphere = hemisphere, settings.max_bounces = 4;
  settings.estimator = Estimator::kNaive;
  return estimateBake(buildWorld(s), settings, radiance, threads);
}

nlohmann::json bakeReport(const std::string& dir) {
  auto text = readFileToString(dir + "/bake_report.json");
  return text ? nlohmann::json::parse(*text) : nlohmann::json::object();
}

TEST(BakeEstimate, CountsAndAtlasBytesEqualTheBakedAtlas) {
  const std::string dir = tempDir("estimate_chess");
  const CliResult r = runRdm(
      "bake --scene chess --spp 1 --max-hemisphere 16 --max-bounces 4 "
      "--estimator naive --threads 2 --backend cpu -o " +
      dir);
  ASSERT_EQ(r.code, 0) << r.err;
  auto atlas = readAtlasOutputs(dir);
  ASSERT_TRUE(atlas.ok()) << atlas.error();
  uint64_t page_texels = 0, stored_texels = 0;
  for (const AtlasPage& p : atlas->layout.pages) page_texels += uint64_t(p.width) * p.height;
  for (const AtlasEntry& e : atlas->layout.entries)
    stored_texels += uint64_t(__builtin_popcount(e.storedMask())) * e.id.size * e.id.size;
  const BakeEstimate f = estimateOf("chess", 1, 16, RadianceFormat::kFloat32, 2);
  const BakeEstimate h = estimateOf("chess", 1, 16, RadianceFormat::kHalf, 2);
  EXPECT_EQ(f.rdms, atlas->layout.entries.size());
  EXPECT_EQ(f.texels, stored_texels);
  EXPECT_EQ(f.pages, int(atlas->layout.pages.size()));
  EXPECT_EQ(f.atlas_bytes, page_texels * 16);  // float32 R, G, B, Z
  EXPECT_EQ(h.atlas_bytes, page_texels * 10);  // half R, G, B, float Z
  EXPECT_GT(f.disk_bytes, f.atlas_bytes);
}

// The model leaves out the process itself (code, allocator, the scene's JSON), so both sides
// are compared above a bake of the same scene at S = 2, whose texels are negligible.
TEST(BakeEstimate, PeakMemoryAndCpuWithinFactorsOfRdmBake) {
  if (test::kSanitized) GTEST_SKIP() << "the factors hold for the release build's memory and speed";
  const std::string dir = tempDir("estimate_rss");
  const std::vector<std::string> common = {
      "--scene",      "chess", "--spp",     "1", "--max-bounces", "4",   "--estimator", "naive",
      "--face-light", "0",     "--threads", "2", "--backend",     "cpu", "-o",          dir};
  std::vector<std::string> small = common, large = common;
  small.insert(small.end(), {"--max-hemisphere", "2"});
  large.insert(large.end(), {"--max-hemisphere", "128"});
  const uint64_t rss_small = bakePeakRss(small), rss_large = bakePeakRss(large);
  ASSERT_GT(rss_small, 0u);
  ASSERT_GT(rss_large, 0u);
  const double measured = double(rss_large) - double(rss_small);
  const BakeEstimate e_small = estimateOf("chess", 1, 2, RadianceFormat::kFloat32, 2);
  const BakeEstimate e_large = estimateOf("chess", 1, 128, RadianceFormat::kFloat32, 2);
  const double estimated = double(e_large.peak_memory_bytes) - double(e_small.peak_memory_bytes);
  const double cpu = bakeReport(dir).value("cpu_seconds", 0.0);
  std::printf(
      "[ estimate ] chess S <= 128: rdm bake peak RSS %.1f MB over S = 2, estimate %.1f "
      "MB; cpu %.2f s, estimate %.2f s\n",
      measured / 1e6, estimated / 1e6, cpu, e_large.cpu_seconds);
  // Stated factors: memory within 3x (measured: the estimate is 1.3x); CPU time from a sixth
  // to 3x the estimate, whose 3 M rays per CPU-second is a slow scene's rate (chess ran
  // 2.4x faster on the 2-core development machine).
  EXPECT_LT(measured, 3.0 * estimated);
  EXPECT_GT(measured, estimated / 3.0);
  EXPECT_LT(cpu, 3.0 * e_large.cpu_seconds);
  EXPECT_GT(cpu, e_large.cpu_seconds / 6.0);
}

TEST(BakeEstimate, SceneBoundsComeBeforeTheWorld) {
  Scene chess = *builtinScene("chess");
  const SceneEstimate c = estimateScene(chess);
  const VoxelWorld world = buildWorld(chess);
  EXPECT_GE(c.world_bytes, worldBytes(world));  // an upper bound
  EXPECT_LE(c.world_bytes, 2 * worldBytes(world));
  EXPECT_EQ(c.filled_placements, size_t(std::count_if(world.slots.begin(), world.slots.end(),
                                                      [](int32_t b) { return b >= 0; })));
  // A million placements of one block in a 256^3 grid: bounded without building anything.
  Scene big;
  big.size = {256, 256, 256};
  big.palette = {PaletteEntry{}};
  big.blocks["a"].voxels.assign(4096, 1);
  for (int n = 0; n < 1000000; ++n)
    big.placements.push_back({{n % 256, n / 256 % 256, n / 65536}, "a", 0});
  const SceneEstimate b = estimateScene(big);
  EXPECT_EQ(b.filled_placements, 1000000u);
  EXPECT_GE(b.world_bytes, uint64_t(256) * 256 * 256 * 8);
  EXPECT_GE(b.min_daemon_memory_bytes, b.world_bytes + 1000000 * minDaemonBytesPerPlacement() - 1);
}

// bench/gen_world.py's city: pillars on every other slot of a square grid, half diffuse (one
// RDM) and half glossy (two), about `rdms` RDMs at 4 spp and S <= 16.
Scene cityWorld(int rdms) {
  const int blocks = (rdms * 2 + 2) / 3;
  const int side = int(std::ceil(std::sqrt(2.0 * blocks)));
  Scene s;
  s.size = {side, 2, side};
  s.palette = {{{190, 180, 170}, 7, 0, 0}, {{120, 140, 170}, 3, 1, 0}};
  auto pillar = [](int index) {
    Block b;
    b.voxels.assign(4096, 0);
    for (int z = 0; z < 16; ++z)
      for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 16; ++x)
          if ((x >= 3 && x < 13 && z >= 3 && z < 13) || y < 2)
            b.voxels[size_t(x + 16 * (y + 16 * z))] = uint8_t(index);
    return b;
  };
  s.blocks["matte"] = pillar(1);
  s.blocks["gloss"] = pillar(2);
  for (int k = 0; k < side; ++k)
    for (int i = 0; i < side && int(s.placements.size()) < blocks; ++i)
      if ((i + k) % 2 == 0)
        s.placements.push_back({{i, 0, k}, (i / 2 + k) % 2 ? "matte" : "gloss", 0});
  s.sky = Sky{{0.3, 0.5, 0.9}, {0.8, 0.85, 0.9}, {0.2, 0.18, 0.15}};
  s.bake.spp = 4, s.bake.max_bounces = 2, s.bake.max_hemisphere = 16;
  return s;
}

// `rdm bake` keeps every RDM's slot sets as runs for rdms.bin; the peak estimate counts them
// (slotSetBytesPerRdm). Measured 2026-12-07 on the 5,001-RDM city: 13.1 MB of peak RSS with
// them over --no-slot-sets, estimate 16.4 MB. Stated factors: from half to 1.5x the estimate.
TEST(BakeEstimate, SlotSetsCountInThePeakAndTheDenoiserInTheDisk) {
  if (test::kSanitized) GTEST_SKIP() << "the factors hold for the release build's memory";
  const Scene city = cityWorld(5000);
  const std::string dir = tempDir("estimate_city");
  ASSERT_TRUE(saveSceneFile(dir + ".json", city).ok());
  const std::vector<std::string> common = {dir + ".json", "--face-light", "0",  "--threads", "2",
                                           "--backend",   "cpu",          "-o", dir};
  std::vector<std::string> without = common;
  without.push_back("--no-slot-sets");
  const uint64_t rss_with = bakePeakRss(common), rss_without = bakePeakRss(without);
  ASSERT_GT(rss_with, 0u);
  ASSERT_GT(rss_without, 0u);
  const VoxelWorld world = buildWorld(city);
  const BakeEstimate e = estimateBake(world, city.bake, RadianceFormat::kFloat32, 2),
                     sets = estimateBake(world, city.bake, RadianceFormat::kFloat32, 2, {true}),
                     denoise =
                         estimateBake(world, city.bake, RadianceFormat::kFloat32, 2, {false, true});
  const double measured = double(rss_with) - double(rss_without);
  const double estimated = double(sets.peak_memory_bytes) - double(e.peak_memory_bytes);
  std::printf("[ estimate ] %zu RDMs: slot sets %.1f MB of peak RSS, estimate %.1f MB\n", e.rdms,
              measured / 1e6, estimated / 1e6);
  EXPECT_GT(measured, estimated / 2.0);
  EXPECT_LT(measured, 1.5 * estimated);
  // The denoiser's spill: 7 floats an RDM image texel, beside the bake's own.
  uint64_t image_texels = 0;
  for (const RdmId& id : listRdms(world, city.bake)) image_texels += 6ull * id.size * id.size;
  EXPECT_EQ(denoise.disk_bytes - e.disk_bytes, image_texels * 28);
}

}  // namespace
}  // namespace rdm
