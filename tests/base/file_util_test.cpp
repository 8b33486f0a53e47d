// Atomic writes (rdm/base/file_util.h): a reader sees the old file or the whole new one, and
// nothing is left behind, also with several writers of one path at once.
#include "rdm/base/file_util.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

namespace rdm {
namespace {

namespace fs = std::filesystem;

std::string freshDir(const std::string& name) {
  const std::string dir = testing::TempDir() + "/file_util_" + std::to_string(getpid()) + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// With one temp name per path, a second writer truncated the first one's temp file or
// renamed it away before the first could, so writes failed or the file held a mix.
TEST(FileUtil, ConcurrentWritersOfOnePathNeverTearItOrFail) {
  const std::string dir = freshDir("concurrent");
  const std::string path = dir + "/job.json";
  constexpr int kWriters = 4, kWrites = 200;
  std::vector<std::string> contents;
  for (int w = 0; w < kWriters; ++w) contents.push_back(std::string(4096 + w, char('a' + w)));
  std::vector<int> failures(kWriters, 0);
  std::vector<std::thread> writers;
  for (int w = 0; w < kWriters; ++w) {
    writers.emplace_back([&, w] {
      for (int i = 0; i < kWrites; ++i) {
        if (!writeFileAtomic(path, contents[size_t(w)], Durability::kRenameOnly).ok())
          ++failures[size_t(w)];
      }
    });
  }
  for (std::thread& t : writers) t.join();
  for (int w = 0; w < kWriters; ++w) EXPECT_EQ(failures[size_t(w)], 0) << "writer " << w;
  auto text = readFileToString(path);
  ASSERT_TRUE(text.ok());
  EXPECT_NE(std::find(contents.begin(), contents.end(), *text), contents.end());
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1)
      << "a temp file was left behind";
}

TEST(FileUtil, AFailedWriteLeavesNoTempFile) {
  const std::string dir = freshDir("failed");
  EXPECT_FALSE(writeFileAtomic(dir + "/missing/sub/file.txt", "x").ok());
  EXPECT_TRUE(fs::is_empty(dir));
}

}  // namespace
}  // namespace rdm
