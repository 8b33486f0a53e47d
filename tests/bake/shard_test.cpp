#include "rdm/bake/shard.h"

#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rdm/base/file_util.h"

namespace rdm {
namespace {

std::string shardDir(const std::string& name) {
  std::string dir = testing::TempDir() + "/shard_" + std::to_string(getpid()) + "_" + name;
  std::filesystem::remove_all(dir);
  return dir;
}

RdmData smallRdm(const glm::ivec3& slot, std::array<bool, 6> skipped) {
  RdmData d;
  d.id = {slot, 7, 2};
  d.image.width = 4, d.image.height = 6, d.image.channels = 4;
  d.image.pixels.assign(size_t(4 * 6 * 4), 0.25f);
  d.skipped = skipped;
  return d;
}

// The compact atlas leaves skipped faces out, so a merge must know them: the manifest keeps them.
TEST(Shard, RoundTripKeepsSkippedFaces) {
  const std::string dir = shardDir("round_trip");
  const std::array<bool, 6> skipped{false, true, false, false, true, false};
  ASSERT_TRUE(writeShard(dir, {0, 1, "digest", 2},
                         {smallRdm({0, 0, 0}, skipped), smallRdm({1, 0, 0}, {})}));
  auto shard = readShard(dir);
  ASSERT_TRUE(shard.ok()) << shard.error();
  ASSERT_EQ(shard->rdms.size(), 2u);
  EXPECT_EQ(shard->rdms[0].skipped, skipped);
  EXPECT_EQ(shard->rdms[1].skipped, (std::array<bool, 6>{}));
  auto set = mergeShards({*shard});
  ASSERT_TRUE(set.ok()) << set.error();
  ASSERT_TRUE(
      set->visit(0,
                 [](const RdmData& d) { EXPECT_EQ(d.image.pixels, smallRdm({}, {}).image.pixels); })
          .ok());
}

// Images are read when visited: a missing one fails the read naming its file, before a merge
// writes anything (writeAtlasOutputs reads every digest first).
TEST(Shard, AMissingRdmImageFailsNamingTheFile) {
  const std::string dir = shardDir("missing");
  ASSERT_TRUE(writeShard(dir, {0, 1, "digest", 1}, {smallRdm({0, 0, 0}, {})}));
  std::filesystem::remove(dir + "/rdm_0_0_0_L7.exr");
  auto set = mergeShards({*readShard(dir)});
  ASSERT_TRUE(set.ok()) << set.error();
  auto digests = set->digests();
  ASSERT_FALSE(digests.ok());
  EXPECT_NE(digests.error().find("rdm_0_0_0_L7.exr"), std::string::npos) << digests.error();
}

TEST(Shard, RefusesAVersion1ManifestNamingTheVersion) {
  const std::string dir = shardDir("version1");
  ASSERT_TRUE(writeShard(dir, {0, 1, "digest", 1}, {smallRdm({0, 0, 0}, {})}));
  auto j = nlohmann::json::parse(*readFileToString(dir + "/shard.json"));
  j["version"] = 1;
  ASSERT_TRUE(writeFileAtomic(dir + "/shard.json", j.dump()));
  auto shard = readShard(dir);
  ASSERT_FALSE(shard.ok());
  EXPECT_NE(shard.error().find("rdm-shard version 1"), std::string::npos) << shard.error();
  EXPECT_NE(shard.error().find("bake the shard again"), std::string::npos) << shard.error();
}

}  // namespace
}  // namespace rdm
