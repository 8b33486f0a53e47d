// Waiting costs no thread, slow clients are cut by a least rate (docs/api.md, "Long polls",
// "Slow clients"): each against a real `rdm serve` on an ephemeral loopback port. Latency
// targets are the (50 ms p99); under sanitizers the bound is ten times looser. The
// measured figures are printed and recorded in docs/deploy.md.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <filesystem>
#include <thread>
#include <vector>

#include "fresh_dir.h"
#include "raw_http.h"
#include "rdm/scene/scene.h"
#include "rdm/service/client.h"
#include "server_fixtures.h"
#include "server_process.h"
#include "test_requirements.h"

namespace rdm {
namespace {

using nlohmann::json;
using test::chessJson;
using test::connectClient;
using test::openConnection;
using test::readAll;
using test::secondsSince;
using test::ServerProcess;
using test::statusOf;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

constexpr double kSlowdown = test::kSanitized ? 10.0 : 1.0;

std::string freshDir(const std::string& name) {
  return test::freshTestDir("longpoll", name);
}

// Opens `count` connections that each long-poll `job` for up to 30 s.
std::vector<int> parkPolls(int port, const std::string& job, int count) {
  const std::string request = "GET /v1/jobs/" + job + "?wait=30 HTTP/1.1\r\nHost: x\r\n\r\n";
  std::vector<int> fds;
  for (int i = 0; i < count; ++i) {
    const int fd = openConnection(port);
    EXPECT_GE(fd, 0);
    if (fd < 0) continue;
    send(fd, request.data(), request.size(), MSG_NOSIGNAL);
    fds.push_back(fd);
  }
  return fds;
}

// The 99th percentile of `n` GETs of `path`, in seconds; every answer must be 200.
double p99Seconds(BakeClient& c, const std::string& path, int n) {
  std::vector<double> t;
  for (int i = 0; i < n; ++i) {
    const auto start = Clock::now();
    auto r = c.get(path);
    t.push_back(secondsSince(start));
    EXPECT_TRUE(r.ok() && r->status == 200) << path;
  }
  std::sort(t.begin(), t.end());
  return t[std::min(t.size() - 1, size_t(0.99 * double(t.size())))];
}

bool answered(int fd) {
  pollfd p{fd, POLLIN, 0};
  return poll(&p, 1, 0) > 0;
}

// 8 and then 200 parked long polls with two HTTP workers: health, metrics and plain polls
// stay fast, no poll is answered before its job changes, and SIGTERM answers all at once.
TEST(ServerLongPoll, ParkedPollsHoldNoWorkerAndStopAnswersThemAll) {
  ServerProcess server(freshDir("parked"), {"--threads", "1", "--http-threads", "2"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(chessJson(256, 16)), "upload")["id"];
  const std::string job = test::must(c->submitBake(scene, json::object()), "submit")["id"];
  std::vector<int> polls;
  for (int count : {8, 200}) {
    std::vector<int> more = parkPolls(server.port(), job, count - int(polls.size()));
    polls.insert(polls.end(), more.begin(), more.end());
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    const double health = p99Seconds(*c, "/healthz", 100);
    const double metrics = p99Seconds(*c, "/metrics", 20);
    const double status = p99Seconds(*c, "/v1/jobs/" + job, 20);
    std::printf("[ long poll ] %d parked: p99 /healthz %.1f ms, /metrics %.1f ms, job %.1f ms\n",
                count, health * 1e3, metrics * 1e3, status * 1e3);
    EXPECT_LT(health, 0.050 * kSlowdown);
    EXPECT_LT(status, 0.250 * kSlowdown);  // on the two workers the polls do not hold
  }
  auto now = test::must(c->get("/v1/jobs/" + job), "status");
  ASSERT_NE(json::parse(now.body)["state"], "succeeded") << "the job must outlive the polls";
  int early = 0;
  for (int fd : polls) early += answered(fd) ? 1 : 0;
  EXPECT_EQ(early, 0);
  const auto stop = Clock::now();
  server.stop(SIGTERM);
  const double stop_s = secondsSince(stop);
  int ok = 0;
  for (int fd : polls) {
    ok += statusOf(readAll(fd, 2.0)) == 200 ? 1 : 0;
    close(fd);
  }
  std::printf("[ long poll ] SIGTERM with %zu parked polls: exited in %.2f s, %d answered 200\n",
              polls.size(), stop_s, ok);
  EXPECT_EQ(ok, int(polls.size()));
  EXPECT_LT(stop_s, 5.0 * kSlowdown);
}

// A parked poll is answered when its job ends, not at its deadline.
TEST(ServerLongPoll, ParkedPollAnswersWhenTheJobEnds) {
  ServerProcess server(freshDir("ends"), {"--threads", "1"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(chessJson(2, 4)), "upload")["id"];
  const std::string job = test::must(c->submitBake(scene, json::object()), "submit")["id"];
  const auto start = Clock::now();
  std::vector<int> fd = parkPolls(server.port(), job, 1);
  ASSERT_EQ(fd.size(), 1u);
  const std::string reply = readAll(fd[0], 60.0);
  close(fd[0]);
  const double waited = secondsSince(start);
  ASSERT_EQ(statusOf(reply), 200) << reply;
  const json body = json::parse(reply.substr(reply.find("\r\n\r\n") + 4));
  EXPECT_EQ(body["state"], "succeeded") << body;
  EXPECT_LT(waited, 29.0);
}

// A body dripped at 1 byte per 100 ms loses its connection soon after the grace; nine
// clients that never read a result do not delay /healthz, and free their workers after
// about the grace plus what the socket buffers took at the least rate.
TEST(ServerSlowClients, DrippedBodiesAndUnreadResponsesAreCutByTheLeastRate) {
  ServerProcess server(freshDir("slow"), {"--threads", "1", "--http-threads", "2", "--min-rate",
                                          "65536", "--rate-grace", "1"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(chessJson(2, 16)), "upload")["id"];
  const std::string job = test::must(c->submitBake(scene, json::object()), "submit")["id"];
  ASSERT_TRUE(c->waitForJob(job, test::kJobWaitSeconds).ok());
  const int drip = openConnection(server.port());
  const std::string head =
      "POST /v1/scenes HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
      "Content-Length: 100000\r\n\r\n";
  send(drip, head.data(), head.size(), MSG_NOSIGNAL);
  std::vector<int> readers;
  const std::string get = "GET /v1/jobs/" + job + "/atlas.exr HTTP/1.1\r\nHost: x\r\n\r\n";
  for (int i = 0; i < 9; ++i) {
    readers.push_back(openConnection(server.port(), 4096));
    send(readers.back(), get.data(), get.size(), MSG_NOSIGNAL);
  }
  const auto start = Clock::now();
  bool cut = false;
  while (!cut && secondsSince(start) < 10.0 * kSlowdown) {
    cut = send(drip, "{", 1, MSG_NOSIGNAL) < 0 || answered(drip);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const double drip_s = secondsSince(start);
  const double health = p99Seconds(*c, "/healthz", 50);  // the readers may still hold workers
  const auto plain_start = Clock::now();
  auto plain = c->get("/v1/jobs/" + job);  // queued behind the readers on the two workers
  const double plain_s = secondsSince(plain_start);
  std::printf(
      "[ slow clients ] dripped body cut after %.2f s; with 9 unread atlases /healthz "
      "p99 %.1f ms, a job status behind them %.2f s\n",
      drip_s, health * 1e3, plain_s);
  EXPECT_TRUE(cut);
  EXPECT_LT(drip_s, 4.0 * kSlowdown);  // grace 1 s + 1 byte/65536 per s, plus polling
  EXPECT_LT(health, 0.050 * kSlowdown);
  EXPECT_TRUE(plain.ok() && plain->status == 200);
  EXPECT_LT(plain_s, 20.0 * kSlowdown);  // each reader holds a worker about 1 s + buffers/rate
  close(drip);
  for (int fd : readers) close(fd);
}

}  // namespace
}  // namespace rdm
