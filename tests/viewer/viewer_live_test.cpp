// The viewer's live-rebake path against a real daemon: upload, full bake, an edit sent as
// a PATCH and a progressive exact bake whose passes arrive as deltas, and the new atlas
// showing the change; and the scripted edit (`rdm-viewer --server --offscreen --edit`).
#include <gtest/gtest.h>

#ifndef RDM_VIEWER_BINARY
TEST(ViewerLive, NotBuilt) {
  GTEST_SKIP() << "configured with RDM_BUILD_VIEWER=OFF";
}
#else

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <thread>

#include "face_light_expect.h"
#include "live_overlay.h"
#include "live_rebake.h"
#include "rdm/base/file_util.h"
#include "rdm/image/exr_io.h"
#include "rdm/service/client.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "server_process.h"
#include "test_scenes.h"

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
  const Scene edited = test::withoutPlacementAt(scene, {5, 1, 2});
  ASSERT_EQ(edited.placements.size(), scene.placements.size() - 1);
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

// Polls `live` every 50 ms until `done` holds for its state (returned), or nullopt after
// `seconds`.
template <class Pred>
std::optional<viewer::LiveState> waitForState(viewer::LiveRebake& live, Pred done, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    viewer::LiveState state = live.state();
    if (done(state)) return state;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return std::nullopt;
}

// Chess at settings whose first bake runs for tens of seconds on 2 threads, so the tests
// below act on it while it runs.
Scene slowChess() {
  Scene scene = *builtinScene("chess");
  scene.bake.spp = 1024, scene.bake.max_hemisphere = 32;
  scene.face_light_spp = 0;
  return scene;
}

// The status bar as the window fills it from the rebaker's state and the renderer's atlas.
viewer::StatusBarState statusBar(const viewer::LiveState& live, bool has_atlas) {
  viewer::StatusBarState bar;
  bar.live = bar.daemon = true, bar.connected = live.connected, bar.busy = live.busy;
  bar.message = live.message, bar.stale_blocks = int(live.stale_slots.size());
  bar.has_atlas = has_atlas;
  return bar;
}

// Cancelling the first (whole) bake leaves no atlas: the status bar says "not baked", not
// "RDMs up to date", and the cancel is not a failure. The next request bakes whole.
TEST(ViewerLive, CancellingTheFirstBakeLeavesItNotBaked) {
  const std::string dir = freshDir("viewer_live_cancel");
  test::ServerProcess server(dir, {"--threads", "2"});
  ASSERT_GT(server.port(), 0);
  auto live = viewer::LiveRebake::connect(server.url(), slowChess());
  ASSERT_TRUE(live.ok()) << live.error();
  auto running = waitForState(
      **live, [](const viewer::LiveState& s) { return !s.job.empty(); }, 60.0);
  ASSERT_TRUE(running.has_value()) << (*live)->statusLine();
  (*live)->requestCancel();
  auto idle = waitForState(
      **live, [](const viewer::LiveState& s) { return !s.busy; }, test::kJobWaitSeconds);
  ASSERT_TRUE(idle.has_value()) << (*live)->statusLine();
  EXPECT_FALSE((*live)->takeAtlas().has_value());
  EXPECT_FALSE(idle->failed);
  EXPECT_NE(idle->message.find("cancelled"), std::string::npos) << idle->message;
  EXPECT_STREQ(viewer::idleStatusText(statusBar(*idle, false)), "not baked");
  // The status bar's "bake" asks again; cheap settings, so the whole atlas comes in seconds.
  Scene cheap = *builtinScene("chess");
  cheap.bake.spp = 1, cheap.bake.max_hemisphere = 4, cheap.face_light_spp = 0;
  (*live)->requestRebake(cheap);
  auto atlas = waitForAtlas(**live, test::kJobWaitSeconds);
  ASSERT_TRUE(atlas.has_value()) << (*live)->statusLine();
  EXPECT_FALSE(atlas->is_delta);
  EXPECT_TRUE(atlas->final);
  auto done = waitForState(
      **live, [](const viewer::LiveState& s) { return !s.busy; }, test::kJobWaitSeconds);
  ASSERT_TRUE(done.has_value()) << (*live)->statusLine();
  EXPECT_STREQ(viewer::idleStatusText(statusBar(*done, true)), "RDMs up to date");
}

// The progress bar's text names the face-light phase (the daemon's progress.phase).
TEST(ViewerLive, ProgressTextNamesTheFaceLightPhase) {
  viewer::StatusBarState bar;
  bar.live = true, bar.busy = true, bar.mode = "exact", bar.pass = 1, bar.passes = 2;
  bar.fraction = 0.93, bar.phase = "rdms";
  EXPECT_EQ(viewer::progressText(bar), "exact pass 2/2  93 %");
  bar.phase = "face_light", bar.eta_seconds = 1.2;
  EXPECT_EQ(viewer::progressText(bar), "exact pass 2/2 face light  93 %, about 1.2 s left");
}

