// rdm bake --radiance bc6h through the real binary (docs/spec.md section 4, docs/bc6h.md):
// the files, the block-aligned tiles, the radiance and depth read back against a float32 bake
// of the same scene and seed, the verbs that read atlases, and a truncated page.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "atlas_error.h"
#include "cli_run.h"
#include "rdm/atlas/atlas.h"
#include "rdm/base/file_util.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "test_requirements.h"

namespace rdm {
namespace {

namespace fs = std::filesystem;

const std::string kSmall = " --spp 2 --max-hemisphere 16 --seed 5 -q ";

nlohmann::json jsonFile(const std::string& path) {
  return nlohmann::json::parse(readFileToString(path).value());
}

// Every stored tile of index.json starts at multiples of 4, tiles below 4 texels take a
// block of their own, and page sides are multiples of 4.
void expectBlockAligned(const std::string& dir) {
  auto layout = readAtlasLayout(dir);
  ASSERT_TRUE(layout.ok()) << layout.error();
  EXPECT_TRUE(blockAligned(*layout)) << dir;
  for (const AtlasPage& p : layout->pages) EXPECT_EQ(p.width % 4 + p.height % 4, 0);
}

// Chess: atlas.ktx2 and depth.exr, no atlas.exr; within the codec's error of the float32
// bake of the same seed at S <= 16, 2 spp (mean relative error < 1.5 %, p99 < 10 % over values
// above 1e-3; measured 0.84 % and 7.2 %, see tests/atlas/atlas_bc6h_test.cpp), depth within
// half's rounding (2^-11 relative).
TEST(CliBc6h, ChessBakeWritesKtx2AndDepthAndReadsBackNearFloat32) {
  const std::string f32 = tempDir("bc6h_f32"), bc6h = tempDir("bc6h_chess");
  ASSERT_EQ(runRdm("bake --scene chess" + kSmall + "-o " + f32).code, 0);
  const std::string loud = " --spp 2 --max-hemisphere 16 --seed 5 ";
  CliResult r = runRdm("bake --scene chess" + loud + "--radiance bc6h -o " + bc6h);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("wrote " + bc6h + "/atlas.ktx2, depth.exr, index.json"), std::string::npos)
      << r.out;
  EXPECT_TRUE(fs::exists(bc6h + "/atlas.ktx2"));
  EXPECT_TRUE(fs::exists(bc6h + "/depth.exr"));
  EXPECT_FALSE(fs::exists(bc6h + "/atlas.exr"));
  EXPECT_EQ(jsonFile(bc6h + "/index.json")["radiance"], "bc6h");
  EXPECT_EQ(jsonFile(bc6h + "/bake_report.json")["radiance"], "bc6h");
  expectBlockAligned(bc6h);
  auto a = readAtlasOutputs(f32), b = readAtlasOutputs(bc6h);
  ASSERT_TRUE(a.ok() && b.ok()) << (a.ok() ? b.error() : a.error());
  const test::AtlasError e = test::atlasError(*a, *b, 1e-3f);
  std::printf("[ bc6h ] rdm bake chess: %zu values, mean relative %.3f %%, p99 %.3f %%\n", e.values,
              100.0 * e.mean, 100.0 * e.p99);
  EXPECT_LT(e.mean, 0.015);
  EXPECT_LT(e.p99, 0.10);
  EXPECT_LE(e.max_depth_relative, 0x1p-11);
  CliResult diff = runRdm("diff " + f32 + " " + bc6h);
  EXPECT_TRUE(contains(diff.out, "RDM(s) differ")) << diff.out << diff.err;
  EXPECT_EQ(runRdm("preview " + bc6h + " -o " + bc6h + "/p.png").code, 0);
  EXPECT_EQ(runRdm("preview " + bc6h + " -o " + bc6h + "/d.png --depth").code, 0);
  EXPECT_GT(fs::file_size(bc6h + "/p.png"), 100u);
}

// mirror_floor has S = 2 tiles: each gets a 4 x 4 block of its own.
TEST(CliBc6h, SmallTilesTakeWholeBlocks) {
  const std::string dir = tempDir("bc6h_mirror");
  CliResult r = runRdm("bake --scene mirror_floor" + kSmall + "--radiance bc6h -o " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  auto layout = readAtlasLayout(dir);
  ASSERT_TRUE(layout.ok()) << layout.error();
  size_t small = 0;
  for (const AtlasEntry& e : layout->entries) small += e.id.size < 4 ? e.storedMask() != 0 : 0;
  EXPECT_GT(small, 0u);
  expectBlockAligned(dir);
  auto atlas = readAtlasOutputs(dir);
  EXPECT_TRUE(atlas.ok()) << atlas.error();
}

// float32 and half keep their files and their layout (the packer changes bc6h only).
TEST(CliBc6h, Float32AndHalfBakesAreUnchanged) {
  const std::string f32 = tempDir("bc6h_keep_f32"), half = tempDir("bc6h_keep_half");
  ASSERT_EQ(runRdm("bake --scene mirror_floor" + kSmall + "-o " + f32).code, 0);
  ASSERT_EQ(runRdm("bake --scene mirror_floor" + kSmall + "--radiance half -o " + half).code, 0);
  for (const std::string& dir : {f32, half}) {
    EXPECT_TRUE(fs::exists(dir + "/atlas.exr"));
    EXPECT_FALSE(fs::exists(dir + "/atlas.ktx2"));
    EXPECT_FALSE(fs::exists(dir + "/depth.exr"));
  }
  auto a = readAtlasLayout(f32), b = readAtlasLayout(half);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_FALSE(blockAligned(*a));  // its S = 2 tiles share blocks, as before
  ASSERT_EQ(a->entries.size(), b->entries.size());
  for (size_t i = 0; i < a->entries.size(); ++i) {
    for (int f = 0; f < 6; ++f) {
      const FaceTile& ta = a->entries[i].faces[size_t(f)];
      const FaceTile& tb = b->entries[i].faces[size_t(f)];
      EXPECT_EQ(ta.page, tb.page);
      EXPECT_EQ(ta.x, tb.x);
      EXPECT_EQ(ta.y, tb.y);
    }
  }
}

TEST(CliBc6h, TruncatedKtx2PageIsRefusedNamingTheFile) {
  const std::string dir = tempDir("bc6h_cut"), other = tempDir("bc6h_cut_other");
  ASSERT_EQ(runRdm("bake --scene mirror_floor" + kSmall + "--radiance bc6h -o " + dir).code, 0);
  ASSERT_EQ(runRdm("bake --scene mirror_floor" + kSmall + "-o " + other).code, 0);
  fs::resize_file(dir + "/atlas.ktx2", 100);
  CliResult diff = runRdm("diff " + other + " " + dir);
  EXPECT_NE(diff.code, 0);
  EXPECT_TRUE(contains(diff.err, dir + "/atlas.ktx2")) << diff.err;
  CliResult preview = runRdm("preview " + dir + " -o " + dir + "/p.png");
  EXPECT_NE(preview.code, 0);
  EXPECT_TRUE(contains(preview.err, "atlas.ktx2")) << preview.err;
}

}  // namespace
}  // namespace rdm

