// Running `rdm` as a child the test signals: started in the background with its output in a
// file, watched for a line, and waited for with a deadline.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cli_run.h"
#include "rdm/base/file_util.h"

namespace rdm {

// Starts `rdm ARGS...` with stdout and stderr into the file `log`; returns the pid.
inline pid_t spawnRdm(const std::vector<std::string>& args, const std::string& log) {
  pid_t pid = fork();
  if (pid == 0) {
    FILE* f = std::freopen(log.c_str(), "w", stderr);
    (void)f;
    dup2(STDERR_FILENO, STDOUT_FILENO);
    std::vector<std::string> all = {RDM_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

// True once `log` contains `part`, polled every 20 ms for at most `seconds`.
inline bool waitForLog(const std::string& log, const std::string& part, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    auto text = readFileToString(log);
    if (text.ok() && contains(*text, part)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

// The wait status of `pid` once it ends within `seconds`; else it is killed (SIGKILL) and
// reaped, and nullopt says it did not end by itself.
inline std::optional<int> waitForExit(pid_t pid, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (waitpid(pid, &status, WNOHANG) == pid) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  return std::nullopt;
}

}  // namespace rdm