// The status bar's idle line: no atlas is "not baked" whatever else holds; then stale blocks.
TEST(ViewerLive, IdleStatusSaysNotBakedWithoutAnAtlas) {
  viewer::StatusBarState bar;
  bar.live = true;
  bar.has_atlas = false;
  EXPECT_STREQ(viewer::idleStatusText(bar), "not baked");
  bar.stale_blocks = 3;
  EXPECT_STREQ(viewer::idleStatusText(bar), "not baked");
  bar.has_atlas = true;
  EXPECT_STREQ(viewer::idleStatusText(bar), "edits waiting for a bake");
  bar.stale_blocks = 0;
  EXPECT_STREQ(viewer::idleStatusText(bar), "RDMs up to date");
}

// `rdm serve` on a given port (test::ServerProcess always asks for a free one, and the
// daemon refuses a second --port); SIGTERM on destruction. port() is 0 when it did not listen.
class DaemonOnPort {
 public:
  DaemonOnPort(const std::string& data_dir, int port) {
    int fds[2];
    if (pipe(fds) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      dup2(fds[1], STDOUT_FILENO);
      close(fds[0]);
      const std::string p = std::to_string(port);
      execl(RDM_BINARY, RDM_BINARY, "serve", "--data-dir", data_dir.c_str(), "--port", p.c_str(),
            "--threads", "2", "--log-level", "warn", nullptr);
      _exit(127);
    }
    close(fds[1]);
    FILE* out = fdopen(fds[0], "r");
    char line[256] = {};
    const std::string want = "listening on http://127.0.0.1:" + std::to_string(port);
    if (std::fgets(line, sizeof line, out) && std::string(line).rfind(want, 0) == 0) port_ = port;
    std::fclose(out);
  }
  ~DaemonOnPort() {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    waitpid(pid_, nullptr, 0);
  }
  int port() const { return port_; }

 private:
  pid_t pid_ = -1;
  int port_ = 0;
};

// The daemon SIGKILLed mid-bake and restarted on the same port and data directory: the viewer
// says "daemon unreachable" while it is gone, and once it answers again (the restarted daemon
// resumes the job) the message from before the outage is back in the same state snapshot that
// says connected.
TEST(ViewerLive, ReconnectClearsDaemonUnreachable) {
  const std::string dir = freshDir("viewer_live_reconnect");
  test::ServerProcess server(dir, {"--threads", "2"});
  const int port = server.port();
  ASSERT_GT(port, 0);
  auto live = viewer::LiveRebake::connect(server.url(), slowChess());
  ASSERT_TRUE(live.ok()) << live.error();
  auto running = waitForState(
      **live, [](const viewer::LiveState& s) { return !s.job.empty() && s.busy; }, 60.0);
  ASSERT_TRUE(running.has_value()) << (*live)->statusLine();
  const std::string before = running->message;
  ASSERT_EQ(before.find("unreachable"), std::string::npos) << before;
  server.stop(SIGKILL);
  auto lost = waitForState(
      **live, [](const viewer::LiveState& s) { return !s.connected; }, 30.0);
  ASSERT_TRUE(lost.has_value()) << (*live)->statusLine();
  EXPECT_NE(lost->message.find("daemon unreachable"), std::string::npos) << lost->message;
  DaemonOnPort restarted(dir, port);
  ASSERT_EQ(restarted.port(), port);
  auto back = waitForState(
      **live, [](const viewer::LiveState& s) { return s.connected; }, 60.0);
  ASSERT_TRUE(back.has_value()) << (*live)->statusLine();
  EXPECT_EQ(back->message.find("unreachable"), std::string::npos) << back->message;
  EXPECT_EQ(back->message, before);
  EXPECT_TRUE(back->busy);  // the resumed job: nothing else has replaced the message yet
}

// The scripted edit runs the same live path headless and reports both times as JSON.
// A daemon baking on Vulkan bakes the built-in scenes' prefiltered estimator as the CPU does:
// the viewer's edit converges with no fallback.
TEST(ViewerLive, VulkanDaemonBakesTheScenesOwnEstimator) {
  const std::string dir = freshDir("viewer_vulkan");
  test::ServerProcess server(dir + "/data", {"--threads", "2", "--backend", "vulkan"});
  ASSERT_GT(server.port(), 0);
  Scene scene = *builtinScene("chess");
  scene.bake.spp = 8, scene.bake.max_hemisphere = 8;
  ASSERT_TRUE(writeFileAtomic(dir + "/chess.json", sceneToJson(scene)).ok());
  const std::string cmd = std::string(RDM_VIEWER_BINARY) + " --server " + server.url() +
                          " --scene " + dir + "/chess.json --width 64 --height 36" +
                          " --offscreen " + dir + "/edit.png --edit 'remove 5,1,2' > " + dir +
                          "/out.txt 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << *readFileToString(dir + "/out.txt");
  const std::string out = *readFileToString(dir + "/out.txt");
  EXPECT_EQ(out.find("naive estimator"), std::string::npos) << out;
  EXPECT_NE(out.find("converged after"), std::string::npos) << out;
  auto client = test::connectClient(server);
  auto jobs = client->get("/v1/jobs");
  ASSERT_TRUE(jobs.ok() && jobs->status == 200);
  const auto listed = nlohmann::json::parse(jobs->body);
  ASSERT_FALSE(listed["jobs"].empty()) << jobs->body;
  for (const auto& job : listed["jobs"]) {
    EXPECT_EQ(job.value("backend", ""), "vulkan") << job.dump();
    EXPECT_EQ(job["settings"].value("estimator", ""), "prefiltered") << job.dump();
  }
}

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
