// Child processes of the window tests: rdm-viewer (or any program) with its output in a file,
// a private Xvfb server, and waiting for a line of a child's output.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "rdm/base/file_util.h"

namespace rdm::viewer::window_test {

// A child process (argv[0] a path, or a name looked up in PATH) with `display` as DISPLAY
// and stdout and stderr to `out` (/dev/null when empty); it inherits this process's other
// descriptors. SIGTERM on destruction.
class Child {
 public:
  Child(std::vector<std::string> argv, const std::string& display, const std::string& out) {
    pid_ = fork();
    if (pid_ != 0) return;
    if (!display.empty()) setenv("DISPLAY", display.c_str(), 1);
    const std::string path = out.empty() ? "/dev/null" : out;
    if (FILE* f = std::fopen(path.c_str(), "w")) {
      dup2(fileno(f), STDOUT_FILENO);
      dup2(fileno(f), STDERR_FILENO);
    }
    std::vector<char*> args;
    for (std::string& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    waitpid(pid_, nullptr, 0);
  }
  bool running() {
    if (pid_ > 0 && waitpid(pid_, nullptr, WNOHANG) != 0) pid_ = -1;  // ended (and reaped)
    return pid_ > 0;
  }

 private:
  pid_t pid_ = -1;
};

// An Xvfb server on a free display number (-displayfd: it writes the number once it accepts
// clients); its name (":N") is empty when it did not start.
class Xvfb {
 public:
  Xvfb() {
    int fds[2];
    if (pipe(fds) != 0) return;
    server_.emplace(std::vector<std::string>{"Xvfb", "-displayfd", std::to_string(fds[1]),
                                             "-screen", "0", "1280x720x24", "-nolisten", "tcp"},
                    "", "");
    close(fds[1]);
    FILE* in = fdopen(fds[0], "r");
    char line[32] = {};
    if (std::fgets(line, sizeof line, in) && line[0] >= '0' && line[0] <= '9')
      display_ = ":" + std::string(line, std::strcspn(line, "\n"));
    std::fclose(in);
  }
  const std::string& display() const { return display_; }

 private:
  std::optional<Child> server_;
  std::string display_;
};

// The exit status of `cmd` run by the shell, its output discarded; -1 when it did not exit.
inline int shell(const std::string& cmd) {
  const int status = std::system((cmd + " > /dev/null 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::string fileText(const std::string& path) {
  auto text = readFileToString(path);
  return text.ok() ? *text : std::string();
}

// The file's text once `needle` occurs in it, or what it holds after `seconds` or once
// `child` ended.
inline std::string waitForLine(const std::string& path, const std::string& needle, Child& child,
                               double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (;;) {
    const std::string text = fileText(path);
    if (text.find(needle) != std::string::npos || !child.running() ||
        std::chrono::steady_clock::now() > deadline)
      return text;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

}  // namespace rdm::viewer::window_test
