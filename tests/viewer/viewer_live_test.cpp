// The viewer's live-rebake path against a real daemon: upload, full bake, an edit sent as
// a PATCH and a progressive exact bake whose passes arrive as deltas, and the new atlas
// showing the change; and the scripted edit (`rdm-viewer --server --offscreen --edit`).
#include <gtest/gtest.h>

#ifndef RDM_VIEWER_BINARY
TEST(ViewerLive, NotBuilt) {
  GTEST_SKIP() << "configured with RDM_BUILD_VIEWER=OFF";
}
#else

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "face_light_expect.h"
#include "live_rebake.h"
#include "rdm/base/file_util.h"
#include "rdm/image/exr_io.h"
#include "rdm/service/client.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "server_process.h"

namespace rdm {
namespace {

// An empty directory of this test process's own under the test temp directory.
std::string freshDir(const std::string& name) {
  const std::string dir = testing::TempDir() + "/" + name + "_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::optional<viewer::LiveAtlas> waitForAtlas(viewer::LiveRebake& live, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    if (auto atlas = live.takeAtlas()) return atlas;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return std::nullopt;
}

// Depths of the +Y face of the tile RDM (slot, level) in `pages` laid out by `layout`.
std::vector<float> topFaceDepths(const AtlasLayout& layout, const std::vector<Image>& pages,
                                 glm::ivec3 slot, int level) {
  const AtlasEntry* e = layout.find(slot, level);
  if (!e) return {};
  std::vector<float> out;
  const int S = e->id.size;
  const FaceTile& t = e->faces[2];
  if (!t.stored()) return {};
  for (int j = 0; j < S; ++j)
    for (int i = 0; i < S; ++i) out.push_back(pages[size_t(t.page)].at(t.x + i, t.y + j, 3));
  return out;
}

// A scene with bake.face_light_spp gets the daemon's face light with its first (whole) atlas,
// without a viewer option: the bits of the in-process bake of the same scene (docs/spec.md
// section 3.2). Edits then update it in the renderer by the same rule as in-process
// (Renderer::setScene).
TEST(ViewerLive, WholeAtlasBringsTheDaemonsFaceLight) {
  const std::string dir = freshDir("viewer_live_light");
  test::ServerProcess server(dir, {"--threads", "2"});
  ASSERT_GT(server.port(), 0);
  Scene scene = *builtinScene("chess");
  scene.bake.spp = 2, scene.bake.max_hemisphere = 4;
  scene.face_light_spp = 4;
  auto live = viewer::LiveRebake::connect(server.url(), scene);
  ASSERT_TRUE(live.ok()) << live.error();
  auto first = waitForAtlas(**live, 120.0);
  ASSERT_TRUE(first.has_value()) << (*live)->statusLine();
  ASSERT_FALSE(first->is_delta);
  ASSERT_TRUE(first->face_light.has_value());
  FaceLightOptions bake;
  bake.threads = 2, bake.spp = 4;
  test::expectSameFaceLight(bakeFaceLight(buildWorld(scene), scene, bake), *first->face_light);
}

TEST(ViewerLive, EditTriggersIncrementalRebakeThatUpdatesTheTileUnderIt) {
  const std::string dir = freshDir("viewer_live");
  test::ServerProcess server(dir, {"--threads", "2"});
  ASSERT_GT(server.port(), 0);
  Scene scene = *builtinScene("chess");
  scene.bake.spp = 16;  // a preview pass at 1 spp, then 16
  scene.bake.max_hemisphere = 8;
  scene.face_light_spp = 0;  // the RDM tiles are what this test follows
  auto live = viewer::LiveRebake::connect(server.url(), scene);
  ASSERT_TRUE(live.ok()) << live.error();
  auto before = waitForAtlas(**live, 120.0);
  ASSERT_TRUE(before.has_value()) << (*live)->statusLine();

  // Remove the light pawn standing on tile (5, 0, 2): its base covered the tile's +Y face
  // origin, so every central depth there was 0; afterwards the face sees the board.
  const glm::ivec3 tile(5, 0, 2);
  ASSERT_FALSE(before->is_delta);  // the first bake comes whole
  std::vector<Image> pages = before->atlas.pages;
  const std::vector<float> old_depths = topFaceDepths(before->atlas.layout, pages, tile, 1);
  ASSERT_FALSE(old_depths.empty());
  for (float z : old_depths) EXPECT_EQ(z, 0.0f);
  Scene edited = scene;
  auto& p = edited.placements;
  p.erase(std::remove_if(p.begin(), p.end(),
                         [](const Placement& q) {
                           return q.at == std::array<int, 3>{5, 1, 2};
                         }),
          p.end());
  ASSERT_EQ(p.size(), scene.placements.size() - 1);
  (*live)->requestRebake(edited);
  EXPECT_EQ((*live)->state().stale_slots.size(), 1u);  // the edited slot, until converged
  std::vector<viewer::LiveAtlas> passes;
  while (passes.empty() || !passes.back().final) {
    auto next = waitForAtlas(**live, 120.0);
    ASSERT_TRUE(next.has_value()) << (*live)->statusLine();
    passes.push_back(std::move(*next));
  }
  EXPECT_TRUE((*live)->state().stale_slots.empty());
  // Editing and then undoing every edit leaves nothing stale: staleness is measured against
  // the scene the atlas was baked for, not accumulated.
  Scene again = edited;
  again.placements.pop_back();
  (*live)->requestRebake(again);
  EXPECT_FALSE((*live)->state().stale_slots.empty());
  (*live)->requestRebake(edited);
  EXPECT_TRUE((*live)->state().stale_slots.empty());
  // Every pass travels as a delta of face tiles; the preview covers the same tiles.
  for (const viewer::LiveAtlas& p : passes) {
    EXPECT_TRUE(p.is_delta);
    EXPECT_EQ(p.updates.size(), passes.back().updates.size());
  }
  viewer::LiveAtlas* after = &passes.back();
  const AtlasLayout& layout = after->atlas.layout;
  EXPECT_EQ(layout.scene_version, 2);
  EXPECT_EQ(layout.find({5, 1, 2}, 7), nullptr);  // the pawn's own RDMs are gone
  // Only the re-baked RDMs travel: a delta of their stored face tiles, applied here as the
  // viewer's texture does, not the whole atlas.
  ASSERT_TRUE(after->is_delta);
  EXPECT_EQ(after->passes, 2);
  EXPECT_GT(after->updates.size(), 0u);
  EXPECT_LT(after->updates.size(), layout.storedTiles());
  for (const viewer::AtlasRectUpdate& u : after->updates) {
    for (int y = 0; y < u.texels.height; ++y)
      for (int x = 0; x < u.texels.width; ++x)
        for (int c = 0; c < 4; ++c)
          pages[size_t(u.page)].at(u.x + x, u.y + y, c) = u.texels.at(x, y, c);
  }
  for (float z : topFaceDepths(layout, pages, tile, 1)) EXPECT_GT(z, 0.0f);
  // Every RDM the new layout references now equals the job's own atlas.
  auto client = BakeClient::connect(server.url(), "");
  ASSERT_TRUE(client.ok());
  // The final pass is published from memory before the job's files are written.
  auto job = (*client)->jobProgress(after->job, 30.0);
  while (job.ok() && !job->terminal()) job = (*client)->jobProgress(after->job, 30.0);
  ASSERT_TRUE(job.ok() && job->succeeded());
  auto bytes = (*client)->download(after->job, "atlas.exr?page=0");
  ASSERT_TRUE(bytes.ok()) << bytes.error();
  auto full = decodeExr(*bytes, kRgbzChannels);
  ASSERT_TRUE(full.ok());
  int mismatches = 0;
  for (const AtlasEntry& e : layout.entries) {
    for (const FaceTile& t : e.faces) {
      if (t.page != 0) continue;
      for (int y = t.y; y < t.y + e.id.size; ++y)
        for (int x = t.x; x < t.x + e.id.size; ++x)
          for (int c = 0; c < 4; ++c) mismatches += pages[0].at(x, y, c) != full->at(x, y, c);
    }
  }
  EXPECT_EQ(mismatches, 0);
}

// The scripted edit runs the same live path headless and reports both times as JSON.
TEST(ViewerLive, ScriptedEditReportsFirstAndConvergedUpdate) {
  const std::string dir = freshDir("viewer_edit");
  test::ServerProcess server(dir + "/data", {"--threads", "2"});
  ASSERT_GT(server.port(), 0);
  Scene scene = *builtinScene("chess");
  scene.bake.spp = 16, scene.bake.max_hemisphere = 8;
  ASSERT_TRUE(writeFileAtomic(dir + "/chess.json", sceneToJson(scene)).ok());
  const std::string report = dir + "/edit.json";
  const std::string cmd = std::string(RDM_VIEWER_BINARY) + " --server " + server.url() +
                          " --scene " + dir + "/chess.json --width 320 --height 180" +
                          " --offscreen " + dir + "/edit.png --edit 'remove 5,1,2'" +
                          " --edit-report " + report + " > " + dir + "/out.txt 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << *readFileToString(dir + "/out.txt");
  const std::string out = *readFileToString(dir + "/out.txt");
  EXPECT_NE(out.find("first update after"), std::string::npos) << out;
  EXPECT_NE(out.find("converged after"), std::string::npos) << out;
  const auto j = nlohmann::json::parse(*readFileToString(report));
  EXPECT_EQ(j["passes"], 2);
  EXPECT_EQ(j["mode"], "exact");
  EXPECT_EQ(j["live_divisor"], 2);  // the default interactive resolution before the final pass
  EXPECT_GT(j["first_update_seconds"].get<double>(), 0.0);
  EXPECT_LE(j["first_update_seconds"].get<double>(), j["converged_seconds"].get<double>());
  EXPECT_GT(j["converged_tiles"].get<int>(), 0);
  EXPECT_TRUE(std::filesystem::exists(dir + "/edit.png"));
  // A bad edit is refused before anything is baked, naming what is wrong.
  const std::string bad = std::string(RDM_VIEWER_BINARY) + " --server " + server.url() +
                          " --scene chess --offscreen " + dir + "/bad.png --edit 'remove 0,0'" +
                          " > " + dir + "/bad.txt 2>&1";
  EXPECT_NE(std::system(bad.c_str()), 0);
  EXPECT_NE(readFileToString(dir + "/bad.txt")->find("slot must be I,J,K"), std::string::npos);
}

}  // namespace
}  // namespace rdm
#endif
