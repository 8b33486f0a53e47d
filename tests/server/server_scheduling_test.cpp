// A daemon stopped (SIGTERM) while a job bakes its face light or is being prepared exits
// within the bound docs/deploy.md ("Stopping") states, and the restarted daemon resumes the
// job to the bytes a run straight through writes. The in-process scheduling tests (a job
// beside another's long phase, a prompt cancel) are tests/service/job_manager_test.cpp's.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "fresh_dir.h"
#include "rdm/scene/scene.h"
#include "rdm/service/client.h"
#include "server_process.h"
#include "test_requirements.h"
#include "test_scenes.h"

namespace rdm {
namespace {

using nlohmann::json;
using test::connectClient;
using test::must;
using test::ServerProcess;
using test::submit;
using test::waitSucceeded;
namespace fs = std::filesystem;

// docs/deploy.md, "Stopping": 5 s plus one work unit (milliseconds here); ten times that
// under the sanitizers.
constexpr double kStopBound = test::kSanitized ? 50.0 : 5.0;
// Chess's face light at these samples per face bakes for about 6 s on 2 loaded cores.
constexpr int kFaceLightSpp = 1024;

std::string freshDir(const std::string& name) {
  return test::freshTestDir("scheduling", name);
}

using test::tinyChess;

const std::vector<std::string> kServeFlags = {"--threads", "2", "--backend", "cpu"};

std::unique_ptr<ServerProcess> startServer(const std::string& dir, const char* failpoint = "") {
  setenv("RDM_FAILPOINT", failpoint, 1);  // the child reads it at start
  auto server = std::make_unique<ServerProcess>(dir, kServeFlags);
  unsetenv("RDM_FAILPOINT");
  if (server->port() == 0) throw std::runtime_error("rdm serve did not start");
  return server;
}

// Polls the job (10 ms steps, at most 60 s) until `done` holds for its status.
template <class Pred>
json waitStatus(BakeClient& c, const std::string& job, Pred done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  json status = must(c.job(job), "job status");
  while (!done(status) && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    status = must(c.job(job), "job status");
  }
  EXPECT_TRUE(done(status)) << status.dump(1);
  return status;
}

// SIGTERM; the seconds until the process was reaped.
double stopSeconds(ServerProcess& server) {
  const auto start = std::chrono::steady_clock::now();
  server.stop(SIGTERM);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("SIGTERM to exit: %.3f s\n", s);
  return s;
}

// Restarts the daemon on `dir`, waits for `job` to succeed there, runs the same request
// straight through, and compares the two jobs' files byte for byte.
void expectResumedIdentical(const std::string& dir, const std::string& scene,
                            const std::string& job, const json& request,
                            const std::vector<std::string>& files) {
  auto server = startServer(dir);
  auto c = connectClient(*server);
  const json resumed = waitSucceeded(*c, job);
  EXPECT_EQ(resumed.value("runs_started", 0), 1) << resumed.dump(1);  // the stop gave it back
  const std::string straight = submit(*c, scene, request);
  waitSucceeded(*c, straight);
  for (const std::string& name : files) {
    const std::string a = must(c->download(job, name), name);
    const std::string b = must(c->download(straight, name), name);
    EXPECT_FALSE(a.empty()) << name;
    EXPECT_TRUE(a == b) << name << " differs between the resumed and the straight job";
  }
}

TEST(ServerScheduling, StopDuringFaceLightIsPromptAndResumesIdentical) {
  const std::string dir = freshDir("face_light");
  auto server = startServer(dir);
  auto c = connectClient(*server);
  const std::string scene = must(c->uploadScene(tinyChess()), "upload")["id"];
  const json request = {{"face_light", kFaceLightSpp}};
  const std::string job = submit(*c, scene, request);
  // The one pass is published when the units all landed, just before the face light.
  waitStatus(*c, job, [](const json& j) {
    return j["passes"]["done"] == 1 || (j["state"] != "running" && j["state"] != "queued");
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_EQ(must(c->job(job), "job status")["state"], "running") << "the face light ended early";
  c.reset();
  EXPECT_LT(stopSeconds(*server), kStopBound);
  expectResumedIdentical(dir, scene, job, request, {"atlas.exr", "face_light.bin"});
}

TEST(ServerScheduling, StopDuringPreparationIsPromptAndResumesIdentical) {
  const std::string dir = freshDir("prepare");
  auto server = startServer(dir, "prepare_slow");  // the first preparation takes 20 s more
  auto c = connectClient(*server);
  const std::string scene = must(c->uploadScene(tinyChess()), "upload")["id"];
  const json request = json::object();
  const std::string job = submit(*c, scene, request);
  waitStatus(*c, job, [](const json& j) { return j.value("runs_started", 0) >= 1; });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_EQ(must(c->job(job), "job status")["state"], "queued");  // still being prepared
  c.reset();
  EXPECT_LT(stopSeconds(*server), kStopBound);
  expectResumedIdentical(dir, scene, job, request, {"atlas.exr"});
}

}  // namespace
}  // namespace rdm
