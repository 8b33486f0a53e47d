// IncrementalBaker::seedFromAtlas: an in-process rebake that starts from the atlas `rdm bake`
// wrote (atlas pages, index.json with its lighting, rdms.bin with the slot sets) instead of
// baking everything again, with the same passes and bits as a baker that baked the atlas
// itself; and the atlases it must refuse.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>

#include "fresh_dir.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/incremental_baker.h"
#include "rdm/atlas/slot_sets_file.h"
#include "test_scenes.h"

namespace rdm {
namespace {

Scene smallChess() {
  Scene scene = *builtinScene("chess");
  scene.bake.spp = 16, scene.bake.max_hemisphere = 8;
  return scene;
}

// What `rdm bake` writes for `scene` into a fresh directory: atlas, index and rdms.bin.
std::string bakeAtlasDir(const Scene& scene, const std::string& name) {
  const std::string dir = test::freshTestDir("seed", name);
  BakeOptions options;
  options.threads = 2, options.record_slot_sets = true;
  const std::vector<RdmData> rdms = bakeScene(buildWorld(scene), scene.bake, options).rdms;
  std::vector<RdmId> ids;
  std::vector<RdmRecord> records;
  for (const RdmData& d : rdms) ids.push_back(d.id), records.push_back(recordOf(d, ""));
  AtlasLayout layout = packCanonical(ids, storedFacesOf(rdms));
  layout.lighting = lightingFingerprint(scene, scene.bake);
  EXPECT_TRUE(writeAtlasOutputs(dir, layout, rdms).ok());
  EXPECT_TRUE(writeSlotSetsFile(dir, records).ok());
  return dir;
}

std::vector<AtlasDelta> bakePasses(IncrementalBaker& baker, const Scene& scene) {
  std::vector<AtlasDelta> passes;
  EXPECT_TRUE(baker.bake(scene, {}, [&](AtlasDelta d) { passes.push_back(std::move(d)); }).ok());
  return passes;
}

TEST(IncrementalSeed, EditAfterSeedingBakesWhatTheBakerThatBakedTheAtlasBakes) {
  const Scene scene = smallChess();
  const std::string dir = bakeAtlasDir(scene, "chess");
  IncrementalBaker seeded;
  ASSERT_TRUE(seeded.seedFromAtlas(scene, dir).ok());
  EXPECT_TRUE(seeded.hasBase());
  IncrementalBaker own;
  bakePasses(own, scene);

  const Scene edited = test::withoutPlacementAt(scene, {5, 1, 2});
  const std::vector<AtlasDelta> from_seed = bakePasses(seeded, edited);
  const std::vector<AtlasDelta> from_own = bakePasses(own, edited);
  ASSERT_EQ(from_seed.size(), 2u);  // preview and final: incremental, not one whole pass
  ASSERT_EQ(from_own.size(), 2u);
  const AtlasDelta& a = from_seed.back();
  const AtlasDelta& b = from_own.back();
  EXPECT_TRUE(a.final);
  EXPECT_GT(a.rects.size(), 0u);
  EXPECT_LT(a.rects.size(), a.layout.entries.size());
  ASSERT_EQ(a.rects.size(), b.rects.size());
  int differ = 0;
  for (size_t i = 0; i < a.rects.size(); ++i) {
    EXPECT_EQ(rdmKey(a.rects[i].entry.id), rdmKey(b.rects[i].entry.id));
    EXPECT_TRUE(a.rects[i].entry.faces == b.rects[i].entry.faces);
    differ += a.rects[i].texels.pixels != b.rects[i].texels.pixels;
  }
  EXPECT_EQ(differ, 0);
}

TEST(IncrementalSeed, AtlasWithoutSlotSetsIsRefusedNamingTheFile) {
  const Scene scene = smallChess();
  const std::string dir = bakeAtlasDir(scene, "no_sets");
  std::filesystem::remove(dir + "/rdms.bin");
  IncrementalBaker baker;
  const Status s = baker.seedFromAtlas(scene, dir);
  EXPECT_EQ(s.code(), StatusCode::kNotFound);
  EXPECT_NE(s.message().find("rdms.bin is missing"), std::string::npos) << s.message();
  EXPECT_FALSE(baker.hasBase());
}

TEST(IncrementalSeed, AtlasOfOtherLightOrGeometryIsRefused) {
  const Scene scene = smallChess();
  const std::string dir = bakeAtlasDir(scene, "other");
  Scene brighter = scene;
  ASSERT_TRUE(brighter.sun.has_value());
  brighter.sun->irradiance *= 10.0;
  IncrementalBaker baker;
  const Status lit = baker.seedFromAtlas(brighter, dir);
  EXPECT_EQ(lit.field(), "lighting") << lit.message();
  Scene more_spp = scene;
  more_spp.bake.spp *= 2;
  EXPECT_EQ(baker.seedFromAtlas(more_spp, dir).field(), "lighting");
  const Status moved = baker.seedFromAtlas(test::withoutPlacementAt(scene, {5, 1, 2}), dir);
  EXPECT_FALSE(moved.ok());
  EXPECT_NE(moved.message().find("other RDMs"), std::string::npos) << moved.message();
  EXPECT_FALSE(baker.hasBase());
}

TEST(IncrementalSeed, SlotSetsFileReadsBackAndTornFilesAreRefused) {
  const Scene scene = smallChess();
  const std::string dir = bakeAtlasDir(scene, "torn");
  auto records = readSlotSetsFile(dir);
  ASSERT_TRUE(records.ok()) << records.error();
  EXPECT_GT(records->size(), 0u);
  const std::string path = dir + "/rdms.bin";
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 7);
  auto torn = readSlotSetsFile(dir);
  ASSERT_FALSE(torn.ok());
  EXPECT_NE(torn.error().find("corrupt or cut short"), std::string::npos) << torn.error();
}

}  // namespace
}  // namespace rdm
