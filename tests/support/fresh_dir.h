// A test's own empty directory under the GoogleTest temp dir:
// TempDir/<prefix>_<pid>_<name>, removed first if a previous run left it.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace rdm::test {

inline std::string freshTestDir(const std::string& prefix, const std::string& name) {
  const std::string dir =
      testing::TempDir() + "/" + prefix + "_" + std::to_string(getpid()) + "_" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace rdm::test