namespace rdm {
namespace {

// --bc6h-encoder vulkan encodes the pages on the device (lavapipe here) into the CPU encoder's
// bytes (docs/bc6h.md: one integer encoder, shaders/shared/rdm_bc6h_encode.h).
TEST(CliBc6h, TheVulkanEncoderWritesTheCpuEncodersBytes) {
  RDM_TEST_REQUIRE(listVulkanDevices().ok() && !listVulkanDevices()->empty(), "a Vulkan device");
  const std::string cpu = tempDir("bc6h_cpu_enc"), vk = tempDir("bc6h_vk_enc");
  const std::string tiny = " --spp 1 --max-hemisphere 4 --seed 5 -q --radiance bc6h ";
  CliResult a = runRdm("bake --scene chess" + tiny + "--bc6h-encoder cpu -o " + cpu);
  ASSERT_EQ(a.code, 0) << a.err;
  CliResult b = runRdm("bake --scene chess" + tiny + "--bc6h-encoder vulkan -o " + vk);
  ASSERT_EQ(b.code, 0) << b.err;
  const auto x = readFileToString(cpu + "/atlas.ktx2"), y = readFileToString(vk + "/atlas.ktx2");
  ASSERT_TRUE(x.ok() && y.ok());
  EXPECT_GT(x->size(), 1000u);
  EXPECT_TRUE(*x == *y) << "atlas.ktx2 differs between the encoders";
}

}  // namespace
}  // namespace rdm
