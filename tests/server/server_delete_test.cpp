// Deleting jobs, scenes and versions, and retention (docs/api.md, "Deleting and retention"),
// against a real `rdm serve` on tiny chess scenes: 204 then 404 and the files gone, 409
// naming what still needs a job or scene, deletes racing a running job, the scene limit
// freed, retention keeping the data directory under --max-data-bytes without touching a job
// in use, and a bake of a deleted version answering 404.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include "fresh_dir.h"
#include "rdm/scene/scene.h"
#include "rdm/service/client.h"
#include "server_process.h"
#include "test_scenes.h"

namespace rdm {
namespace {

using nlohmann::json;
using test::connectClient;
using test::ServerProcess;
using test::submit;
using test::waitSucceeded;
namespace fs = std::filesystem;

std::string freshDir(const std::string& name) {
  return test::freshTestDir("server_delete", name);
}

using test::tinyChess;

// Bytes of the files under `dir`; files the daemon deletes meanwhile count 0.
uint64_t treeBytes(const std::string& dir) {
  uint64_t bytes = 0;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code size_ec;
    const uintmax_t n = it->is_regular_file(size_ec) ? it->file_size(size_ec) : 0;
    if (!size_ec) bytes += n;
  }
  return bytes;
}

int status(const Expected<HttpReply>& r) {
  return r.ok() ? r->status : -1;
}

// The problem's detail, or the transport error.
std::string detail(const Expected<HttpReply>& r) {
  if (!r.ok()) return r.error();
  json j = json::parse(r->body, nullptr, false);
  return j.is_object() ? j.value("detail", r->body) : r->body;
}

// Polls (10 ms steps, at most `seconds`) until `done()`.
template <class Pred>
bool eventually(Pred done, double seconds = 20.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

TEST(ServerDelete, FinishedJobGoesAndADependedOnJobIsRefused) {
  const std::string dir = freshDir("jobs");
  ServerProcess server(dir, {"--threads", "2"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(tinyChess()), "upload")["id"];
  const std::string full = submit(*c, scene, json::object());
  waitSucceeded(*c, full);
  const std::string exact = submit(*c, scene, {{"mode", "exact"}});
  waitSucceeded(*c, exact);  // copies every RDM from `full`

  auto refused = c->del("/v1/jobs/" + full);
  EXPECT_EQ(status(refused), 409);
  EXPECT_NE(detail(refused).find(exact), std::string::npos) << detail(refused);
  EXPECT_EQ(status(c->get("/v1/jobs/" + full)), 200);
  EXPECT_EQ(status(c->get("/v1/jobs/" + exact + "/index.json")), 200);

  // A cancel only (`rdm cancel`): a finished job is left as it is.
  auto kept = c->del("/v1/jobs/" + exact + "?finished=keep");
  EXPECT_EQ(status(kept), 409);
  EXPECT_NE(detail(kept).find("job already succeeded"), std::string::npos) << detail(kept);
  EXPECT_EQ(status(c->del("/v1/jobs/" + exact + "?finished=drop")), 400);
  EXPECT_EQ(status(c->get("/v1/jobs/" + exact + "/index.json")), 200);

  auto gone = c->del("/v1/jobs/" + exact);
  EXPECT_EQ(status(gone), 204) << detail(gone);
  EXPECT_EQ(status(c->get("/v1/jobs/" + exact)), 404);
  EXPECT_EQ(status(c->get("/v1/jobs/" + exact + "/atlas.exr")), 404);
  EXPECT_FALSE(fs::exists(dir + "/jobs/" + exact));
  EXPECT_EQ(status(c->del("/v1/jobs/" + full)), 204);
  EXPECT_EQ(status(c->get("/v1/jobs/" + full)), 404);
  EXPECT_EQ(status(c->del("/v1/jobs/" + full)), 404);
  EXPECT_FALSE(fs::exists(dir + "/jobs/" + full));
  EXPECT_EQ(json::parse(c->get("/v1/jobs")->body)["total"], 0);
  // Nothing left in the jobs directory (no trash either).
  EXPECT_TRUE(fs::is_empty(dir + "/jobs"));

  // A trashed job a crash left behind is swept at the next start.
  server.stop(SIGTERM);
  fs::create_directories(dir + "/jobs/.trash-j0123456789abcdef/out");
  ServerProcess again(dir, {"--threads", "2"});
  ASSERT_GT(again.port(), 0);
  EXPECT_TRUE(fs::is_empty(dir + "/jobs"));
}

TEST(ServerDelete, SceneDeleteWaitsForItsRunningJob) {
  const std::string dir = freshDir("race");
  ServerProcess server(dir, {"--threads", "1"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  // Long enough (a few seconds on one thread) that the deletes meet it running.
  const std::string scene = test::must(c->uploadScene(tinyChess(64, 16)), "upload")["id"];
  const std::string job = submit(*c, scene, json::object());
  auto refused = c->del("/v1/scenes/" + scene);
  EXPECT_EQ(status(refused), 409);
  EXPECT_NE(detail(refused).find(job), std::string::npos) << detail(refused);
  EXPECT_EQ(status(c->del("/v1/scenes/" + scene + "/versions/1")), 409);  // current
  // Cancels it (409 when it just finished).
  const int cancelled = status(c->del("/v1/jobs/" + job));
  EXPECT_TRUE(cancelled == 202 || cancelled == 409) << cancelled;
  auto ended = c->waitForJob(job, test::kJobWaitSeconds);
  ASSERT_TRUE(ended.ok()) << ended.error();

  // The finished job is kept: the scene goes only with ?jobs=delete.
  auto kept = c->del("/v1/scenes/" + scene);
  EXPECT_EQ(status(kept), 409);
  EXPECT_NE(detail(kept).find("jobs=delete"), std::string::npos) << detail(kept);
  EXPECT_EQ(status(c->del("/v1/scenes/" + scene + "?jobs=maybe")), 400);
  EXPECT_EQ(status(c->del("/v1/scenes/" + scene + "?jobs=delete")), 204);
  EXPECT_EQ(status(c->get("/v1/scenes/" + scene)), 404);
  EXPECT_EQ(status(c->get("/v1/jobs/" + job)), 404);
  EXPECT_EQ(status(c->post("/v1/scenes/" + scene + "/bakes", "{}")), 404);
  EXPECT_EQ(status(c->del("/v1/scenes/" + scene)), 404);
  EXPECT_FALSE(fs::exists(dir + "/scenes/" + scene));
  EXPECT_FALSE(fs::exists(dir + "/jobs/" + job));
}

TEST(ServerDelete, SceneDeleteFreesTheSceneLimit) {
  const std::string dir = freshDir("limit");
  ServerProcess server(dir, {"--threads", "1", "--max-scenes", "2"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  const std::string first = test::must(c->uploadScene(tinyChess()), "upload")["id"];
  test::must(c->uploadScene(tinyChess()), "upload");
  EXPECT_EQ(status(c->post("/v1/scenes", tinyChess())), 429);
  EXPECT_EQ(status(c->del("/v1/scenes/" + first)), 204);
  EXPECT_EQ(status(c->post("/v1/scenes", tinyChess())), 201);
  EXPECT_EQ(status(c->del("/v1/scenes/s0123456789abcdef")), 404);
  EXPECT_EQ(status(c->del("/v1/scenes/nonsense")), 404);
}

TEST(ServerDelete, VersionDeleteAndBakesOfGoneVersionsAnswer404) {
  const std::string dir = freshDir("versions");
  ServerProcess server(dir, {"--threads", "2", "--max-versions", "2"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(tinyChess()), "upload")["id"];
  const std::string path = "/v1/scenes/" + scene;
  for (int v = 1; v <= 2; ++v) {
    const std::string body = "{\"base_version\": " + std::to_string(v) +
                             ", \"emission_scale\": " + std::to_string(1.0 + 0.01 * v) + "}";
    ASSERT_EQ(status(c->patch(path, body)), 200) << v;
  }
  waitSucceeded(*c, submit(*c, scene, {{"version", 2}}));  // version 2: the newest base's
  auto needed = c->del(path + "/versions/2");
  EXPECT_EQ(status(needed), 409);
  EXPECT_NE(detail(needed).find("needed"), std::string::npos) << detail(needed);
  EXPECT_EQ(status(c->del(path + "/versions/3")), 409);  // current
  EXPECT_EQ(status(c->del(path + "/versions/9")), 404);
  EXPECT_EQ(status(c->del(path + "/versions/x")), 404);

  // Four more versions (4..7): --max-versions 2 keeps 6 and 7, and 2 (needed), and prunes
  // 3..5; version 1 went with the first prune.
  for (int v = 3; v <= 6; ++v) {
    const std::string body = "{\"base_version\": " + std::to_string(v) +
                             ", \"emission_scale\": " + std::to_string(1.0 + 0.01 * v) + "}";
    ASSERT_EQ(status(c->patch(path, body)), 200) << v;
  }
  EXPECT_EQ(status(c->get(path + "?version=3")), 404);
  auto pruned = c->post(path + "/bakes", "{\"version\": 3}");
  // Pruned: 404 as GET answers.
  EXPECT_EQ(status(pruned), 404) << detail(pruned);
  EXPECT_EQ(status(c->del(path + "/versions/3")), 404);  // already gone
  EXPECT_EQ(status(c->get(path + "?version=6")), 200);
  EXPECT_EQ(status(c->del(path + "/versions/6")), 204);
  EXPECT_EQ(status(c->get(path + "?version=6")), 404);
  auto deleted = c->post(path + "/bakes", "{\"version\": 6}");
  EXPECT_EQ(status(deleted), 404) << detail(deleted);
  EXPECT_FALSE(fs::exists(dir + "/scenes/" + scene + "/v6.json"));
  EXPECT_EQ(status(c->get(path + "?version=2")), 200);  // still needed, still there
}

TEST(ServerRetention, ByteBudgetHoldsAcrossJobsAndSparesJobsInUse) {
  const std::string dir = freshDir("budget");
  std::string scene, last;
  uint64_t job_bytes = 0;
  {  // Without a limit: three jobs stay.
    ServerProcess server(dir, {"--threads", "2"});
    ASSERT_GT(server.port(), 0);
    auto c = connectClient(server);
    scene = test::must(c->uploadScene(tinyChess()), "upload")["id"];
    for (int i = 0; i < 3; ++i) waitSucceeded(*c, last = submit(*c, scene, json::object()));
    job_bytes = treeBytes(dir + "/jobs/" + last);
    EXPECT_EQ(json::parse(c->get("/v1/jobs")->body)["total"], 3);
  }
  ASSERT_GT(job_bytes, 0u);
  // Room for the scene and about two jobs: the start expires the oldest.
  const uint64_t limit = treeBytes(dir + "/scenes") + 2 * job_bytes + job_bytes / 2;
  ServerProcess server(
      dir, {"--threads", "2", "--max-data-bytes", std::to_string(limit), "--fetch-grace", "0"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  EXPECT_TRUE(eventually([&] { return treeBytes(dir) <= limit; })) << treeBytes(dir);
  EXPECT_EQ(status(c->get("/v1/jobs/" + last)), 200);  // the newest base stays
  for (int i = 0; i < 5; ++i) {
    const std::string base = last;
    // An exact job on the newest full job: its base is in use while it runs and after it
    // (its result copies the base's RDMs).
    // Each ends before the next is submitted: jobs prepare side by side, and the newest
    // succeeded job is the one retention must keep.
    const std::string exact = submit(*c, scene, {{"mode", "exact"}});
    waitSucceeded(*c, exact);
    last = submit(*c, scene, json::object());
    waitSucceeded(*c, last);
    EXPECT_TRUE(eventually([&] { return treeBytes(dir) <= limit + job_bytes; }))
        << i << ": " << treeBytes(dir) << " > " << limit;
    EXPECT_EQ(status(c->get("/v1/jobs/" + last)), 200) << i;  // the newest base
    // The exact job's base stays while the exact job is kept.
    if (status(c->get("/v1/jobs/" + exact)) == 200) {
      EXPECT_EQ(status(c->get("/v1/jobs/" + base)), 200) << i;
    }
  }
  EXPECT_TRUE(eventually([&] { return treeBytes(dir) <= limit; })) << treeBytes(dir);
}

TEST(ServerRetention, KeepJobsExpiresTheOldestFinishedJobs) {
  const std::string dir = freshDir("count");
  ServerProcess server(dir, {"--threads", "2", "--keep-jobs", "2", "--fetch-grace", "0"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(tinyChess()), "upload")["id"];
  std::vector<std::string> jobs;
  for (int i = 0; i < 4; ++i) {
    jobs.push_back(submit(*c, scene, json::object()));
    waitSucceeded(*c, jobs.back());
  }
  EXPECT_TRUE(eventually([&] { return json::parse(c->get("/v1/jobs")->body)["total"] == 2; }));
  EXPECT_EQ(status(c->get("/v1/jobs/" + jobs[0])), 404);
  EXPECT_EQ(status(c->get("/v1/jobs/" + jobs[1])), 404);
  EXPECT_EQ(status(c->get("/v1/jobs/" + jobs[3])), 200);
  EXPECT_FALSE(fs::exists(dir + "/jobs/" + jobs[0]));
}

}  // namespace
}  // namespace rdm
