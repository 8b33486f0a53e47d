// The PATCH format (rdm/scene/scene_patch.h), one implementation for the daemon, the viewer and
// the CLI: makeScenePatch(from, to) applied to `from` gives `to`, for every kind of change.
#include <gtest/gtest.h>

#include <filesystem>

#include "rdm/base/file_util.h"
#include "rdm/base/json_parse.h"
#include "rdm/scene/scene_diff.h"
#include "rdm/scene/scene_patch.h"

namespace rdm {
namespace {

using nlohmann::json;

void expectRoundTrip(const Scene& from, const Scene& to) {
  const json patch = makeScenePatch(from, to, 7);
  EXPECT_EQ(patch["base_version"], 7);
  auto applied = applyScenePatch(from, patch);
  ASSERT_TRUE(applied.ok()) << applied.error() << "\n" << patch.dump(1);
  EXPECT_EQ(sceneToJson(*applied), sceneToJson(to)) << patch.dump(1);
}

TEST(ScenePatch, CarriesEveryKindOfChange) {
  const Scene base = *builtinScene("chess");
  Scene s = base;
  s.placements.erase(s.placements.begin() + 20);  // remove
  expectRoundTrip(base, s);
  s = base;
  s.placements.push_back({{3, 1, 3}, "queen_light", 5});  // add
  expectRoundTrip(base, s);
  s = base;
  s.blocks["tile_dark"].voxels[5] = 2;  // redefine a block (paint)
  expectRoundTrip(base, s);
  s = base;
  s.palette[1].roughness = 2;  // palette entry
  s.palette.push_back(s.palette[0]);
  expectRoundTrip(base, s);
  s = base;
  s.sun->direction = {0.3, 1.0, 0.2};
  s.sky.zenith = {0.1, 0.2, 0.9};
  s.emission_scale = 3.0;
  s.ambient = {0.01, 0.01, 0.02};
  s.bake.spp = 4, s.bake.max_hemisphere = 8;
  expectRoundTrip(base, s);
  s = base;
  s.sun.reset();  // the sun removed
  expectRoundTrip(base, s);
  s = base;
  s.size = {8, 3, 9};  // the grid grows
  expectRoundTrip(base, s);
}

TEST(ScenePatch, EmptyPatchIsRecognisedAndChangesNothing) {
  const Scene base = *builtinScene("island");
  const json patch = makeScenePatch(base, base, 1);
  EXPECT_TRUE(scenePatchIsEmpty(patch));
  EXPECT_FALSE(scenePatchIsEmpty({{"base_version", 1}, {"sky", json::object()}}));
  EXPECT_TRUE(diffScenes(base, *applyScenePatch(base, patch)).changed_slots.empty());
}

TEST(ScenePatch, RefusesBadPatchesNamingTheField) {
  const Scene base = *builtinScene("chess");
  auto refused = [&](const json& patch, const std::string& field) {
    auto r = applyScenePatch(base, patch);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidInput);
    EXPECT_EQ(r.status().field(), field) << r.error();
  };
  refused({{"base_version", 1}, {"colour", 1}}, "colour");
  refused({{"base_version", 1}, {"edits", {{{"at", {9, 0, 0}}, {"block", nullptr}}}}},
          "edits[0].at[0]");
  refused({{"base_version", 1}, {"size", {0, 1, 1}}}, "size[0]");
  refused({{"base_version", 1}, {"palette", {{"0", json::object()}}}}, "palette.0");
}

}  // namespace
}  // namespace rdm

namespace rdm {
namespace {

// The patch fuzzer's seeds (fuzz/corpus/patch) and its property, in the suite: each seed
// applies to chess, and makeScenePatch of the result reproduces it.
TEST(ScenePatch, FuzzSeedsApplyAndMakeScenePatchReproducesThem) {
  const Scene base = builtinScene("chess").value();
  const std::string dir = std::string(RDM_TEST_DATA_DIR) + "/../../fuzz/corpus/patch";
  int seeds = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    SCOPED_TRACE(entry.path().string());
    nlohmann::json body;
    ASSERT_TRUE(parseJsonLimited(*readFileToString(entry.path().string()), body).ok());
    auto patched = applyScenePatch(base, body);
    ASSERT_TRUE(patched.ok()) << patched.error();
    ASSERT_TRUE(validateScene(*patched).ok());
    const nlohmann::json again = makeScenePatch(base, *patched, 1);
    auto replayed = applyScenePatch(base, again);
    ASSERT_TRUE(replayed.ok()) << replayed.error();
    EXPECT_TRUE(*replayed == *patched) << again.dump();
    EXPECT_EQ(scenePatchIsEmpty(again), *patched == base);
    ++seeds;
  }
  EXPECT_GE(seeds, 6);
}

}  // namespace
}  // namespace rdm
