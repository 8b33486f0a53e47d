// A real `rdm serve` child process on an ephemeral loopback port, for tests that talk to
// the daemon over HTTP (the binary is RDM_BINARY), and the helpers those tests share. A
// helper that cannot go on throws: GoogleTest then fails the one test that called it and
// runs the next, where an RDM_CHECK would end the whole binary.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <map>
#include <tuple>

#include <nlohmann/json.hpp>

#include "rdm/atlas/atlas.h"
#include "rdm/image/exr_io.h"
#include "rdm/service/client.h"

namespace rdm::test {

// A running `rdm serve`; SIGTERM on destruction. With `log_path` its stderr (the JSON log
// lines) goes to that file instead of the test's.
class ServerProcess {
 public:
  ServerProcess(const std::string& data_dir, const std::vector<std::string>& extra,
                const std::string& log_path = {}) {
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
    std::vector<std::string> args = {RDM_BINARY, "serve", "--data-dir", data_dir, "--port", "0"};
    args.insert(args.end(), extra.begin(), extra.end());
    // One JSON line per request would drown the test's own output; tests of the logs ask.
    if (std::find(extra.begin(), extra.end(), "--log-level") == extra.end())
      args.insert(args.end(), {"--log-level", "warn"});
    pid_ = fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      dup2(fds[1], STDOUT_FILENO);
      close(fds[0]);
      if (!log_path.empty()) {
        const int log = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (log >= 0) dup2(log, STDERR_FILENO);
      }
      std::vector<char*> argv;
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    close(fds[1]);
    FILE* out = fdopen(fds[0], "r");
    char line[256] = {};
    if (fgets(line, sizeof line, out)) {
      std::string s(line);
      size_t colon = s.rfind(':');
      if (s.rfind("listening on http://", 0) == 0 && colon != std::string::npos)
        port_ = std::atoi(s.c_str() + colon + 1);
    }
    fclose(out);
  }
  ~ServerProcess() { stop(SIGTERM); }
  void stop(int sig) {
    if (pid_ <= 0) return;
    kill(pid_, sig);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port_); }

 private:
  pid_t pid_ = -1;
  int port_ = 0;
};

// How long a test waits for a job, in seconds: generous, since sanitizer builds on a loaded
// 2-core CI machine run ten times slower; a passing run never waits this long.
constexpr double kJobWaitSeconds = 300.0;

// The value of `e`, or a std::runtime_error naming `what` and the error.
template <class T>
T must(Expected<T> e, const std::string& what) {
  if (!e.ok()) throw std::runtime_error(what + ": " + e.error());
  return std::move(*e);
}

inline std::unique_ptr<BakeClient> connectClient(const ServerProcess& server,
                                                 const std::string& token = {}) {
  return must(BakeClient::connect(server.url(), token), "connect to " + server.url());
}

inline std::string submit(BakeClient& c, const std::string& scene, const nlohmann::json& request) {
  return must(c.submitBake(scene, request), "submit")["id"];
}

// The job once it ended, expected to have succeeded (an empty object when the wait failed).
inline nlohmann::json waitSucceeded(BakeClient& c, const std::string& job) {
  auto j = c.waitForJob(job, kJobWaitSeconds);
  EXPECT_TRUE(j.ok()) << (j.ok() ? "" : j.error());
  if (!j.ok()) return nlohmann::json::object();
  EXPECT_EQ((*j)["state"], "succeeded") << j->dump(1);
  return *j;
}

// Per-RDM texels of a job's atlas, keyed by (slot, level).
inline std::map<std::tuple<int, int, int, int>, std::vector<float>> texelsByRdm(
    BakeClient& c, const std::string& job) {
  LoadedAtlas atlas;
  atlas.layout = *parseIndexJson(*c.download(job, "index.json"));
  atlas.pages.push_back(*decodeExr(*c.download(job, "atlas.exr"), kRgbzChannels));
  std::map<std::tuple<int, int, int, int>, std::vector<float>> out;
  for (const AtlasEntry& e : atlas.layout.entries)
    out[{e.id.slot.x, e.id.slot.y, e.id.slot.z, e.id.level}] = rdmTexels(atlas, e).pixels;
  return out;
}

// Every RDM of job `got` equals the same RDM of job `want` bit for bit (the tiles may differ).
inline void expectSameRdms(BakeClient& c, const std::string& want_job, const std::string& got_job) {
  auto want = texelsByRdm(c, want_job), got = texelsByRdm(c, got_job);
  ASSERT_EQ(want.size(), got.size());
  for (const auto& [key, texels] : want) {
    ASSERT_TRUE(got.count(key));
    EXPECT_EQ(0, std::memcmp(texels.data(), got[key].data(), texels.size() * sizeof(float)))
        << "RDM slot " << std::get<0>(key) << "," << std::get<1>(key) << "," << std::get<2>(key)
        << " level " << std::get<3>(key);
  }
}

}  // namespace rdm::test
