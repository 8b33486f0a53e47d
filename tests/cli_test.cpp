// The rdm command as a user runs it: separate processes, real files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "rdm/exr_io.h"
#include "rdm/file_util.h"

namespace rdm {
namespace {

int run(const std::string& args) {
  std::string cmd = std::string(RDM_BINARY) + " " + args + " > /dev/null 2>&1";
  int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string tempDir(const std::string& name) {
  std::string dir = testing::TempDir() + "/cli_" + std::to_string(getpid()) + "_" + name;
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(Cli, BakeWritesAtlasWithFiniteTexels) {
  std::string dir = tempDir("bake");
  ASSERT_EQ(run("bake --scene island --spp 2 --max-hemisphere 8 --quiet -o " + dir), 0);
  for (const char* f : {"/atlas.exr", "/index.json", "/index.txt", "/bake_report.json"}) {
    EXPECT_TRUE(std::filesystem::exists(dir + f)) << f;
  }
  auto atlas = readExr(dir + "/atlas.exr", {"R", "G", "B", "Z"});
  ASSERT_TRUE(atlas.ok()) << atlas.error();
  for (float v : atlas->pixels) ASSERT_TRUE(std::isfinite(v));
}

TEST(Cli, ShardsMergeToTheOneProcessBakeByteForByte) {
  const std::string settings = "--scene chess --spp 2 --max-hemisphere 8 --quiet";
  std::string whole = tempDir("whole"), merged = tempDir("merged");
  ASSERT_EQ(run("bake " + settings + " -o " + whole), 0);
  std::string shards;
  for (int i = 0; i < 3; ++i) {
    std::string dir = tempDir("shard" + std::to_string(i));
    ASSERT_EQ(
        run("bake " + settings + " --threads 1 --shard " + std::to_string(i) + "/3 -o " + dir), 0);
    shards += " " + dir;
  }
  ASSERT_EQ(run("merge" + shards + " -o " + merged), 0);
  for (const char* f : {"/atlas.exr", "/index.json", "/index.txt"}) {
    EXPECT_EQ(*readFileToString(whole + f), *readFileToString(merged + f)) << f;
  }
  EXPECT_NE(
      run("merge " + tempDir("shard0") + " " + tempDir("shard1") + " -o " + tempDir("partial")), 0);
}

TEST(Cli, BadInputGetsClearErrorsAndExitCodes) {
  const std::string x = tempDir("x");
  EXPECT_EQ(run("bake --scene nosuch -o " + x), 1);
  EXPECT_EQ(run("bake --scene chess --spp 0 -o " + x), 1);
  EXPECT_EQ(run("bake --scene chess --bogus -o " + x), 2);
  EXPECT_EQ(run("bake --scene chess"), 2);
  EXPECT_EQ(run("bake --scene chess --shard 3/3 -o " + x), 2);
  EXPECT_EQ(run("frobnicate"), 2);
  EXPECT_FALSE(std::filesystem::exists(x));  // nothing written for refused input
}

TEST(Cli, SceneExportRoundTripsThroughBake) {
  std::string dir = tempDir("export");
  std::filesystem::create_directories(dir);
  ASSERT_EQ(run("scene --scene furnace -o " + dir + "/furnace.json"), 0);
  ASSERT_EQ(run("scene " + dir + "/furnace.json"), 0);
  ASSERT_EQ(run("bake " + dir + "/furnace.json --quiet -o " + dir + "/out"), 0);
  EXPECT_TRUE(std::filesystem::exists(dir + "/out/atlas.exr"));
}

TEST(Cli, RenderWritesReferenceImage) {
  std::string dir = tempDir("render");
  std::filesystem::create_directories(dir);
  ASSERT_EQ(run("render --scene chess --camera 1 --spp 2 --width 64 --height 36 --quiet -o " + dir +
                "/ref.exr"),
            0);
  auto image = readExr(dir + "/ref.exr", {"R", "G", "B"});
  ASSERT_TRUE(image.ok());
  double sum = 0.0;
  for (float v : image->pixels) sum += v;
  EXPECT_GT(sum, 0.0);
  EXPECT_EQ(run("render --scene chess --camera 9 --quiet -o " + dir + "/bad.exr"), 1);
}

}  // namespace
}  // namespace rdm
