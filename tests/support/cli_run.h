// Running the rdm binary from tests: exit code, stdout and stderr of one process.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "rdm/base/file_util.h"

namespace rdm {

struct CliResult {
  int code = -1;
  std::string out, err;
};

inline std::string tempDir(const std::string& name) {
  std::string dir = testing::TempDir() + "/cli_" + std::to_string(getpid()) + "_" + name;
  std::filesystem::remove_all(dir);
  return dir;
}

// Runs `rdm ARGS` through the shell, stdin from /dev/null.
inline CliResult runRdm(const std::string& args) {
  static int counter = 0;
  const std::string base = testing::TempDir() + "/cli_capture_" + std::to_string(getpid()) + "_" +
                           std::to_string(counter++);
  const std::string cmd =
      std::string(RDM_BINARY) + " " + args + " < /dev/null > " + base + ".out 2> " + base + ".err";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  auto out = readFileToString(base + ".out"), err = readFileToString(base + ".err");
  r.out = out ? *out : "";
  r.err = err ? *err : "";
  std::filesystem::remove(base + ".out");
  std::filesystem::remove(base + ".err");
  return r;
}

inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace rdm
