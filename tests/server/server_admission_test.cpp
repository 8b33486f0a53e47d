// Refuse, never crash (docs/api.md, "Admission" and "Test hooks"): real `rdm serve`
// processes refuse uploads and jobs over their limits with 413 / 422 and stay healthy, fail
// a job whose work throws std::bad_alloc and bake the next one, and quarantine a job that
// killed the daemon twice instead of dying on it a third time.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include "fresh_dir.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/scene.h"
#include "rdm/service/client.h"
#include "server_process.h"
#include "test_scenes.h"

namespace rdm {
namespace {

using nlohmann::json;
using test::connectClient;
using test::ServerProcess;
namespace fs = std::filesystem;

std::string freshDir(const std::string& name) {
  return test::freshTestDir("admission", name);
}

using test::tinyChess;

// A daemon started with RDM_FAILPOINT=`failpoint` (the child reads it at start).
std::unique_ptr<ServerProcess> startWithFailpoint(const std::string& dir, const char* failpoint,
                                                  const std::vector<std::string>& extra = {}) {
  setenv("RDM_FAILPOINT", failpoint, 1);
  auto server = std::make_unique<ServerProcess>(dir, extra);
  unsetenv("RDM_FAILPOINT");
  return server;
}

void expectHealthy(BakeClient& c) {
  auto health = c.get("/healthz");
  ASSERT_TRUE(health.ok()) << health.error();
  EXPECT_EQ(health->status, 200);
}

// Waits until the daemon no longer answers (it died), at most `timeout_s`.
bool waitDead(const ServerProcess& server, double timeout_s) {
  if (server.port() == 0) return true;  // died before it listened
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  auto c = BakeClient::connect(server.url(), "");
  while (std::chrono::steady_clock::now() < end) {
    if (!c.ok() || !(*c)->get("/healthz").ok()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

// A million placements in a 100^3 grid (about 28 MB of JSON, under --max-body's 32 MiB).
std::string millionPlacements() {
  std::string body = R"({"format": "rdm-scene", "version": 1, "size": [100, 100, 100],)"
                     R"( "palette": [{"color": [200, 200, 200]}], "blocks": {"a": {"fill": 1}},)"
                     R"( "placements": [)";
  body.reserve(30u << 20);
  for (int n = 0; n < 1000000; ++n) {
    if (n) body += ',';
    body += "{\"at\":[" + std::to_string(n % 100) + "," + std::to_string(n / 100 % 100) + "," +
            std::to_string(n / 10000) + "],\"block\":\"a\"}";
  }
  return body + "]}";
}

TEST(ServerAdmission, MillionPlacementSceneRefusedAtUpload) {
  ServerProcess server(freshDir("million"), {"--threads", "1", "--max-job-memory", "2147483648"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  const std::string body = millionPlacements();
  ASSERT_LT(body.size(), size_t(32) << 20);
  auto r = c->post("/v1/scenes", body);
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(r->status, 413) << r->body;
  const json problem = json::parse(r->body);
  const std::string detail = problem.value("detail", "");
  EXPECT_NE(detail.find("1000000 placements"), std::string::npos) << detail;
  EXPECT_NE(detail.find("--max-placements"), std::string::npos) << detail;
  EXPECT_EQ(problem.value("field", ""), "placements");
  expectHealthy(*c);
  auto scenes = c->get("/v1/scenes");
  ASSERT_TRUE(scenes.ok());
  EXPECT_TRUE(json::parse(scenes->body)["scenes"].empty());  // nothing was stored
  auto small = c->uploadScene(tinyChess());
  EXPECT_TRUE(small.ok()) << (small.ok() ? "" : small.error());
}

TEST(ServerAdmission, JobOverTheMemoryLimitRefusedWith422) {
  ServerProcess server(freshDir("memory"), {"--threads", "1", "--max-job-memory", "67108864"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  const json scene = test::must(c->uploadScene(tinyChess()), "upload");
  ASSERT_TRUE(scene.contains("estimate"));
  auto r = c->post("/v1/scenes/" + scene["id"].get<std::string>() + "/bakes",
                   R"({"settings": {"max_hemisphere": 256}})");
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(r->status, 422) << r->body;
  const json problem = json::parse(r->body);
  const std::string detail = problem.value("detail", "");
  EXPECT_EQ(problem.value("type", ""), "https://rdm.invalid/problems/job-too-large");
  EXPECT_NE(detail.find("needs about"), std::string::npos) << detail;
  EXPECT_NE(detail.find("(67108864 bytes) (rdm serve --max-job-memory)"), std::string::npos)
      << detail;
  EXPECT_NE(detail.find("max_hemisphere"), std::string::npos) << detail;
  expectHealthy(*c);
  auto jobs = c->get("/v1/jobs");
  ASSERT_TRUE(jobs.ok());
  EXPECT_EQ(json::parse(jobs->body)["total"], 0);  // the refusal queued nothing
  const std::string job = test::submit(*c, scene["id"], json::object());
  test::waitSucceeded(*c, job);
}

// A work unit or the preparation throwing std::bad_alloc fails that job with the reason; the
// daemon bakes the next job.
TEST(ServerAdmission, OutOfMemoryInAJobFailsOnlyThatJob) {
  for (const char* failpoint : {"unit_alloc", "prepare_alloc"}) {
    SCOPED_TRACE(failpoint);
    auto server = startWithFailpoint(freshDir(failpoint), failpoint, {"--threads", "1"});
    ASSERT_GT(server->port(), 0);
    auto c = connectClient(*server);
    const std::string scene = test::must(c->uploadScene(tinyChess()), "upload")["id"];
    const std::string failed = test::submit(*c, scene, json::object());
    const json f = test::must(c->waitForJob(failed, test::kJobWaitSeconds), "wait");
    EXPECT_EQ(f["state"], "failed");
    const std::string error = f["error"].is_string() ? f["error"].get<std::string>() : "";
    const std::string doing =
        std::string(failpoint) == "unit_alloc" ? "baking a work unit" : "preparing the job";
    EXPECT_NE(error.find("out of memory while " + doing), std::string::npos) << error;
    test::waitSucceeded(*c, test::submit(*c, scene, json::object()));
    expectHealthy(*c);
  }
}

TEST(ServerAdmission, JobThatKilledTheDaemonTwiceIsQuarantined) {
  const std::string dir = freshDir("quarantine");
  std::string scene, job;
  for (int death = 1; death <= 2; ++death) {
    auto server = startWithFailpoint(dir, "prepare_abort", {"--threads", "1"});
    if (death == 1) {
      ASSERT_GT(server->port(), 0);
      auto c = connectClient(*server);
      scene = test::must(c->uploadScene(tinyChess()), "upload")["id"];
      job = test::submit(*c, scene, json::object());
    }  // the second start resumes the job and dies on it again
    ASSERT_TRUE(waitDead(*server, 60.0)) << "death " << death;
    server->stop(SIGKILL);  // reaps it
    const json record = json::parse(*readFileToString(dir + "/jobs/" + job + "/job.json"));
    EXPECT_EQ(record["runs_started"], death);
    EXPECT_EQ(record["state"], "queued");
  }
  ServerProcess server(dir, {"--threads", "1"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  expectHealthy(*c);
  const json q = test::must(c->job(job), "job");
  EXPECT_EQ(q["state"], "failed");
  const std::string error = q["error"].is_string() ? q["error"].get<std::string>() : "";
  EXPECT_NE(error.find("stopped twice while this job was being prepared; quarantined"),
            std::string::npos)
      << error;
  test::waitSucceeded(*c, test::submit(*c, scene, json::object()));
}

}  // namespace
}  // namespace rdm

namespace rdm {
namespace {

struct TwoJobs {
  json first, second;
  uint64_t estimate = 0;
};

// Submits two full jobs of one scene back to back and waits for both.
TwoJobs runTwoJobs(const std::string& dir, const std::vector<std::string>& args,
                   const std::string& scene_json) {
  ServerProcess server(dir, args);
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(scene_json), "upload")["id"];
  auto a = c->post("/v1/scenes/" + scene + "/bakes", "{}");
  auto b = c->post("/v1/scenes/" + scene + "/bakes", "{}");
  EXPECT_TRUE(a.ok() && a->status == 202 && b.ok() && b->status == 202);
  TwoJobs out;
  const json posted = json::parse(a->body);
  out.estimate = posted["estimate"]["memory_bytes"];
  out.first = test::waitSucceeded(*c, posted["id"]);
  out.second = test::waitSucceeded(*c, json::parse(b->body)["id"]);
  return out;
}

// Admitted jobs run side by side only while their estimates sum within --max-job-memory:
// with room for both, the second is prepared (started) while the first bakes; with room
// for one, it starts once the first ended.
TEST(ServerAdmission, JobsRunSideBySideOnlyWithinTheMemoryLimit) {
  Scene s = *builtinScene("chess");
  s.bake.spp = 4, s.bake.max_hemisphere = 16, s.bake.max_bounces = 2;
  s.face_light_spp = 0;
  const std::string scene_json = sceneToJson(s);
  const TwoJobs roomy = runTwoJobs(freshDir("roomy"), {"--threads", "1"}, scene_json);
  EXPECT_LT(roomy.second["started"].get<double>(), roomy.first["finished"].get<double>());
  const uint64_t one_and_a_half = std::max<uint64_t>(roomy.estimate * 3 / 2, 1 << 20);
  const TwoJobs tight = runTwoJobs(
      freshDir("tight"), {"--threads", "1", "--max-job-memory", std::to_string(one_and_a_half)},
      scene_json);
  EXPECT_EQ(tight.estimate, roomy.estimate);
  EXPECT_GE(tight.second["started"].get<double>(), tight.first["finished"].get<double>());
}

}  // namespace
}  // namespace rdm
