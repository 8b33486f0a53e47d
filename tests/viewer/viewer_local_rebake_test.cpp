// The viewer's in-process rebakes (viewer/app/local_rebake.h). After `--atlas` (issue 38, row
// 6), through the real programs: `rdm bake` writes the atlas and its slot sets (rdms.bin),
// `rdm-viewer --atlas DIR --offscreen --edit` rebakes only what the edit touches, in the
// progressive passes of an edit; without rdms.bin the viewer says why and bakes every RDM in
// one pass. And the stale outlines (row 17): only the edited slots, until the final pass.
#include <gtest/gtest.h>

#if !defined(RDM_VIEWER_BINARY) || !defined(RDM_BINARY)
TEST(ViewerLocalRebake, NotBuilt) {
  GTEST_SKIP() << "configured with RDM_BUILD_VIEWER=OFF";
}
#else

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include <nlohmann/json.hpp>

#include "fresh_dir.h"
#include "local_rebake.h"
#include "rdm/atlas/atlas.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/scene_diff.h"
#include "test_scenes.h"

namespace rdm {
namespace {

struct EditRun {
  int code = -1;
  std::string out;
  nlohmann::json report;
};

// rdm-viewer --scene SCENE --atlas ATLAS --offscreen ... --edit 'remove 5,1,2', in-process.
EditRun editWithAtlas(const std::string& dir, const std::string& scene, const std::string& atlas) {
  const std::string report = dir + "/edit.json";
  const std::string cmd = std::string(RDM_VIEWER_BINARY) + " --scene " + scene + " --atlas " +
                          atlas + " --width 64 --height 36 --offscreen " + dir +
                          "/edit.png --edit 'remove 5,1,2' --edit-report " + report + " > " + dir +
                          "/out.txt 2>&1";
  EditRun run;
  run.code = std::system(cmd.c_str());
  if (auto out = readFileToString(dir + "/out.txt")) run.out = *out;
  if (auto text = readFileToString(report)) run.report = nlohmann::json::parse(*text);
  return run;
}

// chess at 8 spp and S <= 8, written as a scene file so that its bake settings (part of the
// atlas' lighting fingerprint) are the scene's own.
std::string smallChessFile(const std::string& dir) {
  Scene scene = *builtinScene("chess");
  scene.bake.spp = 8, scene.bake.max_hemisphere = 8, scene.face_light_spp = 0;
  const std::string path = dir + "/chess.json";
  EXPECT_TRUE(writeFileAtomic(path, sceneToJson(scene)).ok());
  return path;
}

TEST(ViewerLocalRebake, EditAfterAtlasRebakesOnlyWhatItTouchesInProgressivePasses) {
  const std::string dir = test::freshTestDir("viewer_seed", "edit");
  const std::string scene = smallChessFile(dir);
  const std::string bake = std::string(RDM_BINARY) + " bake --scene " + scene + " -o " + dir +
                           "/atlas --quiet > " + dir + "/bake.txt 2>&1";
  ASSERT_EQ(std::system(bake.c_str()), 0) << *readFileToString(dir + "/bake.txt");
  ASSERT_TRUE(std::filesystem::exists(dir + "/atlas/rdms.bin"));
  auto layout = readAtlasLayout(dir + "/atlas");
  ASSERT_TRUE(layout.ok()) << layout.error();
  const size_t all_tiles = layout->storedTiles();

  const EditRun seeded = editWithAtlas(dir, scene, dir + "/atlas");
  ASSERT_EQ(seeded.code, 0) << seeded.out;
  EXPECT_NE(seeded.out.find("in-process bakes start from the atlas in " + dir + "/atlas"),
            std::string::npos)
      << seeded.out;
  EXPECT_EQ(seeded.report["passes"], 2) << seeded.report.dump();  // preview, final
  EXPECT_GT(seeded.report["converged_tiles"].get<size_t>(), 0u);
  EXPECT_LT(seeded.report["converged_tiles"].get<size_t>(), all_tiles);

  std::filesystem::remove(dir + "/atlas/rdms.bin");
  const EditRun unseeded = editWithAtlas(dir, scene, dir + "/atlas");
  ASSERT_EQ(unseeded.code, 0) << unseeded.out;
  EXPECT_NE(unseeded.out.find("the first in-process bake bakes every RDM: " + dir +
                              "/atlas/rdms.bin is missing"),
            std::string::npos)
      << unseeded.out;
  EXPECT_EQ(unseeded.report["passes"], 1) << unseeded.report.dump();  // one whole pass
  EXPECT_GT(unseeded.report["converged_tiles"].get<size_t>(),  // the edited scene's every tile
            seeded.report["converged_tiles"].get<size_t>());
}

// Removing one piece re-lights most of chess: the preview pass shows ~all RDMs at preview
// quality, but only the edited slot is outlined, and nothing is once the final pass is in.
TEST(ViewerLocalRebake, OnlyEditedSlotsAreOutlinedAndNoneAfterTheFinalPass) {
  Scene scene = *builtinScene("chess");
  scene.bake.spp = 64, scene.bake.max_hemisphere = 8;  // a final pass long enough to watch
  viewer::LocalRebake live(BakeMode::kExact);
  auto drain = [&](double seconds) {  // the states seen until the final update, taken
    std::vector<viewer::LiveState> seen;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < deadline) {
      seen.push_back(live.state());
      if (auto update = live.takeAtlas(); update && update->final) return seen;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ADD_FAILURE() << "no final update within " << seconds << " s";
    return seen;
  };
  live.requestRebake(scene);
  drain(300);
  const Scene edited = test::withoutPlacementAt(scene, {5, 1, 2});
  const std::vector<glm::ivec3> edited_slots = diffScenes(scene, edited).changed_slots;
  ASSERT_EQ(edited_slots.size(), 1u);
  live.requestRebake(edited);
  int most_preview = 0;
  for (const viewer::LiveState& s : drain(300)) {
    most_preview = std::max(most_preview, s.preview_rdms);
    EXPECT_TRUE(s.stale_slots.empty() || s.stale_slots == edited_slots) << s.stale_slots.size();
  }
  EXPECT_GT(most_preview, 1);  // the preview pass re-lit more than the edited slot
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (live.state().busy && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const viewer::LiveState after = live.state();
  EXPECT_TRUE(after.stale_slots.empty())
      << after.stale_slots.size() << " outlined after the final pass";
  EXPECT_EQ(after.preview_rdms, 0);
}

}  // namespace
}  // namespace rdm
#endif
